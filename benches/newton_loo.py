"""Leave-one-out choice of a solver option over the bundled scenes (and touching variants).

    python3 benches/newton_loo.py [--by iterations|factorizations] VALUE=CSV[+CSV…] …

Each VALUE's CSVs are `bash benches/newton_iterations.sh` (rows by `scene`) and optionally
`bash benches/touching.sh` (rows by `case`; only its self-contact-on rows) run with that value, e.g.
`NEWTON_SET="solver.static.exact_retry_every=8" bash benches/newton_iterations.sh > k8.csv`. For
every case held out, the value with the fewest non-converged cases over the others, then the
smallest sum of the criterion (`--by`, default iterations) over them, is chosen; the held-out case's
status and counts under that choice are its score. The first VALUE is the baseline column.
"""
import csv
import statistics
import sys


def rows(path):
    with open(path) as f:
        for r in csv.DictReader(line for line in f if not line.startswith("#")):
            if "case" in r:
                if r.get("self") != "on":
                    continue
                yield r["case"], r
            else:
                yield r["scene"], r


def load(spec):
    out = {}
    for path in spec.split("+"):
        out.update(rows(path))
    return out


def count(r, by):
    v = r.get(by, "")
    return int(v) if v not in ("", None) else 0


def main(args):
    by = "iterations"
    if args[:1] == ["--by"]:
        by, args = args[1], args[2:]
    cands = {v: load(spec) for v, spec in (a.split("=", 1) for a in args)}
    base = next(iter(cands))
    cases = [c for c in cands[base] if all(c in t for t in cands.values())]
    failed = lambda t, c: t[c]["status"] != "converged"
    print(f"| value | non-converged (in-sample) | {by}, all cases | median |")
    print("|---|---:|---:|---:|")
    for v, t in cands.items():
        n = [count(t[c], by) for c in cases]
        print(f"| {v} | {sum(failed(t, c) for c in cases)} | {sum(n)} | {statistics.median(n):g} |")
    extra = by != "iterations"
    head = f"| held-out case | chosen on the others | its status | its {by} |"
    head += " its iterations |" if extra else ""
    head += f" baseline ({base}) {by} |" + (" baseline iterations |" if extra else "")
    print("\n" + head)
    print("|---|---|---|" + "---:|" * (4 if extra else 2))
    held = []
    for c in cases:
        def score(v):
            others = [o for o in cases if o != c]
            t = cands[v]
            return (sum(failed(t, o) for o in others), sum(count(t[o], by) for o in others))
        best = min(cands, key=score)
        r, b = cands[best][c], cands[base][c]
        held.append(count(r, by))
        line = f"| {c} | {best} | {r['status']} | {count(r, by)} |"
        line += f" {r['iterations']} |" if extra else ""
        line += f" {count(b, by)} |" + (f" {b['iterations']} |" if extra else "")
        print(line)
    print(f"\nHeld out: {sum(held)} {by} in all, median {statistics.median(held):g}, largest {max(held)}.")


if __name__ == "__main__":
    main(sys.argv[1:])
