#!/usr/bin/python3
"""tools/make_bench_tf.py — writes the harc bench scenes data/scenes/bench/harc-bluntfin-{10,255}.json
(partial pre-integration) and harc-bluntfin-10-full.json (the 10-segment scene with full pre-integration,
"integration": "full", the default 64x64x64 table):
the bluntfin density mesh (as data/scenes/bluntfin.json: no camera, so clvr fits one to the bounds),
512x512, and a transfer function of N linear segments (N + 1 control points) sampled from one smooth
curve, so the two scenes show nearly the same picture and differ in how often a ray's segment in a cell
is split at a control point (the cost seeds/001 Tables 2-3 vary).

    /usr/bin/python3 tools/make_bench_tf.py            # rewrites both scene files
    /usr/bin/python3 tools/make_bench_tf.py --check    # exit 1 if a file differs from what it would write

The curve over t = (s - 0.19) / (4.98 - 0.19), s the density (data/scenes/bluntfin.json's range):
  tau(t) = 0.02 + 3.98 t^2            extinction per world unit: 0.02 in the free stream, 4 in the shock
  r = 0.1 + 0.9 t^0.6,  g = 0.2 + 0.7 sin(pi t) + 0.1 t,  b = 0.95 - 0.85 t
Control points are at equal steps of s; values are rounded to 6 decimals (the files are the reference).
"""
import argparse
import json
import math
import os
import sys

S_MIN, S_MAX = 0.19, 4.98
# (segments, integration): None is the renderer's default, partial pre-integration.
VARIANTS = ((10, None), (255, None), (10, "full"))


def control_points(segments):
    points = []
    for i in range(segments + 1):
        t = i / segments
        s = S_MIN + t * (S_MAX - S_MIN)
        tau = 0.02 + 3.98 * t * t
        r = 0.1 + 0.9 * t ** 0.6
        g = 0.2 + 0.7 * math.sin(math.pi * t) + 0.1 * t
        b = 0.95 - 0.85 * t
        points.append([round(v, 6) for v in (s, r, g, b, tau)])
    return points


def scene_text(segments, integration):
    scene = {
        "technique": "harc",
        "mesh": {"file": "../../../../shared/data/bluntfin/bluntfinxyz.bin",
                 "q_file": "../../../../shared/data/bluntfin/bluntfinq.bin", "scalar": "density"},
        "image": {"width": 512, "height": 512, "background": [0, 0, 0]},
        "transfer_function": {"points": control_points(segments)},
    }
    if integration:
        scene["options"] = {"integration": integration}
    # One key per line and one control point per line, as the hand-written scenes are laid out.
    keys = ['  "%s": %s' % (k, json.dumps(v)) for k, v in scene.items() if k not in ("transfer_function", "options")]
    rows = ",\n".join("    " + json.dumps(p) for p in scene["transfer_function"]["points"])
    options = ',\n  "options": %s' % json.dumps(scene["options"]) if "options" in scene else ""
    return ("{\n" + ",\n".join(keys) + ',\n  "transfer_function": {"points": [\n' + rows + "\n  ]}" + options +
            "\n}\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="compare instead of writing")
    args = ap.parse_args()
    bench_dir = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "scenes", "bench")
    status = 0
    for segments, integration in VARIANTS:
        name = "harc-bluntfin-%d%s.json" % (segments, "-" + integration if integration else "")
        path = os.path.normpath(os.path.join(bench_dir, name))
        text = scene_text(segments, integration)
        if args.check:
            with open(path) as f:
                if f.read() != text:
                    print("make_bench_tf.py: " + path + " differs from the generated scene")
                    status = 1
        else:
            with open(path, "w") as f:
                f.write(text)
            print("wrote %s (%d segments, %d control points)" % (path, segments, segments + 1))
    return status


if __name__ == "__main__":
    sys.exit(main())
