#!/usr/bin/env python3
"""Checks that two runs of drapelab's pipelines give the same tables, times aside.

    python scripts/same_tables.py BEFORE_RUNS AFTER_RUNS [PIPELINE ...]

BEFORE_RUNS and AFTER_RUNS are `runs/` folders (e.g. a copy taken before a refactor, and the
folder after rerunning `drapelab run pipelines/NAME.toml`). For each pipeline (default: every
folder in BEFORE_RUNS), every Parquet file is read with pyarrow and compared with its namesake:
the same rows in the same order and, column by column, equal values (floats within a relative
1e-9, NaN equal to NaN). Columns of wall time, memory and timing (names ending in `_s`, `_ms`,
`peak_rss_bytes`, or holding `time`) are left out. A column only AFTER has is listed as added and
not counted as a difference (say why in the commit); a column or file only BEFORE has is a
difference. Also left out, as derived from wall time: `ratio` (a peer's time over drapelab's) and
`saved_fraction` (a skip's saving), and the work columns (iterations, linear solves,
factorizations) and the residual left (`max_residual_N`) of a row that did not converge in either
run (a point stopped by its wall-time budget: how far it got depends on the machine's load).
Exit code 0 when nothing differs, 1 otherwise, 2 for bad arguments.
"""
import math
import pathlib
import sys

import pyarrow.parquet as pq

TIMING_SUFFIXES = ("_s", "_ms", "peak_rss_bytes")
TIME_DERIVED = ("ratio", "saved_fraction")
WORK = ("iterations", "linear_solves", "factorizations", "inner_iterations", "max_residual_N")


def is_timing(name: str) -> bool:
    return name.endswith(TIMING_SUFFIXES) or "time" in name or name in TIME_DERIVED


def budget_stopped(a, b) -> set[int]:
    """Rows that did not converge in either table: their work depends on a wall-time budget."""
    if "status" not in a.column_names or "status" not in b.column_names:
        return set()
    sa, sb = a.column("status").to_pylist(), b.column("status").to_pylist()
    return {i for i, (x, y) in enumerate(zip(sa, sb)) if x == y and x != "converged"}


def same_value(a, b) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        if math.isnan(a) and math.isnan(b):
            return True
        return a == b or abs(a - b) <= 1e-9 * max(abs(a), abs(b))
    return a == b


def compare_file(before: pathlib.Path, after: pathlib.Path) -> list[str]:
    a, b = pq.read_table(before), pq.read_table(after)
    problems = []
    if a.num_rows != b.num_rows:
        return [f"{a.num_rows} rows before, {b.num_rows} after"]
    stopped = budget_stopped(a, b)
    for name in a.column_names:
        if is_timing(name):
            continue
        if name not in b.column_names:
            problems.append(f"column `{name}` is gone")
            continue
        va, vb = a.column(name).to_pylist(), b.column(name).to_pylist()
        skip = stopped if name in WORK else set()
        bad = [
            i
            for i, (x, y) in enumerate(zip(va, vb))
            if i not in skip and not same_value(x, y)
        ]
        if bad:
            i = bad[0]
            problems.append(
                f"column `{name}`: {len(bad)} of {len(va)} rows differ (row {i}: {va[i]!r} → {vb[i]!r})"
            )
    added = [n for n in b.column_names if n not in a.column_names]
    if added:
        print(f"    note: {after}: added column(s) {', '.join(added)}")
    return problems


def compare_pipeline(before: pathlib.Path, after: pathlib.Path) -> int:
    files = sorted(p.relative_to(before) for p in before.rglob("*.parquet") if "parts" not in p.parts)
    differing = 0
    for rel in files:
        if not (after / rel).exists():
            print(f"  {rel}: missing after")
            differing += 1
            continue
        problems = compare_file(before / rel, after / rel)
        if problems:
            differing += 1
            print(f"  {rel}: " + "; ".join(problems))
    print(f"{before.name}: {len(files)} tables, {differing} differ")
    return differing


def main(argv: list[str]) -> int:
    if len(argv) < 3:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    before, after = pathlib.Path(argv[1]), pathlib.Path(argv[2])
    for d in (before, after):
        if not d.is_dir():
            print(f"same_tables.py: {d}: not a folder", file=sys.stderr)
            return 2
    names = argv[3:] or sorted(p.name for p in before.iterdir() if p.is_dir())
    total = sum(compare_pipeline(before / n, after / n) for n in names)
    return 0 if total == 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
