#!/usr/bin/python3
"""Heat map of one metric of a poundsim study over two of its parameters, from the study's
SQLite database (study.sqlite) — e.g. the reduction of the larger peak base shear with respect to
bare pounding over the gap-element spring η and dashpot μ.

    plot_study.py study.sqlite X_KEY Y_KEY METRIC OUT.png [--fix KEY=VALUE ...] [--title TEXT]

Points must lie on a grid in X and Y; other varied parameters must be fixed with --fix. Each cell
shows its value; the lowest is outlined.
"""

import argparse
import json
import sys

from poundsim_results import finished_points, use_matplotlib

plt = use_matplotlib()


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("database")
    parser.add_argument("x")
    parser.add_argument("y")
    parser.add_argument("metric")
    parser.add_argument("png")
    parser.add_argument("--fix", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--title", default="")
    args = parser.parse_args()

    fixed = {}
    for item in args.fix:
        key, _, value = item.partition("=")
        fixed[key] = json.loads(value) if value else None

    cells = {}
    for parameters, metrics in finished_points(args.database):
        p, m = json.loads(parameters), json.loads(metrics)
        if args.metric not in m:
            continue
        if any(p.get(k) != v for k, v in fixed.items()):
            continue
        if args.x not in p or args.y not in p:
            sys.exit(f"{args.database}: the points do not vary {args.x} and {args.y}")
        key = (p[args.x], p[args.y])
        if key in cells:
            sys.exit(f"{args.database}: several points at {args.x} = {key[0]}, {args.y} = {key[1]}; fix the other parameters with --fix")
        cells[key] = m[args.metric]
    if not cells:
        sys.exit(f"{args.database}: no finished point with metric {args.metric}")
    xs = sorted({k[0] for k in cells})
    ys = sorted({k[1] for k in cells})
    grid = [[cells.get((x, y), float("nan")) for x in xs] for y in ys]

    fig, ax = plt.subplots(figsize=(6.4, 4.8), dpi=130)
    image = ax.imshow(grid, origin="lower", cmap="viridis_r", aspect="auto")
    ax.set_xticks(range(len(xs)), [f"{x:g}" for x in xs])
    ax.set_yticks(range(len(ys)), [f"{y:g}" for y in ys])
    ax.set_xlabel(args.x)
    ax.set_ylabel(args.y)
    best = min(cells, key=cells.get)
    for j, y in enumerate(ys):
        for i, x in enumerate(xs):
            value = grid[j][i]
            if value == value:
                ax.text(i, j, f"{value:.2f}", ha="center", va="center", fontsize=8,
                        color="white" if value > (max(cells.values()) + min(cells.values())) / 2 else "black",
                        fontweight="bold" if (x, y) == best else "normal")
    ax.add_patch(plt.Rectangle((xs.index(best[0]) - 0.5, ys.index(best[1]) - 0.5), 1, 1, fill=False, lw=2, ec="red"))
    fig.colorbar(image, ax=ax, label=args.metric)
    ax.set_title(args.title or args.metric, fontsize=9)
    fig.tight_layout()
    fig.savefig(args.png)


if __name__ == "__main__":
    main()
