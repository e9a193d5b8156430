#!/usr/bin/env bash
# Regenerates datasets/knitted_other/ (issue 17): seed 000's nine knitted samples simulated by drapelab
# with their ground truth (the same Table 4 values as datasets/knitted/, see its README), then
# photographed by an independent renderer (render.py: knit texture, other light, uneven
# background, jittered supersampling, JPEG; nothing shared with drapelab's renderer) at 15 px/cm, with a
# camera.json of only what a camera gives, once with flat triangles between the particles (flat/) and
# once with a smooth surface through them (smooth/), and flat triangles seen through a pinhole 1.2 m away
# (perspective/). Run from the repository root:
#   bash datasets/knitted_other/make.sh
set -euo pipefail
bin="${DRAPELAB:-cargo run --release --quiet --}"
py="${PYTHON:-.venv/bin/python}"
here=datasets/knitted_other
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# One line per sample of datasets/knitted/ground_truth.csv: sample, areal density (kg/m²), stiffness
# (N/m), natural length (m).
while IFS=, read -r s rho k l0; do
  for hang in hang4 hang2; do
    $bin simulate datasets/scenes/$hang.toml --out "$tmp/$s/$hang" -q \
      --set cloth.nx=14 --set cloth.ny=14 --set cloth.areal_density_kg_per_m2="$rho" \
      --set material.mass_spring.stiffness_N_per_m="$k" --set material.mass_spring.natural_length_m="$l0"
    # Two surfaces between the particles: flat triangles (the surface drapelab's silhouette assumes)
    # and a smooth Catmull-Rom surface (8 x 8 quads per cell), square on; and flat triangles through
    # a pinhole 1.2 m from the corners' plane (perspective/). variant = folder:subdivisions:pinhole_m.
    for variant in flat:1:0 smooth:8:0 perspective:1:1.2; do
      IFS=: read -r folder up pinhole <<< "$variant"
      d=$(printf "%s/%s/sample_%02d/%s" "$here" "$folder" "$s" "$hang")
      mkdir -p "$d"
      "$py" "$here/render.py" "$tmp/$s/$hang/particles.parquet" "$hang" 15 "$d/photo.jpg" \
        "$d/camera.json" "$s" "$up" "$pinhole"
    done
    # Another resolution (fine/): a 41 x 41 net with the same macroscopic sheet, i.e. the same spring
    # stiffness (a square net's membrane stiffness per unit width is the spring's, whatever the spacing),
    # areal density and natural sheet size (natural length scaled by 13/40), rendered with flat
    # triangles. The truth for the 14 x 14 model is then the stated 14 x 14 values, up to discretisation.
    l41=$(awk -v l="$l0" 'BEGIN { printf "%.9g", l * 13 / 40 }')
    $bin simulate datasets/scenes/$hang.toml --out "$tmp/$s/fine_$hang" -q \
      --set cloth.nx=41 --set cloth.ny=41 --set cloth.areal_density_kg_per_m2="$rho" \
      --set material.mass_spring.stiffness_N_per_m="$k" --set material.mass_spring.natural_length_m="$l41" \
      --set solver.static.max_iterations=2000
    d=$(printf "%s/fine/sample_%02d/%s" "$here" "$s" "$hang")
    mkdir -p "$d"
    "$py" "$here/render.py" "$tmp/$s/fine_$hang/particles.parquet" "$hang" 15 "$d/photo.jpg" \
      "$d/camera.json" "$s" 1
  done
done < <(grep -v '^#' datasets/knitted/ground_truth.csv | tail -n +2)
