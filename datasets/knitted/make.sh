#!/usr/bin/env bash
# Regenerates the synthetic knitted dataset: for each of the 9 samples of seed 000 Table 2, the
# 4-corner and 2-corner hangs simulated with ground-truth parameters (Table 4, see README.md), rendered
# as photos with camera noise and corner markers, with the exact camera calibration and the edge fit
# made straight from the simulated particles (edges_truth.parquet). Run from the repository root:
#   bash datasets/knitted/make.sh
set -euo pipefail
bin="${DRAPELAB:-cargo run --release --quiet --}"
here=datasets/knitted
# One line per sample of datasets/knitted/ground_truth.csv: sample, areal density (kg/m²), stiffness
# (N/m), natural length (m).
while IFS=, read -r s rho k l0; do
  d=$(printf "%s/sample_%02d" "$here" "$s")
  for hang in hang4 hang2; do
    $bin render datasets/scenes/$hang.toml --out "$d/$hang" --px-per-cm 5 --markers --noise 3 --seed "$s" \
      --set cloth.nx=14 --set cloth.ny=14 --set cloth.areal_density_kg_per_m2="$rho" \
      --set material.mass_spring.stiffness_N_per_m="$k" --set material.mass_spring.natural_length_m="$l0"
    rm -f "$d/$hang/particles.parquet"
  done
done < <(grep -v '^#' datasets/knitted/ground_truth.csv | tail -n +2)
