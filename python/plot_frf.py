#!/usr/bin/python3
"""Draws poundsim frequency responses (frf.csv) the way Pasquino, Santini & Caliò do: V/W against
ω̄/ω₁ for every frame, interacting frames solid and free frames dashed. A two-way sweep
(sweep = "both") is drawn over it as markers, ▲ sweeping up and ▼ down, so that coexisting
branches and jumps show; responses that are not periodic (periodicity 0) are marked ×.
FRF may also be a result folder (poundsim run … --out DIR). Drawn by poundsim.plot.frf.

    plot_frf.py FRF.csv OUT.png [--sweep SWEEP.csv] [--compare OTHER.csv LABEL] [--title TEXT]
    plot_frf.py --figure FRF.csv OUT.png SWEEP.csv TITLE [--figure ...]   (several at once)
"""

import argparse
import json
import os
import sys

from poundsim_results import use_matplotlib

plt = use_matplotlib()

# After use_matplotlib(): the package needs NumPy, which a python3 without Matplotlib may lack.
import poundsim  # noqa: E402
from poundsim import plot  # noqa: E402


def response(path):
    """The frequency response in `path`: a result folder, or a CSV table (with the summary.json
    beside a file named frf.csv, for the frames' names)."""
    if os.path.isdir(path):
        result = poundsim.read(path)
        if not isinstance(result, poundsim.FrequencyResponse):
            sys.exit(f"{path}: not a frequency response ({type(result).__name__})")
        table, summary = result.table, result.summary
    else:
        table = poundsim.Table.read_csv(path)
        beside = os.path.join(os.path.dirname(path), "summary.json")
        summary = {}
        if os.path.basename(path) == "frf.csv" and os.path.isfile(beside):
            with open(beside) as f:
                summary = json.load(f)
    if not len(table):
        sys.exit(f"{path}: no rows")
    return poundsim.FrequencyResponse(table, summary)


def draw(frf, png, sweep=None, title="", compare=None):
    fig = plot.frf(response(frf), sweep=response(sweep) if sweep else None,
                   compare=response(compare[0]) if compare else None,
                   compare_label=compare[1] if compare else "compared", title=title or None,
                   size=(plot.COLUMN_WIDTH * 1.4, 3.4))
    fig.savefig(png)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("frf", nargs="?")
    parser.add_argument("png", nargs="?")
    parser.add_argument("--sweep", help="frf.csv of a two-way sweep to mark over the curves")
    parser.add_argument("--title", default="")
    parser.add_argument("--compare", nargs=2, metavar=("OTHER", "LABEL"),
                        help="frf.csv of another model to draw dotted, e.g. bare pounding")
    parser.add_argument("--figure", nargs=4, action="append", metavar=("FRF", "PNG", "SWEEP", "TITLE"),
                        help="draw one more figure (SWEEP may be '-')")
    args = parser.parse_args()
    jobs = [(f, p, None if s == "-" else s, t) for f, p, s, t in (args.figure or [])]
    if args.frf:
        if not args.png:
            parser.error("give the PNG to write")
        jobs.append((args.frf, args.png, args.sweep, args.title, args.compare))
    if not jobs:
        parser.error("nothing to draw")
    for job in jobs:
        draw(*job)


if __name__ == "__main__":
    main()
