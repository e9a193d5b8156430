//! A simulated drape continued in its bending length (issue 47): the bending-length search of a
//! fabric solves the drape of one seed at a sequence of c, and each solve after the first starts
//! from the last converged drape moved along its tangent, x*(c₀) + (dx*/dc)(c − c₀), which is within
//! O((c − c₀)²) of the answer when the folds stay as they are — a few Newton iterations instead of
//! the fall from the cone. The tangent is the drape's sensitivity to `bending_length_m`
//! ([`crate::sensitivity::Equilibrium`] over [`super::SpecimenParameters`]), from one factor of the
//! exact Hessian. The search then follows one fold pattern (the first solve's) through c, so DC(c)
//! is smooth along it.

use super::drape::{DiscMesh, DrapeParams, drape_model, solve_drape_from};
use super::{SpecimenParameters, Tester, mesh_projection, shadow_measures};
use crate::sensitivity::Equilibrium;
use crate::solve::{NoObserver, SolveReport};
use nalgebra::Vector3;

/// The last converged drape of a continuation and its tangent in c.
#[derive(Debug, Clone)]
pub struct DrapeBranch {
    /// Bending length it was solved at, m.
    pub bending_length_m: f64,
    /// Its positions, m.
    pub x: Vec<Vector3<f64>>,
    /// dx*/dc, m per m of bending length; none where the equilibrium has no sensitivity (a
    /// Hessian that is not positive definite there).
    pub dx_dc: Option<Vec<Vector3<f64>>>,
}

impl DrapeBranch {
    /// The start of a solve at bending length `c`: the drape moved along its tangent (as it is
    /// where there is none).
    pub fn predict(&self, c: f64) -> Vec<Vector3<f64>> {
        let dc = c - self.bending_length_m;
        match &self.dx_dc {
            Some(t) => self.x.iter().zip(t).map(|(x, t)| x + t * dc).collect(),
            None => self.x.clone(),
        }
    }
}

/// The drape of `p` solved from `from`'s prediction at `p.bending_length_m` (from the cone where
/// `from` is none): (report, DC in %, the new branch with its tangent). The branch is none unless
/// the solve converged.
pub fn continue_drape(
    mesh: DiscMesh<'_>,
    p: &DrapeParams,
    tester: &Tester,
    from: Option<&DrapeBranch>,
) -> (SolveReport, f64, Option<DrapeBranch>) {
    let start = from.map(|b| b.predict(p.bending_length_m));
    let (report, x, with_self) =
        solve_drape_from(mesh, p, tester, start.as_deref(), &mut NoObserver);
    if !report.is_converged() {
        return (report, f64::NAN, None);
    }
    let dc = shadow_measures(&mesh_projection(&x, mesh.triangles), tester).dc_pct;
    // The tangent of the model that was solved (without self-contact when the folds stayed apart).
    let solved = DrapeParams {
        self_thickness_m: p.self_thickness_m.filter(|_| with_self),
        ..p.clone()
    };
    let dx_dc = bending_length_tangent(mesh, &solved, tester, &x, &report);
    let branch = DrapeBranch {
        bending_length_m: p.bending_length_m,
        x,
        dx_dc,
    };
    (report, dc, Some(branch))
}

/// dx*/dc of the converged drape `x` of the model `p` describes.
pub fn bending_length_tangent(
    mesh: DiscMesh<'_>,
    p: &DrapeParams,
    tester: &Tester,
    x: &[Vector3<f64>],
    report: &SolveReport,
) -> Option<Vec<Vector3<f64>>> {
    let model = drape_model(mesh, p, tester);
    let params = SpecimenParameters {
        mesh,
        params: p.clone(),
        tester,
    };
    let mut eq = Equilibrium::of(Box::new(params), &model, x, report).ok()?;
    eq.sensitivity("bending_length_m").ok().map(|s| s.dx)
}

/// Largest move in ln c a drape is continued over (10 %); a search step beyond solves from the
/// cone. Near the answer a secant moves by a few per cent, where the last drape's folds stay; a
/// farther move can pass a fold's snap (on a 20-ring disc, seed 3, 22 → 23 mm snapped: the
/// continued drape moved 2 cm and took as many iterations as the cone).
pub const MAX_CONTINUATION_LN: f64 = 0.1;

/// The drapes of one seed solved at a sequence of bending lengths (a bending-length search), each
/// continued from the nearest earlier one within [`MAX_CONTINUATION_LN`] of it, from the cone
/// beyond.
#[derive(Debug, Clone, Default)]
pub struct Continuation {
    branches: Vec<DrapeBranch>,
    /// Solves made.
    pub solves: usize,
    /// Of those, the ones from the cone.
    pub from_cone: usize,
}

impl Continuation {
    /// The DC (%) of the drape of `p` (its seed, at its bending length), continued from the
    /// nearest earlier drape. Err when it does not converge.
    pub fn dc(
        &mut self,
        mesh: DiscMesh<'_>,
        p: &DrapeParams,
        tester: &Tester,
    ) -> Result<f64, String> {
        let c = p.bending_length_m;
        let gap = |b: &DrapeBranch| (b.bending_length_m / c).ln().abs();
        let from = self
            .branches
            .iter()
            .filter(|b| gap(b) <= MAX_CONTINUATION_LN)
            .min_by(|a, b| gap(a).total_cmp(&gap(b)));
        self.solves += 1;
        self.from_cone += usize::from(from.is_none());
        let (report, dc, branch) = continue_drape(mesh, p, tester, from);
        let branch = branch.ok_or_else(|| {
            format!(
                "the drape at c = {c:.4} m did not converge ({})",
                report.message
            )
        })?;
        self.branches.push(branch);
        Ok(dc)
    }

    /// Keeps only the drape nearest `c` (a search of another bending law starts from it).
    pub fn keep_nearest(&mut self, c: f64) {
        let gap = |b: &DrapeBranch| (b.bending_length_m / c).ln().abs();
        if let Some(k) = (0..self.branches.len())
            .min_by(|&a, &b| gap(&self.branches[a]).total_cmp(&gap(&self.branches[b])))
        {
            self.branches.swap(0, k);
            self.branches.truncate(1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::polar_disc;
    use super::*;

    fn distance(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_drape_continued_along_its_tangent_starts_near_its_answer_and_settles_in_a_few_steps() {
        let (rest, tris) = polar_disc(0.15, 20);
        let mesh = DiscMesh {
            rest_xy: &rest,
            triangles: &tris,
        };
        let t = Tester::default();
        let p = DrapeParams {
            bending_length_m: 0.022,
            seed: 3,
            ..DrapeParams::default()
        };
        let (cone, _, branch) = continue_drape(mesh, &p, &t, None);
        let branch = branch.expect("converged");
        assert!(branch.dx_dc.is_some(), "the drape has a tangent");
        // Steps of 0.1 % and 1 % of c: the tangent's start is off by O(Δc²) (a hundredfold for a
        // tenfold step; a first-order start would be off tenfold), and Newton needs a few steps.
        let mut off = Vec::new();
        for c in [0.02202, 0.0222] {
            let q = DrapeParams {
                bending_length_m: c,
                ..p.clone()
            };
            let (report, _, next) = continue_drape(mesh, &q, &t, Some(&branch));
            let next = next.expect("converged");
            let tangent = distance(&branch.predict(c), &next.x);
            let plain = distance(&branch.x, &next.x);
            eprintln!(
                "c = {c} m: the start off by {tangent:.2e} m along the tangent, {plain:.2e} m as it \
                 was; {} iterations against {} from the cone",
                report.iterations, cone.iterations
            );
            assert!(tangent < 0.05 * plain, "{tangent} against {plain}");
            assert!(3 * report.iterations < cone.iterations);
            off.push(tangent);
        }
        assert!(off[1] > 30.0 * off[0], "{off:?}");
    }
}
