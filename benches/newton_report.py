"""Renders one build's Newton iterations of every bundled scene as the table of
reports/newton_iterations.md ("This build").

    bash benches/newton_iterations.sh > newton.csv && python3 benches/newton_report.py newton.csv

The CSV is `bash benches/newton_iterations.sh`'s: each scene with its defaults.
"""
import csv
import statistics
import sys


def load(path):
    with open(path) as f:
        return [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]


def main(path):
    rows = load(path)
    print("| scene | status | iterations | factorizations | wall s | minimum |")
    print("|---|---|---:|---:|---:|---|")
    for r in rows:
        print(
            f'| {r["scene"]} | {r["status"]} | {r["iterations"]} | {r["factorizations"]} '
            f'| {float(r["wall_time_s"]):.3f} | {r["minimum"]} |'
        )
    its = {r["scene"]: int(r["iterations"]) for r in rows}
    worst = max(its, key=its.get)
    wall = sum(float(r["wall_time_s"]) for r in rows)
    print(
        f"\nMedian {statistics.median(its.values()):g}, largest {its[worst]} ({worst}), "
        f"{sum(its.values()):,} iterations and {wall:.1f} s over the {len(rows)} scenes."
    )


if __name__ == "__main__":
    main(sys.argv[1])
