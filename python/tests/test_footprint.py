"""The Python package against the command line and its own promises: byte-identical renders, no
copy of the input, streams equal to arrays, the right exceptions, the GIL released.

The command line is `FOOTPRINT_BIN` (CI sets it to the release build), else the workspace's
target/release/footprint; tests that need it fail without it rather than pass silently.
"""

import os
import pathlib
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import footprint

ROOT = pathlib.Path(__file__).resolve().parents[2]
HEART = ROOT / "tests" / "data" / "heart_32x32x12_float32_le.nhdr"


def cli():
    path = os.environ.get("FOOTPRINT_BIN") or str(ROOT / "target" / "release" / "footprint")
    assert os.path.exists(path), f"the footprint binary is not at {path}: build it or set FOOTPRINT_BIN"
    return path


def cli_flags(keywords):
    """The command line's flags for typed keywords, written out by hand (the package itself writes
    no flags: it hands the values over typed)."""
    out = []
    for key, value in keywords.items():
        flag = "--" + key.replace("_", "-")
        if value is True:
            out.append(flag)
        elif isinstance(value, tuple):
            out += [flag, ",".join(str(v) for v in value)]
        else:
            out += [flag, str(value)]
    return out


def blob(shape=(24, 20, 28), dtype=np.uint16):
    """A smooth asymmetric blob, C order (z, y, x)."""
    z, y, x = np.mgrid[0 : shape[0], 0 : shape[1], 0 : shape[2]].astype(np.float64)
    v = 3000 * np.exp(-((x - 11) ** 2 / 40 + (y - 9) ** 2 / 25 + (z - 13) ** 2 / 60))
    v += 800 * (x > 20)
    return v.astype(dtype)


def read_pfm(path):
    data = pathlib.Path(path).read_bytes()
    head, rest = data.split(b"\n", 1)
    assert head == b"PF"
    size, rest = rest.split(b"\n", 1)
    w, h = (int(t) for t in size.split())
    scale, rest = rest.split(b"\n", 1)
    assert float(scale) < 0, "little-endian PFM"
    rgb = np.frombuffer(rest, dtype="<f4").reshape(h, w, 3)
    return np.flipud(rgb)  # PFM rows run bottom to top


def test_the_issue_one_liner():
    out = subprocess.run(
        [sys.executable, "-c", "import footprint, numpy as np; print(footprint.render(np.zeros((8, 8, 8), np.uint8)).shape)"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert out.stdout.strip() == "(512, 512, 4)"


@pytest.mark.parametrize(
    "flags",
    [
        {},
        {"shading": "phong", "view": (30, 20, 0)},
        {"view": (75, -40, 20), "accum": "fixed", "threads": 3},
        {"view": (30, 20, 0), "slicing": "image", "slab": 1},
        {"view": (30, 20, 0), "classification": "post", "reconstruction": "trilinear"},
    ],
)
def test_render_is_byte_identical_to_the_command_line(tmp_path, flags):
    v = blob()
    raw = tmp_path / "v.raw"
    v.astype("<u2").tofile(raw)
    size = (96, 64)
    py = footprint.render(v, spacing=(1, 1.5, 2), size=size, window=(0, 3500), **flags)
    assert py.shape == (64, 96, 4) and py.dtype == np.float32
    args = [cli(), "render", str(raw), "--dims", "28,20,24", "--type", "u16", "--spacing", "1,1.5,2"]
    args += ["--size", "96x64", "--window", "0,3500", "--out", str(tmp_path / "o.pfm")]
    args += cli_flags(flags)
    if "view" not in flags:
        args += ["--view", "0,0,0"]
    subprocess.run(args, check=True, capture_output=True)
    want = read_pfm(tmp_path / "o.pfm")
    assert want.shape == py[..., :3].shape
    assert py[..., 3].max() > 0.1, "something is drawn"
    # Bit for bit, as float32.
    assert np.array_equal(py[..., :3].view(np.uint32), want.view(np.uint32))


def test_fortran_order_is_the_same_volume():
    v = blob()
    a = footprint.render(v, size=(64, 64), view=(30, 20, 0), window=(0, 3500))
    b = footprint.render(np.asfortranarray(v.T), size=(64, 64), view=(30, 20, 0), window=(0, 3500))
    assert np.array_equal(a, b)
    assert footprint._footprint.shares_memory(v) and footprint._footprint.shares_memory(np.asfortranarray(v.T))
    # A strided view is copied (and still renders the same volume as its copy).
    s = v[:, :, ::2]
    assert not footprint._footprint.shares_memory(s)
    assert np.array_equal(
        footprint.render(s, size=(32, 32), window=(0, 3500)),
        footprint.render(np.ascontiguousarray(s), size=(32, 32), window=(0, 3500)),
    )


def test_rendering_does_not_copy_the_volume():
    """Peak memory of rendering a 512³ uint8 array (128 MiB): the array is read in place, so
    the render adds only its own buffers (image, stencils, the visible voxels of a sparse
    volume), far less than a copy (128 MiB, or 512 MiB as float32)."""
    script = textwrap.dedent(
        """
        import resource, numpy as np, footprint
        n = 512
        v = np.zeros((n, n, n), np.uint8)
        v[200:300, 180:330, 150:350] = 200          # a block: most of the volume is empty
        v[...] += 0                                   # every page touched before measuring
        base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        im = footprint.render(v, size=(256, 256), view=(30, 20, 0), window=(0, 255), lod=0, supersample=1, threads=2)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        assert im[..., 3].max() > 0.5
        print(base // 1024, (peak - base) // 1024)
        """
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    base_mib, extra_mib = (int(t) for t in out.stdout.split())
    print(f"512^3 uint8: resident {base_mib} MiB before rendering, {extra_mib} MiB more at the peak")
    assert base_mib >= 128
    assert extra_mib < 64, f"rendering added {extra_mib} MiB: the volume (128 MiB) was copied?"


def test_a_generator_streamed_equals_the_array_rendered():
    v = blob()
    taken = []

    def slices():
        for k in range(v.shape[0]):
            taken.append(k)
            yield v[k]

    # A stream composites in file order (k = 0 first), as a pipe does: back to front where the
    # view looks along -k (0,0,0 and 30,20,0), front to back from the other side (180,0,0).
    for view, order in [((0, 0, 0), "back-to-front"), ((30, 20, 0), "back-to-front"), ((180, 0, 0), "front-to-back")]:
        taken.clear()
        # With nothing left to a pilot the stream is read three slices at a time.
        s = footprint.render_stream(
            slices(), (28, 20, 24), spacing=(1, 1.5, 2), dtype=np.uint16, size=(80, 64), view=view,
            window=(0, 3500), slicing="object", lod=0,
        )
        a = footprint.render(
            v, spacing=(1, 1.5, 2), size=(80, 64), view=view, window=(0, 3500), order=order, slicing="object", lod=0
        )
        assert taken == list(range(24))
        assert np.array_equal(s, a), view


def test_a_generator_with_default_flags_renders_the_arrays_picture():
    """Same evidence, same plan: with the default flags the stream is held (the pilot needs the
    volume) and renders render()'s picture byte for byte, any view (issue 76)."""
    v = blob()
    for view in [(30, 20, 0), (90, 0, 0)]:
        for size in [(128, 128), (96, 64)]:
            s = footprint.render_stream(
                iter(v), (28, 20, 24), spacing=(1, 1.5, 2), dtype=np.uint16, size=size, view=view, window=(0, 3500)
            )
            a = footprint.render(v, spacing=(1, 1.5, 2), size=size, view=view, window=(0, 3500))
            assert np.array_equal(s, a), (view, size)


def test_a_stream_is_read_as_it_renders():
    """Only the slices the renderer needs are held (nothing left to a pilot): a generator that ends early is an error
    before the whole volume could have been gathered, and a side view is refused as a pipe's."""
    v = blob()
    with pytest.raises(ValueError, match="ended"):
        footprint.render_stream(
            iter([v[0], v[1]]), (28, 20, 24), dtype=np.uint16, size=(32, 32), window=(0, 1), slicing="object", lod=0
        )
    with pytest.raises(ValueError, match="ended"):  # held (the default flags): the same refusal
        footprint.render_stream(iter([v[0], v[1]]), (28, 20, 24), dtype=np.uint16, size=(32, 32), window=(0, 1))
    with pytest.raises(ValueError, match="45"):
        footprint.render_stream(
            iter(v), (28, 20, 24), dtype=np.uint16, size=(32, 32), view=(90, 0, 0), window=(0, 1),
            slicing="object", lod=0,
        )
    with pytest.raises(ValueError, match="window"):
        footprint.render_stream(iter(v), (28, 20, 24), dtype=np.uint16)


def test_bad_input_raises_the_right_exception(tmp_path):
    v = blob()
    with pytest.raises(ValueError, match="3"):
        footprint.render(np.zeros((4, 4)))
    with pytest.raises(ValueError, match="complex64"):
        footprint.render(np.zeros((4, 4, 4), np.complex64))
    with pytest.raises(ValueError, match="--shading"):
        footprint.render(v, shading="glossy")
    with pytest.raises(ValueError, match="empty"):
        footprint.render(np.zeros((0, 4, 4), np.uint8))
    with pytest.raises(ValueError, match="spacing"):
        footprint.render(v, spacing=(1, -1, 1))
    with pytest.raises(ValueError, match="finite"):
        footprint.render(np.full((4, 4, 4), np.nan, np.float32))
    with pytest.raises(OSError):
        footprint.load(tmp_path / "missing.nrrd")
    with pytest.raises(ValueError):
        footprint.load(tmp_path)  # a folder
    # Memory refusing is a MemoryError, never a crash (a child under a 2 GiB address space).
    script = "import resource, numpy as np, footprint\n" \
        "resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))\n" \
        "try:\n    footprint.render(np.ones((4, 4, 4), np.uint8), size=(16384, 16384))\n" \
        "except MemoryError as e:\n    print('MemoryError', e)\n"
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.startswith("MemoryError"), (out.stdout, out.stderr)


def test_keywords_are_typed_values_checked_as_flags_are():
    v = blob()
    base = dict(size=(32, 24), window=(0, 3500), view=(30, 20, 0))
    want = footprint.render(v, lod=0, slicing="object", **base)
    # numpy scalars and arrays are values of their kind, not text.
    got = footprint.render(
        v, lod=np.int64(0), slicing="object", **dict(base, size=np.array([32, 24]))
    )
    assert np.array_equal(want, got)
    for keywords, needle in [
        (dict(lod=2.5), "lod=2.5"),
        (dict(lod="coarse"), "expected auto or a level"),
        (dict(slab="2"), "expected a number"),
        (dict(slicing="diagonal"), "expected one of object, image, auto"),
        (dict(glossiness=1), "unknown keyword 'glossiness'"),
        (dict(eye_distance=300), "needs --perspective"),
        (dict(quality=40, table=65), "--table cannot be used with --quality"),
        (dict(refine_sheets=True), "needs --refine"),
        (dict(threads=object()), "not understood"),
    ]:
        with pytest.raises(ValueError, match=needle):
            footprint.render(v, **dict(base, **keywords))
    with pytest.raises(ValueError, match="render_stream sets it"):
        footprint.render_stream(iter([]), (28, 20, 24), window=(0, 1), endian="big")


def test_depth_map_and_probe(tmp_path):
    """The depth of an opaque slab's near face (voxels z = 12 ... 19 of 32: the face 4 world
    units in front of the centre, within a voxel), as the command line writes it."""
    v = np.zeros((32, 32, 32), np.uint8)
    v[12:20] = 255
    tf = tmp_path / "step.tf"
    tf.write_text("0 1 1 1 0\n0.4 1 1 1 0\n0.6 1 1 1 1\n1 1 1 1 1\n")
    kw = dict(size=(48, 40), window=(0, 255), tf=str(tf))
    d = footprint.depth_map(v, **kw)
    assert d.shape == (40, 48) and d.dtype == np.float32
    assert abs(d[20, 24] + 4) <= 1 and np.isnan(d[0, 0])
    p = footprint.probe(v, at=(24, 20), **kw)
    # The probe's march converges on its own ray, the map's on every ray: they agree within it.
    assert p["depth"] == pytest.approx(float(d[20, 24]), abs=0.05)
    assert p["value"] > 0 and abs(abs(p["world"][2]) - 4) <= 1
    assert np.isnan(footprint.probe(v, at=(0, 0), **kw)["depth"])
    raw = tmp_path / "v.raw"
    v.tofile(raw)
    npy = tmp_path / "d.npy"
    subprocess.run(
        [cli(), "render", str(raw), "--dims", "32,32,32", "--type", "u8", "--size", "48x40",
         "--window", "0,255", "--tf", str(tf), "--out", str(tmp_path / "o.png"),
         "--depth-map", str(npy)],
        check=True, capture_output=True,
    )
    assert np.array_equal(np.load(npy), d, equal_nan=True)
    with pytest.raises(ValueError, match="outside"):
        footprint.probe(v, at=(48, 0), **kw)


def test_crop_is_the_volume_with_the_rest_missing():
    """``crop`` (nested pairs or the flag's text) renders the volume whose samples outside the box
    are NaN, bit for bit; an empty range is refused."""
    rng = np.random.default_rng(7)
    v = rng.random((12, 32, 32), dtype=np.float32)
    kw = dict(size=(48, 48), window=(0.2, 1.0), slicing="object", lod=0)
    cropped = footprint.render(v, crop=((3, 20), (0, 31), (1, 10)), **kw)
    masked = np.full_like(v, np.nan)
    masked[1:11, 0:32, 3:21] = v[1:11, 0:32, 3:21]
    assert np.array_equal(cropped, footprint.render(masked, **kw))
    assert np.array_equal(cropped, footprint.render(v, crop="3:20,0:31,1:10", **kw))
    assert not np.array_equal(cropped, footprint.render(v, **kw))
    # A generator streamed through is cropped as it streams: the array's picture.
    streamed = footprint.render_stream(
        (v[k] for k in range(v.shape[0])), (32, 32, 12), crop=((3, 20), (0, 31), (1, 10)), **kw
    )
    assert np.array_equal(streamed, cropped)
    with pytest.raises(ValueError, match="empty"):
        footprint.render(v, crop=((5, 4), (0, 31), (1, 10)), **kw)
    with pytest.raises(ValueError, match="reaches past the volume"):
        footprint.render(v, crop=((0, 32), (0, 31), (1, 10)), **kw)

def test_clip_keywords_are_the_flags_planes():
    """``clip`` takes one plane or a sequence of planes (or the flag's text) and renders what
    the command line's ``--clip`` renders; a zero normal is refused."""
    rng = np.random.default_rng(3)
    v = rng.random((12, 32, 32), dtype=np.float32)
    kw = dict(size=(48, 48), window=(0.2, 1.0), lod=0)
    one = footprint.render(v, clip=(1, 0, 0, 2), **kw)
    assert np.array_equal(one, footprint.render(v, clip=[(1, 0, 0, 2)], **kw))
    assert np.array_equal(one, footprint.render(v, clip="1,0,0,2", **kw))
    assert not np.array_equal(one, footprint.render(v, **kw))
    two = footprint.render(v, clip=[(1, 0, 0, 2), (0, -1, 0, 3)], **kw)
    assert not np.array_equal(one, two)
    with pytest.raises(ValueError, match="normal"):
        footprint.render(v, clip=(0, 0, 0, 1), **kw)


def test_blend_projects_the_values():
    """``blend`` projects the reconstructed values along each ray: under a rising grey ramp the
    maximum is at least the average at every pixel, and the average at least the minimum; an
    unknown blend is refused."""
    rng = np.random.default_rng(5)
    v = rng.random((12, 32, 32), dtype=np.float32)
    kw = dict(size=(48, 48), window=(0.0, 1.0), tf="grey")
    mip, avg, minip = (footprint.render(v, blend=b, **kw) for b in ("mip", "average", "minip"))
    assert not np.array_equal(mip, avg)
    assert (mip[..., 3] >= avg[..., 3] - 1e-6).all()
    assert (avg[..., 3] >= minip[..., 3] - 1e-6).all()
    with pytest.raises(ValueError, match="sum"):
        footprint.render(v, blend="sum", **kw)


def test_threads_release_the_gil():
    # While one thread renders, the main thread keeps running Python: the longest stretch in
    # which it could not run is a small part of the render (with the GIL held it would be all of
    # it). Not a speed ratio, so a loaded machine does not make it fail.
    v = blob((96, 96, 96), np.uint16)
    span = {}

    def one():
        span["start"] = time.perf_counter()
        footprint.render(v, size=(512, 512), view=(30, 20, 0), shading="phong", threads=1, window=(0, 3500))
        span["end"] = time.perf_counter()

    footprint.render(v, size=(64, 64), window=(0, 3500))  # warm-up
    t = threading.Thread(target=one)
    ticks = []
    t.start()
    while t.is_alive():
        ticks.append(time.perf_counter())
    t.join()
    inside = [x for x in ticks if span["start"] <= x <= span["end"]]
    edges = [span["start"], *inside, span["end"]]
    longest = max(b - a for a, b in zip(edges, edges[1:]))
    duration = span["end"] - span["start"]
    print(f"render {duration:.3f} s; the main thread's longest wait during it {longest:.4f} s")
    assert longest < 0.5 * duration, "the main thread could not run during the render: the GIL is held"


def test_load_verify_bench_and_tables(tmp_path):
    a, spacing, meta = footprint.load(HEART)
    assert a.shape == (12, 32, 32) and a.dtype == np.float32 and spacing == (1.0, 1.0, 4.0)
    assert meta["dims"] == (32, 32, 12) and meta["type"] == "float32"
    # The loaded array renders as the file does.
    assert np.array_equal(
        footprint.render(a, spacing=spacing, size=(48, 48)),
        footprint.render(footprint.load(HEART)[0], spacing=spacing, size=(48, 48)),
    )
    d = footprint.verify(a, spacing=spacing, size=(48, 48), reference="continuous")
    assert {"overall", "continuous", "reference", "volume"} <= d.keys()
    assert d["continuous"]["psnr_db"] > 20
    # Object slicing: the sheets the f64 reference draws (the default plan takes slabs here).
    f = footprint.verify(HEART, size=(48, 48), slicing="object")
    assert f["overall"]["psnr_db"] > 40 and f["volume"] == str(HEART)
    b = footprint.bench(a, spacing=spacing, size=(48, 48), frames=3, orbit=2)
    assert {"first_ms", "median_ms", "min_ms", "max_ms", "threads", "phases_ms"} <= b.keys()
    t = footprint.generic_table(size=33)
    assert t.shape == (33, 33) and t.dtype == np.float32 and abs(t[16, 16] - t.max()) < 1e-6
    footprint.save_table(tmp_path / "t.bin", size=33)
    via_file = footprint.render(a, spacing=spacing, size=(48, 48), table=33, table_file=tmp_path / "t.bin")
    assert np.array_equal(via_file, footprint.render(a, spacing=spacing, size=(48, 48), table=33))
    row = footprint.time_table(a, 33, spacing=spacing, size=(48, 48), frames=2)
    assert row["table"] == 33 and row["median_ms"] > 0 and row["psnr_db"] > 10


def test_uint8_images_and_image_data():
    v = blob()
    f = footprint.render(v, size=(40, 40), window=(0, 3500))
    b = footprint.render(v, size=(40, 40), window=(0, 3500), dtype=np.uint8)
    assert b.dtype == np.uint8 and np.array_equal(b, np.round(np.clip(f, 0, 1) * 255).astype(np.uint8))

    class ImageData:
        """What the package reads of a pyvista.ImageData: x-fastest point scalars."""

        def __init__(self, array, spacing):
            self.dimensions = array.shape[::-1]
            self.spacing = spacing
            self.point_data = {"s": array.ravel()}
            self.active_scalars = array.ravel()

    assert np.array_equal(
        footprint.render(ImageData(v, (1, 1.5, 2)), size=(40, 40), window=(0, 3500)),
        footprint.render(v, spacing=(1, 1.5, 2), size=(40, 40), window=(0, 3500)),
    )


def test_views_keep_their_arrays_convention():
    """A strided view of a Fortran-order (x, y, z) array is (x, y, z) too (the third hostile
    campaign read it as (z, y, x), 1.0 apart), and a view of a C-order array (z, y, x)."""
    v = blob()
    f = np.asfortranarray(v.T)[2:26]  # x from 2 to 25 of the (x, y, z) array: not contiguous
    assert not f.flags.c_contiguous and not f.flags.f_contiguous
    want = footprint.render(np.ascontiguousarray(v[:, :, 2:26]), size=(48, 48), view=(30, 20, 0), window=(0, 3500))
    assert np.array_equal(footprint.render(f, size=(48, 48), view=(30, 20, 0), window=(0, 3500)), want)
    c = v[:, :, 2:26]
    assert np.array_equal(footprint.render(c, size=(48, 48), view=(30, 20, 0), window=(0, 3500)), want)


def test_other_byte_orders_render_the_native_picture():
    v = blob()
    want = footprint.render(v, size=(48, 48), view=(30, 20, 0), window=(0, 3500))
    swapped = v.astype(v.dtype.newbyteorder("S"))
    assert np.array_equal(footprint.render(swapped, size=(48, 48), view=(30, 20, 0), window=(0, 3500)), want)
    fortran = np.asfortranarray(swapped.T)
    assert np.array_equal(footprint.render(fortran, size=(48, 48), view=(30, 20, 0), window=(0, 3500)), want)


def test_render_writes_out_and_json(tmp_path):
    v = blob()
    img = footprint.render(v, size=(40, 32), window=(0, 3500), out=tmp_path / "o.pfm", json=tmp_path / "o.json")
    assert np.array_equal(read_pfm(tmp_path / "o.pfm"), img[..., :3])
    import json as _json

    summary = _json.loads((tmp_path / "o.json").read_text())
    assert summary["size"] == [40, 32] and summary["out"] == str(tmp_path / "o.pfm")
    footprint.render(v, size=(40, 32), window=(0, 3500), json=tmp_path / "only.json")
    assert (tmp_path / "only.json").exists()
    with pytest.raises(ValueError, match="cannot write .jpg"):
        footprint.render(v, size=(40, 32), window=(0, 3500), out=tmp_path / "o.jpg")
    assert not (tmp_path / "o.jpg").exists()


def test_a_generators_exception_comes_out_as_itself():
    """KeyboardInterrupt and SystemExit raised by the slices' iterable are raised again as
    themselves, not as ValueError (which `except ValueError` would swallow)."""
    v = blob()

    def failing(exc):
        def slices():
            yield v[0]
            yield v[1]
            raise exc

        return slices()

    class Mine(Exception):
        pass

    for exc in (KeyboardInterrupt, SystemExit, Mine):
        with pytest.raises(exc):
            footprint.render_stream(failing(exc), (28, 20, 24), dtype=np.uint16, size=(32, 32), window=(0, 3500))


def test_ctrl_c_interrupts_a_long_render():
    """SIGINT half a second into a render that takes several seconds raises KeyboardInterrupt
    within a sheet or slab, not when the frame ends (the third campaign waited 21 s)."""
    script = textwrap.dedent(
        """
        import os, signal, threading, time, numpy as np, footprint
        v = (np.random.default_rng(1).random((160, 160, 160)) * 255).astype(np.uint8)
        t0 = time.perf_counter()
        footprint.render(v, size=(64, 64), window=(0, 255), slicing="image", slab=1, threads=1)
        small = time.perf_counter() - t0
        threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT)).start()
        t0 = time.perf_counter()
        try:
            footprint.render(v, size=(1536, 1536), window=(0, 255), slicing="image", slab=0.25, threads=1)
            print("finished", time.perf_counter() - t0)
        except KeyboardInterrupt:
            print("interrupted", time.perf_counter() - t0)
        # The harness is usable again afterwards.
        footprint.render(v[:8, :8, :8], size=(16, 16), window=(0, 255))
        print("again")
        """
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.split()
    assert lines[0] == "interrupted", out.stdout
    assert float(lines[1]) < 3.0, f"KeyboardInterrupt came {lines[1]} s after the render began"
    assert lines[-1] == "again"


def test_labels_colour_a_label_volume():
    """``labels`` (a mapping, or the flag's JSON) renders an integer label volume in the labels'
    colours only: two touching labels red and blue with green in the table show no green; a
    table of labels the volume does not hold renders nothing; lit shading is refused."""
    v = np.zeros((24, 24, 24), dtype=np.uint8)
    v[6:18, 6:18, 4:12] = 1
    v[6:18, 6:18, 12:20] = 3
    table = {1: (1, 0, 0, 0.5), 2: (0, 1, 0, 1), 3: (0, 0, 1, 0.5)}
    kw = dict(size=(48, 48), view=(30, 20, 0))
    image = footprint.render(v, labels=table, **kw)
    assert image[..., 0].max() > 0.1 and image[..., 2].max() > 0.1
    assert image[..., 1].max() == 0.0
    text = '{"1": [1, 0, 0, 0.5], "2": [0, 1, 0, 1], "3": [0, 0, 1, 0.5]}'
    assert np.array_equal(image, footprint.render(v, labels=text, **kw))
    assert not footprint.render(v, labels={9: (1, 1, 1, 1)}, **kw).any()
    with pytest.raises(ValueError, match="unlit"):
        footprint.render(v, labels=table, shading="phong", **kw)


def test_coordinates_render_a_rectilinear_grid():
    """``coordinates=(x, y, z)`` renders the array on a rectilinear grid: even coordinates give
    the uniform grid's object-sliced picture (within the scaled read's rounding), uneven ones
    another picture; a coordinate that repeats, and image-aligned slabs, are refused."""
    z, y, x = np.mgrid[0:20, 0:16, 0:24].astype(np.float32)
    v = 100 * np.exp(-((x - 12) ** 2 / 40 + (y - 8) ** 2 / 30 + (z - 10) ** 2 / 30))
    kw = dict(size=(48, 48), view=(30, 20, 0), window=(10, 90))
    even = (np.arange(24.0), np.arange(16.0), np.arange(20.0))
    uniform = footprint.render(v, slicing="object", **kw)
    assert np.abs(footprint.render(v, coordinates=even, **kw) - uniform).max() < 2e-3
    zs = np.cumsum(np.geomspace(0.5, 2.0, 20)) - 0.5
    uneven = footprint.render(v, coordinates=(even[0], even[1], zs), **kw)
    assert np.abs(uneven - uniform).max() > 0.05
    with pytest.raises(ValueError, match="repeats"):
        footprint.render(v, coordinates=(even[0], even[1], np.zeros(20)), **kw)
    with pytest.raises(ValueError, match="rectilinear grid with --slicing image"):
        footprint.render(v, coordinates=even, slicing="image", **kw)
