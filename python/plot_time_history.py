#!/usr/bin/python3
"""Pictures of one poundsim time history (the folder `poundsim run … --out DIR` wrote):

- DIR/response.png   top-floor displacement of every frame [mm], and the gap-element forces [kN]
                     in time, with the impacts marked;
- DIR/energy.png     the energy balance in time [kJ]: what the ground motion put in, and where it
                     is (kinetic, strain, dissipated by dashpots, lost in impacts);
- DIR/profiles.png   peak displacement [mm] and interstorey drift ratio [%] over the height of
                     every frame, with (solid) and without (dashed) pounding.

Drawn by poundsim.plot (time_history, gap_forces, energy, envelopes) from poundsim.read(DIR). A
panel whose channels were not recorded is left out, and a figure with none is not written; stderr
says which and how to record them.

    plot_time_history.py DIR [--title TEXT]
"""

import os
import sys

from poundsim_results import folder_arguments, use_matplotlib

plt = use_matplotlib()

# After use_matplotlib(): the package needs NumPy, which a python3 without Matplotlib may lack.
import poundsim  # noqa: E402
from poundsim import plot  # noqa: E402


def left_out(what):
    """What a figure leaves out and why, on stderr: a picture is never the message."""
    sys.stderr.write(f"{os.path.basename(sys.argv[0])}: {what}\n")


def main():
    args = folder_arguments(__doc__)
    th = poundsim.read(args.dir)
    if not isinstance(th, poundsim.TimeHistory):
        sys.exit(f"{args.dir}: not a time history ({type(th).__name__})")
    title = args.title or th.title
    frames = th.summary.to_dict()["model"]["frames"]
    tops = [f"u_{f}_{frame['storeys']}" for f, frame in enumerate(frames, start=1)]
    tops = [c for c in tops if c in th]

    with plot.journal_style():
        # Response and gap forces, each panel whose channels were recorded.
        fig, (top, forces) = plt.subplots(2, 1, figsize=(plot.PAGE_WIDTH, 4.8), dpi=plot.DPI, sharex=True,
                                          layout="constrained")
        drawn = []
        if tops:
            plot.time_history(th, tops, ax=top)
            top.set_ylabel("top-floor displacement [mm]")
            top.set_xlabel("")
            drawn.append(top)
        else:
            left_out("response.png: no top-floor displacement u_<frame>_<top> was recorded: that panel is left out")
        try:
            plot.gap_forces(th, ax=forces)
            drawn.append(forces)
        except KeyError as missing:
            left_out(f"response.png: {missing.args[0]}: that panel is left out")
        if len(drawn) == 1:
            fig.delaxes(forces if drawn[0] is top else top)
            drawn[0].set_subplotspec(fig.add_gridspec(1, 1)[0])
            drawn[0].tick_params(labelbottom=True)
            drawn[0].set_xlabel("t [s]")
        if drawn:
            drawn[0].set_title(title)
            fig.savefig(os.path.join(args.dir, "response.png"))
        else:
            left_out("response.png not written: neither of its panels has its channels")
        plt.close(fig)

        # Energy balance.
        fig, ax = plt.subplots(figsize=(plot.PAGE_WIDTH, 3.2), dpi=plot.DPI, layout="constrained")
        residual = th.summary.energy.max_relative_residual
        try:
            plot.energy(th, ax=ax, title=f"{title}\nenergy balance (largest relative residual {residual:.1e})")
            fig.savefig(os.path.join(args.dir, "energy.png"))
        except KeyError as missing:
            left_out(f"energy.png not written: {missing.args[0]}")
        plt.close(fig)

    # Peak profiles over height.
    fig = plot.envelopes(th, size="page", title=title)
    fig.savefig(os.path.join(args.dir, "profiles.png"))
    plt.close(fig)


if __name__ == "__main__":
    main()
