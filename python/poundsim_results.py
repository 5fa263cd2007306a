"""Reading poundsim's result files; shared by the plotting and report scripts beside it."""

import csv
import sqlite3
import sys

COLOURS = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange"]


def colour(i):
    """The colour of the i-th curve (0-based), cycling."""
    return COLOURS[i % len(COLOURS)]


def read_frf(path):
    """The rows of an frf.csv sorted by ω̄/ω₁, every field a float but `branch`, and the numbers of
    the frames it holds."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no rows")
    rows.sort(key=lambda r: float(r["ratio"]))
    frames = sorted(int(k[1:-2]) for k in rows[0] if k.startswith("V") and k.endswith("_W") and "free" not in k)
    return [{k: (v if k == "branch" else float(v)) for k, v in r.items()} for r in rows], frames


def finished_points(database):
    """The JSON texts (parameters, metrics) of every finished point of a study or ensemble
    database, opened read-only."""
    db = sqlite3.connect(f"file:{database}?mode=ro", uri=True)
    return [(p, m) for p, status, m in db.execute("SELECT parameters, status, metrics FROM points") if status == "done"]
