#!/usr/bin/python3
"""tools/make_tetfaces_bench.py — writes the cell-face bench scenes data/scenes/bench/tetfaces-*.json for
`clvr bench --suite tetfaces` (issue 10 part 7: the experiments of seeds/000 §5, Table 1 and the binary
cellular automaton), each beside harc on the same mesh, camera and transfer function.

    /usr/bin/python3 tools/make_tetfaces_bench.py            # rewrites the scene files
    /usr/bin/python3 tools/make_tetfaces_bench.py --check    # exit 1 if a file differs from what it would write
    /usr/bin/python3 tools/make_tetfaces_bench.py --list     # the file names, in the suite's order

Table 1 (fedata0..3): a finite-element-like part, the L-block of data/surfaces/l-block.poly, meshed by
TetGen at load time to about 60k, 110k, 150k and 200k tetrahedra (max_volume below; the counts are in
the bench output and BENCHMARKS.md), with the "glowing kernel" field (generator "kernel",
host/io/generators.h) and a transfer function from blue to yellow with rising temperature, as the
paper's figure; 400 slices at 400x400, as the paper.
  tetfaces-fedataN-tetslice         tetslice, 400 slices, the paper's face draws ("path": "raster")
  tetfaces-fedataN-fused-tetslice   the same on tetslice's fused path (the cells walked, the same slices)
  tetfaces-fedataN-harc             harc on the same scene
The binary cellular automaton: 8,000 living cells of a 40^3 lattice, 12 tetrahedra each, no shared
vertices, value 1 at the centres and 0 at the corners (mesh generator "automaton"):
  tetfaces-automaton-tetiso     the iso-surface at 0.5 (tetiso, face draws: "path": "raster")
  tetfaces-automaton-fused-tetiso   the same on tetiso's fused path (the cells walked to the first crossing)
  tetfaces-automaton-tetslice   direct rendering, 400 slices (tetslice, face draws)
  tetfaces-automaton-fused-tetslice   the same on tetslice's fused path
  tetfaces-automaton-harc       harc on the same scene as tetslice
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_rts_bench import write_scenes  # noqa: E402

# TetGen -a bounds for about 60k, 110k, 150k and 200k tetrahedra of the L-block (volume 3, quality 1.5).
FEDATA = [("fedata0", 1.0e-4), ("fedata1", 5.45e-5), ("fedata2", 4.0e-5), ("fedata3", 3.0e-5)]

FE_CAMERA = {"position": [2.2, 2.9, 2.6], "focal_point": [0.0, 0.0, -0.5], "view_up": [0, 0, 1], "view_angle": 40}
FE_TF = {"points": [
    [0.10, 0.05, 0.10, 0.60, 0.5],
    [0.30, 0.10, 0.30, 0.90, 0.8],
    [0.60, 0.90, 0.80, 0.20, 3.0],
    [1.00, 1.00, 1.00, 0.30, 12.0]]}
AUTOMATON_CAMERA = {"position": [2.6, 2.0, 3.2], "focal_point": [0.0, 0.0, 0.0], "view_up": [0, 1, 0], "view_angle": 36}
AUTOMATON_TF = {"points": [
    [0.0, 0.10, 0.20, 0.80, 0.0],
    [0.5, 0.30, 0.90, 0.40, 8.0],
    [1.0, 1.00, 0.90, 0.20, 40.0]]}
IMAGE = {"width": 400, "height": 400, "background": [0, 0, 0]}


def scenes():
    out = []
    for name, max_volume in FEDATA:
        mesh = {"surface": "../../surfaces/l-block.poly", "quality": 1.5, "max_volume": max_volume, "scalar": "kernel"}
        for label, technique, options in (("tetslice", "tetslice", {"slices": 400, "path": "raster"}),
                                          ("fused-tetslice", "tetslice", {"slices": 400, "path": "fused"}),
                                          ("harc", "harc", None)):
            scene = {"technique": technique, "mesh": mesh, "camera": FE_CAMERA, "image": IMAGE,
                     "transfer_function": FE_TF}
            if options:
                scene["options"] = options
            out.append(("tetfaces-%s-%s.json" % (name, label), scene))
    automaton = {"generator": "automaton", "cells": 8000, "grid": 40}
    for label, path in (("tetiso", "raster"), ("fused-tetiso", "fused")):
        out.append(("tetfaces-automaton-%s.json" % label,
                    {"technique": "tetiso", "mesh": automaton, "camera": AUTOMATON_CAMERA, "image": IMAGE,
                     "transfer_function": AUTOMATON_TF, "iso": {"value": 0.5}, "options": {"path": path}}))
    for label, technique, options in (("tetslice", "tetslice", {"slices": 400, "path": "raster"}),
                                      ("fused-tetslice", "tetslice", {"slices": 400, "path": "fused"}),
                                      ("harc", "harc", None)):
        scene = {"technique": technique, "mesh": automaton, "camera": AUTOMATON_CAMERA, "image": IMAGE,
                 "transfer_function": AUTOMATON_TF}
        if options:
            scene["options"] = options
        out.append(("tetfaces-automaton-%s.json" % label, scene))
    return out


def main():
    return write_scenes(scenes(), "make_tetfaces_bench.py", __doc__.split("\n")[0])


if __name__ == "__main__":
    sys.exit(main())
