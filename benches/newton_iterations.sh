#!/usr/bin/env bash
# Newton iterations, factorizations and wall time of every bundled scene with its defaults
# (issue 34's table): `drapelab simulate` each datasets/scenes/*.toml into a temporary folder and
# print one CSV row per scene from its run.json. Run it alone (the times are wall times):
#   bash benches/newton_iterations.sh [path/to/drapelab] > newton.csv
# NEWTON_SET="solver.static.KEY=VALUE ..." applies the same --set overrides to every scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-${CARGO_TARGET_DIR:-target}/release/drapelab}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "scene,status,iterations,factorizations,wall_time_s,energy_J,minimum,full_steps,shortened_steps,bounded_steps,curved_steps,projected_steps,rejected_trials"
for scene in datasets/scenes/*.toml; do
  name="$(basename "$scene" .toml)"
  sets=()
  for kv in ${NEWTON_SET:-}; do sets+=(--set "$kv"); done
  "$bin" -q simulate "$scene" --out "$tmp/$name" "${sets[@]}" >/dev/null 2>&1 || true
  python3 - "$tmp/$name/run.json" "$name" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["report"]
g = r.get("globalization", {})
steps = ",".join(str(g.get(k, "")) for k in ("full_steps", "shortened_steps", "bounded_steps", "curved_steps", "projected_steps", "rejected_trials"))
print(f'{sys.argv[2]},{r["status"]},{r["iterations"]},{r["factorizations"]},{r["wall_time_s"]:.3f},{r["energy_J"]:.9e},{r["minimum"]},{steps}')
PY
done
