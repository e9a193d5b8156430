"""Leave-one-out choice of `solver.static.shift_max_rel` over the bundled scenes (issue 34).

    python3 benches/newton_loo.py 1e-6=A.csv 1e-5=B.csv 1e-4=C.csv 1e-3=D.csv

Each CSV is `bash benches/newton_iterations.sh` with that value as the default. For every scene held out, the
value with the fewest Newton iterations over the other sixteen is chosen, and the held-out scene's iterations
under that choice are its score: the table's sum and median are what a scene not looked at may expect.
"""
import csv
import statistics
import sys


def iterations(path):
    with open(path) as f:
        rows = csv.DictReader(line for line in f if not line.startswith("#"))
        return {r["scene"]: int(r["iterations"]) for r in rows}


def main(args):
    cands = {v: iterations(p) for v, p in (a.split("=", 1) for a in args)}
    scenes = list(next(iter(cands.values())))
    print("\n## Leave-one-out choice of `shift_max_rel`\n")
    print("| value | iterations, all scenes (in-sample) | median |")
    print("|---|---|---|")
    for v, it in cands.items():
        print(f"| {v} | {sum(it.values())} | {statistics.median(it.values()):g} |")
    print("\n| held-out scene | value chosen on the other 16 | its iterations |")
    print("|---|---|---|")
    held = []
    for s in scenes:
        best = min(cands, key=lambda v: sum(cands[v][t] for t in scenes if t != s))
        held.append(cands[best][s])
        print(f"| {s} | {best} | {cands[best][s]} |")
    print(
        f"\nHeld-out: {sum(held)} iterations in all, median {statistics.median(held):g}, largest {max(held)}."
    )


if __name__ == "__main__":
    main(sys.argv[1:])
