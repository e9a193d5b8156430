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

from model import G, forces, hang4


def energy(x, pairs, rest, k, mass):
    l = np.linalg.norm(x[pairs[:, 1]] - x[pairs[:, 0]], axis=1)
    return 0.5 * np.sum(k * (l - rest) ** 2) + G * np.sum(mass * x[:, 2])


def hessian(x, pairs, rest, k, n3):
    d = x[pairs[:, 1]] - x[pairs[:, 0]]
    l = np.linalg.norm(d, axis=1)
    u = d / l[:, None]
    # Exact: the transverse term is negative for a compressed spring; the LM shift handles that.
    a = k * (1.0 - rest / l)
    K = a[:, None, None] * np.eye(3)[None] + (k - a)[:, None, None] * u[:, :, None] * u[:, None, :]
    rows, cols, vals = [], [], []
    for (p, q), s in [((0, 0), 1.0), ((1, 1), 1.0), ((0, 1), -1.0), ((1, 0), -1.0)]:
        for r in range(3):
            for c in range(3):
                rows.append(3 * pairs[:, p] + r)
                cols.append(3 * pairs[:, q] + c)
                vals.append(s * K[:, r, c])
    return sp.csc_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n3, n3)
    )


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
        H = hessian(x, pairs, rest, k, 3 * n * n)[free][:, free]
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
            alpha, ok = 1.0, False
            for _ in range(30):
                xt = x + alpha * step
                et = energy(xt, pairs, rest, k, mass)
                if et <= e - 1e-4 * alpha * np.dot(F.ravel(), step.ravel()):
                    ok = True
                    break
                alpha *= 0.5
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
