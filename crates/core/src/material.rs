//! Fabric materials: the seed-000 mass-spring parameter set and continuum (KES) rigidities.
//!
//! Everything is SI inside. [`KesRigidities`] accepts the units of seed 003 Table 10.3
//! (gf/cm, gf·cm²/cm, gf/cm², cm) and converts them with 1 gf = 9.80665e-3 N.

use crate::error::KeyError;
use serde::{Deserialize, Serialize};

/// One gram-force in newtons.
pub const GRAM_FORCE_N: f64 = 9.806_65e-3;

/// Which spring families a mass-spring net has (seed 000, Fig. 1 and Table 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Hash)]
#[serde(rename_all = "lowercase")]
pub enum Topology {
    /// Structural + shear + bend springs.
    A,
    /// Structural + shear springs.
    B,
    /// Structural + bend springs.
    C,
}

impl Topology {
    /// Whether the topology has diagonal shear springs.
    pub fn has_shear(self) -> bool {
        matches!(self, Topology::A | Topology::B)
    }
    /// Whether the topology has skip-one bend springs.
    pub fn has_bend(self) -> bool {
        matches!(self, Topology::A | Topology::C)
    }
    /// The lower-case letter used in files.
    pub fn letter(self) -> &'static str {
        match self {
            Topology::A => "a",
            Topology::B => "b",
            Topology::C => "c",
        }
    }
}

/// The mass-spring parameter set of seed 000 (Eq. 2 springs, Eq. 4 damping, Provot's elongation rate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassSpring {
    /// Stiffness of every spring in N/m, the seed's single `K` (Table 3: 500..1200). Required in a
    /// scene file: no value is a fabric's by default (a calibration finds it).
    pub stiffness_N_per_m: f64,
    /// Stiffness of the structural springs in N/m, overriding `stiffness_N_per_m` when set.
    #[serde(default)]
    pub structural_stiffness_N_per_m: Option<f64>,
    /// Stiffness of the shear springs in N/m, overriding `stiffness_N_per_m` when set.
    #[serde(default)]
    pub shear_stiffness_N_per_m: Option<f64>,
    /// Stiffness of the bend springs in N/m, overriding `stiffness_N_per_m` when set.
    #[serde(default)]
    pub bend_stiffness_N_per_m: Option<f64>,
    /// Viscous damping coefficient per particle in N·s/m (Eq. 4, F = −c v). Only dynamics see it. Default 0.01.
    #[serde(default = "default_damping")]
    pub damping_Ns_per_m: f64,
    /// Provot's critical elongation rate as a fraction (0.05 = 5 %); springs longer than (1 + rate)·L0
    /// are shortened after each explicit step. Only explicit Euler applies it. Default 0.1.
    #[serde(default = "default_elongation")]
    pub elongation_rate: f64,
    /// Natural length of a structural spring in m; shear springs get √2 times it and bend springs twice it.
    /// Absent: every spring's rest length is its initial length.
    #[serde(default)]
    pub natural_length_m: Option<f64>,
    /// Spring families: a (structural+shear+bend), b (structural+shear), c (structural+bend). Default a.
    #[serde(default = "default_topology")]
    pub topology: Topology,
}

fn default_stiffness() -> f64 {
    1000.0
}
fn default_damping() -> f64 {
    0.01
}
fn default_elongation() -> f64 {
    0.1
}
fn default_topology() -> Topology {
    Topology::A
}

impl Default for MassSpring {
    fn default() -> Self {
        Self {
            stiffness_N_per_m: default_stiffness(),
            structural_stiffness_N_per_m: None,
            shear_stiffness_N_per_m: None,
            bend_stiffness_N_per_m: None,
            damping_Ns_per_m: default_damping(),
            elongation_rate: default_elongation(),
            natural_length_m: None,
            topology: Topology::A,
        }
    }
}

impl MassSpring {
    /// Structural stiffness in N/m.
    pub fn structural(&self) -> f64 {
        self.structural_stiffness_N_per_m
            .unwrap_or(self.stiffness_N_per_m)
    }
    /// Shear stiffness in N/m.
    pub fn shear(&self) -> f64 {
        self.shear_stiffness_N_per_m
            .unwrap_or(self.stiffness_N_per_m)
    }
    /// Bend stiffness in N/m.
    pub fn bend(&self) -> f64 {
        self.bend_stiffness_N_per_m
            .unwrap_or(self.stiffness_N_per_m)
    }
}

/// Continuum rigidities per unit width, SI: the inputs of the continuum model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rigidities {
    /// Tensile rigidity along x (warp) in N/m.
    pub tensile_warp_N_per_m: f64,
    /// Tensile rigidity along y (weft) in N/m.
    pub tensile_weft_N_per_m: f64,
    /// In-plane shear rigidity in N/m.
    pub shear_N_per_m: f64,
    /// Bending rigidity for bending about y (curvature along x, warp) in N·m (N·m²/m).
    pub bending_warp_N_m: f64,
    /// Bending rigidity for curvature along y (weft) in N·m.
    pub bending_weft_N_m: f64,
    /// Twisting rigidity D_t in N·m: the plate energy density D_t κ_xy² (Poisson's ratio 0).
    pub bending_twist_N_m: f64,
}

/// Continuum material as given in a scene: KES units of seed 003 Table 10.3 or SI, never both.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Continuum {
    /// Tensile rigidity, warp (x), in gf/cm (Table 10.3 unit).
    pub tensile_warp_gf_per_cm: Option<f64>,
    /// Tensile rigidity, weft (y), in gf/cm.
    pub tensile_weft_gf_per_cm: Option<f64>,
    /// Shear rigidity in gf/cm.
    pub shear_gf_per_cm: Option<f64>,
    /// Bending rigidity, warp, in gf·cm²/cm.
    pub bending_warp_gf_cm2_per_cm: Option<f64>,
    /// Bending rigidity, weft, in gf·cm²/cm.
    pub bending_weft_gf_cm2_per_cm: Option<f64>,
    /// Tensile rigidity, warp, in N/m (alternative to the gf/cm key).
    pub tensile_warp_N_per_m: Option<f64>,
    /// Tensile rigidity, weft, in N/m.
    pub tensile_weft_N_per_m: Option<f64>,
    /// Shear rigidity in N/m.
    pub shear_N_per_m: Option<f64>,
    /// Bending rigidity, warp, in N·m.
    pub bending_warp_N_m: Option<f64>,
    /// Bending rigidity, weft, in N·m.
    pub bending_weft_N_m: Option<f64>,
    /// Twisting rigidity in gf·cm²/cm: the plate energy density D_t κ_xy² (Poisson's ratio 0). An
    /// isotropic plate has D_t = D, which makes bending about a diagonal as stiff as about a grid line;
    /// without it a diagonal bend is half as stiff. KES does not measure it and seed 003's model bends
    /// along warp and weft only, so the default is 0 (reports/seed003.md shows the rod with and
    /// without it).
    pub bending_twist_gf_cm2_per_cm: Option<f64>,
    /// Twisting rigidity in N·m (alternative to the gf·cm²/cm key). Default 0.
    pub bending_twist_N_m: Option<f64>,
    /// Thickness in m (informational; the model is a shell of zero thickness). Default none.
    pub thickness_m: Option<f64>,
    /// Bending saturation, 1/m: the curvature κ₀ about which the bending moment levels off
    /// (M = B κ / √(1 + (κ/κ₀)²), at most B κ₀), as inter-fibre friction makes it in fabric; the
    /// Cusick calibration fits it as a multiple of 1/c. Default none (linear bending). Bends a mesh sheet (`cloth.mesh`) by hinges
    /// ([`crate::physics::sewn_hinge_bending`]); a grid sheet refuses it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending_saturation_per_m: Option<f64>,
    /// Natural curl, 1/m: the curvature a free strip of the fabric rolls up to, positive toward
    /// the pattern's +z side ([`crate::physics::hinge_curl`]); the Cusick calibration fits it from
    /// the gap between face-up and face-down drapes. Default none (no curl). A mesh sheet's; a
    /// grid sheet refuses it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curl_per_m: Option<f64>,
}

/// Converts gf/cm to N/m.
pub fn gf_per_cm_to_n_per_m(v: f64) -> f64 {
    v * GRAM_FORCE_N / 1e-2
}
/// Converts gf·cm²/cm to N·m.
pub fn gf_cm2_per_cm_to_n_m(v: f64) -> f64 {
    v * GRAM_FORCE_N * 1e-4 / 1e-2
}
/// Converts gf/cm² to N/m² (a weight per area; divide by g for kg/m²).
pub fn gf_per_cm2_to_n_per_m2(v: f64) -> f64 {
    v * GRAM_FORCE_N / 1e-4
}

impl Continuum {
    /// Resolves to SI rigidities. Each rigidity must be given exactly once, in KES or SI units;
    /// the error names the key (relative to the `material.continuum` table) and says what to do.
    pub fn rigidities(&self) -> Result<Rigidities, KeyError> {
        fn pick(
            kes: Option<f64>,
            si: Option<f64>,
            kes_key: &str,
            si_key: &str,
            conv: fn(f64) -> f64,
        ) -> Result<f64, KeyError> {
            match (kes, si) {
                (Some(_), Some(_)) => Err(KeyError::new(
                    si_key,
                    format!("given twice: remove either `{kes_key}` or `{si_key}`"),
                )),
                (Some(v), None) => Ok(conv(v)),
                (None, Some(v)) => Ok(v),
                (None, None) => Err(KeyError::new(
                    si_key,
                    format!("missing: give `{si_key}` or `{kes_key}`"),
                )),
            }
        }
        let bending_warp_N_m = pick(
            self.bending_warp_gf_cm2_per_cm,
            self.bending_warp_N_m,
            "bending_warp_gf_cm2_per_cm",
            "bending_warp_N_m",
            gf_cm2_per_cm_to_n_m,
        )?;
        let bending_weft_N_m = pick(
            self.bending_weft_gf_cm2_per_cm,
            self.bending_weft_N_m,
            "bending_weft_gf_cm2_per_cm",
            "bending_weft_N_m",
            gf_cm2_per_cm_to_n_m,
        )?;
        let bending_twist_N_m =
            if self.bending_twist_gf_cm2_per_cm.is_none() && self.bending_twist_N_m.is_none() {
                0.0
            } else {
                pick(
                    self.bending_twist_gf_cm2_per_cm,
                    self.bending_twist_N_m,
                    "bending_twist_gf_cm2_per_cm",
                    "bending_twist_N_m",
                    gf_cm2_per_cm_to_n_m,
                )?
            };
        Ok(Rigidities {
            tensile_warp_N_per_m: pick(
                self.tensile_warp_gf_per_cm,
                self.tensile_warp_N_per_m,
                "tensile_warp_gf_per_cm",
                "tensile_warp_N_per_m",
                gf_per_cm_to_n_per_m,
            )?,
            tensile_weft_N_per_m: pick(
                self.tensile_weft_gf_per_cm,
                self.tensile_weft_N_per_m,
                "tensile_weft_gf_per_cm",
                "tensile_weft_N_per_m",
                gf_per_cm_to_n_per_m,
            )?,
            shear_N_per_m: pick(
                self.shear_gf_per_cm,
                self.shear_N_per_m,
                "shear_gf_per_cm",
                "shear_N_per_m",
                gf_per_cm_to_n_per_m,
            )?,
            bending_warp_N_m,
            bending_weft_N_m,
            bending_twist_N_m,
        })
    }
}

/// The material of a scene: exactly one model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub struct Material {
    /// Seed-000 mass-spring parameters.
    pub mass_spring: Option<MassSpring>,
    /// Continuum rigidities (seed 003).
    pub continuum: Option<Continuum>,
    /// A fabric file (relative to the scene file) whose material model the scene takes instead of
    /// giving one here ([`crate::scene::Fabric`]): what a calibration writes. Default none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fabric: Option<std::path::PathBuf>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wool_table_10_3_converts_to_si() {
        // 0.083 gf·cm²/cm = 0.083 × 9.80665e-3 N × 1e-4 m² / 1e-2 m
        assert!((gf_cm2_per_cm_to_n_m(0.083) - 8.1395e-6).abs() < 1e-9);
        assert!((gf_per_cm_to_n_per_m(1118.2) - 1096.58).abs() < 0.01);
        assert!((gf_per_cm2_to_n_per_m2(0.019) - 1.8633).abs() < 1e-3);
    }
}
