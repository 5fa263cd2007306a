#!/usr/bin/python3
"""A study, an ensemble, an optimisation over records and one whose designs are batched over the
ranks give the serial run's results bit for bit on two MPI ranks; a study cut short
(--max-points) or killed (SIGTERM to mpirun), and an optimisation killed, resume on two ranks with
nothing lost and nothing computed twice; a worker writes nothing; bad input under mpirun ends the
job with exit code 2 and one message (docs/studies.md#distributed-studies-on-mpi).

    check_two_ranks.py POUNDSIM SOURCE_DIR WORK_DIR
"""

import csv
import json
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import time

# --oversubscribe: two ranks on whatever cores CI has; as root, Open MPI wants both flags.
MPIRUN = ["mpirun", "--oversubscribe", "-n", "2"]
if os.geteuid() == 0:
    MPIRUN.insert(1, "--allow-run-as-root")


def rows(folder, stem):
    """The table's rows by id, without the run time (which differs from run to run)."""
    with open(os.path.join(folder, f"{stem}.csv"), newline="") as f:
        return [{k: v for k, v in r.items() if k != "run_time_s"} for r in csv.DictReader(f)]


def run(command, **kwargs):
    r = subprocess.run(command, capture_output=True, text=True, **kwargs)
    return r


def require(condition, message):
    if not condition:
        sys.exit(f"check_two_ranks: {message}")


def kill_once_stored(command, database, table, count):
    """Runs `command` and sends mpirun SIGTERM once `table` of `database` has `count` rows (some
    results stored, not all); returns the rows stored when the job ended."""
    job = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if os.path.exists(database):
            try:
                with sqlite3.connect(f"file:{database}?mode=ro", uri=True) as db:
                    if db.execute(f"select count(*) from {table}").fetchone()[0] >= count:
                        break
            except sqlite3.Error:
                pass
        time.sleep(0.02)
    job.send_signal(signal.SIGTERM)
    job.communicate(timeout=60)
    with sqlite3.connect(f"file:{database}?mode=ro", uri=True) as db:
        return db.execute(f"select count(*) from {table}").fetchone()[0]


def main():
    poundsim, source, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    study = os.path.join(source, "examples", "study_eta_mu.toml")
    out = lambda name: os.path.join(work, name)  # noqa: E731

    # Serial (one thread) and on two ranks: the same table, bit for bit.
    serial = run([poundsim, "run", study, "--out", out("serial"), "--quiet", "--set", "study.threads=1"])
    require(serial.returncode == 0, serial.stderr)
    two = run(MPIRUN + [poundsim, "run", study, "--out", out("two")])
    require(two.returncode == 0, two.stdout + two.stderr)
    require(two.stdout.count("wrote ") == 1, f"one report, from rank 0:\n{two.stdout}")
    require(rows(out("two"), "study") == rows(out("serial"), "study"), "two ranks differ from the serial run")
    require(sorted(os.listdir(out("two"))) == ["input.toml", "study.csv", "study.csv-metadata.json", "study.sqlite", "summary.json"],
            f"files: {sorted(os.listdir(out('two')))}")

    # Cut short, then resumed on two ranks: the rest only.
    first = run(MPIRUN + [poundsim, "run", study, "--out", out("resumed"), "--quiet", "--max-points", "7"])
    require(first.returncode == 0, first.stderr)
    second = run(MPIRUN + [poundsim, "run", study, "--out", out("resumed"), "--quiet"])
    require(second.returncode == 0, second.stderr)
    summary = json.load(open(os.path.join(out("resumed"), "summary.json")))
    require(summary["skipped_as_finished"] == 7 and summary["run_this_time"] == 13, f"resumed: {summary}")
    require(rows(out("resumed"), "study") == rows(out("serial"), "study"), "the resumed run differs")

    # Killed while it runs (mpirun passes SIGTERM on, then SIGKILL), then resumed:
    # every point once, the same table.
    stored = kill_once_stored(MPIRUN + [poundsim, "run", study, "--out", out("killed"), "--quiet"],
                              os.path.join(out("killed"), "study.sqlite"), "points", 3)
    resumed = run(MPIRUN + [poundsim, "run", study, "--out", out("killed"), "--quiet"])
    require(resumed.returncode == 0, resumed.stderr)
    summary = json.load(open(os.path.join(out("killed"), "summary.json")))
    require(summary["skipped_as_finished"] == stored and summary["run_this_time"] == 20 - stored,
            f"killed with {stored} points stored, then: {summary}")
    require(rows(out("killed"), "study") == rows(out("serial"), "study"), "the killed and resumed run differs")

    # An ensemble of records, with its bare-pounding references, on two ranks.
    ensemble = os.path.join(source, "examples", "ensemble_fig2_frames.toml")
    a = run([poundsim, "run", ensemble, "--out", out("ensemble_serial"), "--quiet", "--set", "ensemble.threads=1"])
    b = run(MPIRUN + [poundsim, "run", ensemble, "--out", out("ensemble_two"), "--quiet"])
    require(a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr)
    require(rows(out("ensemble_two"), "ensemble") == rows(out("ensemble_serial"), "ensemble"),
            "the ensemble on two ranks differs")

    # An optimisation over a suite of records, each evaluation's records shared by the ranks:
    # the same evaluations, front and optimum.
    design = os.path.join(source, "examples", "design_5_and_8_storeys.toml")
    settings = ["analysis.duration=3", "optimize.global_evaluations=4", "optimize.local_evaluations=4",
                "optimize.pareto.points=3"]
    sets = [a for s in settings for a in ("--set", s)]
    a = run([poundsim, "run", design, "--out", out("optimize_serial"), "--quiet"] + sets)
    b = run(MPIRUN + [poundsim, "run", design, "--out", out("optimize_two"), "--quiet"] + sets)
    require(a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr)
    for name in ("evaluations.csv", "pareto.csv"):
        same = open(os.path.join(out("optimize_serial"), name)).read() == open(os.path.join(out("optimize_two"), name)).read()
        require(same, f"the optimisation's {name} on two ranks differs")
    summaries = [json.load(open(os.path.join(out(d), "optimize.json"))) for d in ("optimize_serial", "optimize_two")]
    for s in summaries:
        s.pop("run_time_s")
    require(summaries[0] == summaries[1], "the optimisation's optimize.json on two ranks differs")

    # An optimisation of one design per task, its designs batched over the ranks (each rank
    # computes a design NLopt is about to ask for): the same evaluations and optimum as serial.
    gap = os.path.join(source, "examples", "optimize_gap_elements.toml")
    # The whole budget (64 evaluations) at 120 ratios a design, ~3.5 s on two ranks: the kill below
    # must come well before its end (at the example's 27 ratios the run takes under a second and
    # can finish before mpirun's SIGTERM reaches it).
    sets = ["--set", "frf.points=120"]
    a = run([poundsim, "run", gap, "--out", out("batch_serial"), "--quiet", "--set", "optimize.threads=1"] + sets)
    b = run(MPIRUN + [poundsim, "run", gap, "--out", out("batch_two"), "--quiet"] + sets)
    require(a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr)
    same = open(os.path.join(out("batch_serial"), "evaluations.csv")).read() == open(os.path.join(out("batch_two"), "evaluations.csv")).read()
    require(same, "the batched optimisation's evaluations.csv on two ranks differs")
    summaries = [json.load(open(os.path.join(out(d), "optimize.json"))) for d in ("batch_serial", "batch_two")]
    require(summaries[1]["designs_computed"] >= summaries[1]["evaluations"], f"two ranks: {summaries[1]}")
    for s in summaries:
        s.pop("run_time_s")
        s.pop("designs_computed")  # two ranks also compute the guesses the search did not follow
    require(summaries[0] == summaries[1], "the batched optimisation's optimize.json on two ranks differs")

    # Killed while it runs, then resumed on two ranks: the evaluations already stored are read,
    # not computed again, and the search is the serial one.
    database = os.path.join(out("optimize_killed"), "optimize.sqlite")
    stored = kill_once_stored(MPIRUN + [poundsim, "run", gap, "--out", out("optimize_killed"), "--quiet"] + sets,
                              database, "evaluations", 5)
    # No result, whole or in part: the database alone (with SQLite's log when mpirun's SIGKILL came
    # before rank 0 closed it; the next run folds it in).
    left = set(os.listdir(out("optimize_killed")))
    require(left <= {"optimize.sqlite", "optimize.sqlite-wal", "optimize.sqlite-shm"} and "optimize.sqlite" in left,
            f"killed: {sorted(left)}")
    resumed = run(MPIRUN + [poundsim, "run", gap, "--out", out("optimize_killed"), "--quiet"] + sets)
    require(resumed.returncode == 0, resumed.stderr)
    summary = json.load(open(os.path.join(out("optimize_killed"), "optimize.json")))
    with sqlite3.connect(f"file:{database}?mode=ro", uri=True) as db:
        rows_now = db.execute("select count(*) from evaluations").fetchone()[0]
    require(5 <= stored < summary["evaluations"] and summary["evaluations_from_database"] >= 1
            and rows_now == stored + summary["designs_computed"],
            f"killed with {stored} stored, then {rows_now} rows: {summary}")
    same = open(os.path.join(out("batch_serial"), "evaluations.csv")).read() == open(os.path.join(out("optimize_killed"), "evaluations.csv")).read()
    require(same, "the killed and resumed optimisation differs from the serial one")

    # Bad input: exit code 2, one message.
    bad = run(MPIRUN + [poundsim, "run", study, "--out", out("bad"), "--set", "study.threads=-1"])
    require(bad.returncode == 2, f"exit code {bad.returncode}: {bad.stderr}")
    require(bad.stderr.count("poundsim: error:") == 1, bad.stderr)
    require(not os.path.exists(out("bad")), "bad input left a folder")
    print("two ranks: study, resume, kill and resume, ensemble, optimisations (records shared, designs batched, "
          "killed and resumed), bad input: as serial")


if __name__ == "__main__":
    main()
