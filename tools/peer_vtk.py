#!/usr/bin/python3
"""tools/peer_vtk.py — the VTK peer of `clvr bench --peer`: renders a clvr scene (DESIGN.md scene JSON)
with vtkFixedPointVolumeRayCastMapper offscreen at the scene's image size, times frames after a first
one, and writes its image (PNG) and figures (JSON).

Run it as clvr bench does:  xvfb-run -a /usr/bin/python3 tools/peer_vtk.py SCENE.json [--frames 5]
    [--sample-distance D] [--out-png vtk.png] [--out-json vtk.json]

The same integral as clvr (docs/benchmarks.md):
- volume: the scene's NRRD / VTK legacy file as VTK reads it (native type), or the Marschner-Lobb
  generator evaluated with numpy by the formula of host/io/generators.h (float32, [-1,1]^3);
- camera: position, focal point, view up, view angle (or parallel scale) as given; rays through
  pixel centres as in VTK;
- colour: a vtkColorTransferFunction through the control points (s, r, g, b);
- opacity: clvr's extinction tau is per world unit, and a sample of length D gets
  alpha = 1 - exp(-tau D). VTK's mapper corrects the table opacity a for its sample distance D as
  a' = 1 - (1 - a)^(D / u) with u = ScalarOpacityUnitDistance. Setting u = 1 and a = 1 - exp(-tau)
  gives a' = 1 - exp(-tau D), the same opacity. tau is piecewise linear in s but a is not, so the
  opacity function gets 32 points per transfer-function segment;
- sample distance: clvr's slice spacing (clvr bench passes it; standalone it is computed the same
  way: the depth range of the volume box along the view direction divided by options.slices);
- trilinear interpolation, no shading, composite blending, background as the scene says.
"""
import argparse
import json
import math
import os
import sys
import time

import numpy as np
import vtk
from vtk.util import numpy_support

from peer_vtk_common import frame_figures, offscreen_view, timed_frames, volume_property, write_png


def marschner_lobb(dims):
    """host/io/generators.h: grid point i at -1 + 2 i / (n - 1); f_M = 6, alpha = 0.25."""
    nx, ny, nz = dims
    x = np.linspace(-1.0, 1.0, nx)
    y = np.linspace(-1.0, 1.0, ny)
    z = np.linspace(-1.0, 1.0, nz)
    zz, yy, xx = np.meshgrid(z, y, x, indexing="ij")  # x fastest in C order
    r = np.sqrt(xx * xx + yy * yy)
    rho_r = np.cos(2.0 * math.pi * 6.0 * np.cos(math.pi * r / 2.0))
    v = (1.0 - np.sin(math.pi * zz / 2.0) + 0.25 * (1.0 + rho_r)) / (2.0 * 1.25)
    image = vtk.vtkImageData()
    image.SetDimensions(nx, ny, nz)
    image.SetOrigin(-1.0, -1.0, -1.0)
    image.SetSpacing(2.0 / (nx - 1), 2.0 / (ny - 1), 2.0 / (nz - 1))
    arr = numpy_support.numpy_to_vtk(v.astype(np.float32).ravel(), deep=True)
    arr.SetName("values")
    image.GetPointData().SetScalars(arr)
    return image


def load_volume(spec, base_dir):
    if "generator" in spec:
        if spec["generator"] != "marschner-lobb":
            raise SystemExit("peer_vtk.py: only the marschner-lobb generator is implemented, not " + spec["generator"])
        return marschner_lobb(spec["dims"])
    path = os.path.normpath(os.path.join(base_dir, spec["file"]))
    if path.endswith(".nrrd") or path.endswith(".nhdr"):
        # Debian's VTK replaces vtkNrrdReader by an MPI variant (OPENCL-NOTES.md).
        vtk.vtkObjectFactory.SetAllEnableFlags(0, "vtkNrrdReader")
        reader = vtk.vtkNrrdReader()
    elif path.endswith(".vtk"):
        reader = vtk.vtkStructuredPointsReader()
    else:
        raise SystemExit("peer_vtk.py: " + path + ": only NRRD and VTK legacy files are read")
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    if image.GetNumberOfPoints() == 0:
        raise SystemExit("peer_vtk.py: " + path + ": VTK read no points")
    return image


def slice_spacing(camera, image, slices):
    """tools/ceiling.cpp sliceStack(): depth range of the box along the view direction / slices."""
    pos = np.array(camera["position"], float)
    f = np.array(camera["focal_point"], float) - pos
    f /= np.linalg.norm(f)
    b = image.GetBounds()
    depths = [np.dot(np.array([b[i], b[2 + j], b[4 + k]]) - pos, f) for i in (0, 1) for j in (0, 1) for k in (0, 1)]
    return (max(depths) - min(depths)) / slices


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--sample-distance", type=float, default=0.0, help="world units; 0: clvr's slice spacing")
    ap.add_argument("--out-png", default="vtk.png")
    ap.add_argument("--out-json", default="vtk.json")
    args = ap.parse_args()

    with open(args.scene) as f:
        scene = json.load(f)
    base_dir = os.path.dirname(os.path.abspath(args.scene))
    t0 = time.perf_counter()
    image = load_volume(scene["volume"], base_dir)
    load_ms = (time.perf_counter() - t0) * 1e3
    width = scene.get("image", {}).get("width", 512)
    height = scene.get("image", {}).get("height", 512)
    background = scene.get("image", {}).get("background", [0, 0, 0])
    slices = scene.get("options", {}).get("slices", 256)
    points = scene["transfer_function"]["points"]

    color = vtk.vtkColorTransferFunction()
    opacity = vtk.vtkPiecewiseFunction()
    unit_distance = 1.0  # world units: a = 1 - exp(-tau * u)
    for p in points:
        color.AddRGBPoint(p[0], p[1], p[2], p[3])
    for (s0, *_, tau0), (s1, *_, tau1) in zip(points, points[1:]):
        for i in range(32):
            w = i / 32.0
            tau = tau0 + w * (tau1 - tau0)
            opacity.AddPoint(s0 + w * (s1 - s0), 1.0 - math.exp(-tau * unit_distance))
    opacity.AddPoint(points[-1][0], 1.0 - math.exp(-points[-1][4] * unit_distance))

    prop = volume_property(color, opacity, unit_distance)

    mapper = vtk.vtkFixedPointVolumeRayCastMapper()
    mapper.SetInputData(image)
    mapper.SetBlendModeToComposite()
    mapper.SetAutoAdjustSampleDistances(0)
    mapper.SetLockSampleDistanceToInputSpacing(0)
    camera_spec = scene.get("camera")
    sample_distance = args.sample_distance
    if sample_distance <= 0.0:
        if camera_spec is None:
            raise SystemExit("peer_vtk.py: the scene has no camera; pass --sample-distance")
        sample_distance = slice_spacing(camera_spec, image, slices)
    mapper.SetSampleDistance(sample_distance)
    mapper.SetImageSampleDistance(1.0)

    window, camera = offscreen_view(mapper, prop, background, width, height, camera_spec)
    first_ms, times = timed_frames(window, camera, args.frames)
    write_png(window, args.out_png)

    result = {
        "renderer": "VTK " + vtk.vtkVersion.GetVTKVersion(),
        "mapper": "vtkFixedPointVolumeRayCastMapper",
        "threads": mapper.GetNumberOfThreads(),
        "scalar_type": image.GetPointData().GetScalars().GetDataTypeAsString(),
        "dims": list(image.GetDimensions()),
        "width": width,
        "height": height,
        "sample_distance": sample_distance,
        "opacity_unit_distance": unit_distance,
        "load_ms": load_ms,
        **frame_figures(first_ms, times),
        "image": args.out_png,
    }
    with open(args.out_json, "w") as f:
        json.dump(result, f, indent=2)
    print("peer_vtk: %s %s, %d threads: first %.1f ms, median %.1f ms over %d frames (min %.1f, max %.1f)"
          % (result["renderer"], result["mapper"], result["threads"], first_ms, result["frame_ms"], len(times),
             min(times), max(times)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
