"""Renders the before/after table of Newton iterations of every bundled scene (issue 34) as Markdown.

    python3 benches/newton_report.py reports/newton_iterations_before.csv AFTER.csv > reports/newton_iterations.md

Both CSVs come from `bash benches/newton_iterations.sh` (the first at the commit before issue 34).
Energies are compared where both runs converged: on a scene with one equilibrium they agree to
round-off; on a folding drape the new path may land on another minimum, lower or higher.
"""
import csv
import statistics
import sys


def load(path):
    with open(path) as f:
        rows = [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]
    return {r["scene"]: r for r in rows}


def header(path):
    with open(path) as f:
        return [line[1:].strip() for line in f if line.startswith("#")]


def main(before_path, after_path):
    before, after = load(before_path), load(after_path)
    print("# Newton iterations of every bundled scene, before and after issue 34\n")
    for h in header(before_path) + header(after_path):
        print(f"- {h}")
    print(
        "\nEach scene with its defaults (`drapelab simulate datasets/scenes/NAME.toml`); iterations include the"
        " coarse-grid start's. Steps after: whole / shortened by the line search / cut by the contact bound;"
        " curved = along the geodesic acceleration; projected = on the projected Hessian.\n"
    )
    print(
        "| scene | iterations before | after | factorizations before | after | wall s before | after "
        "| energy after − before, J | minimum | steps after (whole/shortened/bounded; curved; projected) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, b in before.items():
        a = after.get(name)
        if a is None:
            continue
        both = b["status"] == a["status"] == "converged"
        de = float(a["energy_J"]) - float(b["energy_J"]) if both else float("nan")
        tol = 1e-9 * max(abs(float(b["energy_J"])), 1e-12)
        verdict = "same" if abs(de) <= tol else ("lower" if de < 0 else "higher")
        steps = f'{a.get("full_steps")}/{a.get("shortened_steps")}/{a.get("bounded_steps")}; {a.get("curved_steps")}; {a.get("projected_steps")}'
        status = "" if a["status"] == "converged" else f' ({a["status"]})'
        print(
            f'| {name} | {b["iterations"]} | {a["iterations"]}{status} | {b["factorizations"]} | {a["factorizations"]} '
            f'| {float(b["wall_time_s"]):.3f} | {float(a["wall_time_s"]):.3f} | {de:+.3e} ({verdict}) | {a["minimum"]} | {steps} |'
        )
    it = lambda rows: [int(r["iterations"]) for r in rows.values()]
    wall = lambda rows: sum(float(r["wall_time_s"]) for r in rows.values())
    print(
        f"\nMedian iterations {statistics.median(it(before)):g} → {statistics.median(it(after)):g}; largest "
        f"{max(it(before))} → {max(it(after))}; all scenes {sum(it(before))} → {sum(it(after))} iterations, "
        f"{wall(before):.1f} s → {wall(after):.1f} s of wall time. Goal of issue 34: every scene ≤ 60, median ≤ 30."
    )


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
