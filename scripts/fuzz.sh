#!/usr/bin/env bash
# Runs the fuzz targets built by the `fuzz` preset (fuzz/README.md).
#
#   scripts/fuzz.sh [--time SECONDS] [--runs N] [--timeout SECONDS] [--build DIR] [--keep-going] [TARGET...]
#                                           fuzz each target for SECONDS (or N executions)
#   scripts/fuzz.sh --corpus [--build DIR] [TARGET...]            only replay the committed corpus
#   scripts/fuzz.sh --findings [--build DIR] [TARGET...]          replay fuzz/findings/ (known defects)
#
# Fuzzing first replays the committed corpus fuzz/corpus/<target>/ (every seed must pass), then
# fuzzes for SECONDS (default 60) with one worker, from that corpus and the inputs found in earlier
# runs (DIR/fuzz-work/<target>/, kept between runs; the committed corpus is never written). A crash,
# sanitizer report, timeout or escaping exception stops the target; its reproducer is written to
# DIR/fuzz-artifacts/<target>/ and the script exits non-zero after the remaining targets.
# --timeout: the longest one input may take, in wall-clock seconds (default 10). libFuzzer's alarm
# counts the wall clock: a niced long run sharing its cores with builds needs more (say 120), or
# an input that takes 0.2 s of CPU is reported as a timeout.
# --keep-going (long runs): a finding does not stop the target; libFuzzer runs the inputs in a
# child process (-fork=1) and collects every reproducer. Targets default to all five; DIR defaults
# to build/fuzz.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build/fuzz
mode=fuzz
seconds=60
timeout=10
keep_going=()
runs=()
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --time) seconds=$2; shift 2 ;;
    --runs) runs=(-runs="$2"); shift 2 ;;
    --timeout) timeout=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --keep-going) keep_going=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1); shift ;;
    --corpus) mode=corpus; shift ;;
    --findings) mode=findings; shift ;;
    -h|--help) sed -n '2,/^set -u/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1" >&2; exit 2 ;;
    *) targets+=("$1"); shift ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=(input_toml input_set record_at2 record_cosmos record_columns)

# Findings must abort at once; leaks count (LeakSanitizer); stacks symbolised.
export ASAN_OPTIONS=${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1:symbolize=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
# The fuzzers' scratch folders (the record targets write each input to a file): in memory when
# possible, which is ten times faster than a disk; removed at the end, also after a crash.
mkdir -p "$build"
scratch_parent=/dev/shm
[ -d "$scratch_parent" ] && [ -w "$scratch_parent" ] || scratch_parent=$build
export TMPDIR=$(mktemp -d "$scratch_parent/poundsim-fuzz.XXXXXX")
trap 'rm -rf "$TMPDIR"' EXIT

# Per-input limits: a reader of a few-KB input has no business taking 10 s or allocating 256 MB.
limits=(-timeout="$timeout" -rss_limit_mb=2048 -malloc_limit_mb=256)
status=0
for t in "${targets[@]}"; do
  binary=$build/fuzz/fuzz_$t
  corpus=$root/fuzz/corpus/$t
  if [ ! -x "$binary" ]; then
    echo "fuzz.sh: $binary not built (cmake --preset fuzz && cmake --build --preset fuzz)" >&2
    exit 2
  fi
  case $mode in
    corpus)
      echo "== $t: replaying $(ls "$corpus" | wc -l) committed inputs"
      "$binary" "${limits[@]}" -runs=0 "$corpus" || status=1
      ;;
    findings)
      shopt -s nullglob
      for f in "$root"/fuzz/findings/"$t"/*; do
        [ "${f##*.}" = md ] && continue
        if "$binary" "${limits[@]}" "$f" >"$TMPDIR/finding.log" 2>&1; then
          echo "fixed:      $f"
        else
          echo "still fails: $f ($(grep -m1 -E 'ERROR|FINDING|runtime error|Timeout|out-of-memory' "$TMPDIR/finding.log"))"
          status=1
        fi
      done
      ;;
    fuzz)
      work=$build/fuzz-work/$t
      artifacts=$build/fuzz-artifacts/$t/
      mkdir -p "$work" "$artifacts"
      echo "== $t: replaying the committed corpus, then fuzzing for $seconds s"
      "$binary" "${limits[@]}" -runs=0 "$corpus" >"$build/fuzz-$t.log" 2>&1 || {
        cat "$build/fuzz-$t.log"; echo "== $t: a committed corpus input fails"; status=1; continue; }
      if "$binary" "${limits[@]}" "${keep_going[@]}" "${runs[@]}" -max_total_time="$seconds" -print_final_stats=1 \
          -dict="$root/fuzz/dict/$t.dict" -artifact_prefix="$artifacts" "$work" "$corpus" \
          >"$build/fuzz-$t.log" 2>&1; then
        grep -E '^#[0-9]+.*(DONE|pulse|NEW)' "$build/fuzz-$t.log" | tail -1
        grep -E '^stat::(number_of_executed_units|average_exec_per_sec|peak_rss_mb)' "$build/fuzz-$t.log" | tr '\n' ' '
        echo
      else
        tail -n 60 "$build/fuzz-$t.log"
        echo "== $t: FINDING, reproducer in $artifacts (log: $build/fuzz-$t.log)"
        status=1
      fi
      ;;
  esac
done
exit $status
