#!/usr/bin/python3
"""The contact laws side by side (time-history result folders of the same frames and excitation,
one per law, e.g. examples/contact_laws/): for each, the peak pounding force, the peak base shear
of each frame (÷ the weight of frame 1, the paper's V/W), the energy the gap elements dissipated
(their damping and the impacts' losses) and the restitution they achieved. Prints the table (GitHub
Markdown) and draws it as bars into OUT (poundsim.plot.compare_runs).

    compare_contact_laws.py DIR [DIR ...] --out OUT.png
"""

import argparse
import os
import sys

from poundsim_results import use_matplotlib

plt = use_matplotlib()

# After use_matplotlib(): the package needs NumPy, which a python3 without Matplotlib may lack.
import poundsim  # noqa: E402
from poundsim import plot  # noqa: E402


def fail(message):
    """Bad input: the message on stderr and exit code 2, as poundsim itself."""
    print(f"compare_contact_laws.py: error: {message}", file=sys.stderr)
    sys.exit(2)


def law_of(summary):
    """The gap elements' law as the run's model file named it ("paper" when it did not)."""
    elements = summary["model"]["gap_elements"]
    return elements[0].get("law", "paper") if elements else "none"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("dirs", nargs="+")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    histories, runs = [], []
    for d in args.dirs:
        path = os.path.join(d, "summary.json")
        if not os.path.isfile(path):
            fail(f"{path}: no such file (a time-history result folder?)")
        if not os.path.isfile(os.path.join(d, "history.csv")):
            fail(f"{path}: not a time history")
        th = poundsim.read(d)
        if not isinstance(th, poundsim.TimeHistory):
            fail(f"{path}: not a time history")
        s = th.summary.to_dict()
        restitution = [g["effective_restitution"]["mean"] for g in s["gap_elements"] if g["effective_restitution"]]
        histories.append(th)
        runs.append({
            "law": law_of(s),
            "force": s["max_gap_force_N"],
            "impulse": s["max_impact_impulse_Ns"],
            "shear": [b["over_frame1_weight"] for b in s["peaks"]["base_shear"]],
            "dissipated": s["energy"]["gap_damping_J"] + s["energy"]["impact_loss_J"],
            "restitution": sum(restitution) / len(restitution) if restitution else None,
            "residual": s["energy"]["max_relative_residual"],
        })
    frames = len(runs[0]["shear"])
    print("| law | peak force [N] | peak impulse [N·s] | " + " | ".join(f"V{f + 1}/W" for f in range(frames)) +
          " | dissipated by the gap elements [J] | mean restitution | energy balance residual |")
    print("|---" * (6 + frames) + "|")
    for r in runs:
        e = "—" if r["restitution"] is None else f"{r['restitution']:.3f}"
        print(f"| {r['law']} | {r['force']:.4g} | {r['impulse']:.4g} | " +
              " | ".join(f"{v:.4f}" for v in r["shear"]) + f" | {r['dissipated']:.4g} | {e} | {r['residual']:.1e} |")

    fig = plot.compare_runs(histories, labels=[r["law"] for r in runs], size=(plot.PAGE_WIDTH, 2.8))
    fig.savefig(args.out)
    plt.close(fig)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
