#!/usr/bin/python3
"""tools/peer_vtk_unstructured.py — the VTK peer of `clvr bench --peer` for tetrahedral-mesh scenes: renders a
clvr scene offscreen at the scene's image size, times frames after a first one, and writes its image (PNG) and
figures (JSON). For harc (and the cell-face techniques) with vtkUnstructuredGridVolumeRayCastMapper and
vtkUnstructuredGridPartialPreIntegration (Moreland and Angel's partial pre-integration, the integration harc
does); for projtet (`--mapper projected`, the default when the scene's technique is projtet) with
vtkProjectedTetrahedraMapper, VTK's Shirley-Tuchman cell projection (OpenGL, Mesa under xvfb-run): cells
sorted by their centres' depth (vtkCellCenterDepthSort), per-vertex colour and attenuation averaged at the
thick vertex, alpha = 1 - exp(-attenuation * thickness) per fragment.

Run it as clvr bench does, on the scene clvr bench writes beside its figures (bench.<scene>.peer.json: the
mesh clvr loaded as VTK legacy binary, the camera it used, the image and the transfer function):
    xvfb-run -a /usr/bin/python3 tools/peer_vtk_unstructured.py build/bench/bench.harc-bluntfin-10.peer.json \\
        [--frames 5] [--out-png vtk.png] [--out-json vtk.json]
It also reads a scene whose mesh is a VTK legacy unstructured grid (.vtk) or TetGen .node/.ele (first node
attribute) directly; PLOT3D and surface meshes go through clvr bench, so that both render the same tetrahedra.
The scene must have a camera (clvr bench writes the one it fitted).

The same integral as clvr (docs/benchmarks.md):
- mesh: the same tetrahedra and point scalars, linear inside each tetrahedron;
- camera: position, focal point, view up, view angle (or parallel scale); rays through pixel centres;
- colour: a vtkColorTransferFunction through the control points (s, r, g, b), RGB space;
- extinction: vtkUnstructuredGridPartialPreIntegration takes the attenuation at a control point as
  opacity(s) / ScalarOpacityUnitDistance (vtkPartialPreIntegrationTransferFunction::GetTransferFunction,
  VTK 9.1 Rendering/Volume), linear between control points, per unit world length: exactly clvr's tau. So
  the opacity function holds tau itself at the control points (values above 1 are kept) and the unit
  distance is 1. (vtkFixedPointVolumeRayCastMapper, the regular-grid peer, reads the same table as an
  opacity per unit distance instead: tools/peer_vtk.py.)
- image sample distance 1 (one ray per pixel), no automatic adjustment; composite over the background.
The projected-tetrahedra mapper reads the opacity as an 8-bit attenuation in [0, 1] per ScalarOpacityUnitDistance
(vtkOpenGLProjectedTetrahedraMapper: opacity / unit distance times the thickness), so it gets tau / tau_max with
unit distance 1 / tau_max: the same extinction, quantized to 1/255 of tau_max, and colours to 8 bits.
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


def read_tetgen(path):
    """BASE.node / BASE.ele (0- or 1-based by the first node's number); scalar = first node attribute."""
    base = os.path.splitext(path)[0] if path.endswith(".node") or path.endswith(".ele") else path
    def table(p):
        rows = []
        with open(p) as f:
            for line in f:
                line = line.split("#", 1)[0].split()
                if line:
                    rows.append(line)
        return rows
    node = table(base + ".node")
    n, dim, nattr = int(node[0][0]), int(node[0][1]), int(node[0][2])
    if dim != 3 or nattr < 1:
        raise SystemExit("peer_vtk_unstructured.py: " + base + ".node: need 3D points with an attribute")
    pts = np.array(node[1:1 + n], dtype=np.float64)
    first = int(pts[0, 0])
    ele = table(base + ".ele")
    m = int(ele[0][0])
    cells = np.array(ele[1:1 + m], dtype=np.int64)[:, 1:5] - first
    grid = vtk.vtkUnstructuredGrid()
    points = vtk.vtkPoints()
    points.SetData(numpy_support.numpy_to_vtk(np.ascontiguousarray(pts[:, 1:4]), deep=True))
    grid.SetPoints(points)
    conn = np.hstack([np.full((m, 1), 4, np.int64), cells]).ravel()
    ids = vtk.vtkIdTypeArray()
    ids.DeepCopy(numpy_support.numpy_to_vtkIdTypeArray(conn, deep=True))
    cell_array = vtk.vtkCellArray()
    cell_array.SetCells(m, ids)
    grid.SetCells(vtk.VTK_TETRA, cell_array)
    scalars = numpy_support.numpy_to_vtk(np.ascontiguousarray(pts[:, 4]), deep=True)
    scalars.SetName("scalars")
    grid.GetPointData().SetScalars(scalars)
    return grid


def load_mesh(spec, base_dir):
    if "file" not in spec or "q_file" in spec:
        raise SystemExit("peer_vtk_unstructured.py: the scene's mesh is not a .vtk or TetGen file; run it through "
                         "clvr bench --peer, which writes the mesh it loaded as .vtk")
    path = os.path.normpath(os.path.join(base_dir, spec["file"]))
    if path.endswith(".vtk"):
        reader = vtk.vtkUnstructuredGridReader()
        reader.SetFileName(path)
        if isinstance(spec.get("scalar"), str):
            reader.SetScalarsName(spec["scalar"])
        reader.Update()
        grid = reader.GetOutput()
    elif path.endswith(".node") or path.endswith(".ele"):
        grid = read_tetgen(path)
    else:
        raise SystemExit("peer_vtk_unstructured.py: " + path + ": only VTK legacy and TetGen meshes are read")
    if grid.GetNumberOfCells() == 0 or grid.GetPointData().GetScalars() is None:
        raise SystemExit("peer_vtk_unstructured.py: " + path + ": VTK read no cells or no point scalars")
    return grid


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--out-png", default="vtk.png")
    ap.add_argument("--out-json", default="vtk.json")
    ap.add_argument("--mapper", choices=["raycast", "projected"], default=None,
                    help="raycast (vtkUnstructuredGridVolumeRayCastMapper) or projected (vtkProjectedTetrahedraMapper); "
                         "default: projected for a projtet scene, else raycast")
    ap.add_argument("--pixel-corners", type=int, default=0,
                    help="1: leave VTK's rays through pixel corners (default 0: shifted to clvr's pixel centres)")
    args = ap.parse_args()

    with open(args.scene) as f:
        scene = json.load(f)
    base_dir = os.path.dirname(os.path.abspath(args.scene))
    camera_spec = scene.get("camera")
    if camera_spec is None:
        raise SystemExit("peer_vtk_unstructured.py: the scene has no camera (clvr bench --peer writes one)")
    t0 = time.perf_counter()
    grid = load_mesh(scene["mesh"], base_dir)
    load_ms = (time.perf_counter() - t0) * 1e3
    width = scene.get("image", {}).get("width", 512)
    height = scene.get("image", {}).get("height", 512)
    background = scene.get("image", {}).get("background", [0, 0, 0])
    points = scene["transfer_function"]["points"]

    projected = (args.mapper or ("projected" if scene.get("technique") == "projtet" else "raycast")) == "projected"
    color = vtk.vtkColorTransferFunction()
    color.SetColorSpaceToRGB()
    opacity = vtk.vtkPiecewiseFunction()
    unit_distance = 1.0  # attenuation = opacity(s) / unit distance: tau per world unit
    if projected:  # opacity in [0, 1]: tau / tau_max per 1 / tau_max
        unit_distance = 1.0 / max(max(p[4] for p in points), 1e-30)
    for s, r, g, b, tau in points:
        color.AddRGBPoint(s, r, g, b)
        opacity.AddPoint(s, tau * unit_distance)
    for s, *_, tau in points:  # the table must keep tau > 1 (vtkPiecewiseFunction does not clamp values)
        if not math.isclose(opacity.GetValue(s), tau * unit_distance, rel_tol=1e-9, abs_tol=1e-12):
            raise SystemExit("peer_vtk_unstructured.py: VTK's opacity function changed tau at s = %g" % s)

    prop = volume_property(color, opacity, unit_distance)

    if projected:
        mapper = vtk.vtkProjectedTetrahedraMapper()
        mapper.SetInputData(grid)
    else:
        mapper = vtk.vtkUnstructuredGridVolumeRayCastMapper()
        mapper.SetInputData(grid)
        mapper.SetRayIntegrator(vtk.vtkUnstructuredGridPartialPreIntegration())
        mapper.SetAutoAdjustSampleDistances(0)
        mapper.SetImageSampleDistance(1.0)

    window, camera = offscreen_view(mapper, prop, background, width, height, camera_spec)
    if args.pixel_corners == 0 and not projected:
        # vtkUnstructuredGridBunykRayCastFunction casts the ray of pixel (i, j) through the point that
        # projects to x = i, y = j (TransformPoints: (ndc + 1) / 2 * size; ComputePixelIntersections tests
        # integer x, y): through a pixel's corner. clvr (DESIGN.md) casts through pixel centres, half a
        # pixel up and right. The camera's window centre shifts the projection: ndc' = ndc - centre, so a
        # centre of one pixel's NDC width puts VTK's rays through the same points as clvr's.
        camera.SetWindowCenter(1.0 / width, 1.0 / height)
    first_ms, times = timed_frames(window, camera, args.frames)
    write_png(window, args.out_png)

    tets = grid.GetNumberOfCells()
    frame_ms = float(np.median(times))
    result = {
        "renderer": "VTK " + vtk.vtkVersion.GetVTKVersion(),
        "mapper": "vtkProjectedTetrahedraMapper" if projected else "vtkUnstructuredGridVolumeRayCastMapper",
        "integrator": "per-vertex attenuation, exp per fragment" if projected else "vtkUnstructuredGridPartialPreIntegration",
        "threads": 1 if projected else mapper.GetNumberOfThreads(),
        "points": grid.GetNumberOfPoints(),
        "tets": tets,
        "width": width,
        "height": height,
        "opacity_unit_distance": unit_distance,
        "rays_through": "rasterized (pixel centres)" if projected else (
            "pixel corners" if args.pixel_corners else "pixel centres (window centre shifted half a pixel)"),
        "load_ms": load_ms,
        **frame_figures(first_ms, times),
        "fps": 1000.0 / frame_ms,
        "tets_per_s": tets * 1000.0 / frame_ms,
        "image": args.out_png,
    }
    with open(args.out_json, "w") as f:
        json.dump(result, f, indent=2)
    print("peer_vtk_unstructured: %s %s + %s, %d threads, %d tets: first %.1f ms, median %.1f ms over %d frames "
          "(min %.1f, max %.1f)" % (result["renderer"], result["mapper"], result["integrator"], result["threads"],
                                   tets, first_ms, frame_ms, len(times), min(times), max(times)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
