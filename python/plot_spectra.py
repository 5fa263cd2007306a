#!/usr/bin/python3
"""The records of an ensemble run with [ensemble.scaling], as scaled: each record's pseudo-
acceleration spectrum, their mean and the design spectrum, with the range (or period) they were
matched over. Writes DIR/spectra.png. Drawn by poundsim.plot.spectra from poundsim.read(DIR).

    plot_spectra.py DIR [--title TEXT]
"""

import os
import sys

from poundsim_results import folder_arguments, use_matplotlib

plt = use_matplotlib()

import poundsim  # noqa: E402
from poundsim import plot  # noqa: E402


def main():
    args = folder_arguments(__doc__)
    ensemble = poundsim.read(args.dir)
    if not isinstance(ensemble, poundsim.Study) or ensemble.spectra is None:
        sys.exit(f"{args.dir}: not an ensemble run with [ensemble.scaling] (no spectra.csv)")
    with plot.journal_style():
        fig = plot.spectra(ensemble, title=args.title or "records as scaled")
        fig.savefig(os.path.join(args.dir, "spectra.png"))
    plt.close(fig)


if __name__ == "__main__":
    main()
