"""Where a Newton path goes (issue 90): from a run folder's iterations.parquet, the iterations
spent per decade of the largest residual force (N) they start from, the share of
steps the contact bound cut, line-search trials and factorizations. Prints one Markdown row per run
(counts only: time a run alone, benches/scale.sh).

    python3 benches/path.py RUN_DIR [RUN_DIR ...]
"""
import json
import math
import sys

import pyarrow.parquet as pq


def row(folder):
    t = pq.read_table(f"{folder}/iterations.parquet").to_pydict()
    run = json.load(open(f"{folder}/run.json"))
    r = t["max_residual_N"]
    steps = [i for i, f in enumerate(t["step_fraction"]) if f is not None]
    decades = {}
    for i in steps:
        # The decade of the residual the iteration started from, N.
        d = math.floor(math.log10(r[i - 1])) if r[i - 1] > 0 else -99
        decades[d] = decades.get(d, 0) + 1
    cut = sum(1 for i in steps if t["contact_bound_cut"][i])
    bounded = sum(1 for i in steps if t["contact_bound_fraction"][i] is not None)
    trials = sum(t["line_search_trials"][i] for i in steps)
    facts = sum(t["factorizations"][i] for i in steps)
    spread = ", ".join(f"1e{d}: {n}" for d, n in sorted(decades.items(), reverse=True))
    return (
        f"| {run['scene']['name']} | {run['particles']} | {len(steps)} | {spread} | "
        f"{cut} ({100 * cut / max(1, len(steps)):.0f} %) | {bounded} | {trials} | {facts} |"
    )


print("| scene | particles | iterations | iterations by the decade of the largest residual they start from, N | steps cut by the contact bound | steps with a contact bound | line-search trials | factorizations |")
print("|---|---:|---:|---|---:|---:|---:|---:|")
for f in sys.argv[1:]:
    print(row(f))
