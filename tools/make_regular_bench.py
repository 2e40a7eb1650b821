#!/usr/bin/python3
"""tools/make_regular_bench.py — writes the regular-grid bench scenes data/scenes/bench/reg-*.json for
`clvr bench --suite regular` (issue 4 part 8: every regular-grid technique on engine, lobster and
Marschner-Lobb 256^3 at 512x512).

    /usr/bin/python3 tools/make_regular_bench.py            # rewrites the scene files
    /usr/bin/python3 tools/make_regular_bench.py --check    # exit 1 if a file differs from what it would write
    /usr/bin/python3 tools/make_regular_bench.py --list     # the file names, in the suite's order

Volumes, cameras and the translucent transfer function are those of tools/make_rts_bench.py, so a row
here and a resample-then-shade row of the same volume see the same data from the same place.
Per volume:
  reg-iso3d-V            iso3d, gradient shading, 512 slices (seeds/000 §3), its default fused path
  reg-iso3d-V-raster     the same through the raster stage: the slice draws under the alpha and depth tests
  reg-iso3d-V-bricked    the same within a 16 MiB device-memory budget: bricks front to back, the
                         stencil locking the first hit (seeds/000 §3.1)
  reg-stack2d-V          stack2d, plain bilinear slices of the stack (seeds/003)
  reg-stack2d-V-k1       stack2d, one lerped intermediate slice between stack slices (trilinear again)
  reg-stack2d-V-k1-raster  the same through the raster stage: the quads (the fused path's baseline)
  reg-stack2d-V-k1-p4    the same with four slices per polygon (seeds/003's multi-texture speed-up; raster)
  reg-stack2d-engine-k1-cliptex  (engine only) reg-stack2d-engine-k1 clipped by the clip texture below
  reg-slice3d-raster-V   slice3d through the raster stage, 256 slices: the baseline of the clip rows
  reg-clip-V             the same with a sphere clip mesh, two-pass stencil (seeds/000 §2.1)
  reg-slice3d-V          slice3d's default fused path, 256 slices: the baseline of the next two rows
  reg-clipmesh-V         the same clipped by the sphere clip mesh on the fused path (the mesh peeled into
                         depth layers once, each sample tested against them)
  reg-cliptex-V          the same clipped by a clip texture of the same sphere (seeds/003's stencil texture)
and on the engine also reg-iso3d-engine-gradientless (the pixel-texture shading of §3); and
reg-spherical-atmosphere, the spherical technique on the generated atmosphere (seeds/000 §2.2; a
spherical domain has no counterpart among the three volumes), its default fused path, and
reg-spherical-atmosphere-raster, the same through the raster stage (the shells pass by pass).
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_rts_bench import VOLUMES, transfer_function, write_scenes  # noqa: E402

LIGHT = [1, -0.6, 0.8]

# name: (iso-value, clip sphere (center, radius) in world units)
PER_VOLUME = {
    "engine": (100.0, ([150, 90, 100], 75)),
    "lobster": (60.0, ([150, 120, 40], 70)),
    "ml256": (0.5, ([0.35, 0.25, 0.45], 0.6)),
}


def base(volume, technique):
    spec, camera, _, _ = VOLUMES[volume]
    return {
        "technique": technique,
        "volume": spec,
        "camera": camera,
        "image": {"width": 512, "height": 512, "background": [0, 0, 0]},
    }


def iso_scene(volume, shading):
    scene = base(volume, "iso3d")
    scene["transfer_function"] = {"points": [[VOLUMES[volume][2][0], 0.95, 0.8, 0.6, 0.0],
                                             [VOLUMES[volume][2][1], 0.95, 0.8, 0.6, 1.0]]}
    scene["iso"] = {"value": PER_VOLUME[volume][0], "shading": shading, "light": LIGHT, "ambient": 0.2,
                    "diffuse": 0.8}
    scene["options"] = {"slices": 512}
    return scene


def translucent_scene(volume, technique, options):
    scene = base(volume, technique)
    scene["transfer_function"] = {"points": transfer_function(volume, "translucent")}
    scene["options"] = options
    return scene


def scenes():
    """(file name, scene) for every bench scene, in the suite's order."""
    out = []
    for volume in VOLUMES:
        center, radius = PER_VOLUME[volume][1]
        clip = {"mesh": {"generator": "sphere", "center": center, "radius": radius, "segments": 64},
                "inverse": True, "method": "two-pass"}
        out.append(("reg-iso3d-%s.json" % volume, iso_scene(volume, "gradient")))
        raster = iso_scene(volume, "gradient")
        raster["options"]["path"] = "raster"
        out.append(("reg-iso3d-%s-raster.json" % volume, raster))
        bricked = iso_scene(volume, "gradient")
        bricked["options"]["brick_budget"] = 16 * 2**20
        out.append(("reg-iso3d-%s-bricked.json" % volume, bricked))
        if volume == "engine":
            out.append(("reg-iso3d-engine-gradientless.json", iso_scene(volume, "gradientless")))
        out.append(("reg-stack2d-%s.json" % volume, translucent_scene(volume, "stack2d", {"intermediate": 0})))
        out.append(("reg-stack2d-%s-k1.json" % volume, translucent_scene(volume, "stack2d", {"intermediate": 1})))
        out.append(("reg-stack2d-%s-k1-raster.json" % volume,
                    translucent_scene(volume, "stack2d", {"intermediate": 1, "path": "raster"})))
        out.append(("reg-stack2d-%s-k1-p4.json" % volume,
                    translucent_scene(volume, "stack2d", {"intermediate": 1, "slices_per_polygon": 4})))
        if volume == "engine":
            out.append(("reg-stack2d-engine-k1-cliptex.json",
                        translucent_scene(volume, "stack2d", {"intermediate": 1, "clip_texture": {
                            "shape": "sphere", "center": center, "radius": radius, "inverse": True}})))
        out.append(("reg-slice3d-raster-%s.json" % volume,
                    translucent_scene(volume, "slice3d", {"slices": 256, "path": "raster"})))
        out.append(("reg-clip-%s.json" % volume,
                    translucent_scene(volume, "slice3d", {"slices": 256, "path": "raster", "clip": clip})))
        out.append(("reg-slice3d-%s.json" % volume, translucent_scene(volume, "slice3d", {"slices": 256})))
        out.append(("reg-clipmesh-%s.json" % volume,
                    translucent_scene(volume, "slice3d", {"slices": 256, "clip": clip})))
        clip_texture = {"shape": "sphere", "center": center, "radius": radius, "inverse": True}
        out.append(("reg-cliptex-%s.json" % volume,
                    translucent_scene(volume, "slice3d", {"slices": 256, "clip_texture": clip_texture})))
    out.append(("reg-spherical-atmosphere.json", spherical_scene()))
    raster = spherical_scene()
    raster["options"]["path"] = "raster"
    out.append(("reg-spherical-atmosphere-raster.json", raster))
    return out


def spherical_scene():
    """data/scenes/atmosphere.json's scene."""
    return {
        "technique": "spherical",
        "volume": {"generator": "atmosphere", "dims": [129, 65, 48]},
        "camera": {"position": [2.9, -1.6, 1.5], "focal_point": [0, 0, 0], "view_up": [0, 0, 1], "view_angle": 36},
        "image": {"width": 512, "height": 512, "background": [0, 0, 0]},
        "transfer_function": {"points": [[0.00, 0.00, 0.00, 0.00, 0.0], [0.20, 0.05, 0.15, 0.45, 0.0],
                                         [0.45, 0.20, 0.50, 0.95, 1.5], [0.70, 0.85, 0.90, 1.00, 6.0],
                                         [1.00, 1.00, 0.95, 0.80, 14.0]]},
        "options": {"shells": 96, "segments": 128, "r_min": 0.5, "r_max": 1.0},
    }


def main():
    return write_scenes(scenes(), "make_regular_bench.py", __doc__.split("\n")[0])


if __name__ == "__main__":
    sys.exit(main())
