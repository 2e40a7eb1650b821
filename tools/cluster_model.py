#!/usr/bin/python3
"""tools/cluster_model.py — the scaling model of docs/cluster.md, fitted to `clvr bench --suite cluster`
figures (1, 2 and 4 ranks on one node) and projected to 64 and 1,024 ranks, one rank per node:

    /usr/bin/python3 tools/cluster_model.py build/bench/cluster.json --bandwidth-gbs 12.5 \\
        --plot docs/images/cluster-scaling.png

Model, per frame of P pixels (16-byte float RGBA):
  render     T_r(N) = T_1 * imb(N) / N            strong scaling (the data split over N ranks)
             T_r(N) = T_1 * imb(N) / N^(2/3)      weak scaling (N times the data, the same image: rays
                                                  N^(1/3) times longer, so N^(1/3) / N of the work per rank)
             T_1 the one-rank render time, imb(N) = 1 + k log2 N the slowest rank over the mean, k fitted to
             the per-rank render times measured at 2 and 4 ranks;
  composite  T_c(N) = c + a log2 N + 16 P (N - 1) / N / B
             IceT's radix-k: log2 N rounds (a: per round, fitted) and the image's bytes crossing the network
             once (B: bandwidth, a parameter; on one node B and a are fitted to the measured 1, 2, 4 ranks).
  frame      T(N) = T_r(N) + T_c(N).
On this 2-core machine 2 and 4 ranks share the same cores, so the measured render times show the cost of
splitting (imbalance, boxes), not the speed-up of more nodes; the projection assumes one node per rank.
"""
import argparse
import json
import math
import sys


def fit_composite(points, pixels):
    """c, a, B (bytes/ms) from (N, ms) at N = 1, 2, 4: exact solve of the three-parameter model."""
    by_n = {n: ms for n, ms in points}
    c = by_n[1]
    # T(2) = c + a + 8P/B, T(4) = c + 2a + 12P/B  ->  solve for a and 1/B
    d2, d4 = by_n[2] - c, by_n[4] - c
    inv_b = (d4 - 2.0 * d2) / (16.0 * pixels * (0.75 - 1.0))  # from d4 - 2 d2 = 16P/B (3/4 - 2/2)
    a = d2 - 16.0 * pixels * 0.5 * inv_b
    if inv_b <= 0.0:  # no bandwidth term visible on one node: all of it per round
        inv_b = 0.0
        a = max(0.0, (d2 + d4 / 2.0) / 2.0)
    return c, a, inv_b


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("bench_json")
    ap.add_argument("--bandwidth-gbs", type=float, default=12.5, help="network bandwidth per rank, GB/s (100 Gb/s)")
    ap.add_argument("--plot", default="", help="write the plot (PNG) here")
    args = ap.parse_args()
    with open(args.bench_json) as f:
        report = json.load(f)
    b_net = args.bandwidth_gbs * 1e9 / 1e3  # bytes per ms
    ns = [2 ** i for i in range(0, 11)]
    curves = []
    print("| scene | T_1 render ms | imbalance k | composite c, a ms, B GB/s (one node) | strong 64 | strong 1024 | weak 64 | weak 1024 |")
    print("|---|---|---|---|---|---|---|---|")
    for scene in report["scenes"]:
        rows = {r["ranks"]: r for r in scene["ranks"]}
        pixels = rows[1]["width"] * rows[1]["height"]
        t1 = rows[1]["render_ms"]
        ks = []
        for n in (2, 4):
            per = rows[n]["render_ms_per_rank"]
            mean = sum(per) / len(per)
            ks.append((max(per) / mean - 1.0) / math.log2(n))
        k = max(0.0, sum(ks) / len(ks))
        c, a, inv_b = fit_composite([(n, rows[n]["composite_ms"]) for n in (1, 2, 4)], pixels)

        def composite(n):
            return c + a * math.log2(n) + 16.0 * pixels * (n - 1) / n / b_net

        def strong(n):
            return t1 * (1.0 + k * math.log2(n)) / n + composite(n)

        def weak(n):
            return t1 * (1.0 + k * math.log2(n)) / n ** (2.0 / 3.0) + composite(n)

        name = scene["scene"].split("/")[-1].replace(".json", "")
        shm = "inf" if inv_b == 0.0 else "%.1f" % (1.0 / inv_b * 1e3 / 1e9)
        print("| %s | %.1f | %.3f | %.1f, %.2f, %s | %.1f ms | %.1f ms | %.1f ms | %.1f ms |" %
              (name, t1, k, c, a, shm, strong(64), strong(1024), weak(64), weak(1024)))
        curves.append((name, [(n, rows[n]["frame_ms"]) for n in (1, 2, 4)], [strong(n) for n in ns],
                       [weak(n) for n in ns]))
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4.5), dpi=100)
        for i, (name, measured, s, w) in enumerate(curves):
            color = "C%d" % i
            ax.plot(ns, s, "-", color=color, label=name + ": strong (model)")
            ax.plot(ns, w, "--", color=color, label=name + ": weak (model)")
            ax.plot([m[0] for m in measured], [m[1] for m in measured], "o", color=color,
                    label=name + ": measured, one 2-core node")
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xlabel("ranks (model: one node per rank, %.1f GB/s network)" % args.bandwidth_gbs)
        ax.set_ylabel("ms per frame")
        ax.set_title("clvr sort-last: measured and projected frame time")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(args.plot)
        print("wrote " + args.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
