#!/bin/sh
# `cmake --install` puts the Python package where that python3 finds it without PYTHONPATH: under
# a prefix used as Python's user base (as `--prefix ~/.local` is), it imports and runs.
# Usage: python_install.sh BUILD_DIR PYTHON
set -eu
build=$1
python=$2
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --prefix "$prefix" > /dev/null
cd "$prefix"
PYTHONUSERBASE="$prefix" PYTHONPATH= "$python" -c '
import pathlib, sys
import poundsim
where = pathlib.Path(poundsim.__file__).resolve()
assert str(where).startswith(sys.argv[1]), where
model = poundsim.loads(open(sys.argv[2]).read(), name="fig2c.toml", settings=["analysis.duration=1.0"])
th = poundsim.run(model, progress=False)
assert th.data.shape == (101, 1 + len(th.channels)), th.data.shape
print("installed:", where.parent, poundsim.__version__)
' "$(cd "$prefix" && pwd -P)" "$(dirname "$0")/../examples/fig2c_ratio0.8.toml"
