//! A garment sewn from a sewing pattern as the scene's sheet (`cloth.pattern`, issue 91): read,
//! meshed, arranged and sewn when the scene is loaded ([`crate::sewing`]), so that every reader of
//! the scene (simulate, surface, sweeps, Python) sees the welded garment. A scene loaded twice in
//! one process is sewn once (the sewn garment is kept by a hash of everything sewing reads).

use super::{ClothSpec, Scene};
use crate::error::InputError;
use crate::pattern::Pattern;
use crate::sewing::sew::{SewReport, SewSetup, sew};
use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

type Sewn = (Arc<Pattern>, Arc<SewReport>);

fn sewn_before() -> &'static Mutex<HashMap<blake3::Hash, Sewn>> {
    static CACHE: OnceLock<Mutex<HashMap<blake3::Hash, Sewn>>> = OnceLock::new();
    CACHE.get_or_init(Default::default)
}

/// The smallest and largest sewing resolution, m.
const RESOLUTION_M: (f64, f64) = (1e-3, 0.2);

impl ClothSpec {
    /// Whether the sheet is a garment sewn from a sewing pattern (`cloth.pattern`).
    pub fn is_sewn(&self) -> bool {
        self.sewing_pattern.is_some()
    }
}

/// Sews the scene's `cloth.pattern` (when given) into `cloth.pattern`'s sheet; errors name the
/// JSON file and its key, or the scene file and its key.
pub(super) fn sew_pattern(scene: &mut Scene, scene_path: &Path) -> Result<(), InputError> {
    let Some(file) = scene.cloth.sewing_pattern.clone() else {
        return Ok(());
    };
    let at = |k: &str, m: String| InputError::new(scene_path, k, m);
    if scene.cloth.mesh.is_some() {
        return Err(at(
            "cloth.pattern",
            "and cloth.mesh are both given: a sheet is one or the other".into(),
        ));
    }
    let (lo, hi) = RESOLUTION_M;
    let r = scene.cloth.resolution_m;
    if !(r.is_finite() && (lo..=hi).contains(&r)) {
        return Err(at(
            "cloth.resolution_m",
            format!("must be from {lo} to {hi} m, got {r}"),
        ));
    }
    let path = super::files::named_file(scene_path, &file, "cloth.pattern")?;
    let text = crate::textfile::read_text(&path, crate::textfile::NonUtf8::Refuse)
        .map_err(|e| InputError::new(&path, "", e))?;
    let bad = |d: crate::pattern::Defect| InputError::new(&path, d.key, d.message);
    let spec = crate::sewing::parse(&text).map_err(bad)?;
    let unsewn = crate::sewing::unsewn(&spec, r).map_err(bad)?;
    if let Some(m) = crate::memory::too_large(unsewn.start_m.len() as f64) {
        return Err(at("cloth.resolution_m", m));
    }
    let (rigidities, thickness) = fabric_of(scene, scene_path, r)?;
    let setup = SewSetup {
        rigidities: &rigidities,
        areal_density_kg_per_m2: scene.cloth.areal_density_kg_per_m2,
        warp_angle_rad: scene.cloth.warp_angle_deg.to_radians(),
        obstacles: &scene.obstacles,
        // Sewn a quarter of the spacing off the body at least: an edge between two vertices held
        // off a curved body by the barrier dips towards it by L²/8R, and the welded start must not
        // cut into it (the scene's check of the sheet's edges).
        distance_m: scene.contact.distance_m.max(0.25 * r),
        thickness_m: thickness,
    };
    let key = blake3::hash(
        format!(
            "{text}\n{r}\n{rigidities:?}\n{:?}\n{}\n{}\n{thickness}\n{}",
            scene.obstacles, setup.areal_density_kg_per_m2, setup.warp_angle_rad, setup.distance_m
        )
        .as_bytes(),
    );
    let cached = sewn_before()
        .lock()
        .map(|c| c.get(&key).cloned())
        .ok()
        .flatten();
    let (pattern, report) = match cached {
        Some(s) => s,
        None => {
            let (p, rep) = sew(
                &unsewn,
                &setup,
                &mut |line| eprintln!("{line}"),
                &mut crate::solve::NoObserver,
            )
            .map_err(bad)?;
            let s = (Arc::new(p), Arc::new(rep));
            if let Ok(mut c) = sewn_before().lock() {
                c.insert(key, s.clone());
            }
            s
        }
    };
    scene.cloth.pattern = Some(pattern);
    scene.cloth.sewing = Some(report);
    Ok(())
}

/// The fabric's rigidities and the sewing's self-contact thickness (the scene's, or the fabric's,
/// at most a tenth of the resolution `r`).
fn fabric_of(
    scene: &Scene,
    scene_path: &Path,
    r: f64,
) -> Result<(crate::material::Rigidities, f64), InputError> {
    let at = |k: &str, m: String| InputError::new(scene_path, k, m);
    let continuum = scene.material.continuum.as_ref().ok_or_else(|| {
        at(
            "material",
            "a sewn garment needs [material.continuum] (or a fabric file): its membrane holds the seams".into(),
        )
    })?;
    let rigidities = continuum
        .rigidities()
        .map_err(|e| at(&format!("material.continuum.{}", e.key), e.message))?;
    let thickness = scene
        .contact
        .self_thickness_m
        .or(continuum.thickness_m)
        .unwrap_or(1e-3)
        .min(0.1 * r);
    Ok((rigidities, thickness))
}
