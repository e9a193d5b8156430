"""The strongest Python peer of drapelab's static solver: hang4 by Newton on the exact Hessian with
CHOLMOD's supernodal Cholesky from cvxopt, the symbolic analysis done once and reused by every
iteration, a Levenberg-Marquardt shift (1e-3 of the mean diagonal, raised 10x while the factorization
fails, divided by 10 after each full step) and a backtracking line search on the energy. (Projected
Newton, the transverse stiffness of compressed springs clamped at zero, stalls on hang4: 500
iterations at 11 a side; the exact Hessian converges quadratically.) to a largest residual force of TOL x the lightest particle's
weight. Prints one JSON line: peer, n, wall_time_s, iterations, factorizations, factor_time_s,
centre_z_m."""
import json
import sys
import time

import numpy as np
from cvxopt import cholmod, matrix, spmatrix

from model import G, backtrack, energy, forces, hang4, hessian_triplets


def main(n, tol):
    x, pairs, rest, k, mass, fixed = hang4(n)
    free = np.repeat(~fixed, 3)
    index = -np.ones(3 * n * n, dtype=int)
    index[free] = np.arange(free.sum())
    nf = int(free.sum())
    cholmod.options["supernodal"] = 2
    t0 = time.perf_counter()
    wref = mass[~fixed].min() * G
    mu, it, nfact, tfact = 1e-3, 0, 0, 0.0
    e = energy(x, pairs, rest, k, mass)
    symbolic = None

    def residual(xt):
        Ft = forces(xt, pairs, rest, k, mass)
        Ft[fixed] = 0.0
        return np.linalg.norm(Ft, axis=1).max()
    while it < 500:
        F = forces(x, pairs, rest, k, mass)
        F[fixed] = 0.0
        r0 = np.linalg.norm(F, axis=1).max()
        if r0 <= tol * wref:
            break
        it += 1
        r, c, v = hessian_triplets(x, pairs, rest, k)
        keep = (index[r] >= 0) & (index[c] >= 0)
        r, c, v = index[r[keep]], index[c[keep]], v[keep]
        lower = r >= c
        r, c, v = r[lower], c[lower], v[lower]
        diag = np.bincount(r[r == c], weights=v[r == c], minlength=nf)
        scale = diag.mean()
        rhs = F.ravel()[free]
        while True:
            rr = np.concatenate([r, np.arange(nf)])
            cc = np.concatenate([c, np.arange(nf)])
            vv = np.concatenate([v, np.full(nf, mu * scale)])
            A = spmatrix(matrix(vv), matrix(rr.astype(np.int32)), matrix(cc.astype(np.int32)),
                         (nf, nf))
            tf = time.perf_counter()
            if symbolic is None:
                symbolic = cholmod.symbolic(A, uplo="L")
            try:
                nfact += 1
                cholmod.numeric(A, symbolic)
                B = matrix(rhs)
                cholmod.solve(symbolic, B)
                tfact += time.perf_counter() - tf
            except ArithmeticError:
                tfact += time.perf_counter() - tf
                mu = max(mu * 10, 1e-8)
                continue
            dx = np.array(B).ravel()
            if not np.all(np.isfinite(dx)) or np.dot(dx, rhs) <= 0.0:
                mu = max(mu * 10, 1e-8)
                continue
            step = np.zeros(3 * n * n)
            step[free] = dx
            step = step.reshape(-1, 3)
            ok, alpha, xt, et = backtrack(
                x, step, e, -np.dot(rhs, dx), lambda xt: energy(xt, pairs, rest, k, mass),
                residual, r0)
            if ok:
                x, e = xt, et
                mu = (0.0 if mu < 1e-12 else mu / 10) if alpha == 1.0 else mu
                break
            mu = max(mu * 10, 1e-8)
    wall = time.perf_counter() - t0
    ctr = (n // 2) * n + n // 2
    print(json.dumps({"peer": "cholmod-newton", "n": n, "wall_time_s": wall, "iterations": it,
                      "factorizations": nfact, "factor_time_s": tfact,
                      "centre_z_m": float(x[ctr, 2])}))


if __name__ == "__main__":
    main(int(sys.argv[1]), float(sys.argv[2]) if len(sys.argv) > 2 else 1e-6)
