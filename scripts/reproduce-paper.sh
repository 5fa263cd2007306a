#!/usr/bin/env bash
# Reproduces Figures 2–4 of Pasquino, Santini & Caliò: for each of the seven systems in
# examples/paper/, the frequency response from rest (results/paper/fig2a.csv …) and a two-way
# sweep (…_sweep.csv), and a PNG of each figure (results/paper/fig2a.png …).
#
#   scripts/reproduce-paper.sh [BUILD_DIR] [--out DIR] [--docs]
#
# BUILD_DIR holds the poundsim program (default build/release); --out the results (default
# results/paper); --docs also rewrites docs/paper-reproduction.md and its figures from them.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/release"
out="$root/results/paper"
docs=false
while [ $# -gt 0 ]; do
  case "$1" in
    --docs) docs=true ;;
    --out) out="$2"; shift ;;
    *) build="$1" ;;
  esac
  shift
done
poundsim="$build/poundsim"
if [ ! -x "$poundsim" ]; then
  echo "reproduce-paper: $poundsim not found; build first (cmake --preset release && cmake --build --preset release)" >&2
  exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"

figures=(2a 2b 2c 3a 3b 4a 4b)
now() { date +%s.%N; }
t0=$(now)
for f in "${figures[@]}"; do
  "$poundsim" run "$root/examples/paper/fig$f.toml" --out "$work/fig$f" --quiet
done
t1=$(now)
for f in "${figures[@]}"; do
  "$poundsim" run "$root/examples/paper/fig$f.toml" --out "$work/fig${f}_sweep" --quiet --set frf.sweep=both
done
t2=$(now)
plots=()
for f in "${figures[@]}"; do
  cp "$work/fig$f/frf.csv" "$out/fig$f.csv"
  cp "$work/fig$f/summary.json" "$out/fig$f.json"
  cp "$work/fig${f}_sweep/frf.csv" "$out/fig${f}_sweep.csv"
  title=$(sed -n 's/^title = "\(.*\)"$/\1/p' "$root/examples/paper/fig$f.toml")
  plots+=(--figure "$out/fig$f.csv" "$out/fig$f.png" "$out/fig${f}_sweep.csv" "$title")
done
/usr/bin/python3 "$root/python/plot_frf.py" "${plots[@]}"
t3=$(now)
if $docs; then
  /usr/bin/python3 "$root/python/paper_report.py" "$out" "$root/docs"
fi
points=$(($(wc -l < "$out/fig${figures[0]}.csv") - 1))
awk -v a="$t0" -v b="$t1" -v c="$t2" -v d="$t3" -v n="$(nproc)" -v out="$out" -v k="${#figures[@]}" -v p="$points" 'BEGIN {
  printf "reproduced Figs. 2a–4b in %s/\n", out
  printf "  %d frequency responses from rest (%d points each, interacting and free): %.2f s on %d cores\n", k, p, b - a, n
  printf "  %d two-way sweeps (2 × %d points each): %.2f s\n", k, p, c - b
  printf "  %d figures drawn: %.2f s\n", k, d - c
}'
