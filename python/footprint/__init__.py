"""Footprint from Python: Westover's footprint-evaluation splatting, numpy in, numpy out.

Every function mirrors the ``footprint`` command line: each keyword argument is one of the
command's flags, named with underscores (``eye_distance`` is ``--eye-distance``), and its value
is typed, not text: a number (``lod=0``, ``slab=1.5``, ``threads=4``), a string for a choice or
a word (``shading="phong"``, ``slicing="image"``, ``lod="auto"``), a tuple for a list
(``size=(256, 256)``, ``window=(0, 100)``), ``True`` for a switch (``refine_sheets=True``), a
path for a file; ``None`` leaves the default. The request is built from those values and checked
as the command line's is (the same checks, the same rules between flags, the same one-line
messages); no flag string is written or parsed on the way.

Conventions (as the command line's):

* A volume is x-fastest in memory: a C-order array is indexed ``volume[z, y, x]`` (its last axis
  is x), a Fortran-order array ``volume[x, y, z]``; both are read where they lie, without a copy.
  A strided view keeps the convention of the array it views (its axis that steps least in
  memory is x) and is copied once, x fastest. An array of the other byte order (``">u2"`` on
  this machine) is copied once into the native order. docs/python.md states what each costs.
* ``spacing`` is (x, y, z) in world units per voxel; ``size`` is (width, height) in pixels;
  ``view`` is VTK's camera, (azimuth, elevation, roll) in degrees.
* Images are (height, width, 4) float32 premultiplied linear RGBA, top row first;
  ``dtype=numpy.uint8`` gives 8-bit RGBA as the command line's PNG holds it (linear, alpha kept).
* Sample types: uint8, int8, uint16, int16, uint32, int32, float32, float64.
* Errors: ``ValueError`` for bad input, ``MemoryError`` where memory refuses, ``OSError`` for files.
* Rendering releases the GIL: Python threads render at once.
"""

from __future__ import annotations

import json
import os
import tempfile
from typing import Any, Iterable, Mapping, Optional, Sequence, Tuple

import numpy as np

from . import _footprint

__all__ = [
    "render",
    "render_stream",
    "depth_map",
    "probe",
    "load",
    "verify",
    "bench",
    "generic_table",
    "save_table",
    "time_table",
    "SAMPLE_TYPES",
]

#: The sample types a volume may have.
SAMPLE_TYPES = (
    np.uint8,
    np.int8,
    np.uint16,
    np.int16,
    np.uint32,
    np.int32,
    np.float32,
    np.float64,
)


def _common(size, view, tf, window, flags: dict) -> dict:
    """The keywords of a request: the camera and picture arguments every function names, and the
    rest as given (typed values; the extension checks them as the flags are checked). ``labels``
    may be a mapping of label to (r, g, b, a), passed as the flag's JSON."""
    labels = flags.get("labels")
    if isinstance(labels, Mapping):
        flags = dict(
            flags,
            labels=json.dumps({str(int(k)): [float(c) for c in v] for k, v in labels.items()}),
        )
    return dict(
        flags,
        size=tuple(size),
        view=view if isinstance(view, str) else tuple(view),
        tf=tf,
        window=tuple(window) if window is not None else None,
    )


def _volume_of(volume: Any, spacing):
    """A numpy volume and its spacing from an array or a pyvista.ImageData."""
    if hasattr(volume, "dimensions") and hasattr(volume, "point_data"):
        # pyvista.ImageData (or vtkImageData wrapped by pyvista): its active point scalars, which
        # VTK stores x-fastest, seen as an (x, y, z) Fortran-order array without a copy.
        scalars = volume.active_scalars
        if scalars is None:
            raise ValueError("the ImageData has no active point scalars to render")
        dims = tuple(int(d) for d in volume.dimensions)
        array = np.asarray(scalars)
        if array.ndim != 1:
            raise ValueError("the ImageData's active scalars have several components: render one")
        return array.reshape(dims, order="F"), tuple(float(s) for s in getattr(volume, "spacing", spacing))
    array = np.asarray(volume)
    if array.dtype.byteorder not in ("=", "|") and array.dtype.byteorder != _NATIVE:
        # Another byte order (np.fromfile(f, ">u2"), how raw CT files are read): one copy in
        # the native order, keeping the layout (C, Fortran or the view's own), as large as the
        # array itself.
        array = array.astype(array.dtype.newbyteorder("="), order="K")
    return array, spacing


#: The byte order numpy writes for this machine's native one.
_NATIVE = "<" if np.little_endian else ">"


def _image(image: np.ndarray, dtype) -> np.ndarray:
    if dtype is None or np.dtype(dtype) == np.float32:
        return image
    if np.dtype(dtype) == np.uint8:
        return _footprint.to_rgba8(image)
    raise ValueError(f"dtype {np.dtype(dtype)}: images are float32 or uint8")


def render(
    volume: Any,
    spacing: Sequence[float] = (1, 1, 1),
    size: Sequence[int] = (512, 512),
    view: Sequence[float] = (0, 0, 0),
    tf: Optional[str] = None,
    window: Optional[Sequence[float]] = None,
    dtype: Any = np.float32,
    **flags: Any,
) -> np.ndarray:
    """Renders a 3-D array (or a ``pyvista.ImageData``) as ``footprint render`` would.

    Returns (height, width, 4) premultiplied linear RGBA, float32 (``dtype=numpy.uint8``: 8-bit).
    ``window`` (lo, hi) maps values onto the transfer function; None: the window ``render`` picks
    from the data (Otsu threshold to the 99.5th percentile; ``footprint info`` prints it). ``tf``
    None: ``ct-bone-skin``, as ``footprint render`` on a file.
    Any other ``footprint render`` flag is a keyword (``shading="phong"``, ``threads=2``,
    ``slicing="image"``, ``accum="fixed"``, ``lod=0``, ...). ``labels={1: (1, 0, 0, 0.5), ...}``
    (or a path, or the JSON text) renders an integer label volume in the labels' colours.
    ``coordinates=(x, y, z)`` (each one coordinate per sample, world units, strictly increasing;
    also taken from a ``pyvista.RectilinearGrid``) renders the array on that rectilinear grid,
    each sample's footprint scaled to its own spacings (``spacing`` is then their mean; see
    docs/rectilinear.md). ``out="x.png"`` (or ``.pfm``) and
    ``json="x.json"`` also write the image and the summary as ``footprint render`` does (both or
    neither; the paths are checked before rendering).
    Ctrl-C interrupts the render within a sheet or slab and raises ``KeyboardInterrupt``.
    """
    if hasattr(volume, "x") and hasattr(volume, "z") and hasattr(volume, "point_data"):
        # pyvista.RectilinearGrid: its coordinates, and its scalars as ImageData's are read.
        flags = dict(flags, coordinates=(volume.x, volume.y, volume.z))
    array, spacing = _volume_of(volume, spacing)
    keywords = _common(size, view, tf, window, flags)
    image = _footprint.render_array(array, tuple(float(s) for s in spacing), keywords)
    return _image(image, dtype)


def depth_map(
    volume: Any,
    spacing: Sequence[float] = (1, 1, 1),
    size: Sequence[int] = (512, 512),
    view: Sequence[float] = (0, 0, 0),
    tf: Optional[str] = None,
    window: Optional[Sequence[float]] = None,
    **flags: Any,
) -> np.ndarray:
    """The depth map of the frame :func:`render` draws with the same arguments, as ``footprint
    render --depth-map`` writes it: (height, width) float32, per pixel the screen z where the
    accumulated opacity first reaches 0.5, in world units (0 on the plane through the volume's
    centre, growing away from the viewer), NaN where it never does. Found in the frame's
    continuous model (its f64 march, full resolution), not in the splatted sheets."""
    array, spacing = _volume_of(volume, spacing)
    keywords = _common(size, view, tf, window, flags)
    return _footprint.depth_array(array, tuple(float(s) for s in spacing), keywords)


def probe(
    volume: Any,
    at: Sequence[int],
    spacing: Sequence[float] = (1, 1, 1),
    size: Sequence[int] = (512, 512),
    view: Sequence[float] = (0, 0, 0),
    tf: Optional[str] = None,
    window: Optional[Sequence[float]] = None,
    **flags: Any,
) -> dict:
    """``footprint probe --at X,Y``: where the ray through pixel ``at`` = (x, y) ((0, 0) top
    left) first reaches an accumulated opacity of 0.5. Returns ``{"depth", "world", "value"}``:
    the depth as in :func:`depth_map`, the world point (x, y, z) with the volume's centre at the
    origin, and the volume's value there (trilinear, data units); NaNs where it never does."""
    array, spacing = _volume_of(volume, spacing)
    keywords = _common(size, view, tf, window, flags)
    x, y = (int(a) for a in at)
    depth, world, value = _footprint.probe_pixel(
        array, tuple(float(s) for s in spacing), (x, y), keywords
    )
    return {"depth": depth, "world": world, "value": value}


def render_stream(
    sheets: Iterable[Any],
    dims: Sequence[int],
    spacing: Sequence[float] = (1, 1, 1),
    dtype: Any = np.float32,
    size: Sequence[int] = (512, 512),
    view: Sequence[float] = (0, 0, 0),
    tf: Optional[str] = None,
    window: Optional[Sequence[float]] = None,
    image_dtype: Any = np.float32,
    **flags: Any,
) -> np.ndarray:
    """Renders a volume delivered as z-slices, one 2-D (y, x) array per slice in file order, from
    any iterable (a generator), as ``footprint render --stream -`` renders a pipe: only the
    slices the renderer needs are held (three), so ``window`` must be given (a stream cannot be
    read twice to find its range) and the view must look within 45 degrees of the z axis.
    ``dims`` is (x, y, z), ``dtype`` the slices' sample type (each slice is converted to it).
    An exception the iterable raises comes out as itself (``KeyboardInterrupt``, ``SystemExit``,
    your own); the slices are taken from it on a thread of the renderer's, not the caller's.
    """
    if window is None:
        raise ValueError("render_stream needs window=(lo, hi): a stream cannot be read twice")
    nx, ny, nz = (int(d) for d in dims)
    dtype = np.dtype(dtype)
    if dtype not in [np.dtype(t) for t in SAMPLE_TYPES]:
        raise ValueError(f"dtype {dtype} is not a supported sample type")

    def slices():
        count = 0
        for sheet in sheets:
            a = np.ascontiguousarray(sheet, dtype=dtype)
            if a.shape != (ny, nx):
                raise ValueError(f"slice {count} has shape {a.shape}, expected ({ny}, {nx})")
            count += 1
            yield a

    keywords = _common(size, view, tf, window, flags)
    image = _footprint.render_stream(
        slices(), (nx, ny, nz), dtype.name, tuple(float(s) for s in spacing), keywords
    )
    return _image(image, image_dtype)


def load(path: "os.PathLike[str] | str", **flags: Any) -> Tuple[np.ndarray, Tuple[float, float, float], dict]:
    """Loads a volume file of any format ``footprint`` reads (NRRD, VTI, legacy VTK, MetaImage,
    NIfTI; raw with ``dims=(x, y, z), type="u16"``). Returns (array, spacing, metadata): the
    array C-ordered (z, y, x) in the file's sample type, spacing (x, y, z), and a dict with
    ``dims``, ``type``, ``directions`` (each grid axis's world direction) and ``path``."""
    return _footprint.load(os.fspath(path), flags)


def _command_json(command: str, volume: Any, spacing, size, view, tf, window, flags: dict) -> dict:
    """Runs ``footprint COMMAND`` on ``volume`` (an array, an ImageData, a file path, or None for
    the built-in scene) with ``--json`` to a temporary file, and returns that JSON as a dict."""
    keywords = _common(size, view, tf, window, flags)
    with tempfile.TemporaryDirectory(prefix="footprint-") as d:
        keywords["json"] = os.path.join(d, "out.json")
        if volume is None:
            _footprint.run_measure(command, keywords)
        elif isinstance(volume, (str, os.PathLike)):
            _footprint.run_measure(command, dict(keywords, volume=os.fspath(volume)))
        else:
            array, spacing = _volume_of(volume, spacing)
            _footprint.run_measure(
                command, keywords, array, tuple(float(s) for s in spacing)
            )
        out = keywords["json"]
        with open(out) as f:
            return json.load(f)


def verify(
    volume: Any = None,
    spacing: Sequence[float] = (1, 1, 1),
    size: Sequence[int] = (512, 512),
    view: Sequence[float] = (0, 0, 0),
    tf: Optional[str] = None,
    window: Optional[Sequence[float]] = None,
    **flags: Any,
) -> dict:
    """``footprint verify``: the core's render against a reference (``reference="continuous"``
    for the continuous integral). ``volume`` is an array, an ImageData, a file path, or None for
    the built-in scene. Returns the JSON ``verify --json`` writes, as a dict."""
    return _command_json("verify", volume, spacing, size, view, tf, window, flags)


def bench(
    volume: Any = None,
    spacing: Sequence[float] = (1, 1, 1),
    size: Sequence[int] = (512, 512),
    view: Sequence[float] = (0, 0, 0),
    tf: Optional[str] = None,
    window: Optional[Sequence[float]] = None,
    **flags: Any,
) -> dict:
    """``footprint bench``: ``frames`` frames (``orbit`` degrees apart), timed. ``volume`` as for
    :func:`verify`. Returns the JSON ``bench --json`` writes (``first_ms``, ``median_ms``,
    ``phases_ms``, ...), as a dict."""
    return _command_json("bench", volume, spacing, size, view, tf, window, flags)


def generic_table(kernel: str = "gaussian:spread=1.6,sigmas=2.5", size: int = 129) -> np.ndarray:
    """The generic footprint table of ``kernel`` (a ``--kernel`` spec) at ``size`` x ``size``
    nodes over [-1, 1]^2, normalised to unit integral: float32 (size, size)."""
    return _footprint.generic_table(kernel, int(size))


def save_table(
    path: "os.PathLike[str] | str", kernel: str = "gaussian:spread=1.6,sigmas=2.5", size: int = 129
) -> None:
    """Writes the generic table as ``footprint tables`` does, for ``render(..., table=size,
    table_file=path)``."""
    _footprint.run_command(
        ["tables", "--kernel", kernel, "--size", str(int(size)), "--out", os.fspath(path)]
    )


def time_table(
    volume: Any,
    table: int,
    kernel: str = "gaussian:spread=1.6,sigmas=2.5",
    frames: int = 3,
    reference: str = "continuous",
    **flags: Any,
) -> dict:
    """One table size measured both ways, for charting time against accuracy: ``bench``'s
    median frame (``frames`` frames) and ``verify``'s PSNR against ``reference`` (``"sheets"``,
    the f64 sheet reference, or ``"continuous"``, the continuous integral). Other keywords are
    render flags (``size``, ``view``, ``spacing``, ...). Returns ``{"table", "median_ms",
    "psnr_db", "bench", "verify"}``."""
    common = dict(flags, kernel=kernel, table=int(table))
    b = bench(volume, frames=frames, **common)
    v = verify(volume, reference=reference, **common)
    figure = v["continuous"]["psnr_db"] if reference == "continuous" else v["overall"]["psnr_db"]
    return {"table": int(table), "median_ms": b["median_ms"], "psnr_db": figure, "bench": b, "verify": v}
