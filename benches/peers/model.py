"""The hang4 mass-spring model of seed 000 (topology a: structural, shear and bend springs, every one at
k N/m with its initial length at rest; area-lumped masses; the four corners pinned; gravity along -z),
shared by the peer scripts that drapelab's benchmark runs beside itself."""
import numpy as np

G = 9.80665


def hang4(n, side=0.5, density=0.045, k=1000.0):
    h = side / (n - 1)
    xs = np.linspace(0.0, side, n)
    X, Y = np.meshgrid(xs, xs)  # row j, column i
    x0 = np.stack([X.ravel(), Y.ravel(), np.zeros(n * n)], axis=1)
    idx = lambda i, j: j * n + i
    pairs = []
    for j in range(n):
        for i in range(n):
            for di, dj in [(1, 0), (0, 1), (1, 1), (2, 0), (0, 2)]:
                if i + di < n and j + dj < n:
                    pairs.append((idx(i, j), idx(i + di, j + dj)))
            if i + 1 < n and j + 1 < n:
                pairs.append((idx(i + 1, j), idx(i, j + 1)))
    pairs = np.array(pairs)
    rest = np.linalg.norm(x0[pairs[:, 1]] - x0[pairs[:, 0]], axis=1)
    w = np.full(n, h)
    w[0] = w[-1] = h / 2
    mass = density * np.outer(w, w).ravel()
    fixed = np.zeros(n * n, bool)
    for i, j in [(0, 0), (n - 1, 0), (0, n - 1), (n - 1, n - 1)]:
        fixed[idx(i, j)] = True
    return x0, pairs, rest, np.full(len(pairs), k), mass, fixed


def forces(x, pairs, rest, k, mass):
    """Internal + gravity force on each particle (N)."""
    d = x[pairs[:, 1]] - x[pairs[:, 0]]
    l = np.linalg.norm(d, axis=1)
    f = (k * (l - rest) / l)[:, None] * d
    F = np.zeros_like(x)
    np.add.at(F, pairs[:, 0], f)
    np.add.at(F, pairs[:, 1], -f)
    F[:, 2] -= mass * G
    return F


def energy(x, pairs, rest, k, mass):
    """Spring energy plus gravity (J)."""
    l = np.linalg.norm(x[pairs[:, 1]] - x[pairs[:, 0]], axis=1)
    return 0.5 * np.sum(k * (l - rest) ** 2) + G * np.sum(mass * x[:, 2])


def hessian_triplets(x, pairs, rest, k):
    """(rows, cols, values) of the exact Hessian over all 3n DOFs, both triangles, duplicates to be
    summed: per spring K = k[uu^T + (1 - L0/l)(I - uu^T)] (negative transverse term when compressed)."""
    d = x[pairs[:, 1]] - x[pairs[:, 0]]
    l = np.linalg.norm(d, axis=1)
    u = d / l[:, None]
    a = k * (1.0 - rest / l)
    K = a[:, None, None] * np.eye(3)[None] + (k - a)[:, None, None] * u[:, :, None] * u[:, None, :]
    rows, cols, vals = [], [], []
    for (p, q), s in [((0, 0), 1.0), ((1, 1), 1.0), ((0, 1), -1.0), ((1, 0), -1.0)]:
        for r in range(3):
            for c in range(3):
                rows.append(3 * pairs[:, p] + r)
                cols.append(3 * pairs[:, q] + c)
                vals.append(s * K[:, r, c])
    return np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)


def backtrack(x, step, e, slope, energy_at, residual_at=None, r0=None):
    """Armijo backtracking along `step` (30 halvings): (accepted, alpha, x_new, e_new). With
    `residual_at`, a step whose energy change is below round-off is accepted when it lowers the largest
    residual force below r0 (as drapelab does near the solution)."""
    alpha = 1.0
    for _ in range(30):
        xt = x + alpha * step
        et = energy_at(xt)
        flat = residual_at is not None and abs(et - e) <= 1e-11 * abs(e)
        if et <= e + 1e-4 * alpha * slope or (flat and residual_at(xt) < r0):
            return True, alpha, xt, et
        alpha *= 0.5
    return False, alpha, x, e
