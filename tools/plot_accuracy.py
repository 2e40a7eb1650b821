#!/usr/bin/python3
"""tools/plot_accuracy.py — the time-against-error plot of `clvr bench --suite accuracy --reference --peer`
(issue 14 goal 1): per volume, frame time (x, log) against the mean image error versus the CPU reference
integral (y, log) for clvr's slice3d per sample, pre-integrated, and VTK's fixed-point ray caster at the same
sample distances. clvr's points use the 8-bit PNG's error, as VTK's must (its image comes as a PNG), so the
two are judged alike; clvr's float error is drawn dashed beside them.

    /usr/bin/python3 tools/plot_accuracy.py acc.json docs/images/slice3d-time-vs-error.png

Needs matplotlib (Debian: python3-matplotlib); a tool for the docs, not a dependency of clvr.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def series(scenes, volume):
    """(label, style, [(ms, error, slices)]) per curve of one volume, ordered by slice count."""
    curves = {"clvr per sample (PNG)": [], "clvr per sample (float)": [], "clvr pre-integrated (PNG)": [],
              "VTK FixedPoint (PNG)": []}
    for s in scenes:
        name = s["name"]
        if not name.startswith("acc-%s-" % volume) or "error_vs_reference_png" not in s:
            continue
        n = s["extra"]["slices"]
        if "-sample-" in name:
            curves["clvr per sample (PNG)"].append((s["frame_ms"], s["error_vs_reference_png"]["mean"], n))
            curves["clvr per sample (float)"].append((s["frame_ms"], s["error_vs_reference"]["mean"], n))
            peer = s.get("peer", {})
            if "frame_ms" in peer and "error_vs_reference_png" in peer:
                curves["VTK FixedPoint (PNG)"].append((peer["frame_ms"], peer["error_vs_reference_png"]["mean"], n))
        else:
            curves["clvr pre-integrated (PNG)"].append((s["frame_ms"], s["error_vs_reference_png"]["mean"], n))
    return {k: sorted(v, key=lambda p: p[2]) for k, v in curves.items() if v}


def main():
    if len(sys.argv) != 3:
        print(__doc__.split("\n\n")[1].strip(), file=sys.stderr)
        return 2
    report = json.load(open(sys.argv[1]))
    styles = {"clvr per sample (PNG)": ("C0", "-", "o"), "clvr per sample (float)": ("C0", "--", "."),
              "clvr pre-integrated (PNG)": ("C2", "-", "s"), "VTK FixedPoint (PNG)": ("C3", "-", "^")}
    titles = {"ml256": "Marschner-Lobb 256³, 512²", "engine": "engine 256×256×128, 512²"}
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    for ax, volume in zip(axes, ["ml256", "engine"]):
        for label, points in series(report["scenes"], volume).items():
            color, line, marker = styles[label]
            ax.plot([p[0] for p in points], [p[1] for p in points], line, color=color, marker=marker, label=label)
            for ms, err, n in points:
                if "float" not in label:
                    ax.annotate(str(n), (ms, err), textcoords="offset points", xytext=(4, 3), fontsize=7, color=color)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("frame time, ms (2 CPU cores)")
        ax.set_ylabel("mean |image − exact integral| (worst channel)")
        ax.set_title(titles[volume])
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("slice3d vs VTK: time against error (numbers: slices / samples per ray; %s)"
                 % report["machine"]["date"][:10], fontsize=10)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=110)
    print("wrote " + sys.argv[2])
    return 0


if __name__ == "__main__":
    sys.exit(main())
