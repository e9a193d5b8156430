//! Frictionless rigid contact by a smooth barrier (in the manner of incremental potential contact): for a
//! particle at distance d from an obstacle, E = κ b(d) with b(d) = −(d − d̂)² ln(d/d̂) for 0 < d < d̂ and
//! 0 beyond. The energy grows without bound as d → 0, so a line search that keeps the energy finite
//! keeps every particle outside every obstacle, in any direction; [`super::StepBound::max_step`] caps each
//! step so that no particle closes more than 90 % of its gap, counting its approach along the normal;
//! the infinite energy inside an obstacle
//! makes the line search reject any step that would still end inside.

use super::barrier::{barrier, barrier_band_derivatives};
use super::{EnergyTerm, HessianBlocks, HessianMode, StepBound, Vecs};
use crate::obstacle::{BarrierPiece, Obstacle};
use nalgebra::{Matrix3, Vector3};

/// Barrier contact between the free particles and the obstacles.
pub struct ObstacleBarrier {
    /// The obstacles.
    pub obstacles: Vec<Obstacle>,
    /// Activation distance d̂, m.
    pub d_hat_m: f64,
    /// Per particle: κ (J), zero for fixed particles.
    pub kappa_J: Vec<f64>,
}

/// The change of a particle's gap (relative to the gap) that an obstacle's difference in its shape
/// parameters makes: the Richardson-extrapolated central difference's error is O(10⁻⁸) of the
/// barrier's force, its round-off 10⁻¹⁶ |x|/(10⁻² d).
const SHAPE_STEP_REL: f64 = 1e-2;

/// The relative disagreement of a shape difference's two steps beyond which a kink lies between
/// them (a smooth gap's two central differences differ by O(h²), ~10⁻⁴ of the derivative).
const KINK_AGREEMENT: f64 = 1e-2;

/// Times a shape difference's step shrinks (by 64) looking for two steps that agree.
const KINK_RETRIES: usize = 4;

impl ObstacleBarrier {
    /// κ for a particle of weight `w` (N): the barrier's force reaches w at d ≈ d̂/10, so resting
    /// particles sit well inside the activation band and well away from the surface.
    pub fn kappa_for_weight(w: f64, d_hat: f64) -> f64 {
        let (_, db, _) = barrier(0.1 * d_hat, d_hat);
        w / -db
    }

    /// Barrier contact of `obstacles` for particles of `masses` (kg), each free one with the κ of
    /// its weight under gravity `g` (m/s²) ([`Self::kappa_for_weight`]), fixed ones with none.
    pub fn for_particles(
        obstacles: Vec<Obstacle>,
        d_hat_m: f64,
        masses: &[f64],
        fixed: &[bool],
        g_m_per_s2: f64,
    ) -> Self {
        let kappa_J = masses
            .iter()
            .zip(fixed)
            .map(|(m, &f)| {
                if f || *m <= 0.0 {
                    0.0
                } else {
                    Self::kappa_for_weight(m * g_m_per_s2, d_hat_m)
                }
            })
            .collect();
        ObstacleBarrier {
            obstacles,
            d_hat_m,
            kappa_J,
        }
    }

    /// Calls `f(p, piece, o)` for every share of every obstacle's barrier on every particle with
    /// κ ([`Obstacle::barrier_pieces`]: a mesh body's faces, edges and vertices within d̂, weighted
    /// ±1, or the closest point).
    fn each(&self, x: &Vecs, mut f: impl FnMut(usize, &BarrierPiece, &Obstacle)) {
        for (p, xp) in x.iter().enumerate() {
            let k = self.kappa_J.get(p).copied().unwrap_or(0.0);
            if k == 0.0 {
                continue;
            }
            for o in &self.obstacles {
                for piece in o.barrier_pieces(xp, self.d_hat_m) {
                    f(p, &piece, o);
                }
            }
        }
    }
}

impl EnergyTerm for ObstacleBarrier {
    fn name(&self) -> String {
        "contact/barrier".into()
    }
    fn energy(&self, x: &Vecs) -> f64 {
        let mut e = 0.0;
        self.each(x, |p, &(d, _, _, w), _| {
            e += w * self.kappa_J[p] * barrier(d, self.d_hat_m).0
        });
        e
    }
    fn add_gradient(&self, x: &Vecs, g: &mut Vecs) {
        self.each(x, |p, &(d, n, _, w), _| {
            g[p] += n * (w * self.kappa_J[p] * barrier(d, self.d_hat_m).1);
        });
    }
    fn add_hessian(&self, x: &Vecs, h: &mut HessianBlocks, mode: HessianMode) {
        let project = mode.is_projected();
        // Every particle gets a diagonal block (zero when out of range) so the pattern never changes.
        let mut diag = vec![Matrix3::zeros(); x.len()];
        self.each(x, |p, piece, o| {
            diag[p] += self.particle_block(p, &x[p], piece, o, !project);
        });
        for (p, b) in diag.into_iter().enumerate() {
            if self.kappa_J.get(p).copied().unwrap_or(0.0) != 0.0 {
                // A mesh body's edges weigh −1: their sum may be indefinite, so the projected
                // Hessian clamps it to its positive part.
                h.push(p, p, if project { positive_part(b) } else { b });
            }
        }
    }
    fn step_bound(&self) -> Option<&dyn StepBound> {
        Some(self)
    }
    fn stiffness_scale(&self) -> f64 {
        0.0
    }
    /// κ of every particle (J), d̂ (m), then each obstacle's shape parameters (m; its directions
    /// unitless): the contact stiffness, distance and obstacle keys of a scene move these.
    fn coefficients(&self) -> Vec<f64> {
        let mut c = self.kappa_J.clone();
        c.push(self.d_hat_m);
        c.extend(self.obstacles.iter().flat_map(|o| o.parameters()));
        c
    }
    fn set_coefficients(&mut self, c: &[f64]) {
        let n = self.kappa_J.len();
        self.kappa_J.copy_from_slice(&c[..n]);
        self.d_hat_m = c[n];
        let mut at = n + 1;
        for o in &mut self.obstacles {
            let k = o.parameters().len();
            o.set_parameters(&c[at..at + k]);
            at += k;
        }
    }
    /// κ and d̂ analytically (∂b′/∂d̂, [`barrier_band_derivatives`]); an obstacle's shape by a central
    /// difference of each particle's barrier force ([`Self::shape_difference`]).
    fn add_coefficient_gradient(&self, x: &Vecs, dc: &[f64], g: &mut Vecs) -> bool {
        let n = self.kappa_J.len();
        if dc.len() != self.coefficient_count() {
            return false;
        }
        self.each(x, |p, &(d, nrm, _, w), _| {
            let db = barrier(d, self.d_hat_m).1;
            let ddb = barrier_band_derivatives(d, self.d_hat_m).1;
            g[p] += nrm * (w * (dc[p] * db + self.kappa_J[p] * ddb * dc[n]));
        });
        self.shape_difference(x, &dc[n + 1..], |p, _, dg| g[p] += dg);
        true
    }
    fn coefficient_energy(&self, x: &Vecs, dc: &[f64]) -> Option<f64> {
        let n = self.kappa_J.len();
        if dc.len() != self.coefficient_count() {
            return None;
        }
        let mut e = 0.0;
        self.each(x, |p, &(d, _, _, w), _| {
            let b = barrier(d, self.d_hat_m).0;
            let db_dh = barrier_band_derivatives(d, self.d_hat_m).0;
            e += w * (dc[p] * b + self.kappa_J[p] * db_dh * dc[n]);
        });
        self.shape_difference(x, &dc[n + 1..], |_, de, _| e += de);
        Some(e)
    }
}

impl StepBound for ObstacleBarrier {
    fn max_step(&self, x: &Vecs, dx: &Vecs) -> f64 {
        let mut alpha = f64::INFINITY;
        for (p, xp) in x.iter().enumerate() {
            if self.kappa_J.get(p).copied().unwrap_or(0.0) == 0.0 {
                continue;
            }
            let len = dx[p].norm();
            if len == 0.0 {
                continue;
            }
            for o in &self.obstacles {
                alpha = alpha.min(gap_bound(o, xp, &dx[p]));
            }
        }
        alpha
    }
}

impl ObstacleBarrier {
    /// The number of coefficients: κ per particle, d̂, then each obstacle's shape parameters.
    fn coefficient_count(&self) -> usize {
        self.kappa_J.len()
            + 1
            + self
                .obstacles
                .iter()
                .map(|o| o.parameters().len())
                .sum::<usize>()
    }

    /// The barrier's Hessian block of particle `p` at `xp` from one share `piece` of obstacle `o`:
    /// κ b″ n nᵀ, plus with `curvature` κ b′ ∂n/∂x (the distance's curvature: the piece's own
    /// where known, else finite differences of the normal; b′ < 0, so it is left out of the
    /// projected Hessian).
    fn particle_block(
        &self,
        p: usize,
        xp: &Vector3<f64>,
        &(d, n, dn, w): &BarrierPiece,
        o: &Obstacle,
        curvature: bool,
    ) -> Matrix3<f64> {
        let (_, db, d2b) = barrier(d, self.d_hat_m);
        let k = w * self.kappa_J[p];
        let mut b = n * n.transpose() * (k * d2b);
        if curvature {
            let dn = dn.unwrap_or_else(|| self.normal_derivative(xp, n, o));
            b += dn * (k * db);
        }
        b
    }

    /// ∂n/∂x at `xp` (normal `n` of obstacle `o`), symmetrized: finite differences of the normal,
    /// forward for the analytic shapes (their paths are validated so), central for a mesh body,
    /// whose edge and vertex regions curve as 1/d (a forward step's error would be 10⁻⁴ of it at
    /// d = 1 mm).
    fn normal_derivative(&self, xp: &Vector3<f64>, n: Vector3<f64>, o: &Obstacle) -> Matrix3<f64> {
        let eps = 1e-7;
        let normal = |q: Vector3<f64>| match o.signed_distance_within(&q, 2.0 * self.d_hat_m) {
            Some((_, n2)) => n2,
            None => o.signed_distance(&q).1,
        };
        let central = matches!(o, Obstacle::Mesh { .. });
        let mut dn = Matrix3::zeros();
        for c in 0..3 {
            let step = Vector3::ith(c, eps);
            let column = match central {
                true => (normal(xp + step) - normal(xp - step)) / (2.0 * eps),
                false => (normal(xp + step) - n) / eps,
            };
            dn.set_column(c, &column);
        }
        (dn + dn.transpose()) * 0.5
    }

    /// [`Self::shape_difference`] for a mesh body, exactly: its shape parameters are its offset,
    /// d(x; o) = d_body(x − o), so a move δo changes each particle's energy by −g·δo and its
    /// gradient by −H δo (the particle's own gradient and Hessian block).
    fn mesh_shift(
        &self,
        x: &Vecs,
        o: &Obstacle,
        dco: &[f64],
        f: &mut impl FnMut(usize, f64, Vector3<f64>),
    ) {
        let shift = Vector3::new(dco[0], dco[1], dco[2]);
        for (p, xp) in x.iter().enumerate() {
            if self.kappa_J[p] == 0.0 {
                continue;
            }
            for piece in o.barrier_pieces(xp, self.d_hat_m) {
                let (d, n, _, w) = piece;
                if d <= 0.0 {
                    continue;
                }
                let g = n * (w * self.kappa_J[p] * barrier(d, self.d_hat_m).1);
                let h = self.particle_block(p, xp, &piece, o, true);
                f(p, -g.dot(&shift), -(h * shift));
            }
        }
    }

    /// The barrier's gradient on particle `p` at `xp` from obstacle `o` alone, N.
    fn particle_gradient(&self, p: usize, o: &Obstacle, xp: &Vector3<f64>) -> (f64, Vector3<f64>) {
        let k = self.kappa_J[p];
        if k == 0.0 {
            return (0.0, Vector3::zeros());
        }
        o.barrier_pieces(xp, self.d_hat_m).iter().fold(
            (0.0, Vector3::zeros()),
            |(e, g), &(d, n, _, w)| {
                let (b, db, _) = barrier(d, self.d_hat_m);
                (e + w * k * b, g + n * (w * k * db))
            },
        )
    }

    /// The derivative of every particle's barrier energy and gradient along the obstacles' shape
    /// change `dc` (the shape part of the coefficients' change), `f(p, dE, dg)`: per particle in the
    /// band, a central difference with a shape change of 10⁻² of its gap ([`SHAPE_STEP_REL`]),
    /// Richardson-extrapolated from two steps.
    fn shape_difference(&self, x: &Vecs, dc: &[f64], mut f: impl FnMut(usize, f64, Vector3<f64>)) {
        let mut at = 0;
        for o in &self.obstacles {
            let c = o.parameters();
            let dco = &dc[at..at + c.len()];
            at += c.len();
            let size = dco.iter().map(|v| v * v).sum::<f64>().sqrt();
            if size == 0.0 {
                continue;
            }
            if let Obstacle::Mesh { .. } = o {
                self.mesh_shift(x, o, dco, &mut f);
                continue;
            }
            let reach = c.iter().map(|v| v * v).sum::<f64>().sqrt().max(1.0);
            let moved = |s: f64| {
                let mut m = o.clone();
                let v: Vec<f64> = c.iter().zip(dco).map(|(a, d)| a + s * d).collect();
                m.set_parameters(&v);
                m
            };
            for (p, xp) in x.iter().enumerate() {
                let d = o.signed_distance(xp).0;
                if self.kappa_J[p] == 0.0 || d >= self.d_hat_m || d <= 0.0 {
                    continue;
                }
                let central = |h: f64| {
                    let ((eh, gh), (el, gl)) = (
                        self.particle_gradient(p, &moved(h), xp),
                        self.particle_gradient(p, &moved(-h), xp),
                    );
                    ((eh - el) / (2.0 * h), (gh - gl) / (2.0 * h))
                };
                // The step that changes the gap by about 10⁻² of itself (a turn of a rod's axis
                // moves its surface by the particle's distance along the axis).
                let h0 = SHAPE_STEP_REL * d / (size * reach);
                let dd = (moved(h0).signed_distance(xp).0 - d).abs();
                let mut h = if dd > 0.0 {
                    h0 * (SHAPE_STEP_REL * d / dd).clamp(1e-3, 1e3)
                } else {
                    h0
                };
                // Richardson's extrapolation holds where the two steps agree; where they do not, a
                // kink of the distance (the closest feature switching, a box's face to its edge)
                // lies within the step: smaller steps until they agree (a particle on the kink
                // itself has no derivative; it keeps the smallest step's).
                let (mut e1, mut g1) = central(h);
                let (mut e2, mut g2) = central(0.5 * h);
                for _ in 0..KINK_RETRIES {
                    let gap = (g1 - g2).norm();
                    if gap <= KINK_AGREEMENT * g1.norm().max(g2.norm()) {
                        break;
                    }
                    h *= 1.0 / 64.0;
                    (e1, g1) = central(h);
                    (e2, g2) = central(0.5 * h);
                }
                f(p, (4.0 * e2 - e1) / 3.0, (g2 * 4.0 - g1) / 3.0);
            }
        }
    }
}

impl ObstacleBarrier {
    /// The contacts at `x`: (particle, outward normal, barrier force magnitude in N) for every free
    /// particle within d̂ of an obstacle.
    pub fn contacts(&self, x: &Vecs) -> Vec<(usize, Vector3<f64>, f64)> {
        // Per particle, the sum of its shares' pushes (a mesh body's are weighted ±1).
        let mut push = std::collections::BTreeMap::<usize, Vector3<f64>>::new();
        self.each(x, |p, &(d, n, _, w), _| {
            *push.entry(p).or_insert_with(Vector3::zeros) -=
                n * (w * self.kappa_J[p] * barrier(d, self.d_hat_m).1);
        });
        push.into_iter()
            .filter_map(|(p, f)| f.try_normalize(0.0).map(|n| (p, n, f.norm())))
            .collect()
    }
}

/// The largest fraction of the step `dx` that a particle at `x` may take towards obstacle `o`: its
/// approach along the outward normal covers at most 90 % of its gap d. For a convex obstacle the
/// bound is exact (the segment stays beyond the tangent plane at the closest point, which the whole
/// obstacle lies behind), so sliding along the surface is never slowed. A non-convex one (a solid of
/// revolution) may curve into the path: the bound is halved until four points along the step keep at
/// least 10 % of the gap.
///
/// A particle whose step stays inside the ball of 90 % of its gap about it cannot reach any surface
/// (the per-vertex bound of Offset Geometric Contact, Chen et al. 2025): a non-convex obstacle
/// needs no walk along such a step, and one whose surface lies beyond the step's reach needs no
/// closest-point search ([`Obstacle::signed_distance_within`]).
fn gap_bound(o: &Obstacle, x: &Vector3<f64>, dx: &Vector3<f64>) -> f64 {
    let len = dx.norm();
    let found = match o.is_convex() {
        true => Some(o.signed_distance(x)),
        false => o.signed_distance_within(x, len / 0.9 * (1.0 + 1e-9)),
    };
    let Some((d, n)) = found else {
        return 1.0;
    };
    if d <= 0.0 {
        return 0.0;
    }
    let approach = (-n.dot(dx)).max(0.0);
    let mut a = if approach > 0.0 {
        0.9 * d / approach
    } else {
        f64::INFINITY
    };
    if o.is_convex() {
        return a;
    }
    a = a.min(1.0);
    if a * len <= 0.9 * d {
        return a;
    }
    for _ in 0..60 {
        let clear =
            (1..=4).all(|k| o.signed_distance(&(x + dx * (a * k as f64 / 4.0))).0 >= 0.1 * d);
        if clear {
            return a;
        }
        a *= 0.5;
    }
    0.0
}

/// The positive part of a symmetric 3 × 3 block (its negative eigenvalues set to zero).
fn positive_part(b: Matrix3<f64>) -> Matrix3<f64> {
    let e = nalgebra::SymmetricEigen::new((b + b.transpose()) * 0.5);
    let clamped = e.eigenvalues.map(|l| l.max(0.0));
    e.eigenvectors * Matrix3::from_diagonal(&clamped) * e.eigenvectors.transpose()
}

/// The largest penetration (m) of any particle into any obstacle: max(0, −d).
pub fn max_penetration_m(obstacles: &[Obstacle], x: &Vecs) -> f64 {
    x.iter()
        .flat_map(|p| obstacles.iter().map(move |o| -o.signed_distance(p).0))
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::barrier;

    /// A mesh body's offset derivative is exact (−g·δo and −H δo): central differences of the
    /// energy and gradient with the body moved agree to 10⁻⁶, near faces, edges and vertices.
    #[test]
    fn a_mesh_bodys_offset_derivative_matches_central_differences() {
        use crate::obstacle::{Obstacle, TriangleBody};
        use crate::physics::EnergyTerm;
        use nalgebra::Vector3;
        let (v, t) = crate::obstacle::mesh::tests::icosphere(0.1, 2);
        let body = TriangleBody::new(v, t).unwrap();
        let o = Obstacle::Mesh {
            mesh: "sphere.obj".into(),
            mesh_unit_m: 1.0,
            offset_m: [0.01, -0.02, 0.03],
            body: Some(std::sync::Arc::new(body)),
        };
        let x: Vec<Vector3<f64>> = (0..40)
            .map(|k| {
                let s = k as f64;
                let u =
                    Vector3::new((s * 0.7).sin(), (s * 1.3).cos(), (s * 0.37).sin()).normalize();
                Vector3::new(0.01, -0.02, 0.03) + u * (0.1 + 0.004 * (0.2 + (s * 0.11).sin().abs()))
            })
            .collect();
        let mut term =
            super::ObstacleBarrier::for_particles(vec![o], 0.005, &[1e-3; 40], &[false; 40], 9.81);
        let c = term.coefficients();
        let mut dc = vec![0.0; c.len()];
        let n = c.len();
        dc[n - 3..].copy_from_slice(&[0.3, -0.5, 0.8]);
        let mut g = vec![Vector3::zeros(); x.len()];
        assert!(term.add_coefficient_gradient(&x, &dc, &mut g));
        let de = term.coefficient_energy(&x, &dc).unwrap();
        let h = 1e-7;
        let at = |term: &mut super::ObstacleBarrier, s: f64| {
            let moved: Vec<f64> = c.iter().zip(&dc).map(|(a, d)| a + s * d).collect();
            term.set_coefficients(&moved);
            let mut g = vec![Vector3::zeros(); x.len()];
            term.add_gradient(&x, &mut g);
            (term.energy(&x), g)
        };
        let ((ep, gp), (em, gm)) = (at(&mut term, h), at(&mut term, -h));
        let scale = g.iter().map(|v| v.norm()).fold(0.0, f64::max);
        assert!(scale > 0.0);
        for p in 0..x.len() {
            let fd = (gp[p] - gm[p]) / (2.0 * h);
            assert!(
                (fd - g[p]).norm() < 1e-5 * scale,
                "{p}: {fd} against {}",
                g[p]
            );
        }
        assert!(((ep - em) / (2.0 * h) - de).abs() < 1e-6 * de.abs(), "{de}");
    }

    /// An L-shaped prism (x, z) ∈ [0, 2]×[0, 1] ∪ [0, 1]×[0, 2], y ∈ [0, 1]: its notch is a
    /// concave crease along x = z = 1.
    fn crease_body() -> crate::obstacle::Obstacle {
        use nalgebra::Vector3;
        let l = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        let v: Vec<Vector3<f64>> = [0.0, 1.0]
            .iter()
            .flat_map(|&y| l.iter().map(move |&(x, z)| Vector3::new(x, y, z)))
            .collect();
        let mut t: Vec<[u32; 3]> = Vec::new();
        for k in 1..5u32 {
            t.push([0, k + 1, k]);
            t.push([6, 6 + k, 7 + k]);
        }
        for k in 0..6u32 {
            let j = (k + 1) % 6;
            t.push([k, j, 6 + j]);
            t.push([k, 6 + j, 6 + k]);
        }
        t.iter_mut().for_each(|tri| tri.swap(1, 2));
        let body = crate::obstacle::TriangleBody::new(v, t).unwrap();
        crate::obstacle::Obstacle::Mesh {
            mesh: "crease.obj".into(),
            mesh_unit_m: 1.0,
            offset_m: [0.0; 3],
            body: Some(std::sync::Arc::new(body)),
        }
    }

    /// In a concave crease the nearest distance switches faces across the bisector (a kink the
    /// Newton solve of a garment in an armpit stalled on, residual 8 N); the barrier summed over
    /// the faces within d̂ is smooth there: its gradient matches central differences on both
    /// sides and on the bisector, pushes out of the crease along the bisector there, and its
    /// Hessian matches central differences of the gradient.
    #[test]
    fn a_barrier_in_a_concave_crease_is_smooth_across_its_bisector() {
        use crate::physics::{EnergyTerm, HessianBlocks, HessianMode};
        use nalgebra::Vector3;
        let at = |a: f64, b: f64| vec![Vector3::new(1.0 + a, 0.5, 1.0 + b)];
        let term = super::ObstacleBarrier::for_particles(
            vec![crease_body()],
            5e-3,
            &[1e-3],
            &[false],
            9.81,
        );
        for (a, b) in [
            (1e-3, 1.5e-3),
            (1.5e-3, 1e-3),
            (1.2e-3, 1.2e-3),
            (4e-3, 0.6e-3),
        ] {
            crate::physics::tests::check_gradient_scaled(&term, &at(a, b), [0], (1e-9, 1e-5));
        }
        let mut g = vec![Vector3::zeros()];
        term.add_gradient(&at(1.2e-3, 1.2e-3), &mut g);
        assert!(
            g[0].x < 0.0 && (g[0].x - g[0].z).abs() < 1e-9 * g[0].norm(),
            "{}",
            g[0]
        );
        let x = at(1e-3, 1.4e-3);
        let mut h = HessianBlocks::default();
        term.add_hessian(&x, &mut h, HessianMode::Exact);
        let eps = 1e-9;
        let columns: Vec<(Vector3<f64>, Vector3<f64>)> = (0..3)
            .map(|c| {
                let e = vec![Vector3::ith(c, 1.0)];
                let mut he = vec![Vector3::zeros()];
                h.mul_add(&e, &mut he);
                let grad = |s: f64| {
                    let mut g = vec![Vector3::zeros()];
                    term.add_gradient(&[x[0] + e[0] * s], &mut g);
                    g[0]
                };
                ((grad(eps) - grad(-eps)) / (2.0 * eps), he[0])
            })
            .collect();
        let scale = columns.iter().map(|(_, he)| he.norm()).fold(0.0, f64::max);
        for (c, (fd, he)) in columns.iter().enumerate() {
            assert!((fd - he).norm() < 1e-4 * scale, "{c}: {fd} vs {he}");
        }
    }

    #[test]
    fn barrier_derivatives_match_finite_differences() {
        let dh = 1e-3;
        for d in [1e-5, 1e-4, 5e-4, 9e-4] {
            let (e, g, h) = barrier(d, dh);
            let eps = 1e-9;
            let (e2, g2, _) = barrier(d + eps, dh);
            assert!(((e2 - e) / eps - g).abs() < 1e-4 * g.abs().max(1e-3), "{d}");
            assert!(((g2 - g) / eps - h).abs() < 1e-3 * h.abs().max(1.0), "{d}");
        }
        for d in [1e-5, 1e-4, 5e-4, 9e-4] {
            let eps = 1e-12;
            let (e, g, _) = barrier(d, dh);
            let (e2, g2, _) = barrier(d, dh + eps);
            let (de, dg) = super::barrier_band_derivatives(d, dh);
            assert!(((e2 - e) / eps - de).abs() < 1e-4 * de.abs(), "{d}");
            assert!(((g2 - g) / eps - dg).abs() < 1e-4 * dg.abs(), "{d}");
        }
        assert_eq!(barrier(2e-3, dh), (0.0, 0.0, 0.0));
        assert!(barrier(0.0, dh).0.is_infinite());
    }
}
