#!/usr/bin/env bash
# Regenerates the synthetic knitted dataset: for each of the 9 samples of seed 000 Table 2, the
# 4-corner and 2-corner hangs simulated with ground-truth parameters (Table 4, see README.md), rendered
# as photos with camera noise and corner markers, with the exact camera calibration and the edge fit
# made straight from the simulated particles (edges_truth.parquet). Run from the repository root:
#   bash datasets/knitted/make.sh
set -euo pipefail
bin="${DRAPELAB:-cargo run --release --quiet --}"
here=datasets/knitted
# sample, areal density (kg/m², Table 2), stiffness (N/m, Table 4), natural length (m, Table 4 read as mm)
while IFS=, read -r s rho k l0; do
  d=$(printf "%s/sample_%02d" "$here" "$s")
  for hang in hang4 hang2; do
    $bin render datasets/scenes/$hang.toml --out "$d/$hang" --px-per-cm 5 --markers --noise 3 --seed "$s" \
      --set cloth.nx=14 --set cloth.ny=14 --set cloth.areal_density_kg_per_m2="$rho" \
      --set material.mass_spring.stiffness_N_per_m="$k" --set material.mass_spring.natural_length_m="$l0"
    rm -f "$d/$hang/particles.parquet"
  done
done <<'TABLE'
1,0.04165,852,0.049
2,0.04414,942,0.047
3,0.04676,988,0.053
4,0.04463,945,0.040
5,0.04962,1034,0.049
6,0.02760,674,0.040
7,0.05116,1092,0.040
8,0.05441,1100,0.055
9,0.05826,1100,0.050
TABLE
