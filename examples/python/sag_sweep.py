"""drapelab from Python: sweep the spring stiffness of seed 000's 4-corner hang, plot the centre's sag
against it, and measure a real Cusick capture.

    pip install .                       # at the repository root (under a minute after `cargo build --release`)
    pip install matplotlib polars
    python examples/python/sag_sweep.py  # writes runs/examples/sag_vs_stiffness.png

Run from the repository root (the bundled scene and photo are found relative to it). The tests run
this script (tests/python/test_drapelab.py) with DRAPELAB_EXAMPLE_OUT set to a temporary folder.
"""

import os
import pathlib

import matplotlib.pyplot as plt
import numpy as np

import drapelab

out = pathlib.Path(os.environ.get("DRAPELAB_EXAMPLE_OUT", "runs/examples"))
out.mkdir(parents=True, exist_ok=True)

# 1. A stiffness sweep: the static solves run in parallel threads, arrays back in order.
n = 21
stiffness = np.geomspace(100.0, 3000.0, 7)  # N/m
results = drapelab.simulate_many(
    "datasets/scenes/hang4.toml",
    overrides=[{"cloth.nx": n, "cloth.ny": n, "material.mass_spring.stiffness_N_per_m": float(k)}
               for k in stiffness])
sag = []
for k, r in zip(stiffness, results):
    if not r.converged:  # a status, never a number passed off as a result
        print(f"k = {k:.0f} N/m: {r.status}")
        sag.append(np.nan)
        continue
    g = r.grid()  # (ny, nx, 3): g[j, i] is the particle in column i, row j
    corners_z = g[[0, 0, -1, -1], [0, -1, 0, -1], 2].mean()
    sag.append(corners_z - g[n // 2, n // 2, 2])
    print(f"k = {k:7.1f} N/m: centre sag {sag[-1] * 1000:6.2f} mm in {r.report['iterations']} Newton iterations")

fig, ax = plt.subplots(figsize=(5, 3.5))
ax.loglog(stiffness, np.array(sag) * 1000, "o-")
ax.set_xlabel("spring stiffness k (N/m)")
ax.set_ylabel("centre sag below the corners (mm)")
ax.set_title("hang4 21², seed 000's knitted sheet")
ax.grid(True, which="both", alpha=0.3)
fig.tight_layout()
fig.savefig(out / "sag_vs_stiffness.png", dpi=120)
print(f"wrote {out / 'sag_vs_stiffness.png'}")

# 2. A real capture: fabric 1 of the Cusick drape tester dataset (BDP, CVPR 2024).
m = drapelab.measure_silhouette("datasets/cusick/fabric_01/silhouettes/sample_01_capture_1.jpg")
print(f"Cusick fabric 1, capture 1: drape coefficient {m['drape_coefficient_pct']:.1f} %, {m['nodes']} nodes")
