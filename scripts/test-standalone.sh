#!/usr/bin/env bash
# Builds and tests a copy of the repository in a temporary folder with no ../shared beside it,
# which proves that the tests and examples need nothing outside the repository (a user has only
# the clone). CI's stage `standalone` (a test of the `ci` workflow); run it by hand the same way.
#
#   scripts/test-standalone.sh [--keep]   --keep: leave the copy (its path is printed)
#
# The copy holds what a clone of the working tree would: tracked files and new files that are not
# ignored, uncommitted changes included, no build folders. It is built with the `ci` preset
# (without the benchmarks and without CI's stages) and runs `ctest --preset ci`.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
keep=0
[ "${1:-}" = --keep ] && keep=1

work=$(mktemp -d "${TMPDIR:-/tmp}/poundsim-standalone.XXXXXX")
[ $keep = 1 ] || trap 'rm -rf "$work"' EXIT
copy=$work/poundsim
mkdir "$copy"
(cd "$root" && git ls-files -z --cached --others --exclude-standard) |
  (cd "$root" && while IFS= read -r -d '' f; do [ -e "$f" ] || [ -L "$f" ] && printf '%s\0' "$f"; done) |
  (cd "$root" && tar --null -T - -cf -) | tar -xf - -C "$copy"

for shared in "$work/shared" "$(dirname "$work")/shared"; do
  if [ -e "$shared" ]; then
    echo "test-standalone: $shared exists, so the copy would not stand alone" >&2
    exit 1
  fi
done
echo "test-standalone: testing $copy (no ../shared)"
cd "$copy"
cmake --preset ci -DPOUNDSIM_CI_STAGES=OFF -DPOUNDSIM_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build --preset ci
ctest --preset ci
