#!/usr/bin/python3
"""Heat map of one metric of a poundsim study over two of its parameters, from the study's
SQLite database (study.sqlite) — e.g. the reduction of the larger peak base shear with respect to
bare pounding over the gap-element spring η and dashpot μ.

    plot_study.py study.sqlite X_KEY Y_KEY METRIC OUT.png [--fix KEY=VALUE ...] [--title TEXT]

Points must lie on a grid in X and Y; other varied parameters must be fixed with --fix. Each cell
shows its value to 3 significant digits (drift ratios in %); the lowest is outlined; the title is
the metric in words unless --title gives one. Drawn by poundsim.plot.study_map from the study as
poundsim.read reads its folder (study.csv), or from the database's finished points when the CSV
beside it is missing or holds another count of them (a study stopped before it wrote the CSV).
"""

import argparse
import json
import os
import sys

from poundsim_results import finished_points, use_matplotlib

plt = use_matplotlib()

# After use_matplotlib(): the package needs NumPy, which a python3 without Matplotlib may lack.
import numpy as np  # noqa: E402

import poundsim  # noqa: E402
from poundsim import plot  # noqa: E402


def from_database(database, points):
    """A Study of the database's finished points (parameters and metrics as columns)."""
    rows = [(json.loads(p), json.loads(m)) for p, m in points]
    keys = list(dict.fromkeys(k for p, _ in rows for k in p)) + list(dict.fromkeys(k for _, m in rows for k in m))
    columns = {"status": np.array(["done"] * len(rows))}
    for key in keys:
        values = [p.get(key, m.get(key)) for p, m in rows]
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) or v is None for v in values):
            columns[key] = np.array([np.nan if v is None else float(v) for v in values])
        else:
            columns[key] = np.array([str(v) for v in values])
    return poundsim.Study(poundsim.Table(columns), {"analysis": {"kind": "study"}}, database)


def load(database):
    points = finished_points(database)
    folder = os.path.dirname(os.path.abspath(database))
    stem = os.path.splitext(os.path.basename(database))[0]
    if os.path.isfile(os.path.join(folder, f"{stem}.csv")):
        study = poundsim.read(folder)
        if isinstance(study, poundsim.Study) and study.database and \
                os.path.samefile(study.database, database) and \
                int(np.count_nonzero(np.asarray(study["status"]).astype(str) == "done")) == len(points):
            return study
    return from_database(database, points)


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

    study = load(args.database)
    if args.x not in study.table or args.y not in study.table:
        sys.exit(f"{args.database}: the points do not vary {args.x} and {args.y}")
    if args.metric not in study.table:
        sys.exit(f"{args.database}: no finished point with metric {args.metric}")
    try:
        fig = plot.study_map(study, args.x, args.y, args.metric, fix=fixed,
                             title=args.title or plot.metric_label(args.metric, study[args.metric]),
                             size=(plot.COLUMN_WIDTH * 1.4, 3.6))
    except ValueError as e:
        sys.exit(f"{args.database}: {e}")
    fig.savefig(args.png)
    plt.close(fig)


if __name__ == "__main__":
    main()
