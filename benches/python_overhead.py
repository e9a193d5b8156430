"""What the Python call adds to a solve (issue 35): hang4 41² solved N times by `drapelab simulate`
(the command line, a process each) and by `drapelab.simulate` (one interpreter), each timed from
outside and against the solve's own wall time in its report. Prints a Markdown table.

    .venv-package/bin/python benches/python_overhead.py [N] [--bin target/release/drapelab]

Run from the repository root with the package installed (`pip install .`); alone on the machine.
"""

import json
import statistics
import subprocess
import sys
import tempfile
import time

import drapelab

n = int(sys.argv[1]) if len(sys.argv) > 1 and sys.argv[1].isdigit() else 5
exe = sys.argv[sys.argv.index("--bin") + 1] if "--bin" in sys.argv else "target/release/drapelab"
scene = "datasets/scenes/hang4.toml"
sets = {"cloth.nx": 41, "cloth.ny": 41}

rows = {"command line": [], "Python": []}
native = []
for _ in range(n):
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        subprocess.run([exe, "simulate", scene, "--out", out] + sum((["--set", f"{k}={v}"] for k, v in sets.items()), []),
                       check=True, capture_output=True)
        wall = time.perf_counter() - t0
        solve = json.load(open(f"{out}/run.json"))["report"]["wall_time_s"]
        rows["command line"].append((wall, solve))
    t0 = time.perf_counter()
    r = drapelab.simulate(scene, set=sets)
    wall = time.perf_counter() - t0
    assert r.converged
    rows["Python"].append((wall, r.report["wall_time_s"]))
    native.append(r.native_time_s)

print(f"hang4 41², {n} runs each (median), drapelab {drapelab.__version__}\n")
print("| caller | call wall time s | solve wall time s (report) | call beyond the solve (files written, process) |")
print("|---|---|---|---|")
for name, v in rows.items():
    wall = statistics.median(w for w, _ in v)
    solve = statistics.median(s for _, s in v)
    print(f"| {name} | {wall:.3f} | {solve:.3f} | {100 * (wall - solve) / solve:+.1f} % |")
py = statistics.median(w for w, _ in rows["Python"])
cli = statistics.median(w for w, _ in rows["command line"])
rust = statistics.median(native)
print(f"\nThe Python call's own part (arguments, temporary folder, run.json parsed, NumPy arrays): "
      f"{py - rust:.4f} s, {100 * (py - rust) / rust:+.1f} % of the {rust:.3f} s it spends in Rust "
      f"(scene loaded, solved, files written).")
print(f"Python call against the command line (a process each): {100 * (py - cli) / cli:+.1f} %")
