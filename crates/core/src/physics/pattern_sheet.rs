//! A pattern as the sheet's model ([`crate::pattern::Pattern`]): the continuum material of seed
//! 003's scenes on its triangles — the orthotropic membrane ([`Membrane`]: tensile warp/weft and
//! shear rigidities) and orthotropic hinge bending (warp/weft bending rigidities) — with masses
//! lumped from the triangles' areas and gravity; obstacles and self-contact are added to the
//! builder it returns, as for every sheet.

use super::{
    EnergyTerm, Membrane, MembraneError, ModelBuilder, SewnSheet, hinge_curl, patch_bending,
    reads_creases, sewn_hinge_bending,
};
use crate::material::Rigidities;
use crate::pattern::Pattern;

/// A pattern and its fabric.
pub struct PatternSheet<'a> {
    /// The checked pattern (rest positions in its plane, m).
    pub pattern: &'a Pattern,
    /// The fabric's rigidities (SI: N/m for tensile and shear, N·m for bending).
    pub rigidities: &'a Rigidities,
    /// The warp's angle from the pattern's +x, rad.
    pub warp_angle_rad: f64,
    /// The curvature beyond which the bending moment levels off, 1/m (∞: linear bending).
    pub bending_saturation_per_m: f64,
    /// The natural curl, 1/m ([`crate::physics::hinge_curl`]); none: no curl term.
    pub curl_per_m: Option<f64>,
    /// Areal density, kg/m².
    pub areal_density_kg_per_m2: f64,
}

impl PatternSheet<'_> {
    /// Lumped masses: a third of each triangle's mass (its rest area's) to each of its vertices, kg.
    pub fn lumped_masses(&self) -> Vec<f64> {
        let p = self.pattern;
        let mut m = vec![0.0; p.vertex_count()];
        for (t, r) in p.triangles.iter().zip(&p.rest_triangles) {
            let [a, b, c] = r.map(|v| p.rest_m[v]);
            let area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])).abs();
            for &v in t {
                m[v] += self.areal_density_kg_per_m2 * area / 3.0;
            }
        }
        m
    }
}

/// The builder of `sheet` under gravity `g_m_per_s2` with the particles `pinned` fixed: lumped
/// masses, membrane, hinge bending (when the bending rigidities are not both zero) and gravity.
pub fn pattern_builder(
    sheet: &PatternSheet<'_>,
    g_m_per_s2: f64,
    pinned: &[usize],
) -> Result<ModelBuilder, MembraneError> {
    let p = sheet.pattern;
    let r = sheet.rigidities;
    let mut fixed = vec![false; p.vertex_count()];
    pinned.iter().for_each(|&v| fixed[v] = true);
    let mut b = ModelBuilder::new(sheet.lumped_masses(), fixed, g_m_per_s2);
    let y = [
        r.tensile_warp_N_per_m,
        r.tensile_weft_N_per_m,
        r.shear_N_per_m,
    ];
    let sewn = SewnSheet {
        rest: &p.rest_m,
        rest_triangles: &p.rest_triangles,
        triangles: &p.triangles,
    };
    b.term(Box::new(Membrane::sewn(&sewn, sheet.warp_angle_rad, y)?));
    if r.bending_warp_N_m > 0.0 || r.bending_weft_N_m > 0.0 {
        b.term(bending(&sewn, sheet));
    }
    if let Some(curl) = sheet.curl_per_m {
        let mean = (r.bending_warp_N_m * r.bending_weft_N_m).sqrt();
        b.term(Box::new(hinge_curl(&sewn, mean, curl)));
    }
    b.gravity();
    Ok(b)
}

/// The sheet's bending: the orthotropic plate from each triangle's quadratic patch
/// ([`patch_bending`], exact on quadratics, the grid's twist rigidity included) where the patches
/// read every crease as curvature across it ([`reads_creases`]: a grid split along one diagonal),
/// else orthotropic hinges ([`sewn_hinge_bending`], which charge every crease but read twist and
/// bending across the diagonals two to three times the plate's). A saturating law bends by hinges
/// (seed 000's Cusick model: [`sewn_hinge_bending`] with its κ₀).
fn bending(sewn: &SewnSheet<'_>, sheet: &PatternSheet<'_>) -> Box<dyn EnergyTerm> {
    let (r, warp_angle_rad) = (sheet.rigidities, sheet.warp_angle_rad);
    let b = [r.bending_warp_N_m, r.bending_weft_N_m];
    let kappa0 = sheet.bending_saturation_per_m;
    let patch = (reads_creases(sewn) && kappa0 == f64::INFINITY)
        .then(|| patch_bending(sewn, [b[0], b[1], r.bending_twist_N_m], warp_angle_rad))
        .flatten();
    match patch {
        Some(p) => Box::new(p),
        None => Box::new(sewn_hinge_bending(sewn, b, warp_angle_rad, kappa0)),
    }
}
