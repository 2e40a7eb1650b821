"""tools/peer_vtk_common.py — what the VTK peer scripts (peer_vtk.py, peer_vtk_unstructured.py) share: the
volume property, an off-screen window with clvr's camera, the timed frames and the PNG of the last one.
Imported from the scripts' own folder (python puts it first on sys.path)."""
import time

import numpy as np
import vtk


def volume_property(color, opacity, unit_distance):
    """Linear interpolation, no shading: emission-absorption as clvr renders it."""
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(unit_distance)
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()
    return prop


def offscreen_view(mapper, prop, background, width, height, camera_spec):
    """A renderer and an off-screen window of width x height holding one volume, looking through clvr's
    camera (DESIGN.md's keys), or VTK's reset camera when camera_spec is None. Returns (window, camera)."""
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    renderer = vtk.vtkRenderer()
    renderer.AddVolume(volume)
    renderer.SetBackground(*background)
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(width, height)
    window.AddRenderer(renderer)
    camera = renderer.GetActiveCamera()
    if camera_spec is None:
        renderer.ResetCamera()
    else:
        camera.SetPosition(*camera_spec["position"])
        camera.SetFocalPoint(*camera_spec["focal_point"])
        camera.SetViewUp(*camera_spec.get("view_up", [0, 1, 0]))
        if camera_spec.get("projection") == "parallel":
            camera.ParallelProjectionOn()
            camera.SetParallelScale(camera_spec["parallel_scale"])
        else:
            camera.SetViewAngle(camera_spec.get("view_angle", 30.0))
    renderer.ResetCameraClippingRange()
    return window, camera


def timed_frames(window, camera, frames):
    """Renders a first frame, then `frames` (at least one) more, each after camera.Modified() so that
    every frame casts its rays again. Returns (first frame ms, the other frames' ms)."""
    t0 = time.perf_counter()
    window.Render()
    first_ms = (time.perf_counter() - t0) * 1e3
    times = []
    for _ in range(max(frames, 1)):
        camera.Modified()
        t0 = time.perf_counter()
        window.Render()
        times.append((time.perf_counter() - t0) * 1e3)
    return first_ms, times


def write_png(window, path):
    """The window's RGB back buffer (the last frame) as a PNG."""
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()


def frame_figures(first_ms, times):
    """The timing keys both scripts write to their JSON."""
    return {
        "first_frame_ms": first_ms,
        "frame_ms": float(np.median(times)),
        "frame_ms_min": min(times),
        "frame_ms_max": max(times),
        "frame_ms_all": times,
    }
