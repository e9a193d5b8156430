#!/usr/bin/env bash
# Touching drapes with and without self-contact (issue 76's contact cost and robustness table):
# `drapelab simulate` each case into a temporary folder and print one CSV row per run from its
# run.json: status, Newton iterations, wall time, largest residual, crossing edges, closest parts.
#   bash benches/touching.sh [path/to/drapelab] > touching.csv
# TOUCHING_ONLY="GLOB" runs only the matching cases; TOUCHING_SET="KEY=VALUE ..." adds --set
# overrides to every run.
# The cases: the bundled touching scenes, the sphere drape on a 0.8 m sheet (larger), the limp
# table on a finer grid, and the skirt on 41 and 81 grids; each with contact.self on and off.
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-${CARGO_TARGET_DIR:-target}/release/drapelab}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
big='--set cloth.size_x_m=0.8 --set cloth.size_y_m=0.8 --set cloth.origin_m=[-0.4,-0.4,0.0]'
cases=(
  "sphere_wool|datasets/scenes/sphere_wool.toml|"
  "sphere_wool_0.8m|datasets/scenes/sphere_wool.toml|$big"
  "table_limp_hanging|datasets/scenes/table_limp_hanging.toml|"
  "table_limp_hanging_61|datasets/scenes/table_limp_hanging.toml|--set cloth.nx=61 --set cloth.ny=61"
  "skirt_wool_41|datasets/scenes/skirt_wool.toml|--set cloth.nx=41 --set cloth.ny=41"
  "skirt_wool_81|datasets/scenes/skirt_wool.toml|--set cloth.nx=81 --set cloth.ny=81"
  "l_panel_sphere|datasets/patterns/l_panel_sphere.toml|"
  "l_panel_table|datasets/patterns/l_panel_table.toml|"
)
only="${TOUCHING_ONLY:-}"
echo "case,self,status,iterations,wall_time_s,max_residual_N,crossing_edges,min_distance_m"
for c in "${cases[@]}"; do
  IFS='|' read -r name scene extra <<<"$c"
  [[ -n "$only" && "$name" != $only ]] && continue
  for mode in on off; do
    out="$tmp/$name-$mode"
    sets=()
    for kv in ${TOUCHING_SET:-}; do sets+=(--set "$kv"); done
    # shellcheck disable=SC2086
    "$bin" -q simulate "$scene" --out "$out" --set "contact.self=\"$mode\"" $extra "${sets[@]}" >/dev/null 2>&1 || true
    python3 - "$out/run.json" "$name" "$mode" <<'PY'
import json, sys
try:
    run = json.load(open(sys.argv[1]))
except OSError:
    print(f"{sys.argv[2]},{sys.argv[3]},no run.json,,,,,")
    sys.exit()
r = run["report"]
s = run.get("self_contact") or {}
print(f'{sys.argv[2]},{sys.argv[3]},{r["status"]},{r["iterations"]},{r["wall_time_s"]:.2f},'
      f'{r["max_residual_N"]:.2e},{s.get("crossing_edges", "")},{s.get("min_distance_m", "")}')
PY
  done
done
