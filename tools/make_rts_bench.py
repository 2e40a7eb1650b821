#!/usr/bin/python3
"""tools/make_rts_bench.py — writes the resample-then-shade bench scenes data/scenes/bench/rts-*.json for
`clvr bench --suite rts` (issue 4 part 8; seeds/004 Tables 1-2 compare Planes and Blend on opaque and
translucent data, with early ray termination and the skipping of low-opacity samples on and off).

    /usr/bin/python3 tools/make_rts_bench.py            # rewrites the scene files
    /usr/bin/python3 tools/make_rts_bench.py --check    # exit 1 if a file differs from what it would write

Volumes: engine (256x256x128 uint8), lobster (301x324x56 uint8, spacing 1 1 1.4), Marschner-Lobb 256^3
(generated). Per volume two transfer functions over the same colors: "translucent" (tau up to about 2%
of the box per world unit, most rays cross the volume) and "opaque" (tau 25x larger: most rays saturate
inside the first structures, where early termination pays). Planes: early termination 0.99 and opacity
threshold 0.002 (the paper's settings of skipping and ERT), plus on engine one scene with each turned off.
Blend: 256 slices, threshold 0.002 (back to front cannot terminate early). 512x512, two lights.
"""
import argparse
import json
import os
import sys

LIGHTS = [{"direction": [1, -0.6, 0.8]}, {"direction": [-0.5, -1, 0.2], "color": [0.35, 0.35, 0.45]}]
MATERIAL = {"ambient": 0.35, "diffuse": 0.75, "specular": 0.4, "shininess": 24}

# name: (volume spec, camera, scalar range (lo, hi), translucent tau scale per world unit)
VOLUMES = {
    "engine": ({"file": "../../../../shared/data/engine/engine.nrrd"},
               {"position": [560, -260, 330], "focal_point": [127.5, 127.5, 63.5], "view_up": [0, 0, 1],
                "view_angle": 30}, (0.0, 255.0), 0.1),
    "lobster": ({"file": "../../../../shared/data/lobster/lobster.nrrd"},
                {"position": [330, -110, 300], "focal_point": [150, 161.5, 38.5], "view_up": [0, 0, 1],
                 "view_angle": 32}, (0.0, 255.0), 0.3),
    "ml256": ({"generator": "marschner-lobb", "dims": [256, 256, 256]},
              {"position": [2.8, 1.95, 3.45], "focal_point": [0, 0, 0], "view_up": [0, 1, 0], "view_angle": 38},
              (0.0, 1.0), 1.6),
}

# Control points at fractions of the scalar range: (f, r, g, b, tau as a fraction of the scale).
SHAPE = [(0.0, 0, 0, 0, 0.0), (0.23, 0, 0, 0, 0.0), (0.35, 0.3, 0.5, 0.9, 0.05), (0.63, 0.6, 0.7, 0.9, 0.1),
         (0.78, 1.0, 0.7, 0.3, 0.4), (1.0, 1.0, 1.0, 0.9, 1.0)]
OPAQUE_FACTOR = 25.0


def transfer_function(volume, kind):
    _, _, (lo, hi), scale = VOLUMES[volume]
    factor = OPAQUE_FACTOR if kind == "opaque" else 1.0
    return [[round(lo + f * (hi - lo), 6), r, g, b, round(t * scale * factor, 6)] for f, r, g, b, t in SHAPE]


def scenes():
    """(file name, scene) for every bench scene, in the suite's order."""
    out = []
    for volume in VOLUMES:
        for kind in ("translucent", "opaque"):
            for technique in ("planes", "blend"):
                if technique == "planes":
                    options = {"early_termination": 0.99, "opacity_threshold": 0.002, "reflectance_map_size": 128}
                else:
                    options = {"slices": 256, "opacity_threshold": 0.002, "reflectance_map_size": 128}
                out.append(("rts-%s-%s-%s.json" % (technique, volume, kind), technique, volume, kind, options))
    for kind in ("translucent", "opaque"):
        out.append(("rts-planes-engine-%s-no-ert.json" % kind, "planes", "engine", kind,
                    {"early_termination": 1.0, "opacity_threshold": 0.002, "reflectance_map_size": 128}))
        out.append(("rts-planes-engine-%s-no-skip.json" % kind, "planes", "engine", kind,
                    {"early_termination": 0.99, "opacity_threshold": 0.0, "reflectance_map_size": 128}))
    result = []
    for name, technique, volume, kind, options in out:
        spec, camera, _, _ = VOLUMES[volume]
        scene = {
            "technique": technique,
            "volume": spec,
            "camera": camera,
            "image": {"width": 512, "height": 512, "background": [0, 0, 0]},
            "transfer_function": {"points": transfer_function(volume, kind)},
            "lights": LIGHTS,
            "material": MATERIAL,
            "options": options,
        }
        result.append((name, scene))
    return result


def scene_text(scene):
    keys = ['  "%s": %s' % (k, json.dumps(v)) for k, v in scene.items() if k != "transfer_function"]
    rows = ",\n".join("    " + json.dumps(p) for p in scene["transfer_function"]["points"])
    tf = '  "transfer_function": {"points": [\n' + rows + "\n  ]}"
    keys.insert(4, tf)
    return "{\n" + ",\n".join(keys) + "\n}\n"


def write_scenes(scene_list, tool, description):
    """The command line shared by the bench-scene writers: write, --check or --list `scene_list`
    ((file name, scene) pairs) in data/scenes/bench/; returns the exit status."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--check", action="store_true", help="compare instead of writing")
    ap.add_argument("--list", action="store_true", help="print the file names in the suite's order")
    args = ap.parse_args()
    bench_dir = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "scenes", "bench"))
    status = 0
    for name, scene in scene_list:
        if args.list:
            print(name)
            continue
        path = os.path.join(bench_dir, name)
        text = scene_text(scene)
        if args.check:
            if not os.path.exists(path) or open(path).read() != text:
                print(tool + ": " + path + " differs from the generated scene")
                status = 1
        else:
            with open(path, "w") as f:
                f.write(text)
            print("wrote " + path)
    return status


def main():
    return write_scenes(scenes(), "make_rts_bench.py", __doc__.split("\n")[0])


if __name__ == "__main__":
    sys.exit(main())
