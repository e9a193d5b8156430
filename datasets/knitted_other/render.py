"""An independent renderer for drapelab's hangs (issue 17): photos whose making shares no code with
drapelab's own renderer (src: crates/core/src/edges/render.rs), so that calibrating on them is not an
inverse crime.

Input: a `particles.parquet` written by `drapelab simulate` (columns i, j, x_m, y_m, z_m). Output: a JPEG
photo and a camera.json with only what a camera gives (view, side_cm, px_per_cm or a pinhole's focal
length, distance and principal point, corners_px).

What differs from drapelab's renderer:
- the surface: by default a Catmull-Rom (bicubic) surface through the particles, 8 x 8 quads per grid
  cell (a real fabric is smooth between its "particles"); with subdivisions 1, flat triangles between
  the particles as drapelab's own renderer and silhouette assume;
- the fabric: a knit texture (wales and courses, 0.5 cm period) on the material coordinates, a
  different light and a 0.3 ambient term;
- the background: 190 grey levels with a left-to-right gradient of 20 levels and a vignette darkening
  the image's corners by 24 levels;
- coverage by 5 x 5 jittered supersampling (not a regular 4 x 4), Gaussian noise sigma 3, JPEG quality 90;
- pixel centres at integers (the convention of camera.json);
- optionally a pinhole camera (perspective: the far parts of the drape look smaller), aimed at the
  middle of the sheet rather than drapelab's renderer's world origin.
"""
import json
import sys

import numpy as np
import pyarrow.parquet as pq
from PIL import Image

SS = 5  # supersampling per axis
UP = 8  # surface subdivisions per grid cell


def catmull_rom_weights(t):
    t2, t3 = t * t, t * t * t
    return np.stack([-0.5 * t3 + t2 - 0.5 * t, 1.5 * t3 - 2.5 * t2 + 1.0,
                     -1.5 * t3 + 2.0 * t2 + 0.5 * t, 0.5 * t3 - 0.5 * t2], axis=-1)


def upsample(grid, up):
    """Catmull-Rom surface through grid (ny, nx, 3) sampled `up` times per cell; (Ny, Nx, 3)."""
    ny, nx, _ = grid.shape
    pad = np.pad(grid, ((1, 1), (1, 1), (0, 0)), mode="reflect", reflect_type="odd")

    def along(arr, n, axis):
        out = []
        for k in range(n - 1):
            for s in range(up):
                w = catmull_rom_weights(np.array(s / up))
                idx = [k, k + 1, k + 2, k + 3]
                seg = np.take(arr, idx, axis=axis)
                out.append(np.tensordot(w, seg, axes=([0], [axis])))
        out.append(np.take(arr, n, axis=axis))
        return np.stack(out, axis=axis)

    a = along(pad, nx, 1)  # (ny+2, Nx, 3)
    return along(a, ny, 0)[:, :, :]


def project(fine, grid, corners, distance_m):
    """Central projection of the surface points `fine` onto the plane of the fixed corners through a
    pinhole `distance_m` in front of it (the camera looks along +y, its axis through the middle of the
    sheet's bounding box); returns the projected (x, z) and the axis point."""
    y_c = 0.5 * (grid[corners[0][1], corners[0][0], 1] + grid[corners[1][1], corners[1][0], 1])
    x, y, z = fine[..., 0], fine[..., 1], fine[..., 2]
    ax, az = 0.5 * (x.min() + x.max()), 0.5 * (z.min() + z.max())
    k = distance_m / (distance_m + (y - y_c))
    return ax + (x - ax) * k, az + (z - az) * k, (ax, az)


def render(particles, view, px_per_cm, out_png, out_json, seed, up=UP, pinhole_m=0.0):
    t = pq.read_table(particles).to_pydict()
    i, j = np.array(t["i"]), np.array(t["j"])
    nx, ny = i.max() + 1, j.max() + 1
    grid = np.zeros((ny, nx, 3))
    grid[j, i] = np.stack([t["x_m"], t["y_m"], t["z_m"]], axis=1)
    if view == "hang4":
        corners = [(0, 0), (nx - 1, 0)]
    else:
        corners = [(0, ny - 1), (nx - 1, ny - 1)]
    fine = upsample(grid, up)
    Ny, Nx, _ = fine.shape
    s = px_per_cm * 100.0 * SS  # supersampled px per m
    margin = 40 * SS
    x, y, z = fine[..., 0], fine[..., 1], fine[..., 2]
    axis = None
    if pinhole_m > 0:
        x, z, axis = project(fine, grid, corners, pinhole_m)
    x0, z1 = x.min(), z.max()
    U = (x - x0) * s + margin
    V = (z1 - z) * s + margin
    W = int(np.ceil(U.max() + margin)) // SS * SS + SS
    H = int(np.ceil(V.max() + margin)) // SS * SS + SS
    rng = np.random.default_rng(seed)
    # Material coordinates (cm) of the fine vertices, for the texture.
    side_cm = 50.0
    mu = np.linspace(0, side_cm, Nx)[None, :].repeat(Ny, 0)
    mv = np.linspace(0, side_cm, Ny)[:, None].repeat(Nx, 1)
    depth = np.full((H, W), np.inf)
    shade = np.zeros((H, W))
    light = np.array([0.4, -0.7, 0.6])
    light /= np.linalg.norm(light)
    jitter = rng.uniform(-0.35, 0.35, size=(H, W, 2))
    for a in range(Ny - 1):
        for b in range(Nx - 1):
            quad = [(a, b), (a, b + 1), (a + 1, b + 1), (a + 1, b)]
            for tri in ([0, 1, 2], [0, 2, 3]):
                vs = [quad[k] for k in tri]
                pu = np.array([U[v] for v in vs])
                pv = np.array([V[v] for v in vs])
                pd = np.array([y[v] for v in vs])
                P = np.array([fine[v] for v in vs])
                n = np.cross(P[1] - P[0], P[2] - P[0])
                nn = np.linalg.norm(n)
                if nn == 0:
                    continue
                lum = 0.3 + 0.7 * abs(n @ light) / nn
                tu = np.array([mu[v] for v in vs]).mean()
                tv = np.array([mv[v] for v in vs]).mean()
                tex = 1.0 + 0.12 * np.sin(2 * np.pi * tu / 0.5) * np.sin(2 * np.pi * tv / 0.5)
                u0, u1 = int(np.floor(pu.min())), int(np.ceil(pu.max())) + 1
                v0, v1 = int(np.floor(pv.min())), int(np.ceil(pv.max())) + 1
                if u1 <= u0 or v1 <= v0:
                    continue
                gu, gv = np.meshgrid(np.arange(u0, u1), np.arange(v0, v1))
                qu = gu + 0.5 + jitter[v0:v1, u0:u1, 0]
                qv = gv + 0.5 + jitter[v0:v1, u0:u1, 1]
                area = (pu[1] - pu[0]) * (pv[2] - pv[0]) - (pv[1] - pv[0]) * (pu[2] - pu[0])
                if abs(area) < 1e-12:
                    continue
                w0 = ((pu[1] - qu) * (pv[2] - qv) - (pv[1] - qv) * (pu[2] - qu)) / area
                w1 = ((pu[2] - qu) * (pv[0] - qv) - (pv[2] - qv) * (pu[0] - qu)) / area
                w2 = 1.0 - w0 - w1
                inside = (w0 >= 0) & (w1 >= 0) & (w2 >= 0)
                d = w0 * pd[0] + w1 * pd[1] + w2 * pd[2]
                sub = depth[v0:v1, u0:u1]
                upd = inside & (d < sub)
                sub[upd] = d[upd]
                shade[v0:v1, u0:u1][upd] = 120.0 * lum * tex
    covered = np.isfinite(depth)
    h, w = H // SS, W // SS
    cu = (np.arange(w) + 0.5) / w - 0.5
    cv = (np.arange(h) + 0.5) / h - 0.5
    bg_small = 190.0 + 20.0 * cu[None, :] - 12.0 * (4 * (cu[None, :] ** 2 + cv[:, None] ** 2))
    bg = np.kron(bg_small, np.ones((SS, SS)))
    img = np.where(covered, shade, bg)
    img = img.reshape(h, SS, w, SS).mean(axis=(1, 3))
    img = img + rng.normal(0.0, 3.0, size=img.shape)
    img = np.clip(np.round(img), 0, 255).astype(np.uint8)
    Image.fromarray(img, mode="L").convert("RGB").save(out_png, quality=90)

    def corner_px(ij):
        ci, cj = ij
        k = (cj * up, ci * up)
        # Supersampled continuous coordinates (pixel k spans [k, k+1)) to photo pixels (centres at integers).
        return [U[k] / SS - 0.5, V[k] / SS - 0.5]

    cam = {"view": view, "side_cm": side_cm, "px_per_cm": px_per_cm,
           "corners_px": [corner_px(corners[0]), corner_px(corners[1])]}
    if axis is not None:
        # A pinhole camera as its calibration gives it: focal length (px), distance to the corners'
        # plane and principal point; the scale at the sheet follows from them.
        del cam["px_per_cm"]
        cam["pinhole"] = {
            "focal_length_px": px_per_cm * 100.0 * pinhole_m,
            "distance_m": pinhole_m,
            "principal_point_px": [((axis[0] - x0) * s + margin) / SS - 0.5,
                                   ((z1 - axis[1]) * s + margin) / SS - 0.5],
        }
    with open(out_json, "w") as f:
        json.dump(cam, f, indent=2)
        f.write("\n")


if __name__ == "__main__":
    # Optional 7th argument: surface subdivisions per grid cell (default 8, a smooth surface; 1 draws
    # flat triangles between the particles, the surface drapelab's silhouette assumes). Optional 8th:
    # a pinhole camera this far (m) in front of the fixed corners' plane (default 0: orthographic); the
    # scale px_per_cm is then the one in that plane.
    particles, view, px, png, js, seed = sys.argv[1:7]
    up = int(sys.argv[7]) if len(sys.argv) > 7 else UP
    pinhole_m = float(sys.argv[8]) if len(sys.argv) > 8 else 0.0
    render(particles, view, float(px), png, js, int(seed), up, pinhole_m)
