#!/usr/bin/env python3
"""Writes one small volume through the real writers users' files come from, for tests/real_writers.rs.

    python3 tests/writers/make_fixtures.py OUTDIR

Needs (pip, in a venv): vtk (9.x), SimpleITK, nibabel, pynrrd, numpy. `tests/writers/run.sh`
installs them and runs this script and the test.

The volume is 12 x 10 x 8 int16 (x fastest), spacing 1 x 1.5 x 2, with no symmetry, so a flipped or
transposed read cannot pass. Writes:

  original.raw        the samples, little-endian int16, x fastest (what every file must load to)
  manifest.tsv        one line per file: file, writer, orientation, array
                      orientation: `identity`, or `ras` where the writer converts ITK's LPS
                      directions to NIfTI's RAS (x and y negated: the test checks that flip);
                      array: the --array to render, or `-`
  versions.txt        the writers' versions

and every file the manifest names.
"""
import os
import sys

import numpy as np

DIMS = (12, 10, 8)  # x, y, z
SPACING = (1.0, 1.5, 2.0)


def volume():
    """int16 samples indexed [z, y, x] (C order, so x is fastest on disk)."""
    z, y, x = np.meshgrid(*(np.arange(n) for n in DIMS[::-1]), indexing="ij")
    v = 40 * x + 7 * y * y + 3 * z * x + 11 * z - 300 * ((x - 3) ** 2 + (y - 6) ** 2 < 6)
    return v.astype(np.int16)


def main(out):
    os.makedirs(out, exist_ok=True)
    os.chdir(out)
    data = volume()
    data.astype("<i2").tofile("original.raw")
    rows = []
    versions = []

    def add(name, writer, orientation="identity", array="-"):
        assert os.path.exists(name), name
        rows.append((name, writer, orientation, array))

    # --- VTK 9: every XML mode and compressor, both header types; legacy binary and ascii.
    import vtk
    from vtk.util import numpy_support

    versions.append(f"vtk {vtk.vtkVersion.GetVTKVersion()}")
    img = vtk.vtkImageData()
    img.SetDimensions(*DIMS)
    img.SetSpacing(*SPACING)
    arr = numpy_support.numpy_to_vtk(data.ravel(), deep=True, array_type=vtk.VTK_SHORT)
    arr.SetName("density")
    img.GetPointData().SetScalars(arr)
    compressors = {"none": vtk.vtkXMLWriter.NONE, "zlib": vtk.vtkXMLWriter.ZLIB,
                   "lz4": vtk.vtkXMLWriter.LZ4, "lzma": vtk.vtkXMLWriter.LZMA}
    for mode in ("ascii", "binary", "appended-raw", "appended-base64"):
        for cname, ctype in compressors.items():
            if mode == "ascii" and cname != "none":
                continue  # ASCII is never compressed
            for header in ("UInt32", "UInt64"):
                w = vtk.vtkXMLImageDataWriter()
                w.SetInputData(img)
                name = f"vtk-xml-{mode}-{cname}-{header}.vti"
                w.SetFileName(name)
                w.SetCompressorType(ctype)
                if header == "UInt64":
                    w.SetHeaderTypeToUInt64()
                else:
                    w.SetHeaderTypeToUInt32()
                if mode == "ascii":
                    w.SetDataModeToAscii()
                elif mode == "binary":
                    w.SetDataModeToBinary()
                else:
                    w.SetDataModeToAppended()
                    w.SetEncodeAppendedData(1 if mode == "appended-base64" else 0)
                assert w.Write() == 1, name
                add(name, "vtk.vtkXMLImageDataWriter")
    def legacy(image, name, binary):
        w = vtk.vtkStructuredPointsWriter()
        w.SetInputData(image)
        w.SetFileName(name)
        if binary:
            w.SetFileTypeToBinary()
        else:
            w.SetFileTypeToASCII()
        assert w.Write() == 1, name

    for mode in ("binary", "ascii"):
        legacy(img, f"vtk-legacy-{mode}.vtk", mode == "binary")
        add(f"vtk-legacy-{mode}.vtk", "vtk.vtkStructuredPointsWriter")
    # Several point-data arrays (scalars first, then field arrays): --array picks ours.
    multi = vtk.vtkImageData()
    multi.DeepCopy(img)
    decoy = numpy_support.numpy_to_vtk((data.ravel() * 0 + 5).astype(np.float32), deep=True)
    decoy.SetName("decoy")
    multi.GetPointData().SetScalars(decoy)
    vec = numpy_support.numpy_to_vtk(np.zeros((data.size, 3), np.float32), deep=True)
    vec.SetName("velocity")
    multi.GetPointData().AddArray(vec)
    multi.GetPointData().AddArray(arr)
    for mode in ("binary", "ascii"):
        name = f"vtk-legacy-{mode}-arrays.vtk"
        legacy(multi, name, mode == "binary")
        add(name, "vtk.vtkStructuredPointsWriter, three arrays", array="density")
    w = vtk.vtkXMLImageDataWriter()
    w.SetInputData(multi)
    w.SetFileName("vtk-xml-arrays.vti")
    assert w.Write() == 1
    add("vtk-xml-arrays.vti", "vtk.vtkXMLImageDataWriter, three arrays", array="density")

    # --- SimpleITK: MetaImage, NIfTI, NRRD.
    import SimpleITK as sitk

    versions.append(f"SimpleITK {sitk.Version_VersionString()}")
    im = sitk.GetImageFromArray(data)  # [z, y, x] -> image x, y, z
    im.SetSpacing(SPACING)
    for name, compress in (("sitk.mha", False), ("sitk-zlib.mha", True), ("sitk.mhd", False),
                           ("sitk.nrrd", False), ("sitk-gzip.nrrd", True), ("sitk.nhdr", False)):
        sitk.WriteImage(im, name, compress)
        add(name, "SimpleITK.WriteImage" + (" (compressed)" if compress else ""))
    for name, compress in (("sitk.nii", False), ("sitk.nii.gz", True)):
        sitk.WriteImage(im, name, compress)
        # ITK's identity direction is LPS; NIfTI stores RAS, so the writer negates x and y.
        add(name, "SimpleITK.WriteImage (LPS to RAS)", orientation="ras")

    # --- nibabel: NIfTI-1, NIfTI-2, pairs.
    import nibabel as nib

    versions.append(f"nibabel {nib.__version__}")
    xyz = np.ascontiguousarray(data.transpose(2, 1, 0))  # nibabel indexes [x, y, z]
    affine = np.diag([*SPACING, 1.0])
    for cls, names in ((nib.Nifti1Image, ("nib1.nii", "nib1.nii.gz")),
                       (nib.Nifti2Image, ("nib2.nii", "nib2.nii.gz")),
                       (nib.Nifti1Pair, ("nib1-pair.hdr", "nib1-pairgz.img.gz")),
                       (nib.Nifti2Pair, ("nib2-pair.img",)),
                       (nib.AnalyzeImage, ("analyze.hdr",))):
        for name in names:
            nib.save(cls(xyz, affine), name)
            add(name, f"nibabel.{cls.__name__}")

    # --- pynrrd: gzip attached, detached raw and detached gzip.
    import nrrd

    versions.append(f"pynrrd {nrrd.__version__}")
    header = {"spacings": list(SPACING)}
    nrrd.write("pynrrd-gzip.nrrd", xyz, dict(header, encoding="gzip"), index_order="F")
    add("pynrrd-gzip.nrrd", "nrrd.write (gzip)")
    nrrd.write("pynrrd-raw.nrrd", xyz, dict(header, encoding="raw"), index_order="F")
    add("pynrrd-raw.nrrd", "nrrd.write (raw)")
    nrrd.write("pynrrd-detached.nhdr", xyz, dict(header, encoding="raw"), index_order="F",
               detached_header=True)
    add("pynrrd-detached.nhdr", "nrrd.write (detached raw)")
    nrrd.write("pynrrd-detached-gz.nhdr", xyz, dict(header, encoding="gzip"), index_order="F",
               detached_header=True)
    add("pynrrd-detached-gz.nhdr", "nrrd.write (detached gzip)")

    with open("manifest.tsv", "w") as f:
        f.write("# file\twriter\torientation\tarray\n")
        for r in rows:
            f.write("\t".join(r) + "\n")
    with open("versions.txt", "w") as f:
        f.write("\n".join(versions) + "\n")
    print(f"{len(rows)} files from {', '.join(versions)} in {os.getcwd()}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
