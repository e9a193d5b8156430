//! The parameters of `wrinkles-simulate` (issues 36, 50): the meshes of each reading, the starts and
//! shear stiffnesses tried, the fabric reading, the map and the candidates of the two leave-one-out
//! choices; each key's meaning, unit and default beside it, and their checks.

use drapelab_core::error::KeyError;
use drapelab_core::wrinkles::full::{HungSetup, HungStart, SheetReading};
use serde::{Deserialize, Serialize};

/// Parameters of a `wrinkles-simulate` stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WrinklesSimulateParams {
    /// Grid points along the supports on the coarser mesh; the rows follow h/L at the same
    /// spacing. Default 57 (2.5 cm on a 1.4 m sheet, half the bending length (D/w)^(1/3) of
    /// Table I's fabric).
    #[serde(default = "default_coarse_nx")]
    pub coarse_nx: usize,
    /// Grid points along the supports on the finer mesh, whose wrinkles are the result. Default 113.
    #[serde(default = "default_fine_nx")]
    pub fine_nx: usize,
    /// How the sheets start: "arc" (each row bent in plan to its length between the supports, free
    /// of membrane strain), "compressed" or "folded-K". Default "arc".
    #[serde(default = "default_start")]
    pub start: HungStart,
    /// Other starts solved on the coarser mesh, to show whether the count depends on the start.
    /// Default ["compressed", "folded-3"].
    #[serde(default = "default_other_starts")]
    pub other_starts: Vec<HungStart>,
    /// In-plane shear stiffnesses tried on the coarser mesh from the result's start, as fractions of
    /// the isotropic E·t/(2(1 + ν)) the results use (a woven fabric's shear stiffness is 10⁻² to 10⁻⁴
    /// of that). Default [1e-3, 1e-4].
    #[serde(default = "default_shear_ratios")]
    pub shear_ratios: Vec<f64>,
    /// Seed of the start's out-of-plane ripple. Default 1.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Amplitude of the start's out-of-plane ripple, m. Default 0.005.
    #[serde(default = "default_ripple")]
    pub ripple_amplitude_m: f64,
    /// Lobe thresholds tried, as fractions of the fibre's z_max, in order of preference (smallest
    /// first); the count uses the one chosen by leave-one-out on mesh agreement. Default
    /// [0, 0.002, 0.005, 0.01, 0.02]: small enough not to hide centimetre folds under the
    /// upper boundary's decimetre excursion.
    #[serde(default = "default_thresholds")]
    pub thresholds_rel: Vec<f64>,
    /// Load constants c of Eq. 7 tried against the full simulations (dimensionless; only
    /// c/(1 − ν²) enters). Default 15 values from 10 to 1e5, log-spaced and rounded, and the
    /// seed's reading 135.
    #[serde(default = "default_constants")]
    pub buckling_constants: Vec<f64>,
    /// Only the cases of these names (empty: every case). Default empty.
    #[serde(default)]
    pub cases: Vec<String>,
    /// Solve every case read as a fabric too, on both meshes (issue 50). Default true.
    #[serde(default = "default_true")]
    pub fabric: bool,
    /// The fabric reading's bending length c, m: bending rigidity w c³ both ways (Peirce), no
    /// twist rigidity. Default 0.0143, the geometric middle of the 7–29 mm at which the bundled
    /// Cusick fabrics calibrate — chosen from fabrics, not from the seed's counts.
    #[serde(default = "default_fabric_bending_length")]
    pub fabric_bending_length_m: f64,
    /// The fabric reading's in-plane shear rigidity G, N/m. Default 53.3: 0.95 gf/cm/deg, the
    /// geometric middle of KES shear of apparel fabrics (0.3–3 gf/cm/deg).
    #[serde(default = "default_fabric_shear")]
    pub fabric_shear_N_per_m: f64,
    /// Grid points along the supports of the fabric reading's coarser mesh. Default 85: at 57
    /// (2.5 cm, longer than a fabric's bending length) six of the twelve sheets fold once where the
    /// finer meshes fold three times (issue 50's mesh study: n = 1, 3, 3, 3 on 29, 57, 85, 113
    /// points for I-h140). Must be below `fabric_fine_nx`.
    #[serde(default = "default_fabric_coarse_nx")]
    pub fabric_coarse_nx: usize,
    /// Grid points along the supports of the fabric reading's finer mesh, whose wrinkles are the
    /// result. Default 113.
    #[serde(default = "default_fine_nx")]
    pub fabric_fine_nx: usize,
    /// The cases of the map (issue 50): each solved read as fabric at every bending length ×
    /// shear rigidity below. Default empty (no map); the bundled pipeline names Table I's.
    #[serde(default)]
    pub map_cases: Vec<String>,
    /// The map's bending lengths, m. Default [0.007, 0.029]: the ends of the Cusick fabrics' range.
    #[serde(default = "default_map_lengths")]
    pub map_bending_lengths_m: Vec<f64>,
    /// The map's shear rigidities, N/m. Default [17, 170]: KES 0.3 and 3 gf/cm/deg.
    #[serde(default = "default_map_shears")]
    pub map_shear_N_per_m: Vec<f64>,
    /// Grid points along the supports of the map's and the photographs' coarser mesh. Default 57.
    #[serde(default = "default_coarse_nx")]
    pub points_coarse_nx: usize,
    /// ... and of their finer mesh, whose wrinkles are reported. Default 85.
    #[serde(default = "default_fabric_coarse_nx")]
    pub points_fine_nx: usize,
}

fn default_fabric_coarse_nx() -> usize {
    85
}
fn default_map_lengths() -> Vec<f64> {
    vec![0.007, 0.029]
}
fn default_map_shears() -> Vec<f64> {
    vec![17.0, 170.0]
}

fn default_true() -> bool {
    true
}
fn default_fabric_bending_length() -> f64 {
    0.0143
}
fn default_fabric_shear() -> f64 {
    53.3
}
fn default_coarse_nx() -> usize {
    57
}
fn default_fine_nx() -> usize {
    113
}
fn default_start() -> HungStart {
    HungStart::Arc
}
fn default_other_starts() -> Vec<HungStart> {
    vec![HungStart::Compressed, HungStart::Folded(3)]
}
fn default_shear_ratios() -> Vec<f64> {
    vec![1e-3, 1e-4]
}
fn default_seed() -> u64 {
    1
}
fn default_ripple() -> f64 {
    0.005
}
fn default_thresholds() -> Vec<f64> {
    vec![0.0, 0.002, 0.005, 0.01, 0.02]
}
fn default_constants() -> Vec<f64> {
    let mut c: Vec<f64> = (0..15)
        .map(|k| 10f64.powf(1.0 + k as f64 * 4.0 / 14.0).round())
        .collect();
    c.push(135.0);
    c.sort_by(f64::total_cmp);
    c
}

impl Default for WrinklesSimulateParams {
    fn default() -> Self {
        Self {
            coarse_nx: default_coarse_nx(),
            fine_nx: default_fine_nx(),
            start: default_start(),
            other_starts: default_other_starts(),
            shear_ratios: default_shear_ratios(),
            seed: default_seed(),
            ripple_amplitude_m: default_ripple(),
            thresholds_rel: default_thresholds(),
            buckling_constants: default_constants(),
            cases: Vec::new(),
            fabric: true,
            fabric_bending_length_m: default_fabric_bending_length(),
            fabric_shear_N_per_m: default_fabric_shear(),
            fabric_coarse_nx: default_fabric_coarse_nx(),
            fabric_fine_nx: default_fine_nx(),
            map_cases: Vec::new(),
            map_bending_lengths_m: default_map_lengths(),
            map_shear_N_per_m: default_map_shears(),
            points_coarse_nx: default_coarse_nx(),
            points_fine_nx: default_fabric_coarse_nx(),
        }
    }
}

/// A start and a shear stiffness (fraction of the isotropic one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variant {
    /// The start.
    pub start: HungStart,
    /// In-plane shear stiffness as a fraction of E·t/(2(1 + ν)).
    pub shear_ratio: f64,
}

impl WrinklesSimulateParams {
    /// The result's variant, then the other starts, then the other shear stiffnesses.
    pub fn variants(&self) -> Vec<Variant> {
        let v = |start, shear_ratio| Variant { start, shear_ratio };
        std::iter::once(v(self.start, 1.0))
            .chain(self.other_starts.iter().map(|&s| v(s, 1.0)))
            .chain(self.shear_ratios.iter().map(|&r| v(self.start, r)))
            .collect()
    }
    /// How a sheet of variant `v` is set up, read as the plate.
    pub fn setup(&self, v: Variant) -> HungSetup {
        HungSetup {
            start: v.start,
            ripple_amplitude_m: self.ripple_amplitude_m,
            seed: self.seed,
            reading: SheetReading::Plate {
                shear_ratio: v.shear_ratio,
            },
        }
    }
    /// The fabric reading of these parameters.
    pub fn fabric_reading(&self) -> SheetReading {
        SheetReading::Fabric {
            bending_length_m: self.fabric_bending_length_m,
            shear_N_per_m: self.fabric_shear_N_per_m,
        }
    }
}

impl WrinklesSimulateParams {
    /// Checks the parameters by themselves: the bad key and why.
    pub fn check(&self) -> Result<(), KeyError> {
        let bad = |key: &str, m: &str| Err(KeyError::new(key, m));
        if self.coarse_nx < 5 {
            return bad("coarse_nx", "must be at least 5");
        }
        if self.fine_nx <= self.coarse_nx {
            return bad("fine_nx", "must be larger than coarse_nx");
        }
        if !(self.ripple_amplitude_m.is_finite() && self.ripple_amplitude_m > 0.0) {
            return bad("ripple_amplitude_m", "must be a positive length in m");
        }
        if self.thresholds_rel.is_empty()
            || self.thresholds_rel.iter().any(|t| !(0.0..1.0).contains(t))
        {
            return bad(
                "thresholds_rel",
                "must be fractions in [0, 1), at least one",
            );
        }
        if self.buckling_constants.is_empty()
            || self
                .buckling_constants
                .iter()
                .any(|c| !(c.is_finite() && *c > 0.0))
        {
            return bad(
                "buckling_constants",
                "must be positive numbers, at least one",
            );
        }
        if self
            .shear_ratios
            .iter()
            .any(|r| !(r.is_finite() && *r > 0.0))
        {
            return bad("shear_ratios", "must be positive fractions");
        }
        if !(self.fabric_bending_length_m.is_finite() && self.fabric_bending_length_m > 0.0) {
            return bad("fabric_bending_length_m", "must be a positive length in m");
        }
        if !(self.fabric_shear_N_per_m.is_finite() && self.fabric_shear_N_per_m > 0.0) {
            return bad("fabric_shear_N_per_m", "must be a positive rigidity in N/m");
        }
        for (coarse, fine, key) in [
            (self.fabric_coarse_nx, self.fabric_fine_nx, "fabric_fine_nx"),
            (self.points_coarse_nx, self.points_fine_nx, "points_fine_nx"),
        ] {
            if coarse < 5 || fine <= coarse {
                return bad(
                    key,
                    "must be larger than its coarser mesh's, which must be at least 5",
                );
            }
        }
        let bad_list = |v: &[f64]| v.is_empty() || v.iter().any(|x| !(x.is_finite() && *x > 0.0));
        if bad_list(&self.map_bending_lengths_m) {
            return bad(
                "map_bending_lengths_m",
                "must be positive lengths in m, at least one",
            );
        }
        if bad_list(&self.map_shear_N_per_m) {
            return bad(
                "map_shear_N_per_m",
                "must be positive rigidities in N/m, at least one",
            );
        }
        Ok(())
    }
}
