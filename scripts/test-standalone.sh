#!/usr/bin/env bash
# Builds and tests a copy of the repository in a temporary folder with no ../shared beside it,
# which proves that the tests and examples need nothing outside the repository (a user has only
# the clone). CI runs it with the sanitizer preset (stage ci_asan_standalone of the `ci` workflow):
# one build proves both that the suite is clean under ASan and UBSan and that it stands alone.
#
#   scripts/test-standalone.sh [--preset NAME] [--keep]
#       --preset: ci (default; without the benchmarks and CI's stages) or asan
#       --keep:   leave the copy (its path is printed)
#
# The copy holds what a clone of the working tree would: tracked files and new files that are not
# ignored, uncommitted changes included, no build folders. It is configured, built and tested with
# the preset.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
keep=0
preset=ci
while [ $# -gt 0 ]; do
  case "$1" in
    --keep) keep=1; shift ;;
    --preset) preset=$2; shift 2 ;;
    *) echo "test-standalone: unknown argument $1" >&2; exit 2 ;;
  esac
done

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
echo "test-standalone: testing $copy (no ../shared) with the $preset preset"
cd "$copy"
if [ "$preset" = ci ]; then
  cmake --preset ci -DPOUNDSIM_CI_STAGES=OFF -DPOUNDSIM_BUILD_BENCHMARKS=OFF >/dev/null
else
  cmake --preset "$preset" >/dev/null
fi
cmake --build --preset "$preset"
ctest --preset "$preset"
