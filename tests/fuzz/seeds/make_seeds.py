#!/usr/bin/env python3
"""Writes the seed corpora of the whole-data fuzz targets (load_volume, images, tf_file,
stream_stdin, render) into tests/fuzz/corpus/<target>/. Small valid files of every format and
encoding the loaders read, written by hand here (standard library only) so the seeds are
reproducible: `python3 tests/fuzz/seeds/make_seeds.py`."""
import base64, gzip, os, struct, zlib

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "..", "corpus")
DIMS = (4, 3, 2)
U8 = bytes((7 * i + 3) % 256 for i in range(24))
I16 = struct.pack("<24h", *[(i * 97) % 3000 - 1000 for i in range(24)])
F32 = struct.pack("<24f", *[i * 0.25 - 2.0 for i in range(24)])
EXT = ["nrrd", "nhdr", "vti", "vtk", "mhd", "mha", "nii", "nii.gz", "raw"]


def put(target, name, data):
    d = os.path.join(CORPUS, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


def volume(name, ext, data):
    put("load_volume", name, bytes([EXT.index(ext)]) + data)


def nrrd(ty, enc, payload, extra=""):
    return (
        f"NRRD0004\ntype: {ty}\ndimension: 3\nsizes: 4 3 2\nspacings: 1 1 2\n"
        f"endian: little\nencoding: {enc}\n{extra}\n"
    ).encode() + payload


volume("raw.nrrd", "nrrd", nrrd("uint8", "raw", U8))
volume("gzip.nrrd", "nrrd", nrrd("short", "gzip", gzip.compress(I16)))
volume("ascii.nrrd", "nrrd", nrrd("float", "ascii", " ".join(str(v) for v in U8).encode()))
volume("skip.nrrd", "nrrd", nrrd("uint8", "raw", b"\n\n" + U8, "line skip: 2\n"))
# Detached headers naming themselves, the data in their last bytes: valid with only one file.
volume("detached.nhdr", "nhdr", nrrd("uint8", "raw", U8, "data file: volume.nhdr\nbyte skip: -1\n"))


def vti(array, appended=b"", compressor=""):
    head = (
        '<?xml version="1.0"?>\n<VTKFile type="ImageData" version="0.1" '
        f'byte_order="LittleEndian" header_type="UInt32"{compressor}>\n'
        '<ImageData WholeExtent="0 3 0 2 0 1" Origin="0 0 0" Spacing="1 1 2">\n'
        f'<Piece Extent="0 3 0 2 0 1"><PointData Scalars="s">{array}</PointData></Piece>\n'
        "</ImageData>\n"
    ).encode()
    tail = b"</VTKFile>\n"
    if appended:
        return head + b'<AppendedData encoding="raw">\n_' + appended + b"\n</AppendedData>\n" + tail
    return head + tail


def da(ty, fmt, body="", offset=None):
    off = f' offset="{offset}"' if offset is not None else ""
    return f'<DataArray type="{ty}" Name="s" format="{fmt}"{off}>{body}</DataArray>'


volume("ascii.vti", "vti", vti(da("UInt8", "ascii", " ".join(map(str, U8)))))
volume("binary.vti", "vti", vti(da("Int16", "binary", base64.b64encode(struct.pack("<I", len(I16)) + I16).decode())))
z = zlib.compress(F32)
zhead = struct.pack("<4I", 1, len(F32), len(F32), len(z))
volume(
    "zlib.vti",
    "vti",
    vti(da("Float32", "binary", (base64.b64encode(zhead) + base64.b64encode(z)).decode()),
        compressor=' compressor="vtkZLibDataCompressor"'),
)
volume("appended.vti", "vti", vti(da("UInt8", "appended", offset=0), appended=struct.pack("<I", 24) + U8))


def vtk(mode, ty, payload):
    return (
        f"# vtk DataFile Version 3.0\nseed\n{mode}\nDATASET STRUCTURED_POINTS\nDIMENSIONS 4 3 2\n"
        f"ORIGIN 0 0 0\nSPACING 1 1 2\nPOINT_DATA 24\nSCALARS s {ty} 1\nLOOKUP_TABLE default\n"
    ).encode() + payload


volume("binary.vtk", "vtk", vtk("BINARY", "short", struct.pack(">24h", *struct.unpack("<24h", I16))))
volume("ascii.vtk", "vtk", vtk("ASCII", "float", "\n".join(str(v) for v in U8).encode() + b"\n"))


def meta(ty, payload, extra=""):
    return (
        f"ObjectType = Image\nNDims = 3\nDimSize = 4 3 2\nElementSpacing = 1 1 2\n"
        f"ElementType = {ty}\nElementByteOrderMSB = False\n{extra}ElementDataFile = LOCAL\n"
    ).encode() + payload


volume("local.mha", "mha", meta("MET_UCHAR", U8))
volume("zlib.mha", "mha", meta("MET_SHORT", zlib.compress(I16), f"CompressedData = True\nCompressedDataSize = {len(zlib.compress(I16))}\n"))
volume("detached.mhd", "mhd", meta("MET_UCHAR", U8, "HeaderSize = -1\n").replace(b"LOCAL", b"volume.mhd"))


def nifti(datatype, bitpix, payload, sform=True):
    h = bytearray(352)
    struct.pack_into("<i", h, 0, 348)
    struct.pack_into("<8h", h, 40, 3, *DIMS, 1, 1, 1, 1)
    struct.pack_into("<hh", h, 70, datatype, bitpix)
    struct.pack_into("<4f", h, 76, 1, 1, 1, 2)
    struct.pack_into("<f", h, 108, 352.0)
    struct.pack_into("<ff", h, 112, 2.0, -1.0)
    if sform:
        struct.pack_into("<hh", h, 252, 0, 1)
        struct.pack_into("<12f", h, 280, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 2, 0)
    else:
        struct.pack_into("<hh", h, 252, 1, 0)
        struct.pack_into("<3f", h, 256, 0, 0, 0.7071068)
    h[344:348] = b"n+1\0"
    return bytes(h) + payload


volume("sform.nii", "nii", nifti(2, 8, U8))
volume("qform.nii", "nii", nifti(4, 16, I16, sform=False))
volume("float.nii.gz", "nii.gz", gzip.compress(nifti(16, 32, F32)))
volume("u8.raw", "raw", bytes([4 - 1, 3 - 1, 2 - 1, 0]) + U8)
volume("i16be.raw", "raw", bytes([4 - 1, 3 - 1, 2 - 1, 3 | 8]) + struct.pack(">24h", *struct.unpack("<24h", I16)))

# images: 0 = PFM, 1 = PNG.
pfm = b"Pf\n3 2\n-1.0\n" + struct.pack("<6f", 0, 0.5, 1, 2, -1, 3)
put("images", "grey-pfm", b"\0" + pfm)


def png(w, h, colour, depth, rows):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    raw = b"".join(b"\0" + r for r in rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, colour, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


put("images", "grey.png", b"\1" + png(3, 5, 0, 8, [bytes([10 * r, 20, 30]) for r in range(5)]))
put("images", "rgba.png", b"\1" + png(2, 2, 6, 8, [bytes(range(8)), bytes(range(8, 16))]))
put("images", "rgb16.png", b"\1" + png(2, 1, 2, 16, [bytes(range(12))]))

put("tf_file", "ramp.tf", b"# t r g b a\n0 0 0 0 0\n0.3 1 0.5 0.2 0.05\n1 1 1 1 0.8\n")
put("tf_file", "two.tf", b"0 1 1 1 0\n1 1 1 1 1\n")

put("stream_stdin", "u8", bytes([3, 2, 1, 0]) + U8)
put("stream_stdin", "f32be", bytes([3, 2, 1, 6 | 8]) + struct.pack(">24f", *struct.unpack("<24f", F32)))
put("stream_stdin", "short", bytes([3, 2, 1, 3]) + I16[:30])

# render: dims, spacings, angles, zoom, size, kernel, lookup, LUT, samples (see render.rs).
put("render", "cube", bytes([3, 3, 3, 127, 127, 127, 32, 0, 16, 0, 0, 0, 127, 28, 28, 100, 0, 140, 0, 3]
                           + [0, 0, 0, 0, 255, 128, 64, 40, 255, 255, 255, 200] + list(range(0, 256, 4))[:64]))
put("render", "thin", bytes([5, 1, 2, 250, 127, 60, 96, 0, 64, 0, 200, 0, 180, 40, 20, 200, 1, 2, 1, 2]
                           + [0, 0, 0, 0, 255, 255, 255, 255] + [255] * 10))
put("render", "sinc", bytes([2, 2, 2, 127, 127, 127, 0, 0, 0, 0, 0, 0, 160, 60, 60, 255, 2, 3, 0, 2]
                           + [0, 0, 0, 0, 255, 255, 255, 255] + [255, 0] * 4))

# compressors: pick byte (0 gzip, 1 zlib, 2 LZ4 block, 3 xz, 4 gzip stream, 5 zlib stream), the
# declared size (u32 LE), then the compressed bytes.
import lzma

PLAIN = bytes((i * 37) % 251 for i in range(300)) + bytes(200)
def declared(pick, size, body):
    return bytes([pick]) + struct.pack("<I", size) + body

put("compressors", "gzip", declared(0, len(PLAIN), gzip.compress(PLAIN)))
put("compressors", "zlib", declared(1, len(PLAIN), zlib.compress(PLAIN)))
# An LZ4 block: 15 literals, then a match of offset 1 repeating the last byte 100 times.
LZ4 = bytes([0xF0 | 0x0F, 0]) + bytes(range(15)) + bytes([1, 0, 81]) + bytes([0x00])
put("compressors", "lz4", declared(2, 15 + 100 + 0, LZ4))
put("compressors", "xz", declared(3, len(PLAIN), lzma.compress(PLAIN, format=lzma.FORMAT_XZ, check=lzma.CHECK_CRC64)))
put("compressors", "gzip-stream", declared(4, len(PLAIN), gzip.compress(PLAIN) + gzip.compress(b"")))
put("compressors", "zlib-stream-short", declared(5, len(PLAIN) + 5, zlib.compress(PLAIN)))

# transfer_function: entries - 2 (u8), lo and hi (f32 LE), 4 bytes per entry, then probe values.
def tf(n, lo, hi, entries, probes):
    return bytes([n - 2]) + struct.pack("<ff", lo, hi) + bytes(entries) + struct.pack(f"<{len(probes)}f", *probes)

RAMP = [c for i in range(4) for c in (i * 85, i * 85, i * 85, i * 85)]
put("transfer_function", "ramp", tf(4, 0.0, 1000.0, RAMP, [-1.0, 0.0, 10.0, 500.0, 999.0, 1e30]))
put("transfer_function", "wide", tf(4, -3.4e38, 3.4e38, RAMP, [-3.4e38, 0.0, 1e38, 3.4e38]))
put("transfer_function", "tiny", tf(4, 0.0, 1e-45, RAMP, [0.0, 1e-45, 1.0, -1.0]))
put("transfer_function", "bump", tf(4, 100.0, 200.0, [0, 0, 0, 0, 255, 0, 0, 255, 0, 0, 0, 0, 0, 0, 0, 0], [100.0, 150.0, 199.0]))

# stream_range: type (0 u8 … 7 f64, +8 big-endian), dims - 1 (three bytes, mod 8), offset, file.
put("stream_range", "u8", bytes([0, 3, 2, 1, 0]) + bytes((7 * i) % 256 for i in range(4 * 3 * 2)))
put("stream_range", "i16-offset", bytes([3, 1, 1, 1, 4]) + bytes(4) + I16[:16])
put("stream_range", "f32-be-nan", bytes([6 + 8, 1, 0, 1, 0]) + struct.pack(">4f", 1.5, float("nan"), -2.0, float("inf")))
put("stream_range", "f64-short", bytes([7, 7, 7, 7, 0]) + bytes(64))
