"""tools/peer_pvbatch.py — the cluster peer (docs/cluster.md): ParaView's pvbatch renders a clvr mesh scene
(a VTK legacy unstructured grid) as a volume on N ranks, the data spread over the ranks by
RedistributeDataSet (ParaView's own partitioner), composited by ParaView (IceT inside), and writes its
image and its time per frame. Run it as clvr's cluster bench would, once per rank count:

    xvfb-run -a -s '-screen 0 1024x768x24' mpirun --oversubscribe --bind-to none -np 2 \\
        pvbatch tools/peer_pvbatch.py data/scenes/post.json --frames 5 --out-png pv2.png --out-json pv2.json

then compare the N-rank image with the 1-rank one (oiiotool pv1.png pv2.png --diff): the partition
boundaries show as seams (../shared/CLUSTER-NOTES.md measured up to 56/255 on the oxygen post).
Camera, image size, background and the transfer function's colours come from the scene; the opacity
function holds min(tau, 1) at the control points (ParaView's volume mappers read it as opacity per unit
distance, clamped to 1), so the peer's image is compared with itself across rank counts, not with clvr's.
"""
import argparse
import json
import os
import sys
import time

from paraview import servermanager
from paraview.simple import (ColorBy, CreateView, GetColorTransferFunction, GetOpacityTransferFunction,
                             LegacyVTKReader, RedistributeDataSet, Render, SaveScreenshot, Show)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--out-png", default="pv.png")
    ap.add_argument("--out-json", default="pv.json")
    args = ap.parse_args()

    with open(args.scene) as f:
        scene = json.load(f)
    base_dir = os.path.dirname(os.path.abspath(args.scene))
    mesh = scene["mesh"]
    if "file" not in mesh or not mesh["file"].endswith(".vtk"):
        raise SystemExit("peer_pvbatch.py: the scene's mesh must be a VTK legacy file (\"file\": \"....vtk\")")
    scalar = mesh.get("scalar")
    ranks = servermanager.vtkProcessModule.GetProcessModule().GetNumberOfLocalPartitions()

    t0 = time.perf_counter()
    reader = LegacyVTKReader(FileNames=[os.path.join(base_dir, mesh["file"])])
    source = RedistributeDataSet(Input=reader) if ranks > 1 else reader
    image = scene.get("image", {})
    width, height = image.get("width", 512), image.get("height", 512)
    view = CreateView("RenderView")
    view.ViewSize = [width, height]
    view.Background = image.get("background", [0, 0, 0])
    view.OrientationAxesVisibility = 0
    display = Show(source, view)
    display.SetRepresentationType("Volume")
    ColorBy(display, ("POINTS", scalar))
    points = scene["transfer_function"]["points"]
    lut = GetColorTransferFunction(scalar)
    lut.RGBPoints = [v for s, r, g, b, _ in points for v in (s, r, g, b)]
    pwf = GetOpacityTransferFunction(scalar)
    pwf.Points = [v for s, *_, tau in points for v in (s, min(tau, 1.0), 0.5, 0.0)]
    display.ScalarOpacityUnitDistance = 1.0
    cam = scene["camera"]
    view.CameraPosition = cam["position"]
    view.CameraFocalPoint = cam["focal_point"]
    view.CameraViewUp = cam["view_up"]
    view.CameraViewAngle = cam.get("view_angle", 30)
    load_ms = (time.perf_counter() - t0) * 1e3

    t0 = time.perf_counter()
    Render(view)
    first_ms = (time.perf_counter() - t0) * 1e3
    times = []
    for _ in range(max(1, args.frames)):
        camera = view.GetActiveCamera()
        camera.Modified()
        t0 = time.perf_counter()
        Render(view)
        times.append((time.perf_counter() - t0) * 1e3)
    SaveScreenshot(args.out_png, view, ImageResolution=[width, height])
    times.sort()
    result = {
        "renderer": "ParaView pvbatch " + servermanager.vtkSMProxyManager.GetParaViewSourceVersion(),
        "ranks": ranks,
        "width": width,
        "height": height,
        "load_ms": load_ms,
        "first_frame_ms": first_ms,
        "frame_ms": times[len(times) // 2],
        "frame_ms_all": times,
        "image": args.out_png,
    }
    with open(args.out_json, "w") as f:
        json.dump(result, f, indent=2)
    print(json.dumps(result))
    sys.stdout.flush()
    # pvbatch's window teardown under xvfb fails with GLXBadContext after everything is written: leave
    # before it, with a clean status for mpirun.
    from mpi4py import MPI  # noqa: F401  (initialised by pvbatch)
    MPI.COMM_WORLD.Barrier()
    MPI.Finalize()
    os._exit(0)


if __name__ == "__main__":
    sys.exit(main())
