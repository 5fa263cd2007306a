#!/usr/bin/env python3
"""Does continuation find every periodic response the brute force settles on?

    check_continued_branches.py POUNDSIM MODEL.toml WORK_DIR [--set KEY=VALUE ...]
    check_continued_branches.py --csv BRUTE_FRF.csv CONTINUED_FRF.csv

Runs the frequency response of MODEL.toml twice with the exact integrator — simulated from rest
(frf.method = "simulation") and by continuation — (or reads the two frf.csv files) and, for each
ratio where the response from rest is periodic with minimal period k, looks for a stable continued
orbit of minimal period k with the same peaks there: a continued row at that ratio whose V<f>_W
agree to 1e-3 (relative), or two consecutive rows of one branch of period k either side of the
ratio, one of them stable, whose V<f>_W interpolated linearly to the ratio agree to 3 %. Prints
each ratio missed with what the continuation has nearest in peaks at that ratio, and exits 1 when
any is missed. Ratios the brute force finds not periodic (periodicity 0) are left out.

From the files alone this is a quick look: the interpolation between points admits a coexisting
orbit of close peaks, and a doubled orbit within the simulation's tolerance of the one it doubled
from (the simulation reads period k, the continuation 2k) is reported missed. The test
PeriodicOrbits.ThePeriodicResponsesFromRestAreStableContinuedOrbits shoots the orbit at the
ratio instead (docs/periodic-orbits.md).
"""
import csv
import os
import subprocess
import sys

RTOL = 1e-3
# Between two points of a branch (at most one ratio spacing apart) the peaks are interpolated:
# their curvature and the corners where an impact appears allow a few per cent.
INTERPOLATED_RTOL = 0.03


def read(path):
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def shears(row):
    return [float(row[k]) for k in sorted(row) if k.startswith("V") and k.endswith("_W") and "free" not in k]


def close(a, b, rtol=RTOL):
    return all(abs(x - y) <= rtol * max(abs(y), 1e-12) for x, y in zip(a, b))


def bracketed(a, b, ra, rb, ratio, target, rtol):
    """The peaks interpolated linearly in the ratio between two points of a branch match."""
    t = (ratio - ra) / (rb - ra)
    return all(abs(x + t * (y - x) - v) <= rtol * v for x, y, v in zip(a, b, target))


def branches(continued):
    """Rows of each branch in the order written (arclength order)."""
    out = {}
    for row in continued:
        if int(row["branch_id"]) >= 0:
            out.setdefault(int(row["branch_id"]), []).append(row)
    return out


def orbits_at(by_branch, ratio):
    """(branch, a, b): the continued rows at `ratio` (a is b) or the consecutive pairs bracketing it."""
    for branch, rows in by_branch.items():
        for i, row in enumerate(rows):
            r = float(row["ratio"])
            if abs(r - ratio) <= 1e-9 * max(1.0, ratio):
                yield branch, row, row
            elif i + 1 < len(rows):
                r2 = float(rows[i + 1]["ratio"])
                if min(r, r2) < ratio - 1e-9 < ratio + 1e-9 < max(r, r2):
                    yield branch, row, rows[i + 1]


def describe(row):
    return (f"branch {row['branch_id']} at {float(row['ratio']):.6f}: period {row['periodicity']}, "
            f"{'stable' if row['stable'] == '1' else 'unstable'}, V/W {' '.join(f'{v:.6g}' for v in shears(row))}")


def compare(brute, continued):
    by_branch = branches(continued)
    misses = []
    checked = 0
    for row in brute:
        k = int(row["periodicity"])
        if k == 0:
            continue
        checked += 1
        ratio, target = float(row["ratio"]), shears(row)
        found = False
        nearest = None
        for _, a, b in orbits_at(by_branch, ratio):
            same_period = int(a["periodicity"]) == k and int(b["periodicity"]) == k
            # A branch's stability changes only at a bifurcation, a point of its own (whose |μ| = 1
            # may be labelled either way).
            stable = a["stable"] == "1" or b["stable"] == "1"
            peaks = close(shears(a), target) if a is b else bracketed(
                shears(a), shears(b), float(a["ratio"]), float(b["ratio"]), ratio, target, INTERPOLATED_RTOL)
            if same_period and stable and peaks:
                found = True
                break
            distance = max(abs(x - t) / t for x, t in zip(shears(a), target))
            if nearest is None or distance < nearest[0]:
                nearest = (distance, a, b)
        if not found:
            simulated = [c for c in continued if int(c["branch_id"]) < 0 and abs(float(c["ratio"]) - ratio) <= 1e-9]
            note = "simulated there by the continuation run" if simulated else (
                "nearest: " + describe(nearest[1]) + ("" if nearest[1] is nearest[2] else " … " + describe(nearest[2]))
                if nearest else "no continued orbit there")
            misses.append(f"{ratio:.4f}: period {k}, V/W {' '.join(f'{v:.6g}' for v in target)}; {note}")
    return checked, misses


def run(poundsim, model, out, extra):
    subprocess.run([poundsim, "run", model, "--out", out, "--quiet"] + extra, check=True)
    return read(os.path.join(out, "frf.csv"))


def main(argv):
    if len(argv) >= 3 and argv[0] == "--csv":
        brute, continued = read(argv[1]), read(argv[2])
        name = argv[2]
    elif len(argv) >= 3:
        poundsim, model, work = argv[0], argv[1], argv[2]
        extra = ["--set", "analysis.integrator=exact"]
        rest = argv[3:]
        while rest:
            if rest[0] != "--set" or len(rest) < 2:
                raise SystemExit(__doc__)
            extra += rest[:2]
            rest = rest[2:]
        name = os.path.splitext(os.path.basename(model))[0]
        brute = run(poundsim, model, os.path.join(work, name + "_simulation"), extra + ["--set", "frf.method=simulation"])
        continued = run(poundsim, model, os.path.join(work, name + "_continuation"),
                        extra + ["--set", "frf.method=continuation"])
    else:
        raise SystemExit(__doc__)
    checked, misses = compare(brute, continued)
    print(f"{name}: {checked} periodic ratios, {len(misses)} without a stable continued orbit of their period")
    for m in misses:
        print("  " + m)
    return 1 if misses else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
