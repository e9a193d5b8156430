#!/usr/bin/env bash
# The Python package's tests (issue 35): `pip install .` into a virtual environment made here on first
# use (.venv-package/, with tests/python/requirements.txt), then pytest over tests/python/ against the
# installed package and the command line. Run by scripts/test.sh after `cargo test`, which must have
# released the build folder: maturin builds in the same CARGO_TARGET_DIR and reuses the workspace's
# crates (38 s here when they are built).
set -euo pipefail
cd "$(dirname "$0")/../.."
target="${CARGO_TARGET_DIR:-$PWD/target}"
venv=.venv-package
if ! "$venv/bin/python" -c "import pytest, pyarrow, polars, matplotlib, pandas" 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r tests/python/requirements.txt
fi
started=$SECONDS
CARGO_TARGET_DIR="$target" "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    --force-reinstall --no-deps .
# numpy is the package's one dependency; --no-deps keeps the one already there.
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check numpy
echo "pip install . took $((SECONDS - started)) s"
DRAPELAB_BIN="$target/release/drapelab" "$venv/bin/python" -m pytest -q -p no:cacheprovider -rs tests/python
