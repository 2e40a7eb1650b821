#!/usr/bin/python3
"""tools/make_accuracy_bench.py — writes the scenes of `clvr bench --suite accuracy --reference` (issue 14
goal 1, "at equal image error"): slice3d's fused path on Marschner-Lobb 256^3 and on the engine, at 512x512,
with per-sample classification and with pre-integrated slabs ("integration": "preintegrated"), over a range of
slice counts. With --reference, clvr bench reports each image's error against the CPU reference integral
(computed once per volume and view), so time and error can be read off together; with --peer, VTK's fixed-point
ray caster runs at each scene's slice spacing, and its image is judged against the same reference.

    /usr/bin/python3 tools/make_accuracy_bench.py            # rewrites the scene files
    /usr/bin/python3 tools/make_accuracy_bench.py --check    # exit 1 if a file differs from what it would write
    /usr/bin/python3 tools/make_accuracy_bench.py --list     # the file names, in the suite's order

  acc-ml256-sample-N, acc-ml256-pre-N     the view and sparse transfer function of reg-slice3d-ml256.json
  acc-engine-sample-N, acc-engine-pre-N   the view and transfer function of slice3d-engine.json
N: 64 .. 1024 slices per-sample (1024 is 0.43 voxel on Marschner-Lobb; 96, 144 and 192 between the powers of 2,
where the engine's per-sample error crosses VTK's best), 64 .. 512 pre-integrated.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_rts_bench import write_scenes  # noqa: E402

VOLUMES = {
    "ml256": {
        "volume": {"generator": "marschner-lobb", "dims": [256, 256, 256]},
        "camera": {"position": [2.8, 1.95, 3.45], "focal_point": [0, 0, 0], "view_up": [0, 1, 0], "view_angle": 38},
        "tf": [[0.0, 0, 0, 0, 0.0],
               [0.23, 0, 0, 0, 0.0],
               [0.35, 0.3, 0.5, 0.9, 0.08],
               [0.63, 0.6, 0.7, 0.9, 0.16],
               [0.78, 1.0, 0.7, 0.3, 0.64],
               [1.0, 1.0, 1.0, 0.9, 1.6]],
    },
    "engine": {
        "volume": {"file": "../../../../shared/data/engine/engine.nrrd"},
        "camera": {"position": [440, 340, 350], "focal_point": [127.5, 127.5, 63.5], "view_up": [0, 0, 1],
                   "view_angle": 33},
        "tf": [[0.0, 0.0, 0.0, 0.0, 0.0],
               [60.0, 0.0, 0.0, 0.0, 0.0],
               [100.0, 0.8, 0.4, 0.2, 0.01],
               [180.0, 0.9, 0.8, 0.6, 0.03],
               [255.0, 1.0, 1.0, 1.0, 0.08]],
    },
}
SLICES = {"sample": [64, 96, 128, 144, 192, 256, 512, 1024], "pre": [64, 128, 256, 512]}


def scenes():
    out = []
    for name, v in VOLUMES.items():
        for integration, counts in SLICES.items():
            for n in counts:
                options = {"slices": n}
                if integration == "pre":
                    options["integration"] = "preintegrated"
                out.append(("acc-%s-%s-%d.json" % (name, integration, n),
                            {"technique": "slice3d", "volume": v["volume"], "camera": v["camera"],
                             "image": {"width": 512, "height": 512, "background": [0, 0, 0]},
                             "transfer_function": {"points": v["tf"]}, "options": options}))
    return out


def main():
    return write_scenes(scenes(), "make_accuracy_bench.py", __doc__.split("\n")[0])


if __name__ == "__main__":
    sys.exit(main())
