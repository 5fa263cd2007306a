#!/usr/bin/python3
"""Amplification by pounding over an ensemble of records (the folder an `analysis.kind =
"ensemble"` run wrote). Left: per frame, each record's ratio of the peak base shear with pounding
to the peak without it, and their mean. Right: for every frame and floor, the same ratio of the
displacement, interstorey drift and absolute acceleration peaks, as the mean over the records
(bars) and the largest (markers). Writes DIR/amplification.png. Drawn by
poundsim.plot.ensemble_amplification and ensemble_floor_amplification from poundsim.read(DIR).

    plot_ensemble.py DIR [--title TEXT]
"""

import os
import sys

from poundsim_results import folder_arguments, use_matplotlib

plt = use_matplotlib()

# After use_matplotlib(): the package needs NumPy, which a python3 without Matplotlib may lack.
import numpy as np  # noqa: E402

import poundsim  # noqa: E402
from poundsim import plot  # noqa: E402


def main():
    args = folder_arguments(__doc__)
    ensemble = poundsim.read(args.dir)
    if not isinstance(ensemble, poundsim.Study):
        sys.exit(f"{args.dir}: not an ensemble ({type(ensemble).__name__})")
    records = int(np.count_nonzero(np.asarray(ensemble["status"]).astype(str) == "done"))
    if not records:
        raise SystemExit(f"{args.dir}: no finished record")
    with plot.journal_style():
        fig, (per_frame, per_floor) = plt.subplots(1, 2, figsize=(plot.PAGE_WIDTH, 3.4), dpi=plot.DPI,
                                                   layout="constrained", gridspec_kw={"width_ratios": [2, 3]})
        plot.ensemble_amplification(ensemble, ax=per_frame)
        plot.ensemble_floor_amplification(ensemble, ax=per_floor)
        fig.suptitle((args.title or "amplification by pounding") + f" — {records} records")
        fig.savefig(os.path.join(args.dir, "amplification.png"))
    plt.close(fig)


if __name__ == "__main__":
    main()
