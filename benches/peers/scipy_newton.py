"""Peer of drapelab's static solver: hang4 by a sparse Newton method in scipy (Levenberg-Marquardt shift
on the exact Hessian, raised until the step descends, backtracking line search on the energy), to a largest residual
force of TOL x the lightest particle's weight. Prints one JSON line: n, wall_time_s, iterations,
centre_z_m."""
import json
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from model import G, backtrack, energy, forces, hang4, hessian_triplets


def main(n, tol):
    x, pairs, rest, k, mass, fixed = hang4(n)
    free = np.repeat(~fixed, 3)
    t0 = time.perf_counter()
    wref = mass[~fixed].min() * G
    mu, it = 1e-3, 0
    e = energy(x, pairs, rest, k, mass)
    while it < 500:
        F = forces(x, pairs, rest, k, mass)
        F[fixed] = 0.0
        if np.abs(np.linalg.norm(F, axis=1)).max() <= tol * wref:
            break
        it += 1
        r, c, v = hessian_triplets(x, pairs, rest, k)
        H = sp.csc_matrix((v, (r, c)), shape=(3 * n * n, 3 * n * n))[free][:, free]
        scale = H.diagonal().mean()
        while True:
            A = H + sp.identity(H.shape[0]) * (mu * scale)
            dx = spla.spsolve(A.tocsc(), F.ravel()[free])
            if not np.all(np.isfinite(dx)) or np.dot(dx, F.ravel()[free]) <= 0.0:
                mu = max(mu * 10, 1e-8)
                continue
            step = np.zeros(3 * n * n)
            step[free] = dx
            step = step.reshape(-1, 3)
            ok, alpha, xt, et = backtrack(
                x, step, e, -np.dot(F.ravel(), step.ravel()),
                lambda xt: energy(xt, pairs, rest, k, mass))
            if ok:
                x, e = xt, et
                mu = (0.0 if mu < 1e-12 else mu / 4) if alpha == 1.0 else mu
                break
            mu *= 10
    wall = time.perf_counter() - t0
    c = (n // 2) * n + n // 2
    print(json.dumps({"peer": "scipy-newton", "n": n, "wall_time_s": wall, "iterations": it,
                      "centre_z_m": float(x[c, 2])}))


if __name__ == "__main__":
    main(int(sys.argv[1]), float(sys.argv[2]) if len(sys.argv) > 2 else 1e-6)
