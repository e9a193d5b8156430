//! `drapelab surface`: a drape dressed as a smooth textured surface (seed 003 §10.8).

use super::progress::SolveProgress;
use crate::app::surface::{
    SurfaceOutputs, SurfaceParams, load_run, load_texture, make_surface, solve_drape,
};
use crate::error::{EXIT_OK, InputError};
use anyhow::Result;
use std::path::{Path, PathBuf};

/// The flags of `drapelab surface`, as typed (checked once by [`surface`]).
#[derive(clap::Args, Debug)]
pub struct SurfaceArgs {
    /// A scene TOML (solved here) or a run folder (or its run.json) written by `simulate`.
    #[arg(value_name = "SCENE_OR_RUN")]
    pub source: PathBuf,
    /// Output folder (created; files are written atomically).
    #[arg(long)]
    pub out: PathBuf,
    /// The fabric's texture image, PNG or JPEG (default: drapelab's woven check, 256 px).
    #[arg(long)]
    pub texture: Option<PathBuf>,
    /// Repeats of the texture along the warp and the weft, U,V (or one number for both), each > 0:
    /// 1 lays the image once over the sheet, 6,6 as seed 003's Fig. 10.28.
    #[arg(long, default_value = "1,1", allow_hyphen_values = true)]
    pub repeats: String,
    /// Rotation of the texture on the fabric, degrees counter-clockwise (0: its horizontal along
    /// the warp).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub rotation_deg: f64,
    /// Lattice of the surface's parameter square, points per side (2..=2000).
    #[arg(long, default_value_t = 200)]
    pub resolution: usize,
    /// Where the picture looks from: azimuth,elevation in degrees (90 elevation: from above).
    #[arg(long, default_value = "30,30", allow_hyphen_values = true)]
    pub view: String,
    /// Scene overrides when SCENE_OR_RUN is a scene, as for simulate.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

/// Parses "A,B" (or "A" for both) as two numbers; `flag` names the flag in the error.
fn pair(s: &str, flag: &str) -> Result<[f64; 2], InputError> {
    match super::edges::numbers(s, flag, "two numbers A,B (or one for both), e.g. 6,6")?.as_slice()
    {
        [a] => Ok([*a, *a]),
        [a, b] => Ok([*a, *b]),
        v => Err(InputError::new(
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
    params.check().map_err(|e| {
        let (k, m) = (e.key, e.message);
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
