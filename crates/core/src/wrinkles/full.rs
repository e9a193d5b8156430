//! Seed 002's hung sheet as a full simulation (issue 36, in progress): the continuum sheet (membrane
//! E·t both ways, shear E·t/(2(1 + ν)), bending and twist D = E t³/(12(1 − ν²))) of the case's L × h,
//! hung by its two top corners l = L − 2d apart under gravity (−z), solved from a vertical start
//! compressed along the supports with a seeded out-of-plane ripple; and the wrinkles measured on the
//! solved sheet by the seed's definitions (the centre fibre, Fig. 3).

use super::{WrinkleInputs, support_span_m};
use crate::error::InputError;
use crate::scene::{LoadedScene, Scene};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// How a hung sheet's bending and shear are read from its case (issue 50): seed 002 gives only
/// E, t and ν, which make a plate; a woven or knitted fabric's yarns slide, so its bending and
/// shear are far below the plate's of the same E·t.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "reading", rename_all = "lowercase")]
pub enum SheetReading {
    /// Seed 002's isotropic plate: bending and twist D = E t³/(12(1 − ν²)), shear `shear_ratio`
    /// times E·t/(2(1 + ν)) (1: the seed's sheet).
    Plate {
        /// In-plane shear stiffness as a fraction of the isotropic E·t/(2(1 + ν)).
        shear_ratio: f64,
    },
    /// A fabric: bending rigidity w c³ both ways from its bending length c (Peirce's
    /// cantilever, c = (B/w)^(1/3), w the case's weight per area), no twist rigidity (as seed 003's
    /// KES fabrics), in-plane shear G; the tensile rigidity stays the case's E·t.
    Fabric {
        /// Bending length c, m (the Cusick fabrics drapelab calibrates span 7–29 mm).
        bending_length_m: f64,
        /// In-plane shear rigidity G, N/m (KES shear of apparel fabrics, 0.3–3 gf/cm/deg, is
        /// 17–170 N/m).
        shear_N_per_m: f64,
    },
}

/// Which reading a sheet was solved under, without its numbers: the `reading` column of the
/// wrinkle tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ReadingKind {
    /// Seed 002's isotropic plate.
    Plate,
    /// A fabric's bending length and shear rigidity.
    Fabric,
}

impl ReadingKind {
    /// "plate" or "fabric".
    pub fn name(self) -> &'static str {
        match self {
            ReadingKind::Plate => "plate",
            ReadingKind::Fabric => "fabric",
        }
    }
}

impl SheetReading {
    /// Plate or fabric.
    pub fn kind(&self) -> ReadingKind {
        match self {
            SheetReading::Plate { .. } => ReadingKind::Plate,
            SheetReading::Fabric { .. } => ReadingKind::Fabric,
        }
    }
    /// (bending warp = weft, twist, shear) of a case under this reading: N·m, N·m, N/m.
    pub fn rigidities(&self, inp: &WrinkleInputs) -> (f64, f64, f64) {
        let nu = inp.poisson_ratio;
        let e_t = inp.youngs_modulus_Pa * inp.thickness_m;
        match *self {
            SheetReading::Plate { shear_ratio } => {
                let d = e_t * inp.thickness_m.powi(2) / (12.0 * (1.0 - nu * nu));
                (d, d, shear_ratio * e_t / (2.0 * (1.0 + nu)))
            }
            SheetReading::Fabric {
                bending_length_m,
                shear_N_per_m,
            } => (
                inp.weight_N_per_m2 * bending_length_m.powi(3),
                0.0,
                shear_N_per_m,
            ),
        }
    }
    /// The bending length (B/w)^(1/3) of a case under this reading, m.
    pub fn bending_length_m(&self, inp: &WrinkleInputs) -> f64 {
        (self.rigidities(inp).0 / inp.weight_N_per_m2).cbrt()
    }
}

/// The continuum scene of a case on an `nx × ny` grid: the rest state is the flat L × h sheet (grid
/// x along the supports, grid y up the sheet, the top row at y = h), its two top corners pinned;
/// membrane E·t both ways, bending, twist and shear as `reading` says.
pub fn hung_sheet_scene(
    inp: &WrinkleInputs,
    nx: usize,
    ny: usize,
    reading: &SheetReading,
) -> Result<LoadedScene, InputError> {
    let e_t = inp.youngs_modulus_Pa * inp.thickness_m;
    let (d, twist, g_t) = reading.rigidities(inp);
    let rho = inp.weight_N_per_m2 / crate::STANDARD_GRAVITY_M_PER_S2;
    let text = format!(
        "name = \"wrinkles-full\"\n\
         [cloth]\nsize_x_m = {L}\nsize_y_m = {h}\nnx = {nx}\nny = {ny}\n\
         areal_density_kg_per_m2 = {rho}\n\
         [material.continuum]\ntensile_warp_N_per_m = {e_t}\ntensile_weft_N_per_m = {e_t}\n\
         shear_N_per_m = {g_t}\nbending_warp_N_m = {d}\nbending_weft_N_m = {d}\n\
         bending_twist_N_m = {twist}\nthickness_m = {t}\n\
         [boundary]\npin_corners = [\"xmin_ymax\", \"xmax_ymax\"]\n\
         [solver]\nkind = \"static\"\n[solver.static]\nmax_iterations = 3000\n",
        L = inp.length_m,
        h = inp.height_m,
        t = inp.thickness_m,
    );
    let table: toml::Table = text
        .parse()
        .map_err(|e| InputError::new("wrinkles-full", "", format!("{e}")))?;
    Scene::load_table(Path::new("wrinkles-full"), table, &[])
}

/// How a hung sheet starts, before gravity and the supports find its equilibrium. Written
/// "compressed", "arc" or "folded-K" (K ≥ 1) in configs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum HungStart {
    /// Vertical, every row compressed uniformly to the supports' span l (a membrane strain of
    /// l/L − 1 everywhere, which the sheet must buckle away).
    Compressed,
    /// Vertical, every row bent in plan into the circular arc of length L whose chord is l: free of
    /// membrane strain, so no fold is put in by the start; gravity and the supports make them.
    Arc,
    /// Vertical, every row compressed to l and waved in plan into K half sines whose amplitude
    /// gives the row about its length L: K folds put in by hand, to see whether they stay.
    Folded(u32),
}

impl std::fmt::Display for HungStart {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            HungStart::Compressed => write!(f, "compressed"),
            HungStart::Arc => write!(f, "arc"),
            HungStart::Folded(k) => write!(f, "folded-{k}"),
        }
    }
}

impl TryFrom<String> for HungStart {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        match s.as_str() {
            "compressed" => Ok(HungStart::Compressed),
            "arc" => Ok(HungStart::Arc),
            _ => s
                .strip_prefix("folded-")
                .and_then(|k| k.parse::<u32>().ok())
                .filter(|&k| k >= 1)
                .map(HungStart::Folded)
                .ok_or_else(|| {
                    format!(
                        "`{s}` is no start: use \"compressed\", \"arc\" or \"folded-K\" (K ≥ 1)"
                    )
                }),
        }
    }
}

impl From<HungStart> for String {
    fn from(s: HungStart) -> String {
        s.to_string()
    }
}

/// The start of a hung sheet: vertical (x along the supports, z up, the top row at z = 0), each row
/// spanning the supports' l as `start` says, plus an out-of-plane ripple y of `amplitude_m` from
/// six sine modes with seeded wavenumbers and phases (breaking the mirror symmetry as a real
/// sheet's imperfections do). Grid order as `grid` (j · nx + i).
pub fn hung_start(
    inp: &WrinkleInputs,
    grid: &crate::cloth::Grid,
    start: HungStart,
    amplitude_m: f64,
    seed: u64,
) -> Vec<Vector3<f64>> {
    let (len, h, l) = (inp.length_m, inp.height_m, support_span_m(inp));
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let modes: Vec<[f64; 4]> = (0..6)
        .map(|_| {
            [
                rng.random_range(1..=12) as f64,
                rng.random_range(1..=3) as f64,
                rng.random_range(0.0..std::f64::consts::TAU),
                rng.random_range(-1.0..1.0),
            ]
        })
        .collect();
    let pi = std::f64::consts::PI;
    let radius = arc_radius_m(len, l);
    grid.flat_positions()
        .iter()
        .map(|p| {
            let (s, eta) = (p.x / len, (h - p.y) / h);
            let y: f64 = modes
                .iter()
                .map(|[kv, ku, phase, a]| a * (pi * kv * eta + phase).sin() * (pi * ku * s).sin())
                .sum::<f64>()
                * amplitude_m
                / modes.len() as f64;
            let u = (p.x - 0.5 * len) * l / len;
            let (x, bulge) = match (start, radius) {
                (HungStart::Arc, Some(r)) => {
                    let phi = (p.x - 0.5 * len) / r;
                    (r * phi.sin(), r * (phi.cos() - (0.5 * len / r).cos()))
                }
                (HungStart::Folded(k), Some(_)) => {
                    // A sine of k half-waves over l has length ≈ l (1 + (kπa/l)²/4) = L.
                    let k = f64::from(k);
                    let a = 2.0 * l / (k * pi) * (len / l - 1.0).sqrt();
                    (u, a * (k * pi * (u + 0.5 * l) / l).sin())
                }
                _ => (u, 0.0),
            };
            Vector3::new(x, y + bulge, p.y - h)
        })
        .collect()
}

/// Radius of the circular arc of length `len` whose chord is `chord` (bisection on the half
/// angle θ: sin θ / θ = chord / len); None when the chord is not shorter than the arc.
pub fn arc_radius_m(len: f64, chord: f64) -> Option<f64> {
    let ratio = chord / len;
    if !(ratio > 0.0 && ratio < 1.0) {
        return None;
    }
    let (mut lo, mut hi) = (1e-9, std::f64::consts::PI);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid.sin() / mid > ratio {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * len / (0.5 * (lo + hi)))
}

/// How a hung sheet is set up besides its case and grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HungSetup {
    /// The start.
    pub start: HungStart,
    /// Amplitude of the start's out-of-plane ripple, m.
    pub ripple_amplitude_m: f64,
    /// Seed of the ripple.
    pub seed: u64,
    /// How the sheet's bending and shear are read from the case.
    pub reading: SheetReading,
}

/// A case solved on an `nx × ny` grid as `setup` says: the static equilibrium (or why there is
/// none), the grid and the final positions.
pub fn solve_hung(
    inp: &WrinkleInputs,
    (nx, ny): (usize, usize),
    setup: &HungSetup,
) -> Result<crate::simulate::Solution, InputError> {
    let loaded = hung_sheet_scene(inp, nx, ny, &setup.reading)?;
    let start = hung_start(
        inp,
        &loaded.scene.grid(),
        setup.start,
        setup.ripple_amplitude_m,
        setup.seed,
    );
    Ok(crate::simulate::solve_scene_from(
        &loaded.scene,
        &start,
        &mut crate::solve::NoObserver,
    ))
}

/// The wrinkles of a solved hung sheet: its centre fibre (column nx/2, top to bottom; depth below
/// the supports −z, out of plane y), lobes counted from `threshold_rel` of the largest |y|.
pub fn sheet_wrinkles(
    grid: &crate::cloth::Grid,
    x: &[Vector3<f64>],
    threshold_rel: f64,
) -> FibreWrinkles {
    let i = grid.nx / 2;
    let fibre: Vec<&Vector3<f64>> = (0..grid.ny).rev().map(|j| &x[grid.index(i, j)]).collect();
    let depth: Vec<f64> = fibre.iter().map(|p| -p.z).collect();
    let y: Vec<f64> = fibre.iter().map(|p| p.y).collect();
    fibre_wrinkles(&depth, &y, threshold_rel)
}

/// Wrinkles seen on the centre fibre of a hung sheet (seed 002 Fig. 3): the fibre crosses the n
/// strips between wrinkle lines, each strip turning the sheet from one side to the other.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FibreWrinkles {
    /// Number of wrinkles n: sign changes of the out-of-plane displacement down the fibre, counted
    /// between excursions beyond the threshold (so noise near zero does not count).
    pub n: usize,
    /// Largest out-of-plane displacement |z| on the fibre, m.
    pub zmax_m: f64,
    /// Depth below the supports of each wrinkle line (the extremum of each lobe), top first, m.
    pub line_depths_m: Vec<f64>,
    /// The ratio Q = (a₀/a_n)^(1/n) of the deepest to the shallowest line depth (Eq. 5); None with
    /// no wrinkle.
    pub q: Option<f64>,
}

/// Wrinkles of a fibre sampled top to bottom: depths below the supports (m) and out-of-plane
/// displacements (m); a lobe counts when it reaches `threshold_rel` of the largest |z|.
pub fn fibre_wrinkles(depth_m: &[f64], z_m: &[f64], threshold_rel: f64) -> FibreWrinkles {
    let zmax = z_m.iter().fold(0.0f64, |m, z| m.max(z.abs()));
    let threshold = threshold_rel * zmax;
    let mut lobes: Vec<(f64, f64)> = Vec::new(); // (sign, depth at the lobe's extremum)
    let mut best = 0.0f64;
    for (&d, &z) in depth_m.iter().zip(z_m) {
        if z.abs() < threshold || zmax == 0.0 {
            continue;
        }
        let s = z.signum();
        match lobes.last_mut() {
            Some((sign, at)) if *sign == s => {
                if z.abs() > best {
                    best = z.abs();
                    *at = d;
                }
            }
            _ => {
                lobes.push((s, d));
                best = z.abs();
            }
        }
    }
    let n = lobes.len().saturating_sub(1);
    let line_depths_m: Vec<f64> = lobes.iter().map(|&(_, d)| d).collect();
    let q = (n > 0).then(|| {
        let (shallow, deep) = (line_depths_m[0].abs(), line_depths_m[n].abs());
        (deep / shallow.max(f64::MIN_POSITIVE)).powf(1.0 / n as f64)
    });
    FibreWrinkles {
        n,
        zmax_m: zmax,
        line_depths_m,
        q,
    }
}

/// A choice among candidates (a threshold, a constant) made by leave-one-out over cases.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LeaveOneOut {
    /// The candidate chosen on all cases (the first of the best).
    pub chosen: usize,
    /// For each case: the candidate chosen on the other cases, and whether it holds on this one.
    pub held_out: Vec<(usize, bool)>,
}

impl LeaveOneOut {
    /// Cases where the candidate chosen without them holds.
    pub fn held_out_hits(&self) -> usize {
        self.held_out.iter().filter(|h| h.1).count()
    }
}

/// Leave-one-out over `ok[case][candidate]` (does the candidate hold on the case): for each case
/// the candidate that holds on most other cases (ties: the first), scored on the case left out.
/// Candidates are given in order of preference (e.g. the smallest threshold first).
pub fn leave_one_out(ok: &[Vec<bool>]) -> LeaveOneOut {
    let groups: Vec<usize> = (0..ok.len()).collect();
    leave_groups_out(ok, &groups)
}

/// Leave-one-group-out over `ok[row][candidate]`: each row is scored with the candidate that holds
/// on most rows outside its group (`group[row]`, e.g. a case and its map points), ties to the first.
pub fn leave_groups_out(ok: &[Vec<bool>], group: &[usize]) -> LeaveOneOut {
    let candidates = ok.first().map_or(0, Vec::len);
    let best = |skip: Option<usize>| -> usize {
        let hits = |c: usize| {
            ok.iter()
                .zip(group)
                .filter(|&(row, &g)| Some(g) != skip && row[c])
                .count()
        };
        (0..candidates).fold(0, |b, c| if hits(c) > hits(b) { c } else { b })
    };
    LeaveOneOut {
        chosen: best(None),
        held_out: (0..ok.len())
            .map(|k| {
                let c = best(Some(group[k]));
                (c, ok[k][c])
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Leaving a group out leaves all its rows out: a candidate that holds only on one group's two
    /// rows wins row 0 back through its sibling row 1 when rows are left out one at a time, but not
    /// when the group leaves together.
    #[test]
    fn leaving_a_group_out_leaves_its_rows_out_together() {
        // Candidate 0 holds on rows 0 and 1 (group 0); candidate 1 on row 2 (group 1).
        let ok = vec![vec![true, false], vec![true, false], vec![false, true]];
        let rows = leave_one_out(&ok);
        assert_eq!((rows.chosen, rows.held_out[0]), (0, (0, true)));
        let grouped = leave_groups_out(&ok, &[0, 0, 1]);
        assert_eq!(grouped.chosen, 0);
        assert_eq!(grouped.held_out, vec![(1, false), (1, false), (0, false)]);
    }

    /// A synthetic sheet whose centre fibre is a cosine of n half-waves: n sign changes, n + 1
    /// lines at the half-waves' extrema, z_max its amplitude.
    #[test]
    fn a_cosine_fibre_of_known_n_is_counted_exactly() {
        for n in 1..=17usize {
            let m = 400;
            let depth: Vec<f64> = (0..m).map(|k| 1.4 * k as f64 / (m - 1) as f64).collect();
            let z: Vec<f64> = depth
                .iter()
                .map(|d| 0.05 * (std::f64::consts::PI * n as f64 * d / 1.4).cos())
                .collect();
            let w = fibre_wrinkles(&depth, &z, 0.1);
            assert_eq!(w.n, n, "n = {n}");
            assert!((w.zmax_m - 0.05).abs() < 1e-12);
            assert_eq!(w.line_depths_m.len(), n + 1);
            for (i, d) in w.line_depths_m.iter().enumerate() {
                assert!((d - 1.4 * i as f64 / n as f64).abs() <= 1.4 / (m - 1) as f64);
            }
        }
    }

    #[test]
    fn noise_below_the_threshold_adds_no_wrinkle_and_a_flat_fibre_has_none() {
        let depth: Vec<f64> = (0..100).map(|k| k as f64 * 0.01).collect();
        let z: Vec<f64> = depth
            .iter()
            .enumerate()
            .map(|(k, d)| {
                (std::f64::consts::PI * d).sin() * 0.02 + if k % 2 == 0 { 1e-4 } else { -1e-4 }
            })
            .collect();
        assert_eq!(fibre_wrinkles(&depth, &z, 0.1).n, 0);
        let flat = fibre_wrinkles(&depth, &vec![0.0; 100], 0.1);
        assert_eq!((flat.n, flat.zmax_m, flat.q), (0, 0.0, None));
    }

    #[test]
    fn the_hung_sheet_starts_vertical_between_its_supports_with_its_rest_state_flat() {
        let inp = crate::wrinkles::WrinkleInputs {
            length_m: 1.4,
            height_m: 1.4,
            thickness_m: 0.25e-3,
            youngs_modulus_Pa: 165e6,
            poisson_ratio: 0.3,
            weight_N_per_m2: 1.5,
            support_displacement_m: 0.1,
            buckling_constant: 135.0,
            tolerance_rel: 0.05,
            max_iterations: 50,
            initial_zmax_m: 0.014,
            simpson_intervals: 200,
            bending_length_m: None,
        };
        let plate = SheetReading::Plate { shear_ratio: 1.0 };
        let loaded = hung_sheet_scene(&inp, 15, 15, &plate).expect("a valid scene");
        let grid = loaded.scene.grid();
        let x = hung_start(&inp, &grid, HungStart::Compressed, 1e-3, 7);
        let (tl, tr) = (grid.index(0, 14), grid.index(14, 14));
        assert!((x[tl] - Vector3::new(-0.6, x[tl].y, 0.0)).norm() < 1e-12);
        assert!((x[tr] - Vector3::new(0.6, x[tr].y, 0.0)).norm() < 1e-12);
        assert!(
            x.iter()
                .all(|p| p.y.abs() <= 1e-3 && p.z <= 1e-12 && p.z >= -1.4 - 1e-12)
        );
        assert_ne!(
            x,
            hung_start(&inp, &grid, HungStart::Compressed, 1e-3, 8),
            "the seed changes the ripple"
        );
        assert_eq!(
            x,
            hung_start(&inp, &grid, HungStart::Compressed, 1e-3, 7),
            "and only the seed"
        );
        // The arc start: the same supports, every row of its rest length L (no membrane strain).
        let arc = hung_start(&inp, &grid, HungStart::Arc, 0.0, 7);
        assert!((arc[tl] - Vector3::new(-0.6, 0.0, 0.0)).norm() < 1e-12);
        assert!((arc[tr] - Vector3::new(0.6, 0.0, 0.0)).norm() < 1e-12);
        let row: f64 = (0..14)
            .map(|i| (arc[grid.index(i + 1, 3)] - arc[grid.index(i, 3)]).norm())
            .sum();
        // Its 14 chords of the arc of radius r and length L: 14 · 2r sin(L/(28r)).
        let r = arc_radius_m(1.4, 1.2).expect("a chord shorter than the arc");
        assert!(
            (2.0 * r * (0.5 * 1.2 / r).asin() - 1.4).abs() < 1e-9,
            "r = {r}"
        );
        let chords = 14.0 * 2.0 * r * (1.4 / (28.0 * r)).sin();
        assert!(
            (row - chords).abs() < 1e-9,
            "an arc row is {row} m long, {chords} m expected"
        );
        assert!(arc_radius_m(1.4, 1.4).is_none());
    }

    /// Leave-one-out picks the candidate that holds on most other cases, the first on ties, and
    /// scores it on the case left out.
    #[test]
    fn leave_one_out_scores_each_case_with_a_choice_made_without_it() {
        let ok = vec![
            vec![true, true, false],
            vec![false, true, false],
            vec![false, true, true],
            vec![true, false, true],
        ];
        let loo = leave_one_out(&ok);
        assert_eq!(loo.chosen, 1);
        // Without case 3, candidate 1 holds on 3 of 3 others; it fails on case 3.
        assert_eq!(loo.held_out[3], (1, false));
        // Without case 1, candidates 0, 1 and 2 tie at 2: the first wins, and fails on case 1.
        assert_eq!(loo.held_out[1], (0, false));
        // Without case 0, candidates 1 and 2 tie at 2: candidate 1, which holds on case 0.
        assert_eq!(loo.held_out[0], (1, true));
        assert_eq!(loo.held_out[2], (0, false));
        assert_eq!(loo.held_out_hits(), 1);
    }
}
