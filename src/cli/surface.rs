//! `drapelab surface`: a drape dressed as a smooth textured surface (seed 003 §10.8).

use super::progress::SolveProgress;
use crate::error::{EXIT_OK, InputError};
use crate::stages::{
    SurfaceOutputs, SurfaceParams, load_run, load_texture, make_surface, solve_drape,
};
use anyhow::Result;
use std::path::{Path, PathBuf};

/// The raw flags of `drapelab surface`.
pub struct SurfaceArgs {
    pub source: PathBuf,
    pub out: PathBuf,
    pub texture: Option<PathBuf>,
    pub repeats: String,
    pub rotation_deg: f64,
    pub resolution: usize,
    pub view: String,
    pub set: Vec<String>,
}

/// Parses "A,B" (or "A" for both) as two numbers; `flag` names the flag in the error.
fn pair(s: &str, flag: &str) -> Result<[f64; 2], InputError> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            InputError::new(
                format!("{flag} {s}"),
                "",
                "expected two numbers A,B (or one for both), e.g. 6,6",
            )
        })?;
    match v.as_slice() {
        [a] => Ok([*a, *a]),
        [a, b] => Ok([*a, *b]),
        _ => Err(InputError::new(
            format!("{flag} {s}"),
            "",
            format!("expected two numbers A,B, got {}", v.len()),
        )),
    }
}

/// Runs `drapelab surface`: every flag checked before any work, then the drape loaded (a run
/// folder) or solved (a scene), then DIR/drape.glb, drape.png, surface.rrd and surface.json.
pub fn surface(a: SurfaceArgs) -> Result<i32> {
    let params = SurfaceParams {
        repeats: pair(&a.repeats, "--repeats")?,
        rotation_deg: a.rotation_deg,
        resolution: a.resolution,
        view_deg: pair(&a.view, "--view")?,
        picture_px: [1000, 750],
    };
    params.check().map_err(|(k, m)| {
        let flag = if k == "view_deg" {
            "--view".to_string()
        } else {
            format!("--{}", k.replace('_', "-"))
        };
        InputError::new(flag, "", m)
    })?;
    let texture = load_texture(a.texture.as_deref(), "--texture")?;
    let src = &a.source;
    let is_run = src.is_dir() || src.extension().is_some_and(|e| e == "json");
    let drape = if is_run {
        load_run(src)?
    } else if src.extension().is_some_and(|e| e == "toml") {
        let loaded = super::load_scene(src, &a.set)?;
        let mut progress = SolveProgress::new(&loaded.scene.name);
        solve_drape(&loaded, &mut progress)?
    } else {
        return Err(InputError::new(
            src,
            "",
            "expected a scene .toml, a run folder or its run.json",
        )
        .into());
    };
    std::fs::create_dir_all(&a.out)
        .map_err(|e| InputError::new(format!("--out {}", a.out.display()), "", e.to_string()))?;
    let out = SurfaceOutputs {
        glb: Some(a.out.join("drape.glb")),
        picture: Some(a.out.join("drape.png")),
        recording: Some(a.out.join("surface.rrd")),
        summary: Some(a.out.join("surface.json")),
    };
    let name = a
        .texture
        .as_deref()
        .map_or("woven check (drapelab)".to_string(), |p: &Path| {
            p.display().to_string()
        });
    let s = make_surface(&drape, &params, &texture, &name, &out)?;
    eprintln!(
        "{}: surface of {} vertices, {} triangles{}, {:.4} m² ({:.4} m² projected; the solver's mesh {:.4} m²), nodes within {:.1e} m → {}",
        s.scene,
        s.vertices,
        s.triangles,
        if s.trimmed { ", trimmed" } else { "" },
        s.area_m2,
        s.projected_area_m2,
        s.mesh_projected_area_m2,
        s.max_node_distance_m,
        a.out.display()
    );
    Ok(EXIT_OK)
}
