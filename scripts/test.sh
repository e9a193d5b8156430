#!/usr/bin/env bash
# The test suite (the README's test command; .ci/run runs exactly this): the Rust tests, the book
# built with mdBook and its links checked (scripts/book.sh), then the Python package built from
# source and tested with pytest (tests/python/run.sh). Extra arguments go to `cargo test`.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release --workspace "$@"
bash scripts/book.sh
bash tests/python/run.sh
