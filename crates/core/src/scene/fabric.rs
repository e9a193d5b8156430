//! Fabric files (issue 77): a fabric's simulation parameters as a calibration writes them, which a
//! scene takes with `[material] fabric = "FILE.toml"` (relative to the scene file) or
//! `drapelab simulate SCENE --fabric FILE`. The file holds the material's table (`continuum` or
//! `mass_spring`, the keys of `[material.continuum]` / `[material.mass_spring]`), the areal density
//! where it is known, which keys were calibrated with their 2σ intervals, and where it came from:
//!
//! ```toml
//! [fabric]
//! name = "wool (seed 003, Table 10.3)"
//! source = "KES measurements of seed 003, Table 10.3"
//! areal_density_kg_per_m2 = 0.19
//! calibrated = []
//! [fabric.continuum]
//! bending_warp_gf_cm2_per_cm = 0.083
//! ```
//!
//! Keys the file leaves out of `calibrated` are stated defaults, not measured: a Cusick tester
//! measures bending, never tensile or shear rigidity.

use crate::error::InputError;
use crate::material::{Continuum, MassSpring, Material};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// A fabric file's contents.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FabricFile {
    /// The fabric.
    pub fabric: Fabric,
}

/// A fabric: its material model, its areal density where known, and its provenance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fabric {
    /// A name for reports.
    pub name: String,
    /// What the parameters came from (a calibration run and its specimen, a measurement).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// The build that calibrated it ([`crate::provenance::build_id`]), when a calibration wrote it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub build_id: Option<String>,
    /// Mass per area, kg/m², where measured; a scene without one must give
    /// `cloth.areal_density_kg_per_m2`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub areal_density_kg_per_m2: Option<f64>,
    /// Peirce's bending length along the warp, c_warp (BS 3356), m: the continuum's bending
    /// rigidity B_warp = w g c_warp³ from the areal density w the fabric or the scene gives, in
    /// place of `bending_warp_N_m` for a fabric whose weight is unknown (a drape tester measures c).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending_length_warp_m: Option<f64>,
    /// Peirce's bending length along the weft, m (as `bending_length_warp_m`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending_length_weft_m: Option<f64>,
    /// The continuum rigidities (the keys of `[material.continuum]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub continuum: Option<Continuum>,
    /// The mass-spring parameters (the keys of `[material.mass_spring]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_spring: Option<MassSpring>,
    /// The material keys a calibration fitted; the others are stated defaults.
    #[serde(default)]
    pub calibrated: Vec<String>,
    /// Intervals [low, high] of the calibrated keys, in the keys' units: a Cusick calibration's
    /// 2σ (`cusick-fabric`), a knitted calibration's range its photos allow (`knitted-fabric`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub intervals: BTreeMap<String, [f64; 2]>,
}

impl Fabric {
    /// Reads and checks a fabric file: exactly one material model; every calibrated key and every
    /// interval naming a key the model gives; intervals finite and ordered.
    pub fn read(path: &Path) -> Result<Fabric, InputError> {
        let table = crate::config::read_toml_table(path)?;
        let file: FabricFile = crate::config::from_table(path, "", table)?;
        let f = file.fabric;
        let bad = |key: String, m: String| Err(InputError::new(path, key, m));
        let given = match (&f.continuum, &f.mass_spring) {
            (Some(c), None) => {
                let mut keys = table_keys(c);
                for (k, v) in f.bending_lengths() {
                    if !(v.is_finite() && v > 0.0) {
                        return bad(
                            format!("fabric.{k}"),
                            format!("must be a finite length > 0, got {v}"),
                        );
                    }
                    keys.push(k.to_string());
                }
                keys
            }
            (None, Some(m)) => {
                if let Some((k, _)) = f.bending_lengths().first() {
                    return bad(
                        format!("fabric.{k}"),
                        "sets a continuum's bending rigidity; a mass-spring fabric has none: \
remove it or give [fabric.continuum]"
                            .into(),
                    );
                }
                table_keys(m)
            }
            (Some(_), Some(_)) => {
                return bad(
                    "fabric".into(),
                    "give either [fabric.continuum] or [fabric.mass_spring], not both".into(),
                );
            }
            (None, None) => {
                return bad(
                    "fabric".into(),
                    "missing: add [fabric.continuum] or [fabric.mass_spring]".into(),
                );
            }
        };
        if let Some(d) = f
            .areal_density_kg_per_m2
            .filter(|d| !(d.is_finite() && *d > 0.0))
        {
            let m = format!("must be a finite number > 0, got {d}");
            return bad("fabric.areal_density_kg_per_m2".into(), m);
        }
        for k in f.calibrated.iter().chain(f.intervals.keys()) {
            if !given.contains(k) {
                let m = format!("names `{k}`, which the fabric's material does not give");
                return bad("fabric.calibrated".into(), m);
            }
        }
        let ck = super::check_values::Check { path };
        if let Ok(v) = toml::Value::try_from(&f) {
            super::check_values::magnitudes(&ck, &|| "fabric".to_string(), &v)?;
        }
        super::check_values::check_material_model(&f.with_length_rigidities(), &ck, "fabric")?;
        for (k, [lo, hi]) in &f.intervals {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                let m = format!("must be [low, high] with low ≤ high, got [{lo}, {hi}]");
                return bad(format!("fabric.intervals.{k}"), m);
            }
            if let Some(v) = f.value_of(k).filter(|v| !(lo..=hi).contains(&v)) {
                let m = format!(
                    "[{lo}, {hi}] does not hold the fabric's own `{k}` = {v}: an interval brackets its value"
                );
                return bad(format!("fabric.intervals.{k}"), m);
            }
        }
        Ok(f)
    }

    /// The fabric's material with a stand-in rigidity (1 N·m) where a bending length gives it:
    /// what the material's own checks see before the scene's density resolves the length.
    fn with_length_rigidities(&self) -> Material {
        let mut m = self.material();
        if let Some(c) = m.continuum.as_mut() {
            for (k, _) in self.bending_lengths() {
                let (si, kes) = match k {
                    "bending_length_warp_m" => {
                        (&mut c.bending_warp_N_m, c.bending_warp_gf_cm2_per_cm)
                    }
                    _ => (&mut c.bending_weft_N_m, c.bending_weft_gf_cm2_per_cm),
                };
                if si.is_none() && kes.is_none() {
                    *si = Some(1.0);
                }
            }
        }
        m
    }

    /// The value the fabric gives for `key` (a material key or a bending length), where numeric.
    fn value_of(&self, key: &str) -> Option<f64> {
        if let Some((_, v)) = self.bending_lengths().into_iter().find(|(k, _)| *k == key) {
            return Some(v);
        }
        let table = match (&self.continuum, &self.mass_spring) {
            (Some(c), _) => toml::Value::try_from(c).ok()?,
            (_, Some(m)) => toml::Value::try_from(m).ok()?,
            _ => return None,
        };
        let v = table.get(key)?;
        v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
    }

    /// The bending lengths the fabric gives, by key.
    fn bending_lengths(&self) -> Vec<(&'static str, f64)> {
        [
            ("bending_length_warp_m", self.bending_length_warp_m),
            ("bending_length_weft_m", self.bending_length_weft_m),
        ]
        .into_iter()
        .filter_map(|(k, v)| v.map(|v| (k, v)))
        .collect()
    }

    /// The continuum's bending rigidities from the bending lengths (B = w g c³ at areal density
    /// `w` and gravity `g`); an error message where the continuum gives that rigidity too.
    fn resolve_bending_lengths(
        &self,
        material: &mut Material,
        w: f64,
        g: f64,
    ) -> Result<(), String> {
        let Some(c) = material.continuum.as_mut() else {
            return Ok(());
        };
        for (k, len) in self.bending_lengths() {
            let (si, kes) = match k {
                "bending_length_warp_m" => (&mut c.bending_warp_N_m, c.bending_warp_gf_cm2_per_cm),
                _ => (&mut c.bending_weft_N_m, c.bending_weft_gf_cm2_per_cm),
            };
            if si.is_some() || kes.is_some() {
                return Err(format!(
                    "`{k}` and the continuum's rigidity in that direction are both given: keep one"
                ));
            }
            *si = Some(w * g * len.powi(3));
        }
        Ok(())
    }

    /// The scene's material from this fabric.
    pub fn material(&self) -> Material {
        Material {
            mass_spring: self.mass_spring.clone(),
            continuum: self.continuum.clone(),
            fabric: None,
        }
    }

    /// The file's text (TOML), as [`Fabric::read`] reads it.
    pub fn to_toml(&self) -> String {
        let file = FabricFile {
            fabric: self.clone(),
        };
        toml::to_string(&file).unwrap_or_default()
    }
}

/// The keys a material table gives (its serialization's keys with a value).
fn table_keys<T: Serialize>(t: &T) -> Vec<String> {
    match toml::Value::try_from(t) {
        Ok(toml::Value::Table(t)) => t.keys().cloned().collect(),
        _ => Vec::new(),
    }
}

/// Takes a scene's `material.fabric` (read from `scene_path`'s folder when relative): the
/// material's model from the fabric file, and its areal density where it gives one (the fabric's,
/// in place of the scene's), else the scene's. A scene that names a fabric and gives a material
/// model too is refused, as is one where neither gives the areal density.
pub(super) fn apply_fabric(scene: &mut super::Scene, scene_path: &Path) -> Result<(), InputError> {
    let Some(file) = scene.material.fabric.clone() else {
        return Ok(());
    };
    if scene.material.continuum.is_some() || scene.material.mass_spring.is_some() {
        return Err(InputError::new(
            scene_path,
            "material.fabric",
            "give either a fabric file or [material.continuum] / [material.mass_spring], not both",
        ));
    }
    let path = super::files::named_file(scene_path, &file, "material.fabric")?;
    let fabric = Fabric::read(&path)?;
    let mut material = fabric.material();
    material.fabric = Some(file);
    match fabric.areal_density_kg_per_m2 {
        Some(d) => scene.cloth.areal_density_kg_per_m2 = d,
        None if scene.cloth.areal_density_kg_per_m2 == 0.0 => {
            return Err(InputError::new(
                scene_path,
                "cloth.areal_density_kg_per_m2",
                format!(
                    "missing: the fabric file {} gives no areal density; set it in the scene",
                    path.display()
                ),
            ));
        }
        None => {}
    }
    let w = scene.cloth.areal_density_kg_per_m2;
    fabric
        .resolve_bending_lengths(&mut material, w, scene.gravity.g_m_per_s2)
        .map_err(|m| InputError::new(&path, "fabric", m))?;
    scene.material = material;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fabric_written_reads_back_the_same() {
        let dir = tempfile::tempdir().unwrap();
        let f = Fabric {
            name: "limp".into(),
            source: Some("a calibration".into()),
            build_id: Some("0123456789abcdef".into()),
            areal_density_kg_per_m2: Some(0.12),
            bending_length_warp_m: None,
            bending_length_weft_m: None,
            continuum: Some(Continuum {
                bending_warp_N_m: Some(2.5e-6),
                bending_weft_N_m: Some(1.5e-6),
                tensile_warp_N_per_m: Some(1000.0),
                tensile_weft_N_per_m: Some(800.0),
                shear_N_per_m: Some(40.0),
                ..Continuum::default()
            }),
            mass_spring: None,
            calibrated: vec!["bending_warp_N_m".into()],
            intervals: [("bending_warp_N_m".to_string(), [2.0e-6, 3.0e-6])].into(),
        };
        let path = dir.path().join("limp.toml");
        std::fs::write(&path, f.to_toml()).unwrap();
        assert_eq!(Fabric::read(&path).unwrap(), f);
    }

    #[test]
    fn a_fabric_that_names_what_it_does_not_give_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.toml");
        let cases = [
            ("[fabric]\nname = \"x\"\n", "fabric"),
            (
                "[fabric]\nname = \"x\"\ncalibrated = [\"shear_N_per_m\"]\n[fabric.continuum]\nbending_warp_N_m = 1e-6\nbending_weft_N_m = 1e-6\n",
                "fabric.calibrated",
            ),
            (
                "[fabric]\nname = \"x\"\nareal_density_kg_per_m2 = -1.0\n[fabric.continuum]\nbending_warp_N_m = 1e-6\n",
                "fabric.areal_density_kg_per_m2",
            ),
            ("[fabric]\nname = \"x\"\ncolour = 3\n", "fabric.colour"),
        ];
        for (text, key) in cases {
            std::fs::write(&path, text).unwrap();
            let e = Fabric::read(&path).unwrap_err();
            assert_eq!(e.key, key, "{text}: {e}");
        }
    }
}
