#!/usr/bin/python3
"""tools/make_cubefan_bench.py — writes the cubefan bench scenes data/scenes/bench/cubefan-*.json for
`clvr bench --suite cubefan` (issue 12 part 5: the experiment of seeds/002 Figure 9), and slice3d on the same
view beside them.

    /usr/bin/python3 tools/make_cubefan_bench.py            # rewrites the scene files
    /usr/bin/python3 tools/make_cubefan_bench.py --check    # exit 1 if a file differs from what it would write
    /usr/bin/python3 tools/make_cubefan_bench.py --list     # the file names, in the suite's order

The engine block (256x256x128 here; the paper's is 256x256x110) at 512x512 in perspective, with the camera
and transfer function of data/scenes/engine.json (unshaded):
  cubefan-engine-e0, -e18, -e48   cubefan at 0 %, 18 % and 48 % error tolerance (the paper's three images:
                                  its triangle fans, "path": "raster")
  cubefan-engine-x0, -x18         the same at 0 % and 18 % with "thickness": "exact" (each fragment's chord)
  cubefan-engine-f0, -f18, -f48   the fused path (each pixel's ray walks the selected cubes) at 0, 18, 48 %
  cubefan-engine-t0, -t18, -t48   the tile path (the cubes in visibility order binned to 8x4-pixel tiles) at 0, 18,
                                  48 % (the default path where the error is above 0)
  cubefan-slice3d-1024            slice3d (fused) on the same view with 1024 slices: its full quality
  cubefan-slice3d-256, -128, -100, -96, -64, -32   slice3d with fewer slices (96-100: 18 %'s image error)
clvr bench compares every scene with the first of its group (the name up to its last '-'): the cubefan
scenes with cubefan-engine-e0, the slice3d ones with cubefan-slice3d-1024.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_rts_bench import write_scenes  # noqa: E402

ENGINE = "../../../../shared/data/engine/engine.nrrd"
CAMERA = {"position": [560, -260, 330], "focal_point": [127.5, 127.5, 63.5], "view_up": [0, 0, 1], "view_angle": 30}
TF = [[0, 0.00, 0.00, 0.00, 0.0],
      [60, 0.00, 0.00, 0.00, 0.0],
      [90, 0.30, 0.50, 0.90, 0.01],
      [160, 0.60, 0.70, 0.90, 0.02],
      [200, 1.00, 0.70, 0.30, 0.08],
      [255, 1.00, 1.00, 0.90, 0.20]]


def scene(technique, options):
    return {"technique": technique,
            "volume": {"file": ENGINE},
            "camera": CAMERA,
            "image": {"width": 512, "height": 512, "background": [0, 0, 0]},
            "transfer_function": {"points": TF},
            "options": options}


def scenes():
    out = []
    for run, error, thickness in [("e0", 0.0, None), ("e18", 0.18, None), ("e48", 0.48, None),
                                  ("x0", 0.0, "exact"), ("x18", 0.18, "exact"),
                                  ("f0", 0.0, None), ("f18", 0.18, None), ("f48", 0.48, None),
                                  ("t0", 0.0, None), ("t18", 0.18, None), ("t48", 0.48, None)]:
        options = {"error": error}
        if thickness:
            options["thickness"] = thickness
        else:
            options["path"] = {"e": "raster", "f": "fused", "t": "tiles"}[run[0]]
        out.append(("cubefan-engine-" + run + ".json", scene("cubefan", options)))
    for slices in [1024, 256, 128, 100, 96, 64, 32]:
        out.append(("cubefan-slice3d-%d.json" % slices, scene("slice3d", {"slices": slices})))
    return out


def main():
    return write_scenes(scenes(), "make_cubefan_bench.py", __doc__.split("\n")[0])


if __name__ == "__main__":
    sys.exit(main())
