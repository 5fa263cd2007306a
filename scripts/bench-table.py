#!/usr/bin/env python3
"""Runs Google Benchmark programs and prints one Markdown table of their results.

The performance tables in docs/ are made by this script; each is preceded in the docs by the
command that made it, so that anyone can make it again on their machine:

    scripts/bench-table.py build/ci/bench/poundsim_benchmarks --filter 'BM_SevenPaperFigures|BM_Fig2c141'

With --before OLD_BINARY the same benchmarks of an earlier build run in the same invocation,
one after the other, and the table gets a column for each (a change's effect measured side by
side, on the same machine state). Times are each benchmark's real time in its own unit; the
counters it sets (points, events, per-figure seconds) follow in a last column.
"""

import argparse
import json
import subprocess
import sys


def run(binary, pattern, min_time):
    command = [binary, f"--benchmark_filter={pattern}", "--benchmark_format=json"]
    if min_time:
        command.append(f"--benchmark_min_time={min_time}")
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        sys.exit(f"bench-table: {binary} exited with {done.returncode}: {done.stderr.strip()}")
    results = json.loads(done.stdout)
    return {b["name"]: b for b in results["benchmarks"] if b.get("run_type", "iteration") == "iteration"}


def counters(b):
    skip = {"name", "run_name", "run_type", "repetitions", "repetition_index", "threads", "iterations",
            "real_time", "cpu_time", "time_unit", "family_index", "per_family_instance_index", "label",
            "aggregate_name", "aggregate_unit", "error_occurred", "error_message"}
    parts = [f"{k} {v:.4g}" for k, v in b.items() if k not in skip and isinstance(v, (int, float))]
    if b.get("label"):
        parts.append(b["label"])
    return ", ".join(parts)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("binary", help="the benchmark program")
    parser.add_argument("--filter", default=".", help="the benchmarks to run (a regular expression)")
    parser.add_argument("--before", help="the same program of an earlier build, run side by side")
    parser.add_argument("--min-time", default="", help="passed as --benchmark_min_time")
    args = parser.parse_args()

    now = run(args.binary, args.filter, args.min_time)
    before = run(args.before, args.filter, args.min_time) if args.before else None
    if not now:
        sys.exit(f"bench-table: no benchmark of {args.binary} matches {args.filter!r}")
    if before is not None:
        print("| benchmark | before | now | counters (now) |")
        print("|---|---|---|---|")
    else:
        print("| benchmark | real time | counters |")
        print("|---|---|---|")
    for name, b in now.items():
        time = f"{b['real_time']:.4g} {b['time_unit']}"
        if before is not None:
            old = before.get(name)
            old_time = f"{old['real_time']:.4g} {old['time_unit']}" if old else "—"
            print(f"| `{name}` | {old_time} | {time} | {counters(b)} |")
        else:
            print(f"| `{name}` | {time} | {counters(b)} |")


if __name__ == "__main__":
    main()
