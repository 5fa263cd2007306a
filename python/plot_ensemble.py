#!/usr/bin/python3
"""Amplification by pounding over an ensemble of records (the folder an `analysis.kind =
"ensemble"` run wrote): for every frame and floor, the ratio of the peak with pounding to the peak
without it — displacement, interstorey drift and absolute acceleration — as the mean over the
records (bars) and the largest (markers). Writes DIR/amplification.png.

    plot_ensemble.py DIR [--title TEXT]
"""

import argparse
import json
import os
import re

from poundsim_results import finished_points, use_matplotlib

plt = use_matplotlib()


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("dir")
    parser.add_argument("--title", default="")
    args = parser.parse_args()
    records = [json.loads(m) for _, m in finished_points(os.path.join(args.dir, "ensemble.sqlite"))]
    if not records:
        raise SystemExit(f"{args.dir}: no finished record")
    quantities = [("amp_u", "displacement"), ("amp_drift", "interstorey drift"), ("amp_acc", "absolute acceleration")]
    keys = sorted({k for r in records for k in r if re.match(r"amp_u_\d+_\d+$", k)},
                  key=lambda k: tuple(int(x) for x in k.split("_")[2:]))
    labels = [f"frame {k.split('_')[2]}\nfloor {k.split('_')[3]}" for k in keys]
    fig, ax = plt.subplots(figsize=(max(6.0, 1.1 * len(keys) + 3), 4.4), dpi=130)
    width = 0.26
    highest = 1.0
    for q, (prefix, name) in enumerate(quantities):
        mean = [sum(r[prefix + k[5:]] for r in records) / len(records) for k in keys]
        worst = [max(r[prefix + k[5:]] for r in records) for k in keys]
        highest = max(highest, *worst)
        x = [i + (q - 1) * width for i in range(len(keys))]
        bars = ax.bar(x, mean, width, label=f"{name}: mean")
        ax.plot(x, worst, "v", color=bars.patches[0].get_facecolor(), mec="black", ms=6,
                label=f"{name}: largest")
    ax.axhline(1.0, color="black", lw=0.8)
    ax.set_xticks(range(len(keys)), labels, fontsize=8)
    ax.set_ylabel("peak with pounding ÷ peak without")
    ax.set_title((args.title or "amplification by pounding") + f" — {len(records)} records", fontsize=9)
    ax.set_ylim(0, 1.4 * highest)  # room for the legend above the bars
    ax.legend(fontsize=7, ncol=3, loc="upper center")
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(os.path.join(args.dir, "amplification.png"))


if __name__ == "__main__":
    main()
