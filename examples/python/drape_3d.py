"""A drape in 3D, notebook style: solve seed 003's sheet on a table with a progress callback, plot
the drape as a surface with matplotlib, and how Newton's residual fell over its kept frames.

    pip install . matplotlib
    python examples/python/drape_3d.py   # writes runs/examples/drape_3d.png

Each cell of a notebook is one block below. Run from the repository root; the tests run this script
(tests/python/test_drapelab.py) with DRAPELAB_EXAMPLE_OUT set to a temporary folder.
"""

import os
import pathlib

import matplotlib.pyplot as plt
import numpy as np

import drapelab

out = pathlib.Path(os.environ.get("DRAPELAB_EXAMPLE_OUT", "runs/examples"))
out.mkdir(parents=True, exist_ok=True)

# Solve, watching the residual as it goes (the callback runs at most every 50 ms).
seen = []
r = drapelab.simulate("datasets/scenes/table_wool.toml",
                      overrides={"cloth.nx": 21, "cloth.ny": 21},
                      frames=50,
                      progress=lambda i, t, res, e: seen.append((i, res)))
print(r)
if not r.converged:  # a status, never a drape passed off as a result
    raise SystemExit(f"the solve ended {r.status}: {r.report['message']}")

# The drape as a surface over its triangles (the present particles only).
keep = r.present[r.triangles].all(axis=1)
x = r.positions * 100  # cm
fig = plt.figure(figsize=(9, 4))
ax = fig.add_subplot(1, 2, 1, projection="3d")
ax.plot_trisurf(x[:, 0], x[:, 1], x[:, 2], triangles=r.triangles[keep], cmap="viridis",
                linewidth=0.1, edgecolor="k")
ax.set_xlabel("x (cm)")
ax.set_ylabel("y (cm)")
ax.set_zlabel("z (cm)")
ax.set_title(f"{r.scene['name']}: {r.status}")

# Newton's iterations: how the sheet's lowest point moved over the kept frames.
frames, index, _ = r.frames()
drop = frames[:, :, 2].min(axis=1) * 100
ax2 = fig.add_subplot(1, 2, 2)
ax2.plot(index, drop, "o-")
ax2.set_xlabel("Newton iteration")
ax2.set_ylabel("lowest point of the sheet (cm)")
ax2.set_title(f"{len(index)} kept frames, {len(seen)} progress calls")
ax2.grid(True, alpha=0.3)
fig.tight_layout()
fig.savefig(out / "drape_3d.png", dpi=110)
print(f"wrote {out / 'drape_3d.png'}")
