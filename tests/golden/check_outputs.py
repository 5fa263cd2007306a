#!/usr/bin/env python3
"""Outputs bit for bit: runs every example and the paper's figures and compares checksums of
what they write with tests/golden/outputs.json.

A pure refactor keeps every checksum; a change that moves results re-records them (--update)
and says in its commit message what moved, by how much, and why. What is hashed: every CSV as
written (one with columns named run_time…, wall clock, is re-written without them), every JSON
document (its text) without the lines of its run-time fields (run_time_s and the version), the
rows of every SQLite table (run-time columns and fields dropped), and the input.toml each run
echoes (the configuration as read, which a change to the input layer must keep). The source and output folders
are replaced by placeholders so that the checksums do not depend on where the repository lives.

    check_outputs.py POUNDSIM SOURCE_DIR WORK_DIR            compare
    check_outputs.py POUNDSIM SOURCE_DIR WORK_DIR --update   write outputs.json anew
"""
import csv
import hashlib
import io
import json
import os
import re
import shutil
import sqlite3
import subprocess
import sys

# (name, model file relative to the source folder, extra arguments)
CASES = [
    ("fig2c_ratio0.8", "examples/fig2c_ratio0.8.toml", []),
    ("fig2c_ratio0.8_exact", "examples/fig2c_ratio0.8.toml", ["--set", "analysis.integrator=exact"]),
    ("fig4a_ratio0.7", "examples/fig4a_ratio0.7.toml", []),
    ("fig4a_ratio0.7_exact", "examples/fig4a_ratio0.7.toml", ["--set", "analysis.integrator=exact"]),
    ("free_vibration_impact", "examples/free_vibration_impact.toml", []),
    ("free_vibration_impact_exact", "examples/free_vibration_impact.toml",
     ["--set", "analysis.integrator=exact"]),
    ("three_buildings_el_centro", "examples/three_buildings_el_centro.toml", []),
    ("three_buildings_el_centro_force", "examples/three_buildings_el_centro.toml",
     ["--set", "analysis.separation=force"]),
    ("el_centro_5_and_8_storeys_hertzdamp", "examples/el_centro_5_and_8_storeys_hertzdamp.toml", []),
    ("el_centro_5_and_8_storeys_bilinear", "examples/el_centro_5_and_8_storeys_bilinear.toml", []),
    ("different_storey_heights", "examples/different_storey_heights.toml", []),
    ("slab_to_column", "examples/slab_to_column.toml", []),
    ("ensemble_fig2_frames", "examples/ensemble_fig2_frames.toml", []),
    ("ensemble_ec8_spectrum", "examples/ensemble_ec8_spectrum.toml", []),
] + [(f"contact_laws_{law}", f"examples/contact_laws/{law}.toml", [])
     for law in ("paper", "kelvin_voigt", "hertz", "hertzdamp", "jankowski")] + [
    ("study_eta_mu", "examples/study_eta_mu.toml", []),
    ("optimize_gap_elements", "examples/optimize_gap_elements.toml", []),
    ("optimize_ensemble", "examples/optimize_ensemble.toml", []),
    # The design example at a smaller budget and 4 s of each record (the whole of it: 24 s).
    ("design_5_and_8_storeys", "examples/design_5_and_8_storeys.toml",
     ["--set", "analysis.duration=4", "--set", "optimize.global_evaluations=6",
      "--set", "optimize.local_evaluations=5", "--set", "optimize.pareto.points=3"]),
] + [(f"paper_fig{f}", f"examples/paper/fig{f}.toml", [])
     for f in ("2a", "2b", "2c", "3a", "3b", "4a", "4b")] + [
    ("paper_fig2c_sweep", "examples/paper/fig2c.toml", ["--set", "frf.sweep=both"]),
]

RUN_TIME_KEYS = {"run_time_s", "run_time", "poundsim_version"}
RUN_TIME_LINE = re.compile(r'^\s*"(run_time_s|run_time|poundsim_version)": ')


def normalise_text(text, source, out):
    return text.replace(out, "<out>").replace(source, "<source>")


def drop_run_time(value):
    if isinstance(value, dict):
        return {k: drop_run_time(v) for k, v in value.items() if k not in RUN_TIME_KEYS}
    if isinstance(value, list):
        return [drop_run_time(v) for v in value]
    return value


def canonical_csv(text):
    rows = list(csv.reader(io.StringIO(text, newline="")))
    if not rows:
        return text
    keep = [i for i, name in enumerate(rows[0]) if not name.startswith("run_time")]
    if len(keep) == len(rows[0]):
        return text  # no wall-clock column: the bytes as written
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    for row in rows:
        writer.writerow([row[i] for i in keep if i < len(row)])
    return buffer.getvalue()


def canonical_json_text(text):
    # The document's own lines minus the run-time ones: number spellings count too.
    json.loads(text)  # and it must be JSON
    return "".join(line for line in text.splitlines(keepends=True)
                   if not RUN_TIME_LINE.match(line))


def canonical_sqlite(path, source, out):
    connection = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    lines = []
    tables = [row[0] for row in connection.execute(
        "SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name")]
    for table in tables:
        columns = [row[1] for row in connection.execute(f"PRAGMA table_info({table})")]
        kept = [c for c in columns if c not in RUN_TIME_KEYS]
        lines.append(f"table {table} {kept}")
        order = ", ".join(columns)
        for row in connection.execute(f"SELECT {', '.join(kept)} FROM {table} ORDER BY {order}"):
            if table == "study" and row[0] == "fingerprint":
                continue  # a hash of the definition with its absolute record paths: where it ran
            cells = []
            for cell in row:
                if isinstance(cell, str) and cell[:1] in "{[":
                    try:
                        cell = json.dumps(drop_run_time(json.loads(cell)), sort_keys=True)
                    except ValueError:
                        pass
                cells.append(repr(cell))
            lines.append(normalise_text(" | ".join(cells), source, out))
    connection.close()
    return "\n".join(lines)


def checksums(poundsim, source, work):
    result = {}
    for name, model, extra in CASES:
        out = os.path.join(work, name)
        shutil.rmtree(out, ignore_errors=True)
        command = [poundsim, "run", model, "--out", out, "--quiet"] + extra
        run = subprocess.run(command, cwd=source, capture_output=True, text=True)
        if run.returncode != 0:
            raise SystemExit(f"{' '.join(command)} exited {run.returncode}: {run.stderr}")
        files = {}
        for file in sorted(os.listdir(out)):
            path = os.path.join(out, file)
            if file.endswith(".sqlite"):
                text = canonical_sqlite(path, source, out)
            else:
                with open(path, encoding="utf-8", newline="") as handle:
                    text = normalise_text(handle.read(), source, out)
                if file.endswith(".csv"):
                    text = canonical_csv(text)
                elif file.endswith(".json"):
                    text = canonical_json_text(text)
                elif file.endswith(".toml"):
                    text = re.sub(r"poundsim \d+\.\d+\.\d+", "poundsim VERSION", text)
                else:
                    continue  # pictures are drawn elsewhere
            files[file] = hashlib.sha256(text.encode()).hexdigest()
        result[name] = files
    return result


def main():
    if len(sys.argv) < 4:
        raise SystemExit(__doc__)
    poundsim, source, work = (os.path.abspath(a) for a in sys.argv[1:4])
    update = "--update" in sys.argv[4:]
    stored_path = os.path.join(source, "tests", "golden", "outputs.json")
    os.makedirs(work, exist_ok=True)
    covered = {model for _, model, _ in CASES}
    for folder in ("examples", "examples/paper"):
        for file in sorted(os.listdir(os.path.join(source, folder))):
            if file.endswith(".toml") and f"{folder}/{file}" not in covered:
                raise SystemExit(f"{folder}/{file} has no case in check_outputs.py: add it")
    now = checksums(poundsim, source, work)
    if update:
        with open(stored_path, "w", encoding="utf-8") as handle:
            json.dump(now, handle, indent=2, sort_keys=True)
            handle.write("\n")
        print(f"wrote {stored_path}")
        return
    with open(stored_path, encoding="utf-8") as handle:
        stored = json.load(handle)
    differences = []
    for name in sorted(set(stored) | set(now)):
        before, after = stored.get(name, {}), now.get(name, {})
        for file in sorted(set(before) | set(after)):
            if before.get(file) != after.get(file):
                differences.append(f"{name}/{file}: stored {before.get(file, 'absent')}, "
                                   f"now {after.get(file, 'absent')} (in {work}/{name})")
    if differences:
        print("outputs differ from tests/golden/outputs.json:\n  " + "\n  ".join(differences))
        sys.exit(1)
    print(f"{sum(len(f) for f in now.values())} outputs of {len(now)} runs match bit for bit")


if __name__ == "__main__":
    main()
