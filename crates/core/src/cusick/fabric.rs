//! One fabric's calibrate → predict workflow (issue 31): what its calibration specimen shows — the
//! drape coefficient and the node count — fits the bending length c (geometric mean of warp and
//! weft) and the bending law (anisotropy B_warp/B_weft, saturation of the moment); the drapes of
//! those parameters over seeded perturbations are then the prediction for the other specimens, as
//! a distribution.
//!
//! DC pins c (DC rises with c). At a given DC the bending law moves the fold count: a stiffer
//! direction opens fewer, larger folds on stiff fabrics, and a moment that levels off at large
//! curvature (cheap sharp folds) gives fewer folds at any DC. So the node count chooses the law
//! where it tells the laws apart, and the fit says when it does not (an identifiability flag).

use super::face::{CurlFit, FaceGap, MAX_CURL_PER_M, fit_curl};
use super::{
    Continuation, DC_SLOPE_PRIOR_PCT, DiscMesh, DrapeParams, SecantSearch, Tester,
    calibrate_bending_length, mesh_projection, secant_bending_length, shadow_measures, solve_drape,
};
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// What the calibration specimen's captures show.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpecimenTargets {
    /// Mean drape coefficient of its captures, %.
    pub dc_pct: f64,
    /// Standard error of that mean, %.
    pub dc_se_pct: f64,
    /// Median node count of its captures.
    pub nodes: f64,
    /// Its face gap, where it was photographed on both faces (none: the fit is face-blind).
    pub face_gap: Option<FaceGap>,
    /// The face gap DC_down − DC_up expected of the fabric's *other* specimens, points: one
    /// specimen's gap is a noisy reading of its fabric's, so the caller may shrink it toward the
    /// population's (the app's leave-one-fabric-out gap line). The prediction's drapes lie at the
    /// curl that gives this gap; none: at the calibration specimen's own curl.
    pub predicted_face_gap_pct: Option<f64>,
}

/// One bending law a calibration tries: an anisotropy and a saturation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BendingLaw {
    /// B_warp / B_weft (1: isotropic).
    pub bending_ratio: f64,
    /// Saturation curvature in units of 1/c ([`DrapeParams::bending_saturation`]); None: linear.
    #[serde(default)]
    pub bending_saturation: Option<f64>,
}

impl BendingLaw {
    /// A law with no saturation.
    pub const fn linear(bending_ratio: f64) -> Self {
        BendingLaw {
            bending_ratio,
            bending_saturation: None,
        }
    }
    /// The drape parameters `base` with this law and bending length `c`.
    pub fn apply(&self, base: &DrapeParams, c: f64) -> DrapeParams {
        DrapeParams {
            bending_length_m: c,
            bending_ratio: self.bending_ratio,
            bending_saturation: self.bending_saturation,
            ..base.clone()
        }
    }
}

/// Settings of a fabric calibration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FabricSettings {
    /// Bending laws tried; the first (its c searched from the bracket's middle) is the simplest. Default: linear
    /// isotropic; linear with B_warp/B_weft = 2 and 4 (cantilever measurements of 618 fabrics,
    /// DrapeTester/ClothDrapeTester: 1.3–2.6 for the middle half, up to 4 for the top tenth);
    /// isotropic saturating at 2/c and 1/c. A list of one fits c alone.
    pub laws: Vec<BendingLaw>,
    /// Perturbation seeds per law whose mean node count is compared with the target.
    /// Default 6 (the mean's standard error ~0.35 node).
    pub calibration_seeds: u64,
    /// Bending lengths the search may try, m. Default [0.005, 0.06] (with the pedestal an
    /// obstacle a limp fabric cannot hang inside it: the limpest bundled fabric, DC 15 %, needs c ≈ 6 mm).
    pub bracket_m: [f64; 2],
    /// The first law's search stops when c is within half this of its root at the prior slope
    /// (|DC − target| ≤ 50 % · ln(1 + rel_tol) / 2, 0.5 points by default). Default 0.02.
    pub rel_tol: f64,
    /// DC a later law's secant search must reach, points (the first law's too, where tighter
    /// than `rel_tol`'s). Default 1.0.
    pub dc_tol_pct: f64,
}

impl Default for FabricSettings {
    fn default() -> Self {
        FabricSettings {
            laws: vec![
                BendingLaw::linear(1.0),
                BendingLaw::linear(2.0),
                BendingLaw::linear(4.0),
                BendingLaw {
                    bending_ratio: 1.0,
                    bending_saturation: Some(2.0),
                },
                BendingLaw {
                    bending_ratio: 1.0,
                    bending_saturation: Some(1.0),
                },
            ],
            calibration_seeds: 6,
            bracket_m: [0.005, 0.06],
            rel_tol: 0.02,
            dc_tol_pct: 1.0,
        }
    }
}

/// One simulated drape: its seed, DC (%), node count and vertices.
#[derive(Debug, Clone, PartialEq)]
pub struct SeededDrape {
    /// Perturbation seed.
    pub seed: u64,
    /// Drape coefficient, %.
    pub dc_pct: f64,
    /// Nodes of its shadow.
    pub nodes: usize,
    /// Its shadow's smoothed outline r(θ) in 1° sectors from +x, m.
    pub outline_m: Vec<f64>,
    /// Positions, m.
    pub x: Vec<Vector3<f64>>,
}

/// The distribution of the node count (and DC) over perturbation seeds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NodeDistribution {
    /// Seeds that converged.
    pub converged: usize,
    /// Seeds tried.
    pub tried: usize,
    /// Mean node count.
    pub nodes_mean: f64,
    /// Sample SD of the node count.
    pub nodes_sd: f64,
    /// Most frequent node count (the smaller on a tie).
    pub nodes_mode: usize,
    /// (nodes, how many seeds) for every node count seen, ascending.
    pub histogram: Vec<(usize, usize)>,
    /// Mean DC, %.
    pub dc_mean_pct: f64,
    /// Sample SD of the DC, %.
    pub dc_sd_pct: f64,
}

impl NodeDistribution {
    /// The distribution of `drapes` out of `tried` seeds (None when none converged).
    pub fn of(drapes: &[SeededDrape], tried: usize) -> Option<Self> {
        if drapes.is_empty() {
            return None;
        }
        let n = drapes.len() as f64;
        let histogram = histogram(drapes.iter().map(|d| d.nodes));
        let nodes_mean = drapes.iter().map(|d| d.nodes as f64).sum::<f64>() / n;
        let nodes_var = drapes
            .iter()
            .map(|d| (d.nodes as f64 - nodes_mean).powi(2))
            .sum::<f64>()
            / (n - 1.0).max(1.0);
        let top = histogram.iter().map(|h| h.1).max().unwrap_or(0);
        let dc_mean = drapes.iter().map(|d| d.dc_pct).sum::<f64>() / n;
        let var = drapes
            .iter()
            .map(|d| (d.dc_pct - dc_mean).powi(2))
            .sum::<f64>()
            / (n - 1.0).max(1.0);
        Some(NodeDistribution {
            converged: drapes.len(),
            tried,
            nodes_mean,
            nodes_sd: nodes_var.sqrt(),
            nodes_mode: histogram.iter().find(|h| h.1 == top).map_or(0, |h| h.0),
            histogram,
            dc_mean_pct: dc_mean,
            dc_sd_pct: var.sqrt(),
        })
    }
}

/// (value, how many times) of every value in `values`, ascending.
pub fn histogram(values: impl Iterator<Item = usize>) -> Vec<(usize, usize)> {
    let mut sorted: Vec<usize> = values.collect();
    sorted.sort_unstable();
    let mut h: Vec<(usize, usize)> = Vec::new();
    for k in sorted {
        match h.last_mut() {
            Some(last) if last.0 == k => last.1 += 1,
            _ => h.push((k, 1)),
        }
    }
    h
}

/// A histogram as "value×count" words, e.g. "6×2 7×4".
pub fn histogram_label(h: &[(usize, usize)]) -> String {
    h.iter()
        .map(|(v, k)| format!("{v}×{k}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The drapes of `p` at every seed in `seeds` (in parallel; the ones that did not converge left out).
pub fn seeded_drapes(
    mesh: DiscMesh<'_>,
    p: &DrapeParams,
    tester: &Tester,
    seeds: std::ops::Range<u64>,
) -> Vec<SeededDrape> {
    seeds
        .into_par_iter()
        .filter_map(|seed| {
            let q = DrapeParams { seed, ..p.clone() };
            let (report, x) = solve_drape(mesh, &q, tester);
            // Never numbers passed off as a result: a drape that did not converge is left out.
            report.is_converged().then(|| {
                let m = shadow_measures(&mesh_projection(&x, mesh.triangles), tester);
                SeededDrape {
                    seed,
                    dc_pct: m.dc_pct,
                    nodes: m.nodes,
                    outline_m: m.outline_m,
                    x,
                }
            })
        })
        .collect()
}

/// One bending law tried by the calibration: the bending length that gives the target DC with it,
/// and the node count of its drapes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LawCandidate {
    /// The law.
    pub law: BendingLaw,
    /// Bending length (geometric mean) whose seed-0 drape has the target DC, m.
    pub bending_length_m: f64,
    /// The calibration seeds' node distribution at that bending length.
    pub drapes: NodeDistribution,
}

/// A fabric's calibration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FabricFit {
    /// The chosen bending length c (geometric mean of warp and weft), m: where the calibration
    /// seeds' mean DC meets the target (the seed-0 root moved by one secant step).
    pub bending_length_m: f64,
    /// The bending length whose seed-0 drape meets the target, m.
    pub seed0_bending_length_m: f64,
    /// 2σ interval of c from the DC's uncertainty (delta method over dDC/d ln c), m.
    pub bending_length_interval_m: Option<[f64; 2]>,
    /// dDC/d ln c near the isotropic c, %.
    pub dc_sensitivity_pct: Option<f64>,
    /// The chosen bending law.
    pub law: BendingLaw,
    /// The laws whose mean node count lies within one node of the target (the chosen law's
    /// interval on the laws tried).
    pub laws_within_one_node: Vec<BendingLaw>,
    /// Whether the node count tells the laws apart (their mean node counts span more than one
    /// node); if not, the law is not identifiable from this specimen.
    pub law_identifiable: bool,
    /// Every law tried.
    pub candidates: Vec<LawCandidate>,
    /// Drape solves made.
    pub solves: usize,
}

/// The largest move in ln c from the seed-0 root to the seeds' mean (10 %: the continuation's
/// reach, [`super::MAX_CONTINUATION_LN`]).
pub const MAX_SEED_MEAN_LN: f64 = 0.1;

/// Calibrates a fabric on its calibration specimen: per law, c by a secant on ln c over the seed-0
/// drape continued through c ([`Continuation`]; the first law from the bracket's geometric middle,
/// each later one from the previous law's c, slope and drape); per law the mean node count over
/// `calibration_seeds` (each from the cone); the law whose mean is nearest the target node count
/// wins (ties to the earlier law), and its c is moved to where the seeds' mean DC meets the target.
/// Err names what failed.
pub fn calibrate_fabric(
    mesh: DiscMesh<'_>,
    target: &SpecimenTargets,
    base: &DrapeParams,
    tester: &Tester,
    s: &FabricSettings,
) -> Result<FabricFit, String> {
    let first = s.laws.first().ok_or("no bending law to try")?;
    let mut continuation = Continuation::default();
    let first_tol = s
        .dc_tol_pct
        .min(DC_SLOPE_PRIOR_PCT * (1.0 + s.rel_tol).ln() / 2.0);
    let cal = calibrate_bending_length(
        mesh,
        target.dc_pct,
        &first.apply(base, s.bracket_m[0]),
        tester,
        (s.bracket_m, first_tol),
        &mut continuation,
    )?;
    let slope = cal.sensitivity_pct(1.3).unwrap_or(DC_SLOPE_PRIOR_PCT);
    let (mut candidates, mut seeded) = (Vec::new(), 0);
    let mut c = cal.bending_length_m;
    for (k, law) in s.laws.iter().enumerate() {
        if k > 0 {
            // From the previous law's c and drape; a law that cannot reach the target is left out.
            continuation.keep_nearest(c);
            let search = SecantSearch {
                target_dc_pct: target.dc_pct,
                start_m: c,
                slope_pct: slope,
                bracket_m: s.bracket_m,
                dc_tol_pct: s.dc_tol_pct,
                max_solves: 7,
            };
            let dc = |c| continuation.dc(mesh, &law.apply(base, c), tester);
            match secant_bending_length(dc, &search) {
                Ok(found) => c = found.bending_length_m,
                Err(_) => continue,
            }
        }
        let drapes = seeded_drapes(mesh, &law.apply(base, c), tester, 0..s.calibration_seeds);
        seeded += s.calibration_seeds as usize;
        let Some(d) = NodeDistribution::of(&drapes, s.calibration_seeds as usize) else {
            continue;
        };
        candidates.push(LawCandidate {
            law: *law,
            bending_length_m: c,
            drapes: d,
        });
    }
    let solves = continuation.solves + seeded;
    let (best, near, law_identifiable) = choose_law(&candidates, target.nodes)?;
    let sigma = target.dc_se_pct.hypot(best.drapes.dc_sd_pct);
    // c puts the seed-0 drape on the target; the prediction is a mean over other seeds. One secant
    // step along dDC/d ln c moves c to where the calibration seeds' mean would meet the target
    // (no further solve), by at most MAX_SEED_MEAN_LN in ln c.
    let step = (target.dc_pct - best.drapes.dc_mean_pct) / slope;
    let c = best.bending_length_m * step.clamp(-MAX_SEED_MEAN_LN, MAX_SEED_MEAN_LN).exp();
    let scale = c / cal.bending_length_m;
    Ok(FabricFit {
        bending_length_m: c,
        seed0_bending_length_m: best.bending_length_m,
        bending_length_interval_m: cal
            .interval_m(sigma, 2.0)
            .map(|[a, b]| [a * scale, b * scale]),
        dc_sensitivity_pct: cal.sensitivity_pct(1.3),
        law: best.law,
        laws_within_one_node: near,
        law_identifiable,
        candidates,
        solves,
    })
}

/// The candidate whose drapes' mean node count is nearest `nodes`, the laws within one node of it,
/// and whether the laws' node counts spread over more than one node (the law identifiable).
fn choose_law(
    candidates: &[LawCandidate],
    nodes: f64,
) -> Result<(LawCandidate, Vec<BendingLaw>, bool), String> {
    let miss = |r: &LawCandidate| (r.drapes.nodes_mean - nodes).abs();
    let best = candidates
        .iter()
        .min_by(|a, b| miss(a).total_cmp(&miss(b)))
        .ok_or("no candidate's drapes converged")?
        .clone();
    let near: Vec<BendingLaw> = candidates
        .iter()
        .filter(|r| miss(r) <= 1.0)
        .map(|r| r.law)
        .collect();
    let (lo, hi) = candidates
        .iter()
        .map(|r| r.drapes.nodes_mean)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, m| {
            (a.0.min(m), a.1.max(m))
        });
    Ok((best, near, hi - lo > 1.0))
}

/// A fabric's calibrate → predict outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct FabricOutcome {
    /// The calibration on the calibration specimen.
    pub fit: FabricFit,
    /// The curl fitted to its face gap, or why there is none (the prediction is then face-blind).
    pub curl: Result<CurlFit, String>,
    /// The converged drapes of the fitted parameters at the prediction seeds: face up, then (with
    /// a curl) face down at the seeds of `face_down_seeds`.
    pub drapes: Vec<SeededDrape>,
    /// The seeds of the face-down drapes (empty without a curl).
    pub face_down_seeds: std::ops::Range<u64>,
    /// The curl of the prediction's drapes (face up; face down its negative), 1/m: the fitted
    /// curl moved along the fit's gap slope to [`SpecimenTargets::predicted_face_gap_pct`].
    pub prediction_curl_per_m: Option<f64>,
    /// The face gap the model gives at that curl, points (the fit's solved gap carried along its
    /// slope: the gap is linear in the curl well beyond the fitted range).
    pub prediction_gap_pct: Option<f64>,
    /// The node and DC distribution of all of them, the face average (None when none converged).
    pub distribution: Option<NodeDistribution>,
    /// Prediction seeds tried per face.
    pub seeds: u64,
    /// Drape solves made, calibration included.
    pub solves: usize,
}

impl FabricOutcome {
    /// The drapes of one face (`down`), or every drape of a face-blind prediction.
    pub fn face(&self, down: bool) -> Vec<SeededDrape> {
        let blind = self.face_down_seeds.is_empty();
        self.drapes
            .iter()
            .filter(|d| blind || self.face_down_seeds.contains(&d.seed) == down)
            .cloned()
            .collect()
    }
}

/// The whole workflow of one fabric: [`calibrate_fabric`] on its calibration specimen, the curl
/// on its face gap ([`fit_curl`], where it has both faces), then the drapes of the fitted
/// (c, law) at `seeds` further seeds per face (after the calibration's, so that no drape is both
/// fitted and predicted) as the prediction for the other specimens.
pub fn calibrate_and_predict(
    mesh: DiscMesh<'_>,
    target: &SpecimenTargets,
    base: &DrapeParams,
    tester: &Tester,
    s: &FabricSettings,
    seeds: u64,
) -> Result<FabricOutcome, String> {
    let fit = calibrate_fabric(mesh, target, base, tester, s)?;
    let q = fit.law.apply(base, fit.bending_length_m);
    let curl = match &target.face_gap {
        Some(gap) => fit_curl(mesh, &q, tester, gap),
        None => Err("the calibration specimen was photographed on one face only".into()),
    };
    let first = s.calibration_seeds;
    let prediction = curl
        .as_ref()
        .ok()
        .map(|c| prediction_curl(c, target.predicted_face_gap_pct));
    let (drapes, face_down_seeds, solves) = match (&curl, prediction) {
        (Ok(c), Some((kappa, _))) => {
            let at = |k: f64| DrapeParams {
                curl_per_m: Some(k),
                ..q.clone()
            };
            let down = first + seeds..first + 2 * seeds;
            let mut drapes = seeded_drapes(mesh, &at(kappa), tester, first..first + seeds);
            drapes.extend(seeded_drapes(mesh, &at(-kappa), tester, down.clone()));
            (drapes, down, fit.solves + c.solves + 2 * seeds as usize)
        }
        _ => {
            let drapes = seeded_drapes(mesh, &q, tester, first..first + seeds);
            (drapes, 0..0, fit.solves + seeds as usize)
        }
    };
    let tried = seeds as usize * if face_down_seeds.is_empty() { 1 } else { 2 };
    Ok(FabricOutcome {
        distribution: NodeDistribution::of(&drapes, tried),
        solves,
        fit,
        curl,
        drapes,
        face_down_seeds,
        prediction_curl_per_m: prediction.map(|p| p.0),
        prediction_gap_pct: prediction.map(|p| p.1),
        seeds,
    })
}

/// The curl at which the fitted curl `c` gives the face gap `gap_pct` (none: `c` itself), moved
/// along the fit's secant slope and kept within [`MAX_CURL_PER_M`], with the gap it gives there.
pub fn prediction_curl(c: &CurlFit, gap_pct: Option<f64>) -> (f64, f64) {
    let Some(gap) = gap_pct.filter(|_| c.gap_slope_pct_m != 0.0) else {
        return (c.curl_per_m, c.gap_solved_pct);
    };
    let kappa = (c.curl_per_m + (gap - c.gap_solved_pct) / c.gap_slope_pct_m)
        .clamp(-MAX_CURL_PER_M, MAX_CURL_PER_M);
    (
        kappa,
        c.gap_solved_pct + c.gap_slope_pct_m * (kappa - c.curl_per_m),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drape(seed: u64, dc: f64, nodes: usize) -> SeededDrape {
        SeededDrape {
            seed,
            dc_pct: dc,
            nodes,
            outline_m: Vec::new(),
            x: Vec::new(),
        }
    }

    #[test]
    fn the_prediction_curl_moves_along_the_fits_slope_to_the_gap_asked_for() {
        let fit = CurlFit {
            curl_per_m: 4.0,
            interval_per_m: [2.0, 6.0],
            gap_slope_pct_m: -0.5,
            gap_solved_pct: -2.1,
            identifiable: true,
            at_bound: false,
            solves: 3,
        };
        assert_eq!(prediction_curl(&fit, None), (4.0, -2.1));
        let (k, gap) = prediction_curl(&fit, Some(-4.1));
        assert!(
            (k - 8.0).abs() < 1e-12 && (gap + 4.1).abs() < 1e-12,
            "{k} {gap}"
        );
        let (k, gap) = prediction_curl(&fit, Some(1e6));
        assert_eq!(k, -MAX_CURL_PER_M);
        assert!((gap - (-2.1 - 0.5 * (-MAX_CURL_PER_M - 4.0))).abs() < 1e-9);
    }

    #[test]
    fn a_node_distribution_has_its_mean_mode_and_histogram() {
        let d = [
            drape(0, 70.0, 7),
            drape(1, 72.0, 8),
            drape(2, 71.0, 7),
            drape(3, 73.0, 9),
        ];
        let n = NodeDistribution::of(&d, 5).expect("some");
        assert_eq!(n.histogram, vec![(7, 2), (8, 1), (9, 1)]);
        assert_eq!(n.nodes_mode, 7);
        assert!((n.nodes_mean - 7.75).abs() < 1e-12);
        assert!((n.nodes_sd - (2.75f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!(histogram_label(&n.histogram), "7×2 8×1 9×1");
        assert!((n.dc_mean_pct - 71.5).abs() < 1e-12);
        assert!((n.dc_sd_pct - (5.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!((n.converged, n.tried), (4, 5));
        assert!(NodeDistribution::of(&[], 3).is_none());
    }
}
