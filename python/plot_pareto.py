#!/usr/bin/python3
"""The Pareto front of an optimisation run with [optimize.pareto]: the objective against the
second figure at each point of the front, with bare pounding at the joint width and the free
frames (when their figures exist, e.g. free_peak_drift_ratio_1 for peak_drift_ratio_1) marked.
Writes DIR/pareto.png. Drawn by poundsim.plot.pareto from poundsim.read(DIR).

    plot_pareto.py DIR [--title TEXT]
"""

import os
import sys

from poundsim_results import folder_arguments, use_matplotlib

plt = use_matplotlib()

import poundsim  # noqa: E402
from poundsim import plot  # noqa: E402


def references(summary):
    """Bare pounding's and the free frames' (second figure, objective), where they have them."""
    front = summary["pareto"]
    objective, metric = front["objective"], front["metric"]
    marks = {}
    bare = summary["comparison"]["bare_pounding"]
    if objective in bare and metric in bare:
        marks["bare pounding"] = (bare[metric], bare[objective])
    optimum = summary["comparison"]["optimum"]
    free = [optimum.get("free_" + name) for name in (metric, objective)]
    if all(v is not None for v in free):
        marks["free frames"] = tuple(free)
    return marks


def main():
    args = folder_arguments(__doc__)
    opt = poundsim.read(args.dir)
    if not isinstance(opt, poundsim.Optimization) or opt.pareto is None:
        sys.exit(f"{args.dir}: not an optimisation with [optimize.pareto] (no pareto.csv)")
    with plot.journal_style():
        fig = plot.pareto(opt, title=args.title, reference=references(opt.summary.to_dict()))
        fig.savefig(os.path.join(args.dir, "pareto.png"))
    plt.close(fig)


if __name__ == "__main__":
    main()
