"""Type stubs for the ``footprint`` package (see ``__init__.py`` for the conventions)."""

import os
from typing import Any, Iterable, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

SAMPLE_TYPES: Tuple[type, ...]

PathLike = Union[str, "os.PathLike[str]"]

def render(
    volume: Any,
    spacing: Sequence[float] = ...,
    size: Sequence[int] = ...,
    view: Sequence[float] = ...,
    tf: Optional[str] = ...,
    window: Optional[Sequence[float]] = ...,
    dtype: npt.DTypeLike = ...,
    **flags: Any,
) -> np.ndarray: ...
def render_stream(
    sheets: Iterable[npt.ArrayLike],
    dims: Sequence[int],
    spacing: Sequence[float] = ...,
    dtype: npt.DTypeLike = ...,
    size: Sequence[int] = ...,
    view: Sequence[float] = ...,
    tf: Optional[str] = ...,
    window: Optional[Sequence[float]] = ...,
    image_dtype: npt.DTypeLike = ...,
    **flags: Any,
) -> np.ndarray: ...
def depth_map(
    volume: Any,
    spacing: Sequence[float] = ...,
    size: Sequence[int] = ...,
    view: Sequence[float] = ...,
    tf: Optional[str] = ...,
    window: Optional[Sequence[float]] = ...,
    **flags: Any,
) -> np.ndarray: ...
def probe(
    volume: Any,
    at: Sequence[int],
    spacing: Sequence[float] = ...,
    size: Sequence[int] = ...,
    view: Sequence[float] = ...,
    tf: Optional[str] = ...,
    window: Optional[Sequence[float]] = ...,
    **flags: Any,
) -> dict: ...
def load(path: PathLike, **flags: Any) -> Tuple[np.ndarray, Tuple[float, float, float], dict]: ...
def verify(
    volume: Any = ...,
    spacing: Sequence[float] = ...,
    size: Sequence[int] = ...,
    view: Sequence[float] = ...,
    tf: Optional[str] = ...,
    window: Optional[Sequence[float]] = ...,
    **flags: Any,
) -> dict: ...
def bench(
    volume: Any = ...,
    spacing: Sequence[float] = ...,
    size: Sequence[int] = ...,
    view: Sequence[float] = ...,
    tf: Optional[str] = ...,
    window: Optional[Sequence[float]] = ...,
    **flags: Any,
) -> dict: ...
def generic_table(kernel: str = ..., size: int = ...) -> np.ndarray: ...
def save_table(path: PathLike, kernel: str = ..., size: int = ...) -> None: ...
def time_table(
    volume: Any,
    table: int,
    kernel: str = ...,
    frames: int = ...,
    reference: str = ...,
    **flags: Any,
) -> dict: ...
