#!/usr/bin/python3
"""Draws poundsim frequency responses (frf.csv) the way Pasquino, Santini & Caliò do: V/W against
ω̄/ω₁ for every frame, interacting frames solid and free frames dashed. A two-way sweep
(sweep = "both") is drawn over it as markers, ▲ sweeping up and ▼ down, so that coexisting
branches and jumps show; responses that are not periodic (periodicity 0) are marked ×.

    plot_frf.py FRF.csv OUT.png [--sweep SWEEP.csv] [--compare OTHER.csv LABEL] [--title TEXT]
    plot_frf.py --figure FRF.csv OUT.png SWEEP.csv TITLE [--figure ...]   (several at once)
"""

import argparse

from poundsim_results import colour, read_frf, use_matplotlib

plt = use_matplotlib()


def column(rows, key):
    return [r[key] for r in rows]


def draw(frf, png, sweep=None, title="", compare=None):
    rows, frames = read_frf(frf)
    ratio = column(rows, "ratio")
    fig, ax = plt.subplots(figsize=(7.0, 4.6), dpi=130)
    chaotic = [r for r in rows if r["periodicity"] == 0]
    for i, f in enumerate(frames):
        ax.plot(ratio, column(rows, f"V{f}_W"), "-", color=colour(i), lw=1.6, label=f"frame {f}, interacting")
        ax.plot(ratio, column(rows, f"V{f}_free_W"), "--", color=colour(i), lw=1.2, label=f"frame {f}, free")
        if chaotic:
            ax.plot(column(chaotic, "ratio"), column(chaotic, f"V{f}_W"), "x", color=colour(i), ms=5,
                    label="not periodic" if i == 0 else None)
    if compare:
        other, _ = read_frf(compare[0])
        for i, f in enumerate(frames):
            ax.plot(column(other, "ratio"), column(other, f"V{f}_W"), ":", color=colour(i), lw=1.4,
                    label=f"frame {f}, {compare[1]}")
    if sweep:
        swept, _ = read_frf(sweep)
        for branch, marker, name in (("up", "^", "sweep up"), ("down", "v", "sweep down")):
            points = [r for r in swept if r["branch"] == branch]
            for i, f in enumerate(frames):
                ax.plot(column(points, "ratio"), column(points, f"V{f}_W"), marker, ms=3.2, mfc="none",
                        mew=0.7, color=colour(i), label=name if i == 0 else None)
    ax.set_xlabel("ω̄ / ω₁")
    ax.set_ylabel("V / W")
    ax.set_xlim(min(ratio), max(ratio))
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    if title:
        ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
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
