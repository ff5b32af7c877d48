#!/usr/bin/env python3
"""VTK's camera and Footprint's `--view` agree: silhouettes of one volume, rendered by VTK (pip `vtk`,
its CPU ray caster, parallel projection) and by Footprint, overlap with intersection over union
>= 0.95 for every view.

    python3 tests/writers/vtk_camera.py FOOTPRINT_BINARY OUTDIR

The volume is an asymmetric shape (an L of two blocks and a ball, on an anisotropic grid), so a
mirrored, rotated or wrongly scaled view cannot pass. VTK is set up as ParaView is: the camera on +z
looking toward -z with +y up, `ResetCamera()`, then `Azimuth`, `Elevation`, `Roll` (and
`ResetCamera()` again, which keeps the direction and fits the bounds); the six direction views as
ParaView's buttons set them (focal point, position and view-up, then `ResetCamera()`). Both render a
binary opacity step at the same threshold on black; a silhouette is where the red channel exceeds
half. Offscreen rendering needs EGL (Debian `libegl-mesa0`) or OSMesa (`libosmesa6`).
"""
import os
import subprocess
import sys

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

import numpy as np  # noqa: E402
import vtk  # noqa: E402
from vtk.util import numpy_support  # noqa: E402

# Fine voxels (about half a pixel): the two reconstructions differ at the border by about a voxel
# (VTK classifies after interpolating, Footprint splats classified voxels, whose kernel tails add
# up along rays grazing a face), which must stay small against the shape for IoU to measure the
# camera.
F = 4
DIMS = (48 * F, 36 * F, 24 * F)
SPACING = (1.0 / F, 1.25 / F, 1.5 / F)
SIZE = (200, 160)
ANGLES = [(0, 0, 0), (30, 20, 0), (-60, 45, 30), (120, -30, -45), (200, 70, 10), (75, -40, 20),
          (10, 120, 0)]
DIRECTIONS = {"+x": ((1, 0, 0), (0, 0, 1)), "-x": ((-1, 0, 0), (0, 0, 1)),
              "+y": ((0, 1, 0), (0, 0, 1)), "-y": ((0, -1, 0), (0, 0, 1)),
              "+z": ((0, 0, 1), (0, 1, 0)), "-z": ((0, 0, -1), (0, 1, 0))}


def volume():
    """u8 [z, y, x]: 100 inside the shape, 0 outside."""
    z, y, x = np.meshgrid(*(np.arange(n) / F for n in DIMS[::-1]), indexing="ij")
    a = (x >= 4) & (x <= 40) & (y >= 4) & (y <= 12) & (z >= 4) & (z <= 19)
    b = (x >= 4) & (x <= 12) & (y >= 4) & (y <= 31) & (z >= 4) & (z <= 11)
    c = (x - 33) ** 2 + ((y - 25) * 1.25) ** 2 + ((z - 15) * 1.5) ** 2 <= 36
    return np.where(a | b | c, 100, 0).astype(np.uint8)


def vtk_render(data, view, path):
    img = vtk.vtkImageData()
    img.SetDimensions(*DIMS)
    img.SetSpacing(*SPACING)
    arr = numpy_support.numpy_to_vtk(data.ravel(), deep=True, array_type=vtk.VTK_UNSIGNED_CHAR)
    img.GetPointData().SetScalars(arr)
    mapper = vtk.vtkFixedPointVolumeRayCastMapper()
    mapper.SetInputData(img)
    mapper.SetSampleDistance(0.1)
    mapper.AutoAdjustSampleDistancesOff()
    colour = vtk.vtkColorTransferFunction()
    colour.AddRGBPoint(0, 1, 1, 1)
    colour.AddRGBPoint(100, 1, 1, 1)
    opacity = vtk.vtkPiecewiseFunction()
    opacity.AddPoint(0, 0)
    opacity.AddPoint(49.5, 0)
    opacity.AddPoint(50.5, 1)
    opacity.AddPoint(100, 1)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(colour)
    prop.SetScalarOpacity(opacity)
    prop.SetInterpolationTypeToLinear()
    vol = vtk.vtkVolume()
    vol.SetMapper(mapper)
    vol.SetProperty(prop)
    ren = vtk.vtkRenderer()
    ren.AddVolume(vol)
    ren.SetBackground(0, 0, 0)
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.AddRenderer(ren)
    win.SetSize(*SIZE)
    cam = ren.GetActiveCamera()
    cam.ParallelProjectionOn()
    if isinstance(view, str):
        look, up = DIRECTIONS[view]
        cam.SetFocalPoint(0, 0, 0)
        cam.SetPosition(*(-v for v in look))
        cam.SetViewUp(*up)
        ren.ResetCamera()
    else:
        cam.SetFocalPoint(0, 0, 0)
        cam.SetPosition(0, 0, 1)
        cam.SetViewUp(0, 1, 0)
        ren.ResetCamera()
        cam.Azimuth(view[0])
        cam.Elevation(view[1])
        cam.Roll(view[2])
        ren.ResetCamera()
    win.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.ReadFrontBufferOff()
    grab.Update()
    w = vtk.vtkPNGWriter()
    w.SetFileName(path)
    w.SetInputConnection(grab.GetOutputPort())
    w.Write()


def read_png(path):
    r = vtk.vtkPNGReader()
    r.SetFileName(path)
    r.Update()
    out = r.GetOutput()
    w, h, _ = out.GetDimensions()
    a = numpy_support.vtk_to_numpy(out.GetPointData().GetScalars())
    return a.reshape(h, w, -1)


def main(fp, out):
    os.makedirs(out, exist_ok=True)
    data = volume()
    raw = os.path.join(out, "shape.raw")
    data.tofile(raw)
    nhdr = os.path.join(out, "shape.nhdr")
    with open(nhdr, "w") as f:
        f.write(f"NRRD0004\ntype: uint8\ndimension: 3\nsizes: {DIMS[0]} {DIMS[1]} {DIMS[2]}\n"
                f"spacings: {SPACING[0]} {SPACING[1]} {SPACING[2]}\nencoding: raw\n"
                f"data file: shape.raw\n")
    tf = os.path.join(out, "step.tf")
    with open(tf, "w") as f:
        f.write("0 1 1 1 0\n0.495 1 1 1 0\n0.505 1 1 1 1\n1 1 1 1 1\n")
    worst = 1.0
    failed = []
    for view in ANGLES + list(DIRECTIONS):
        label = view if isinstance(view, str) else ",".join(str(v) for v in view)
        vpath = os.path.join(out, f"vtk_{label}.png")
        fpath = os.path.join(out, f"footprint_{label}.png")
        vtk_render(data, view, vpath)
        subprocess.run([fp, "render", nhdr, "--view", label, "--size", f"{SIZE[0]}x{SIZE[1]}",
                        "--tf", tf, "--window", "0,100", "--lod", "0", "--out", fpath],
                       check=True, stdout=subprocess.DEVNULL)
        a = read_png(vpath)[..., 0] > 127
        b = read_png(fpath)[..., 0] > 127
        union = np.logical_or(a, b).sum()
        iou = np.logical_and(a, b).sum() / union if union else 0.0
        worst = min(worst, iou)
        print(f"view {label:>14}: IoU {iou:.3f} (VTK {a.sum()} px, Footprint {b.sum()} px)")
        if iou < 0.95:
            failed.append(label)
    print(f"worst IoU {worst:.3f} over {len(ANGLES) + len(DIRECTIONS)} views")
    if failed:
        sys.exit(f"silhouettes disagree (IoU < 0.95) for views {failed}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
