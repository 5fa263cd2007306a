"""What the scripts beside it share before they may import the package poundsim (which needs
NumPy): finding a python3 with Matplotlib (`use_matplotlib`), and, with Python's standard library
only, reading frf.csv for paper_report.py and a study database's finished points for
plot_study.py; and the arguments of the scripts that draw one results folder (`folder_arguments`).
The figures themselves are poundsim.plot's."""

import argparse
import csv
import os
import sqlite3
import subprocess
import sys

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
    database. Only read, but opened for writing (never created): SQLite deletes a WAL database's
    -wal and -shm files when the last connection closes, but not when that one is read-only."""
    db = sqlite3.connect(f"file:{database}?mode=rw", uri=True)
    try:
        rows = db.execute("SELECT parameters, status, metrics FROM points").fetchall()
    finally:
        db.close()
    return [(p, m) for p, status, m in rows if status == "done"]


# Debian's interpreter, where install-deps.sh puts Matplotlib (python3-matplotlib).
SYSTEM_PYTHON = "/usr/bin/python3"
# Set in the environment of a script re-executed under SYSTEM_PYTHON, so that it is tried once.
REEXECUTED = "POUNDSIM_PLOT_REEXECUTED"


def use_matplotlib():
    """Matplotlib's pyplot with the file-only Agg backend, whichever python3 started the script.

    An interpreter without Matplotlib (a pyenv or virtualenv python3, say) hands the script over,
    once, to Debian's /usr/bin/python3 when that one has it; otherwise the script stops with exit
    code 2 and says what to install."""
    try:
        import matplotlib
    except ImportError:
        system_has_it = os.access(SYSTEM_PYTHON, os.X_OK) and subprocess.run(
            [SYSTEM_PYTHON, "-c", "import matplotlib"], stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL).returncode == 0
        if system_has_it and REEXECUTED not in os.environ:
            sys.stdout.flush()
            sys.stderr.flush()
            os.execve(SYSTEM_PYTHON, [SYSTEM_PYTHON, os.path.abspath(sys.argv[0])] + sys.argv[1:],
                      dict(os.environ, **{REEXECUTED: sys.executable}))
        tried = [os.environ.get(REEXECUTED, sys.executable)]
        if SYSTEM_PYTHON not in tried:
            tried.append(SYSTEM_PYTHON)
        sys.stderr.write(
            f"{os.path.basename(sys.argv[0])}: error: needs the Python package matplotlib, which "
            f"{' and '.join(tried)} cannot import: install Debian's python3-matplotlib "
            f"(scripts/install-deps.sh does) and run the script with {SYSTEM_PYTHON}, or install "
            "python/requirements.txt into your interpreter (pip install -r python/requirements.txt)\n")
        sys.exit(2)
    matplotlib.use("Agg")
    import matplotlib.pyplot
    return matplotlib.pyplot


def folder_arguments(doc):
    """The command line of a script that draws one results folder: DIR and --title (its docstring
    `doc` is the help)."""
    parser = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("dir")
    parser.add_argument("--title", default="")
    return parser.parse_args()
