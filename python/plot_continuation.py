#!/usr/bin/python3
"""Draws a continuation in a model parameter (analysis.kind = "continuation", orbits.csv): V/W
against the parameter for every frame, stable branches solid and unstable dashed, folds ○,
period doublings □ and Neimark–Sacker points ◇, the free frames dotted. Drawn by
poundsim.plot.continuation.

    plot_continuation.py DIR OUT.png [--title TEXT]
"""

import argparse
import sys

from poundsim_results import use_matplotlib

plt = use_matplotlib()

# After use_matplotlib(): the package needs NumPy, which a python3 without Matplotlib may lack.
import poundsim  # noqa: E402
from poundsim import plot  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder", help="the result folder of poundsim run … --out DIR")
    parser.add_argument("png")
    parser.add_argument("--title", default="")
    args = parser.parse_args()
    result = poundsim.read(args.folder)
    if not isinstance(result, poundsim.Continuation):
        sys.exit(f"{args.folder}: not a continuation ({type(result).__name__})")
    fig = plot.continuation(result, title=args.title or None, size=(plot.COLUMN_WIDTH * 1.4, 3.4))
    fig.savefig(args.png)
    plt.close(fig)


if __name__ == "__main__":
    main()
