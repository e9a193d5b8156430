"""Where a Newton path goes (issue 90): from a run folder's iterations.parquet, the iterations
spent per decade of the largest residual (relative to the tolerance the run reached), the share of
steps the contact bound cut, line-search trials and factorizations. Prints one Markdown row per run.

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
    final = r[-1]
    decades = {}
    for i in steps:
        d = max(0, math.floor(math.log10(r[i] / final))) if r[i] > 0 and final > 0 else 0
        decades[d] = decades.get(d, 0) + 1
    cut = sum(1 for i in steps if t["contact_bound_cut"][i])
    bounded = sum(1 for i in steps if t["contact_bound_fraction"][i] is not None)
    trials = sum(t["line_search_trials"][i] for i in steps)
    facts = sum(t["factorizations"][i] for i in steps)
    spread = ", ".join(f"10^{d}: {n}" for d, n in sorted(decades.items(), reverse=True))
    return (
        f"| {run['scene']['name']} | {run['particles']} | {len(steps)} | {spread} | "
        f"{cut} ({100 * cut / max(1, len(steps)):.0f} %) | {bounded} | {trials} | {facts} | "
        f"{run['report']['wall_time_s']:.1f} |"
    )


print("| scene | particles | iterations | iterations by residual over the final one (decades) | steps cut by the contact bound | steps with a contact bound | line-search trials | factorizations | wall time, s |")
print("|---|---:|---:|---|---:|---:|---:|---:|---:|")
for f in sys.argv[1:]:
    print(row(f))
