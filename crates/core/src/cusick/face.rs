//! The two faces of a specimen (issue 51). ISO 9073-9 and BS 5058 drape every specimen face up and
//! face down, and the faces of one specimen differ by up to ~12 DC points with a sign that is the
//! fabric's own: a natural curl ([`crate::physics::hinge_curl`]) lifts the rim on the side it curls
//! to and lowers it turned over. Laid face up a fabric curling toward its face by κ has
//! `curl_per_m` = κ; face down, −κ.
//!
//! The curl is fitted to the calibration specimen's face gap Δ = DC_down − DC_up after its
//! bending length (the faces' mean DC is the curl-free DC to second order in κ, so c is fitted as
//! before): the seed-0 drape at κ = 0 and its sensitivity dx/dκ give the gap's slope
//! Δ'(0) = [DC(x₀ − δ dx/dκ) − DC(x₀ + δ dx/dκ)]/δ — no solve per trial κ — and κ = Δ/Δ'; the faces
//! at ±κ are then solved, continued from x₀ ± κ dx/dκ, and κ corrected by a secant on the solved
//! gap until it is within [`GAP_TOL_PCT`].

use super::drape::{DiscMesh, DrapeParams, drape_model, solve_drape_from};
use super::{SpecimenParameters, Tester, mesh_projection, shadow_measures};
use crate::sensitivity::Equilibrium;
use crate::solve::NoObserver;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The face a specimen lies on in a capture (the `face` column of the Cusick tables).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Face {
    /// Face up.
    Up,
    /// Face down.
    Down,
    /// Not given by the dataset's index: predicted as the average of both faces.
    Unknown,
}

impl Face {
    /// The face a dataset's index writes: "up", "down", anything else unknown.
    pub fn of(label: &str) -> Face {
        match label {
            "up" => Face::Up,
            "down" => Face::Down,
            _ => Face::Unknown,
        }
    }

    /// The sign with which a face gap Δ = DC_down − DC_up shifts this face's DC from the faces'
    /// mean: −1 up, +1 down, 0 unknown (the face average).
    pub fn gap_sign(self) -> f64 {
        match self {
            Face::Up => -1.0,
            Face::Down => 1.0,
            Face::Unknown => 0.0,
        }
    }
}

/// What the calibration specimen's two faces show.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FaceGap {
    /// Mean DC of its face-down captures less that of its face-up ones, points.
    pub gap_pct: f64,
    /// Standard error of that difference, points.
    pub gap_se_pct: f64,
}

/// A fitted curl.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CurlFit {
    /// The curvature a free strip rolls up to toward the fabric's face, 1/m (negative: toward its
    /// back). Face up the drape has `curl_per_m` = this, face down its negative.
    pub curl_per_m: f64,
    /// 2σ interval of the curl from the gap's standard error over the gap's slope, 1/m.
    pub interval_per_m: [f64; 2],
    /// The slope of the face gap in the curl, dΔ/dκ, points per (1/m), from the last secant.
    pub gap_slope_pct_m: f64,
    /// The face gap of the solved drapes at ±curl (seed 0), points.
    pub gap_solved_pct: f64,
    /// Whether the gap pins the curl's side: its 2σ interval excludes zero and the curl stays
    /// inside [`MAX_CURL_PER_M`] (at the bound the drape cannot reach the gap by curling).
    pub identifiable: bool,
    /// Whether the curl stopped at [`MAX_CURL_PER_M`].
    pub at_bound: bool,
    /// Drape solves made.
    pub solves: usize,
}

/// The solved gap is accepted within this of the target, points.
pub const GAP_TOL_PCT: f64 = 0.3;

/// Secant corrections of the curl after the tangent's first guess, at most.
const MAX_SECANTS: usize = 3;

/// The largest curl fitted, 1/m (a free strip rolled to a 5 mm radius).
pub const MAX_CURL_PER_M: f64 = 200.0;

/// The curl step of the tangent's slope, 1/m (a 10 cm roll: the gap is linear in κ well beyond,
/// tests/it/cusick.rs).
const SLOPE_STEP_PER_M: f64 = 10.0;

/// Fits the curl of a fabric of parameters `p` (its fitted bending length and law; seed and curl
/// are set here) to the face gap `target`. Err names what did not converge.
pub fn fit_curl(
    mesh: DiscMesh<'_>,
    p: &DrapeParams,
    tester: &Tester,
    target: &FaceGap,
) -> Result<CurlFit, String> {
    let flat = DrapeParams {
        curl_per_m: Some(0.0),
        seed: 0,
        ..p.clone()
    };
    let dc =
        |x: &[Vector3<f64>]| shadow_measures(&mesh_projection(x, mesh.triangles), tester).dc_pct;
    let (x0, t) = curl_free_tangent(mesh, &flat, tester)?;
    let along =
        |k: f64| -> Vec<Vector3<f64>> { x0.iter().zip(&t).map(|(x, t)| x + t * k).collect() };
    let mut slope =
        (dc(&along(-SLOPE_STEP_PER_M)) - dc(&along(SLOPE_STEP_PER_M))) / SLOPE_STEP_PER_M;
    let mut fit = CurlFit {
        curl_per_m: 0.0,
        interval_per_m: [0.0; 2],
        gap_slope_pct_m: slope,
        gap_solved_pct: 0.0,
        identifiable: false,
        at_bound: false,
        solves: 1,
    };
    if slope.abs() < 1e-6 {
        return Err("the drape's DC does not move with the curl".into());
    }
    if (target.gap_pct / slope).abs() > MAX_CURL_PER_M {
        return Err(format!(
            "the drape's DC moves {slope:.3} points per 1/m of curl: a gap of {:.1} points needs a curl beyond {MAX_CURL_PER_M} /m",
            target.gap_pct
        ));
    }
    let mut kappa = target.gap_pct / slope;
    let mut solves = 0;
    for _ in 0..=MAX_SECANTS {
        // From the tangent's prediction; from the cone where that does not converge.
        let mut face = |k: f64| {
            let q = DrapeParams {
                curl_per_m: Some(k),
                ..flat.clone()
            };
            let mut solve = |start: Option<&[Vector3<f64>]>| {
                solves += 1;
                let (r, x, _) = solve_drape_from(mesh, &q, tester, start, &mut NoObserver);
                r.is_converged().then(|| dc(&x))
            };
            solve(Some(&along(k))).or_else(|| solve(None))
        };
        let (up, down) = (face(kappa), face(-kappa));
        let (Some(up), Some(down)) = (up, down) else {
            return Err(format!("a face at curl {kappa:.1} /m did not converge"));
        };
        fit.curl_per_m = kappa;
        fit.gap_solved_pct = down - up;
        if (fit.gap_solved_pct - target.gap_pct).abs() <= GAP_TOL_PCT || kappa == 0.0 {
            break;
        }
        // The secant through the origin (the gap is odd in κ).
        if (fit.gap_solved_pct / kappa).abs() > 1e-6 {
            slope = fit.gap_solved_pct / kappa;
        }
        kappa = (target.gap_pct / slope).clamp(-MAX_CURL_PER_M, MAX_CURL_PER_M);
    }
    fit.solves += solves;
    let half = 2.0 * target.gap_se_pct / slope.abs();
    fit.gap_slope_pct_m = slope;
    fit.interval_per_m = [fit.curl_per_m - half, fit.curl_per_m + half];
    fit.at_bound = fit.curl_per_m.abs() >= MAX_CURL_PER_M;
    fit.identifiable = fit.curl_per_m.abs() > half && !fit.at_bound;
    Ok(fit)
}

/// Particle positions or displacements, m.
type Positions = Vec<Vector3<f64>>;

/// The curl-free drape of `flat` and its tangent dx/dκ in the curl (from the factor of its exact
/// Hessian): where a curled face's solve starts.
fn curl_free_tangent(
    mesh: DiscMesh<'_>,
    flat: &DrapeParams,
    tester: &Tester,
) -> Result<(Positions, Positions), String> {
    let (report, x0, with_self) = solve_drape_from(mesh, flat, tester, None, &mut NoObserver);
    if !report.is_converged() {
        return Err(format!(
            "the curl-free drape did not converge ({})",
            report.message
        ));
    }
    let solved = DrapeParams {
        self_thickness_m: flat.self_thickness_m.filter(|_| with_self),
        ..flat.clone()
    };
    let model = drape_model(mesh, &solved, tester);
    let specimen = SpecimenParameters {
        mesh,
        params: solved.clone(),
        tester,
    };
    let mut eq = Equilibrium::of(Box::new(specimen), &model, &x0, &report)
        .map_err(|e| format!("no sensitivity at the curl-free drape: {e}"))?;
    let t = eq
        .sensitivity("curl_per_m")
        .map_err(|e| format!("no sensitivity to the curl: {e}"))?
        .dx;
    drop(eq);
    Ok((x0, t))
}
