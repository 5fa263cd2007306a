#!/usr/bin/python3
"""Python's overhead on a time history: poundsim.run on two 10-storey frames under 20 s
of El Centro (bench/models/two_ten_storey_frames.toml) against the same run through the C++ library
(poundsim_benchmarks' BM_TimeHistory2x10ThroughTheLibrary), alternately in one session; and the
memory Python allocates to return the history (tracemalloc sees NumPy's allocations: a copy of the
history would show as its size).

    PYTHONPATH=build/release/python /usr/bin/python3 bench/python_overhead.py build/release/bench/poundsim_benchmarks [--rounds 7]

Prints the fastest of the rounds of each and the overhead; exits 1 when the overhead exceeds 5 %
or the history was copied.
"""

import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import time
import tracemalloc

import poundsim

MODEL = pathlib.Path(__file__).resolve().parent / "models" / "two_ten_storey_frames.toml"


def cpp_seconds(benchmarks: str) -> float:
    out = subprocess.run([benchmarks, "--benchmark_filter=BM_TimeHistory2x10ThroughTheLibrary$",
                          "--benchmark_min_time=0.5", "--benchmark_format=json"], check=True, capture_output=True,
                         text=True).stdout
    (entry,) = json.loads(out)["benchmarks"]
    assert entry["time_unit"] == "ms"
    return entry["real_time"] / 1000.0


def python_seconds(model, repeats: int = 5) -> float:
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        th = poundsim.run(model, progress=False)
        best = min(best, time.perf_counter() - start)
        del th
    return best


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("benchmarks", help="the poundsim_benchmarks program (a release build)")
    parser.add_argument("--rounds", type=int, default=7)
    args = parser.parse_args()
    model = poundsim.load(MODEL)
    cpp, python = [], []
    for _ in range(args.rounds):  # alternately, so that both see the same machine
        cpp.append(cpp_seconds(args.benchmarks))
        python.append(python_seconds(model))
    c, p = min(cpp), min(python)
    overhead = (p - c) / c
    print(f"{MODEL.name}: C++ library {1e3 * c:.2f} ms (median {1e3 * statistics.median(cpp):.2f}), "
          f"poundsim.run {1e3 * p:.2f} ms (median {1e3 * statistics.median(python):.2f}): "
          f"Python overhead {100 * overhead:+.2f} % of the run (limit 5 %)")

    tracemalloc.start()
    th = poundsim.run(model, progress=False)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    history = th.data.nbytes
    copied = peak >= history / 2
    print(f"history {th.data.shape[0]} × {th.data.shape[1]} = {history / 1e6:.2f} MB; Python-side allocations "
          f"during the run peaked at {peak / 1e6:.3f} MB ({'a copy' if copied else 'no copy'}: the array is the "
          f"run's buffer, owndata = {th.data.flags.owndata})")
    return 1 if overhead > 0.05 or copied else 0


if __name__ == "__main__":
    sys.exit(main())
