//! `surface`: a drape as a smooth textured surface (seed 003 §10.8) in the files people open —
//! `drape.glb` (binary glTF), a rendered PNG, a rerun recording — from a scene (solved here) or a run
//! folder. [`make_surface`] is what `drapelab surface` and the stage kind share.

use crate::job::Job;
use anyhow::{Context, Result, bail};
use drapelab_core::build::{self, build_scene};
use drapelab_core::error::InputError;
use drapelab_core::error::KeyError;
use drapelab_core::scene::{LoadedScene, Scene, ValidatedScene};
use drapelab_core::solve::{NoObserver, Observer, Status};
use drapelab_core::surface::{
    DrapeSurface, Paint, Parametrization, SurfaceMesh, TextureMapping, View, projected_area,
    render_surface, woven_check,
};
use image::RgbImage;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A drape to dress: its scene, grid positions (m) and which particles belong to the sheet.
pub struct Drape {
    /// The scene it was solved from.
    pub scene: ValidatedScene,
    /// Positions of the grid's particles, index j·nx + i, m.
    pub x: Vec<Vector3<f64>>,
    /// Whether each particle belongs to the sheet (false for a disc's corners).
    pub present: Vec<bool>,
}

/// The error for a run of a mesh sheet: its pattern is a file beside the scene, not in the run.
fn mesh_sheet(file: &Path, key: &str) -> InputError {
    InputError::new(
        file,
        key,
        "a mesh sheet's run reads its pattern beside the scene file it names, which is not there: \
dress the scene file itself (`drapelab surface SCENE.toml`), which solves it",
    )
}

/// The scene of a mesh sheet's run: the recorded scene (its material as solved, the fabric file's
/// name dropped) loaded again beside the scene file the run names, whose folder its mesh paths
/// are relative to; an error naming run.json where that file is gone.
fn mesh_run_scene(
    json: &Path,
    v: &serde_json::Value,
    mut scene: Scene,
) -> Result<drapelab_core::scene::ValidatedScene, InputError> {
    let file = PathBuf::from(v["scene_file"].as_str().unwrap_or(""));
    if !file.is_file() {
        return Err(mesh_sheet(json, "scene_file"));
    }
    scene.material.fabric = None;
    let table = match toml::Value::try_from(&scene) {
        Ok(toml::Value::Table(t)) => t,
        _ => return Err(InputError::new(json, "scene", "cannot be written as TOML")),
    };
    Scene::load_table(&file, table, &[]).map(|l| l.scene)
}

/// The drape of a run folder (or its `run.json`): the scene recorded in `run.json` and the
/// positions of `particles.parquet`; an error when the run did not converge.
pub fn load_run(path: &Path) -> Result<Drape> {
    let json = if path.is_dir() {
        path.join("run.json")
    } else {
        path.to_path_buf()
    };
    let dir = json.parent().unwrap_or(Path::new("."));
    let text = std::fs::read_to_string(&json)
        .map_err(|e| InputError::new(&json, "", format!("cannot read the run record: {e}")))?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| InputError::new(&json, "", format!("not a run record: {e}")))?;
    let status = v["status"].as_str().unwrap_or("unknown");
    if status != Status::Converged.as_str() {
        bail!(
            "{}: the run's status is {status}; only a converged drape is dressed",
            json.display()
        );
    }
    let scene: Scene = serde_json::from_value(v["scene"].clone())
        .map_err(|e| InputError::new(&json, "scene", e.to_string()))?;
    let scene = match scene.cloth.is_mesh() {
        true => mesh_run_scene(&json, &v, scene)?,
        false => scene
            .validated()
            .map_err(|e| InputError::new(&json, format!("scene.{}", e.key), e.message))?,
    };
    let grid = scene.grid();
    let mut x = vec![Vector3::zeros(); grid.len()];
    let particles = dir.join("particles.parquet");
    for (i, j, p) in drapelab_record::read_particles(&particles)? {
        let (i, j) = (i as usize, j as usize);
        if i >= grid.nx || j >= grid.ny {
            bail!(
                "{}: particle ({i}, {j}) outside the {}×{} grid of run.json",
                particles.display(),
                grid.nx,
                grid.ny
            );
        }
        x[grid.index(i, j)] = p;
    }
    let present = build::present_particles(&scene);
    Ok(Drape { scene, x, present })
}

/// The drape of a scene, solved here (statically or as the scene says); an error when it does not
/// converge.
pub fn solve_drape(loaded: &LoadedScene, observer: &mut dyn Observer) -> Result<Drape> {
    let scene = &loaded.scene;
    let built = build_scene(scene);
    let (grid, mut model, mut x) = (built.grid, built.model, built.x0);
    let report = drapelab_core::simulate::solve_model(scene, &grid, &mut model, &mut x, observer);
    if !report.is_converged() {
        bail!(
            "{}: {} ({}); no surface of a drape that did not converge",
            scene.name,
            report.status.as_str(),
            report.message
        );
    }
    x.truncate(grid.len());
    Ok(Drape {
        scene: scene.clone(),
        x,
        present: build::present_particles(scene),
    })
}

/// A mesh sheet dressed on its own triangles: the drape's vertices with area-weighted normals, the
/// texture laid on the flat pattern (its material coordinates: the rest positions in the warp
/// frame), so that a panel's print follows its cut; `resolution` does not apply. The surface's
/// vertices are the rest vertices (a garment's seam vertex once per piece, at one position, so that
/// each piece keeps its own print).
fn dress_mesh(
    drape: &Drape,
    pattern: &drapelab_core::pattern::Pattern,
    params: &SurfaceParams,
    texture_name: &str,
) -> Dressed {
    let (s, c) = drape.scene.cloth.warp_angle_deg.to_radians().sin_cos();
    let material: Vec<[f64; 2]> = pattern
        .rest_m
        .iter()
        .map(|p| [c * p[0] + s * p[1], -s * p[0] + c * p[1]])
        .collect();
    let (lo, hi) = material.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), m| {
            (
                [lo[0].min(m[0]), lo[1].min(m[1])],
                [hi[0].max(m[0]), hi[1].max(m[1])],
            )
        },
    );
    let extent = (lo, [hi[0] - lo[0], hi[1] - lo[1]]);
    let triangles: Vec<[u32; 3]> = pattern
        .rest_triangles
        .iter()
        .map(|t| t.map(|v| v as u32))
        .collect();
    let x = &drape.x[..pattern.vertex_count()];
    let mut vertex_normals = vec![Vector3::zeros(); x.len()];
    for t in &pattern.triangles {
        let [a, b, c] = t.map(|v| x[v]);
        let n = (b - a).cross(&(c - a));
        t.iter().for_each(|&v| vertex_normals[v] += n);
    }
    let positions: Vec<Vector3<f64>> = pattern.vertex_of_rest.iter().map(|&v| x[v]).collect();
    let normals = pattern
        .vertex_of_rest
        .iter()
        .map(|&v| vertex_normals[v].normalize())
        .collect();
    let map = TextureMapping {
        repeats: params.repeats,
        rotation_deg: params.rotation_deg,
    };
    let st = material.iter().map(|m| map.texcoord(*m, extent)).collect();
    let mesh = SurfaceMesh {
        positions,
        normals,
        params: material
            .iter()
            .map(|m| [(m[0] - lo[0]) / extent.1[0], (m[1] - lo[1]) / extent.1[1]])
            .collect(),
        material_m: material,
        triangles,
    };
    let summary = SurfaceSummary {
        scene: drape.scene.name.clone(),
        vertices: mesh.positions.len(),
        triangles: mesh.triangles.len(),
        trimmed: false,
        area_m2: mesh.area_m2(),
        projected_area_m2: mesh.projected_area_m2(),
        mesh_projected_area_m2: projected_area(&mesh.positions, &mesh.triangles),
        max_node_distance_m: 0.0,
        params: params.clone(),
        texture: texture_name.to_string(),
    };
    Dressed { mesh, st, summary }
}

/// How to dress a drape: validated once from the command line or a stage's parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceParams {
    /// Repeats of the texture along the warp and the weft, each > 0. Default [1, 1].
    #[serde(default = "one_one")]
    pub repeats: [f64; 2],
    /// Rotation of the texture on the fabric, degrees. Default 0 (its horizontal along the warp).
    #[serde(default)]
    pub rotation_deg: f64,
    /// Lattice of the parameter square the surface is evaluated on, per side (2..=2000). Default 200.
    #[serde(default = "default_resolution")]
    pub resolution: usize,
    /// Where the picture looks from: azimuth and elevation, degrees. Default [30, 30].
    #[serde(default = "default_view")]
    pub view_deg: [f64; 2],
    /// Size of the picture, px (width, height). Default [1000, 750].
    #[serde(default = "default_picture")]
    pub picture_px: [u32; 2],
}

/// Default of `repeats`: [1, 1].
pub fn one_one() -> [f64; 2] {
    [1.0, 1.0]
}
/// Default of `resolution`: 200 lattice points per side.
pub fn default_resolution() -> usize {
    200
}
/// Default of `view_deg`: azimuth and elevation [30, 30] degrees.
pub fn default_view() -> [f64; 2] {
    [30.0, 30.0]
}
/// Default of `picture_px`: [1000, 750].
pub fn default_picture() -> [u32; 2] {
    [1000, 750]
}

impl Default for SurfaceParams {
    fn default() -> Self {
        Self {
            repeats: one_one(),
            rotation_deg: 0.0,
            resolution: default_resolution(),
            view_deg: default_view(),
            picture_px: default_picture(),
        }
    }
}

impl SurfaceParams {
    /// Checks the values: the offending key and what is wrong.
    pub fn check(&self) -> Result<(), KeyError> {
        if !self.repeats.iter().all(|r| r.is_finite() && *r > 0.0) {
            let m = format!(
                "repeats must be > 0 along both directions (got {:?}), e.g. 6,6",
                self.repeats
            );
            return Err(KeyError::new("repeats", m));
        }
        if !(2..=2000).contains(&self.resolution) {
            return Err(KeyError::new(
                "resolution",
                format!("resolution must be 2..=2000 (got {})", self.resolution),
            ));
        }
        if !self.picture_px.iter().all(|p| (16..=8000).contains(p)) {
            let m = format!(
                "picture sides must be 16..=8000 px (got {:?})",
                self.picture_px
            );
            return Err(KeyError::new("picture_px", m));
        }
        if !self.rotation_deg.is_finite() {
            return Err(KeyError::new(
                "rotation_deg",
                "the rotation must be a finite number of degrees",
            ));
        }
        if !self.view_deg.iter().all(|v| v.is_finite()) {
            return Err(KeyError::new(
                "view_deg",
                "the view's angles must be finite numbers of degrees",
            ));
        }
        Ok(())
    }
}

/// The texture image at `path` (PNG or JPEG) or, without one, drapelab's woven check (256 px);
/// a missing or unreadable file is bad input naming `flag`.
pub fn load_texture(path: Option<&Path>, flag: &str) -> Result<RgbImage, InputError> {
    let Some(path) = path else {
        return Ok(woven_check(256));
    };
    let arg = format!("{flag} {}", path.display());
    let bytes = std::fs::read(path)
        .map_err(|e| InputError::new(&arg, "", format!("cannot read the texture: {e}")))?;
    let img = image::load_from_memory(&bytes)
        .map_err(|e| InputError::new(&arg, "", format!("not a PNG or JPEG image: {e}")))?;
    Ok(img.to_rgb8())
}

/// What [`make_surface`] made, as `surface.json` records it.
#[derive(Debug, Clone, Serialize)]
pub struct SurfaceSummary {
    /// The scene's name.
    pub scene: String,
    /// Vertices and triangles of the evaluated surface.
    pub vertices: usize,
    /// Triangles of the evaluated surface.
    pub triangles: usize,
    /// Whether the drape was trimmed (not a rectangle).
    pub trimmed: bool,
    /// Area of the surface, m².
    pub area_m2: f64,
    /// Area of its vertical projection, m².
    pub projected_area_m2: f64,
    /// Area of the vertical projection of the solver's own mesh, m².
    pub mesh_projected_area_m2: f64,
    /// Largest distance from a node of the drape to the surface at its parameters, m.
    pub max_node_distance_m: f64,
    /// The settings.
    pub params: SurfaceParams,
    /// The texture file, or "woven check (drapelab)".
    pub texture: String,
}

/// The evaluated surface of a drape, with texture coordinates, and its summary.
pub struct Dressed {
    /// The mesh.
    pub mesh: SurfaceMesh,
    /// Texture coordinates of its vertices.
    pub st: Vec<[f64; 2]>,
    /// The summary.
    pub summary: SurfaceSummary,
}

/// The surface of `drape` evaluated as `params` say (uniform knots, as seed 003).
pub fn dress(drape: &Drape, params: &SurfaceParams, texture_name: &str) -> Result<Dressed> {
    if let Some(pattern) = drape.scene.pattern() {
        return Ok(dress_mesh(drape, pattern, params, texture_name));
    }
    let grid = drape.scene.grid();
    let surf = DrapeSurface::new(&grid, &drape.x, &drape.present, Parametrization::Uniform)
        .with_context(|| {
            format!(
                "{}: the drape's grid cannot be interpolated",
                drape.scene.name
            )
        })?;
    let mesh = surf.tessellate(params.resolution);
    let map = TextureMapping {
        repeats: params.repeats,
        rotation_deg: params.rotation_deg,
    };
    let st: Vec<[f64; 2]> = mesh
        .material_m
        .iter()
        .map(|m| map.texcoord(*m, surf.extent_m))
        .collect();
    let (u, v) = &surf.shape.params;
    let max_node_distance_m = (0..grid.len())
        .filter(|&p| drape.present[p])
        .map(|p| (surf.shape.point(u[p % grid.nx], v[p / grid.nx]) - drape.x[p]).norm())
        .fold(0.0, f64::max);
    let kept: Vec<[u32; 3]> = drapelab_core::cloth::grid_triangles(&grid)
        .into_iter()
        .filter(|t| t.iter().all(|&k| drape.present[k as usize]))
        .collect();
    let summary = SurfaceSummary {
        scene: drape.scene.name.clone(),
        vertices: mesh.positions.len(),
        triangles: mesh.triangles.len(),
        trimmed: surf.trim.is_some(),
        area_m2: mesh.area_m2(),
        projected_area_m2: mesh.projected_area_m2(),
        mesh_projected_area_m2: projected_area(&drape.x, &kept),
        max_node_distance_m,
        params: params.clone(),
        texture: texture_name.to_string(),
    };
    Ok(Dressed { mesh, st, summary })
}

/// The picture of a dressed drape (`size` px), textured and lit, from `params.view_deg`.
pub fn picture(
    d: &Dressed,
    texture: &RgbImage,
    params: &SurfaceParams,
    size: (u32, u32),
) -> RgbImage {
    let view = View {
        azimuth_deg: params.view_deg[0],
        elevation_deg: params.view_deg[1],
    };
    render_surface(&d.mesh, &Paint::Texture(texture, &d.st), view, size, 16)
}

/// Where [`make_surface`] writes; any may be left out.
#[derive(Debug, Clone, Default)]
pub struct SurfaceOutputs {
    /// The binary glTF.
    pub glb: Option<PathBuf>,
    /// The rendered picture (PNG, `picture_px`).
    pub picture: Option<PathBuf>,
    /// The rerun recording.
    pub recording: Option<PathBuf>,
    /// The summary (JSON).
    pub summary: Option<PathBuf>,
}

/// Dresses `drape` and writes the outputs asked for (each atomically).
pub fn make_surface(
    drape: &Drape,
    params: &SurfaceParams,
    texture: &RgbImage,
    texture_name: &str,
    out: &SurfaceOutputs,
) -> Result<SurfaceSummary> {
    let d = dress(drape, params, texture_name)?;
    let name = drape.scene.name.as_str();
    let textured = drapelab_record::TexturedSurface {
        mesh: &d.mesh,
        st: &d.st,
        texture,
        name,
    };
    if let Some(p) = &out.glb {
        drapelab_record::write_glb(p, &textured)?;
    }
    if let Some(p) = &out.recording {
        drapelab_record::write_surface_rrd(p, &textured)?;
    }
    if let Some(p) = &out.picture {
        let img = picture(
            &d,
            texture,
            params,
            (params.picture_px[0], params.picture_px[1]),
        );
        drapelab_record::write_atomic(p, |f| {
            img.write_to(&mut std::io::BufWriter::new(f), image::ImageFormat::Png)?;
            Ok(())
        })?;
    }
    if let Some(p) = &out.summary {
        drapelab_record::write_text(p, &serde_json::to_string_pretty(&d.summary)?)?;
    }
    Ok(d.summary)
}

/// The inputs of a surface stage.
pub struct SurfaceInputs {
    /// A scene TOML (solved here) or a run's run.json (its particles.parquet beside it).
    pub drape: PathBuf,
    /// The texture image, PNG or JPEG (default: drapelab's woven check).
    pub texture: Option<PathBuf>,
}

/// The `run` of the stage kind over this workflow.
pub fn run(ctx: &Job<'_, SurfaceInputs>, p: &SurfaceParams) -> Result<()> {
    let path = ctx.inputs.drape.as_path();
    let texture_path = ctx.inputs.texture.as_deref();
    let texture = load_texture(texture_path, "inputs.texture")?;
    ctx.started(1);
    let drape = if path.extension().is_some_and(|e| e == "toml") {
        solve_drape(&Scene::load(path, &[])?, &mut NoObserver)?
    } else {
        load_run(path)?
    };
    let out = SurfaceOutputs {
        glb: ctx.optional_output("glb").map(Path::to_path_buf),
        picture: ctx.optional_output("picture").map(Path::to_path_buf),
        recording: ctx.optional_output("recording").map(Path::to_path_buf),
        summary: ctx.optional_output("summary").map(Path::to_path_buf),
    };
    let name = texture_path.map_or("woven check (drapelab)".to_string(), |t| {
        t.display().to_string()
    });
    make_surface(&drape, p, &texture, &name, &out)?;
    ctx.item_done();
    Ok(())
}
