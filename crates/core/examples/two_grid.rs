//! A two-grid preconditioner for Newton's step on a fine grid, measured against the factorization
//! it would replace (issue 76: a multilevel preconditioner as the design that moves the
//! factorization floor of hang4 at 321²). The scene is solved on the grid with every other line;
//! its drape, interpolated bilinearly as the nested start does, is the fine grid's start. There
//! the projected Hessian H is (a) factorized and solved, and (b) solved by conjugate gradients
//! preconditioned with one two-grid cycle: damped block-Jacobi smoothing (ν sweeps before and
//! after, weight ω) around a coarse correction with either Galerkin's operator Pᵀ H P (P the same
//! bilinear interpolation) or the coarse model's own Hessian at the fine state's coarse points,
//! each factorized once. It prints the times and the iterations CG needs to each relative
//! residual. A square grid of odd size without virtual particles inside it (hang4, hang2).
//!
//! cargo run --release -p drapelab-core --example two_grid -- datasets/scenes/hang4.toml 321 [nu]

use drapelab_core::physics::{HessianBlocks, HessianMode, Model};
use drapelab_core::scene::Scene;
use drapelab_core::simulate::solve_scene;
use drapelab_core::solve::{DofMap, SparseSpd};
use nalgebra::{Matrix3, Vector3};
use std::time::Instant;

type Vecs = Vec<Vector3<f64>>;

/// The bilinear interpolation from the coarse grid (every other line) to the fine one: per fine
/// particle, its coarse parents and weights (the nested start's `coarse_start`).
fn parents(nx: usize, ny: usize, cnx: usize) -> Vec<Vec<(usize, f64)>> {
    let mut out = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let (i0, j0) = (i / 2, j / 2);
            let (i1, j1) = (i0 + i % 2, j0 + j % 2);
            let mut w: Vec<(usize, f64)> = Vec::new();
            for (a, b) in [(i0, j0), (i1, j0), (i0, j1), (i1, j1)] {
                let c = b * cnx + a;
                match w.iter_mut().find(|e| e.0 == c) {
                    Some(e) => e.1 += 0.25,
                    None => w.push((c, 0.25)),
                }
            }
            out.push(w);
        }
    }
    out
}

/// Pᵀ H P over the free fine particles, as coarse blocks (lower triangle).
fn galerkin(h: &HessianBlocks, par: &[Vec<(usize, f64)>], fixed: &[bool]) -> HessianBlocks {
    let mut c = HessianBlocks::default();
    let free = |p: usize| p < par.len() && !fixed[p];
    for (&(p, q), b) in h.all() {
        let (p, q) = (p as usize, q as usize);
        if !free(p) || !free(q) {
            continue;
        }
        for &(a, wa) in &par[p] {
            for &(bb, wb) in &par[q] {
                let m = b * (wa * wb);
                if p == q {
                    // A symmetric diagonal block: every ordered parent pair, counted once each way.
                    if a >= bb {
                        c.push(a, bb, m);
                    }
                } else if a == bb {
                    c.push(a, a, m + m.transpose());
                } else {
                    c.push(a, bb, m);
                }
            }
        }
    }
    c
}

/// y = H x on free particles (zero on fixed ones).
fn apply(h: &HessianBlocks, fixed: &[bool], x: &Vecs, y: &mut Vecs) {
    y.iter_mut().for_each(|v| *v = Vector3::zeros());
    h.mul_add(x, y);
    for (v, f) in y.iter_mut().zip(fixed) {
        if *f {
            *v = Vector3::zeros();
        }
    }
}

struct TwoGrid<'a> {
    h: &'a HessianBlocks,
    fixed: &'a [bool],
    dinv: Vec<Matrix3<f64>>,
    par: &'a [Vec<(usize, f64)>],
    coarse: SparseSpd,
    cdofs: DofMap,
    nu: usize,
    omega: f64,
}

impl TwoGrid<'_> {
    fn smooth(&self, r: &Vecs, z: &mut Vecs, tmp: &mut Vecs) {
        for _ in 0..self.nu {
            apply(self.h, self.fixed, z, tmp);
            for p in 0..z.len() {
                if !self.fixed[p] {
                    z[p] += self.dinv[p] * (r[p] - tmp[p]) * self.omega;
                }
            }
        }
    }

    /// z = M⁻¹ r: smoothing, the coarse correction, smoothing.
    fn precondition(&mut self, r: &Vecs, z: &mut Vecs) {
        let n = r.len();
        let mut tmp = vec![Vector3::zeros(); n];
        z.iter_mut().for_each(|v| *v = Vector3::zeros());
        self.smooth(r, z, &mut tmp);
        apply(self.h, self.fixed, z, &mut tmp);
        let mut rc = vec![0.0; self.cdofs.n];
        for p in 0..self.par.len() {
            if self.fixed[p] {
                continue;
            }
            let res = r[p] - tmp[p];
            for &(a, w) in &self.par[p] {
                if let Some(d) = self.cdofs.dof(a) {
                    for k in 0..3 {
                        rc[d + k] += w * res[k];
                    }
                }
            }
        }
        self.coarse.solve_in_place(&mut rc);
        for ((zp, parents), fixed) in z.iter_mut().zip(self.par).zip(self.fixed) {
            if *fixed {
                continue;
            }
            for &(a, w) in parents {
                if let Some(d) = self.cdofs.dof(a) {
                    *zp += Vector3::new(rc[d], rc[d + 1], rc[d + 2]) * w;
                }
            }
        }
        self.smooth(r, z, &mut tmp);
    }
}

fn dot(a: &Vecs, b: &Vecs) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(y)).sum()
}

/// PCG on H x = b from 0; the iterations at which the relative residual first falls below each
/// of `forcing`, and the wall time to the last.
fn pcg(tg: &mut TwoGrid<'_>, b: &Vecs, forcing: &[f64], max: usize) -> (Vec<Option<usize>>, f64) {
    let start = Instant::now();
    let n = b.len();
    let mut x = vec![Vector3::zeros(); n];
    let mut r = b.clone();
    let mut z = vec![Vector3::zeros(); n];
    tg.precondition(&r, &mut z);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let bn = dot(b, b).sqrt();
    let mut hit = vec![None; forcing.len()];
    let mut ap = vec![Vector3::zeros(); n];
    for it in 1..=max {
        apply(tg.h, tg.fixed, &p, &mut ap);
        let alpha = rz / dot(&p, &ap);
        for k in 0..n {
            x[k] += p[k] * alpha;
            r[k] -= ap[k] * alpha;
        }
        let rel = dot(&r, &r).sqrt() / bn;
        for (h, f) in hit.iter_mut().zip(forcing) {
            if h.is_none() && rel <= *f {
                *h = Some(it);
            }
        }
        if hit.iter().all(Option::is_some) {
            break;
        }
        tg.precondition(&r, &mut z);
        let rz_new = dot(&r, &z);
        for k in 0..n {
            p[k] = z[k] + p[k] * (rz_new / rz);
        }
        rz = rz_new;
    }
    (hit, start.elapsed().as_secs_f64())
}

/// The fine system (Hessian, fixed particles, interpolation, right-hand side).
type FineSystem<'a> = (
    &'a HessianBlocks,
    &'a [bool],
    &'a [Vec<(usize, f64)>],
    &'a Vecs,
);

/// Factorizes the coarse operator `ch` (fixed coarse particles `cfixed`) and prints its cost and
/// the two-grid PCG's iterations on the fine system at two smoothing weights.
fn compare(
    name: &str,
    note: &str,
    (ch, cfixed): (&HessianBlocks, &[bool]),
    (h, fixed, par, b): FineSystem<'_>,
    (dinv, nu): (&[Matrix3<f64>], usize),
) {
    let (cspd, _, ok, first, again) = timed_factor(ch, cfixed);
    println!(
        "{name} coarse operator: {} blocks pushed{note}, factorized {ok} in {first:.3} s with its analysis, {again:.3} s numeric again, {} factor non-zeros",
        ch.pairs.len(),
        cspd.factor_nonzeros()
    );
    for omega in [0.5, 0.7] {
        let mut tg = TwoGrid {
            h,
            fixed,
            dinv: dinv.to_vec(),
            par,
            coarse: cspd.copy(),
            cdofs: DofMap::new(cfixed),
            nu,
            omega,
        };
        let forcing = [1e-1, 1e-2, 1e-4, 1e-6];
        let (hit, secs) = pcg(&mut tg, b, &forcing, 400);
        println!(
            "  two-grid PCG (ν = {nu}, ω = {omega}): iterations to relative residual {forcing:?}: {hit:?}, {secs:.2} s"
        );
    }
}

/// The projected Hessian of `model` at `x` and the Newton right-hand side −g (zero on fixed
/// particles).
fn projected_system(model: &Model, x: &Vecs) -> (HessianBlocks, Vecs) {
    let mut h = HessianBlocks::default();
    model.hessian(x, &mut h, HessianMode::Projected);
    let mut g = Vec::new();
    model.gradient(x, 1.0, &mut g);
    let b = (0..x.len())
        .map(|p| match model.fixed[p] {
            true => Vector3::zeros(),
            false => -g[p],
        })
        .collect();
    (h, b)
}

/// `h` over the particles `fixed` leaves free, factorized as Newton does: the factor, its
/// unknowns, whether it is positive definite, and the seconds of the first factorization (with its
/// analysis) and of the numeric one again.
fn timed_factor(h: &HessianBlocks, fixed: &[bool]) -> (SparseSpd, usize, bool, f64, f64) {
    let dofs = DofMap::new(fixed);
    let mut spd = SparseSpd::new();
    let t = Instant::now();
    let ok = spd.factorize(&dofs, h, &vec![0.0; dofs.n]);
    let first = t.elapsed().as_secs_f64();
    let t = Instant::now();
    spd.refactorize(&vec![0.0; dofs.n]);
    (spd, dofs.n, ok, first, t.elapsed().as_secs_f64())
}

/// Prints what the factorization Newton takes of `h` costs: analysis and numeric factorization,
/// then the numeric factorization again.
fn time_factorization(n: usize, h: &HessianBlocks, fixed: &[bool]) {
    let (spd, unknowns, ok, first, numeric) = timed_factor(h, fixed);
    println!(
        "fine {n}²: {unknowns} unknowns; factorized {ok} in {first:.3} s with its analysis, {numeric:.3} s numeric again; factor non-zeros {}",
        spd.factor_nonzeros()
    );
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(path), Some(n)) = (args.first(), args.get(1)) else {
        anyhow::bail!("usage: two_grid SCENE.toml N [nu]");
    };
    let n: usize = n.parse()?;
    let nu: usize = args.get(2).map_or(Ok(2), |s| s.parse())?;
    let size = toml::Value::Integer(n as i64);
    let sets = [
        ("cloth.nx".to_string(), size.clone()),
        ("cloth.ny".to_string(), size),
    ];
    let fine = Scene::load(std::path::Path::new(path), &sets)?.scene;
    let coarse_scene = fine.regridded(n.div_ceil(2), n.div_ceil(2));
    let t = Instant::now();
    let coarse = solve_scene(&coarse_scene, &mut drapelab_core::solve::NoObserver);
    println!(
        "coarse {}²: {:?} in {:.1} s",
        n.div_ceil(2),
        coarse.report.status,
        t.elapsed().as_secs_f64()
    );
    let built = drapelab_core::build::build_scene(&fine);
    let model: Model = built.model;
    let mut x = built.x0.clone();
    let cnx = coarse.grid.nx;
    let par = parents(n, n, cnx);
    for (p, w) in par.iter().enumerate() {
        if !model.fixed[p] {
            x[p] = w.iter().map(|&(c, wc)| coarse.x[c] * wc).sum();
        }
    }
    let (h, b) = projected_system(&model, &x);
    time_factorization(n, &h, &model.fixed);
    // (b) Two grids: the coarse operator Galerkin's (Pᵀ H P) or the coarse model's Hessian at the
    // fine state's coarse points (rediscretized).
    let dinv: Vec<Matrix3<f64>> = h
        .diagonal(x.len())
        .iter()
        .map(|d| d.try_inverse().unwrap_or_else(Matrix3::zeros))
        .collect();
    let nc = coarse.grid.len();
    let t = Instant::now();
    let galerkin_h = galerkin(&h, &par, &model.fixed);
    let assembled = t.elapsed().as_secs_f64();
    let mut xc = coarse.x.clone();
    for j in 0..coarse.grid.ny {
        for i in 0..cnx {
            xc[j * cnx + i] = x[2 * j * n + 2 * i];
        }
    }
    let mut rediscretized = HessianBlocks::default();
    coarse
        .model
        .hessian(&xc, &mut rediscretized, HessianMode::Projected);
    let open = vec![false; nc];
    let options: [(&str, &HessianBlocks, &[bool]); 2] = [
        ("Galerkin", &galerkin_h, &open),
        ("rediscretized", &rediscretized, &coarse.model.fixed),
    ];
    let fine_system: FineSystem = (&h, &model.fixed, &par, &b);
    for (name, ch, cfixed) in options {
        let note = match name == "Galerkin" {
            true => format!(" (assembled in {assembled:.3} s)"),
            false => String::new(),
        };
        compare(name, &note, (ch, cfixed), fine_system, (&dinv, nu));
    }
    Ok(())
}
