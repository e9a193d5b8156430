"""Peer of drapelab's explicit Euler: hang4 integrated by explicit (forward) Euler with viscous damping,
vectorised in numpy, for STEPS steps at a stable dt. Prints one JSON line: n, steps, wall_time_s,
per_step_s."""
import json
import sys
import time

import numpy as np

from model import forces, hang4


def main(n, steps):
    x, pairs, rest, k, mass, fixed = hang4(n)
    v = np.zeros_like(x)
    m = mass[:, None]
    # A stable step: 0.5 / omega_max with omega_max^2 <= 2 * sum of spring stiffness at a particle / m.
    kmax = np.zeros(len(mass))
    np.add.at(kmax, pairs[:, 0], k)
    np.add.at(kmax, pairs[:, 1], k)
    dt = 0.5 / np.sqrt((2 * kmax / mass).max())
    t0 = time.perf_counter()
    for _ in range(steps):
        F = forces(x, pairs, rest, k, mass) - 0.02 * v
        F[fixed] = 0.0
        x = x + dt * v
        v = v + dt * F / m
    wall = time.perf_counter() - t0
    print(json.dumps({"peer": "numpy-explicit", "n": n, "steps": steps, "wall_time_s": wall,
                      "per_step_s": wall / steps}))


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]) if len(sys.argv) > 2 else 1000)
