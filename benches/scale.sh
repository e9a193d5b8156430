#!/usr/bin/env bash
# How a static solve scales with particles: `drapelab simulate` a scene on N × N grids into a
# temporary folder and print one CSV row per run from its run.json: particles (free and held),
# status, Newton iterations, factorizations, wall time, time in factorizations, crossing edges.
#   bash benches/scale.sh SCENE "N1 N2 …" [path/to/drapelab] > scale.csv
#   e.g. bash benches/scale.sh datasets/scenes/skirt_wool.toml "41 81 121 161"
#        bash benches/scale.sh datasets/scenes/hang4.toml "81 161 321"
# SCALE_SET="KEY=VALUE ..." adds --set overrides to every run (contact.self=\"off\" for the skirt
# without self-contact). Run it alone: the times are wall times.
set -euo pipefail
cd "$(dirname "$0")/.."
scene="${1:?usage: bash benches/scale.sh SCENE \"N1 N2 …\" [drapelab]}"
sizes="${2:?usage: bash benches/scale.sh SCENE \"N1 N2 …\" [drapelab]}"
bin="${3:-${CARGO_TARGET_DIR:-target}/release/drapelab}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "grid,particles,status,iterations,factorizations,wall_time_s,factor_time_s,ms_per_factorization,crossing_edges"
for n in $sizes; do
  sets=(--set "cloth.nx=$n" --set "cloth.ny=$n")
  for kv in ${SCALE_SET:-}; do sets+=(--set "$kv"); done
  "$bin" -q simulate "$scene" --out "$tmp/$n" "${sets[@]}" >/dev/null 2>&1 || true
  python3 - "$tmp/$n/run.json" "$n" <<'PY'
import json, sys
run = json.load(open(sys.argv[1]))
r = run["report"]
n = sys.argv[2]
f = max(r["factorizations"], 1)
crossing = (run.get("self_contact") or {}).get("crossing_edges", "")
print(f'{n}x{n},{run["particles"]},{r["status"]},{r["iterations"]},{r["factorizations"]},'
      f'{r["wall_time_s"]:.2f},{r["factor_time_s"]:.2f},{1e3 * r["factor_time_s"] / f:.1f},{crossing}')
PY
done
