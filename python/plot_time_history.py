#!/usr/bin/python3
"""Pictures of one poundsim time history (the folder `poundsim run … --out DIR` wrote):

- DIR/response.png   top-floor displacement of every frame, and the gap-element forces, in time,
                     with the impacts marked;
- DIR/energy.png     the energy balance in time: what the ground motion put in, and where it is
                     (kinetic, strain, dissipated by dashpots, lost in impacts), with the residual;
- DIR/profiles.png   peak displacement and interstorey drift over the height of every frame, with
                     (solid) and without (dashed) pounding.

    plot_time_history.py DIR [--title TEXT]
"""

import argparse
import csv
import json
import os

from poundsim_results import colour, use_matplotlib

plt = use_matplotlib()


def gap_label(column):
    """F_1_3: "gap 1, floor 3" (left frame and floor); F_1_5_4, a slab of the right frame's
    floor 4 striking the left column below floor 5: "gap 1, column below floor 5, slab 4"."""
    parts = column[2:].split("_")
    if len(parts) == 3:
        return f"gap {parts[0]}, column below floor {parts[1]}, slab {parts[2]}"
    return f"gap {parts[0]}, floor {parts[1]}"


def columns(path):
    """Every column of a CSV of numbers, by name, in the file's order."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, data = rows[0], rows[1:]
    return {name: [float(r[i]) for r in data] for i, name in enumerate(header)}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("dir")
    parser.add_argument("--title", default="")
    args = parser.parse_args()
    summary = json.load(open(os.path.join(args.dir, "summary.json")))
    history = columns(os.path.join(args.dir, "history.csv"))
    with open(os.path.join(args.dir, "events.csv"), newline="") as f:
        events = list(csv.DictReader(f))
    t = history["t"]
    frames = summary["model"]["frames"]
    title = args.title or summary.get("title", "")

    # Response and gap forces.
    fig, (top, forces) = plt.subplots(2, 1, figsize=(8, 5.6), dpi=130, sharex=True)
    for f, frame in enumerate(frames, start=1):
        top.plot(t, history[f"u_{f}_{frame['storeys']}"], color=colour(f - 1), lw=0.9,
                 label=f"frame {f}, floor {frame['storeys']}")
    top.set_ylabel("top-floor displacement [m]")
    top.legend(fontsize=7)
    gap_columns = [h for h in history if h.startswith("F_")]
    for k, name in enumerate(gap_columns):
        forces.plot(t, history[name], lw=0.8, color=colour(k), label=gap_label(name))
    impacts = [float(e["t"]) for e in events if e["kind"] == "impact"]
    locks = [float(e["t"]) for e in events if e["kind"] == "lock"]
    if impacts:
        top.plot(impacts, [0.0] * len(impacts), "k|", ms=8, label="impacts")
        forces.plot(impacts, [0.0] * len(impacts), "k|", ms=8, label=f"impacts ({len(impacts)})")
    if locks:
        forces.plot(locks, [0.0] * len(locks), "v", color="grey", ms=4, label=f"locks ({len(locks)})")
    forces.set_ylabel("gap-element force [N]")
    forces.set_xlabel("t [s]")
    if gap_columns or impacts:
        forces.legend(fontsize=7, ncol=2)
    top.set_title(title, fontsize=9)
    for ax in (top, forces):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(args.dir, "response.png"))
    plt.close(fig)

    # Energy balance.
    fig, ax = plt.subplots(figsize=(8, 4.2), dpi=130)
    stack = [("E_kinetic", "kinetic"), ("E_storey_strain", "storey strain"), ("E_gap_strain", "gap spring"),
             ("E_storey_damping", "storey dashpots"), ("E_gap_damping", "gap dashpots"), ("E_impact", "impacts")]
    ax.stackplot(t, *[history[k] for k, _ in stack], labels=[label for _, label in stack], alpha=0.8)
    ax.plot(t, history["E_input"], "k", lw=1.2, label="input by the ground motion")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("energy [J]")
    residual = summary["energy"]["max_relative_residual"]
    ax.set_title(f"{title}\nenergy balance (largest relative residual {residual:.1e})", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(args.dir, "energy.png"))
    plt.close(fig)

    # Peak profiles over height.
    floors = summary["peaks"]["floors"]
    with_ratio = all(fl.get("interstorey_drift_ratio") is not None for fl in floors)
    if with_ratio:
        drift_of, free_drift_of = (lambda fl: fl["interstorey_drift_ratio"]), (lambda fl: fl["free"]["interstorey_drift_ratio"])
    else:
        drift_of, free_drift_of = (lambda fl: fl["interstorey_drift_m"]["value"]), (lambda fl: fl["free"]["interstorey_drift_m"])
    fig, (disp, drift) = plt.subplots(1, 2, figsize=(8, 4.6), dpi=130, sharey=True)
    for f in range(1, len(frames) + 1):
        rows = sorted((fl for fl in floors if fl["frame"] == f), key=lambda fl: fl["floor"])
        levels = [fl["floor"] for fl in rows]
        c = colour(f - 1)
        disp.plot([fl["displacement_m"]["value"] for fl in rows], levels, "-o", color=c, label=f"frame {f}, pounding")
        if "free" in rows[0]:
            disp.plot([fl["free"]["displacement_m"] for fl in rows], levels, "--s", color=c, mfc="none",
                      label=f"frame {f}, free")
        drift.plot([drift_of(fl) for fl in rows], levels, "-o", color=c)
        if "free" in rows[0]:
            drift.plot([free_drift_of(fl) for fl in rows], levels, "--s", color=c, mfc="none")
    disp.set_xlabel("peak displacement [m]")
    drift.set_xlabel("peak interstorey drift ratio" if with_ratio else "peak interstorey drift [m]")
    disp.set_ylabel("floor")
    disp.legend(fontsize=7)
    for ax in (disp, drift):
        ax.grid(alpha=0.3)
        ax.set_xlim(left=0)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(args.dir, "profiles.png"))
    plt.close(fig)


if __name__ == "__main__":
    main()
