"""What the pytest files share: where the sources and the command line are, running it, reading
its CSV files."""

import csv
import os
import pathlib
import subprocess

SOURCE = pathlib.Path(os.environ.get("POUNDSIM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
CLI = os.environ.get("POUNDSIM_CLI", str(SOURCE / "build" / "ci" / "poundsim"))
EXAMPLES = SOURCE / "examples"


def cli_run(model: pathlib.Path, out: pathlib.Path, *settings: str) -> pathlib.Path:
    """`poundsim run MODEL --out OUT --quiet --set …`; the folder it wrote."""
    args = [CLI, "run", str(model), "--out", str(out), "--quiet"]
    for s in settings:
        args += ["--set", s]
    subprocess.run(args, check=True)
    return out


def read_csv(path: pathlib.Path):
    """The header and the rows of a CSV file, as text."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]
