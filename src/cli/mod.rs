//! The command line: clap arguments become one validated configuration, once (ripgrep's habit);
//! [`run`] returns the process exit code.

mod args;
mod bench;
pub mod edges;
mod progress;
mod surface;

pub use progress::SolveProgress;

use crate::config::parse_override;
use crate::error::{EXIT_FAILED, EXIT_OK, InputError};
use crate::scene::{LoadedScene, Scene};
use anyhow::Result;
use clap::{Parser, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};

/// drapelab: simulate how fabric drapes, measure drape, calibrate and validate models, record every run.
///
/// Units are SI inside and named in every key (`stiffness_N_per_m`, `x_m`). Exit codes: 0 success,
/// 1 a solve or stage failed (its status is written into the outputs), 2 bad input.
#[derive(Debug, Parser)]
#[command(name = "drapelab", version, about, long_about)]
pub struct Cli {
    /// More log lines (-v: debug, e.g. why each stage is stale; -vv: trace); RUST_LOG overrides.
    #[arg(short, long, global = true, action = clap::ArgAction::Count)]
    pub verbose: u8,
    /// Only errors.
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    pub quiet: bool,
    #[command(subcommand)]
    pub command: Command,
}

/// Which hang a photo shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ViewArg {
    /// Four corners pinned: one edge, the lower boundary.
    Hang4,
    /// Two corners pinned: top, bottom, left and right edges.
    Hang2,
}

impl From<ViewArg> for crate::edges::View {
    fn from(v: ViewArg) -> Self {
        match v {
            ViewArg::Hang4 => crate::edges::View::Hang4,
            ViewArg::Hang2 => crate::edges::View::Hang2,
        }
    }
}

/// Where the items of a stage run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ExecutorArg {
    /// This process's threads (--jobs).
    Local,
    /// Slurm job arrays.
    Slurm,
}

impl From<ExecutorArg> for crate::pipeline::ExecutorKind {
    fn from(e: ExecutorArg) -> Self {
        match e {
            ExecutorArg::Local => crate::pipeline::ExecutorKind::Local,
            ExecutorArg::Slurm => crate::pipeline::ExecutorKind::Slurm,
        }
    }
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Solve one scene and record it.
    ///
    /// Writes particles.parquet, triangles.parquet, run.json and, when the scene's [record] asks,
    /// timeline.mcap (Foxglove) and drape.rrd (rerun) into DIR; with --obj also drape.obj.
    ///
    /// Example: drapelab simulate datasets/scenes/hang4.toml --out runs/hang4 --set cloth.nx=41 --set cloth.ny=41
    Simulate {
        /// The scene file, e.g. datasets/scenes/hang4.toml.
        scene: PathBuf,
        /// Output folder (created; files are written atomically).
        #[arg(long)]
        out: PathBuf,
        /// Override any scene key by its dotted path, e.g. --set cloth.nx=41 --set solver.kind=implicit-euler
        /// --set record.timeline=true. Repeatable.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Also write sensitivity.parquet: how every particle of the converged drape moves per unit
        /// of this continuous scene key (dx*/dθ = −H⁻¹ ∂g/∂θ, from the factor of the exact Hessian
        /// at the equilibrium; one back-substitution per key), e.g. --sensitivity
        /// material.mass_spring.stiffness_N_per_m. Repeatable. A state that did not converge or is
        /// no minimum gets none, and run.json says why.
        #[arg(long = "sensitivity", value_name = "KEY")]
        sensitivity: Vec<String>,
        /// Start the solve from a saved drape (a particles.parquet or last_state.parquet of the same
        /// scene and grid) instead of the scene's own start: a restart.
        #[arg(long, value_name = "FILE")]
        start: Option<PathBuf>,
        /// Also write the converged drape as drape.obj (Wavefront OBJ, metres; every particle a
        /// vertex in particles.parquet's order) for Blender, MeshLab or a CAD tool.
        /// triangles.parquet (the same faces as row indices) is written beside every state.
        #[arg(long)]
        obj: bool,
    },
    /// Run a pipeline make-style (only stale stages).
    ///
    /// A stage runs when its inputs' content, parameters or the drapelab build changed since its
    /// manifest; items run in parallel; artifacts go under runs/<pipeline>/. A failing (or panicking)
    /// stage fails alone: the run goes on as far as the graph allows and exits 1.
    ///
    /// Example: drapelab run pipelines/main.toml --jobs 2
    Run {
        /// The pipeline file, e.g. pipelines/main.toml.
        pipeline: PathBuf,
        /// Run only this stage and the stages it depends on.
        #[arg(long, value_name = "STAGE")]
        until: Option<String>,
        /// Rerun this stage and everything downstream of it even if up to date. Repeatable.
        #[arg(long, value_name = "STAGE")]
        force: Vec<String>,
        /// Threads for the items of a stage (0 = all cores).
        #[arg(long, default_value_t = 0)]
        jobs: usize,
        /// Print what would run and why; run nothing.
        #[arg(long)]
        dry_run: bool,
        /// Where the items of sweep and calibrate stages run, overriding the pipeline's [executor]
        /// kind: local (this process's threads) or slurm (one `sbatch --array` job per stage; needs
        /// a filesystem shared with the nodes; docs/src/guide/slurm.md).
        #[arg(long, value_enum)]
        executor: Option<ExecutorArg>,
        /// When another `drapelab run` holds this pipeline's run folder, wait for it to finish
        /// instead of exiting with 2.
        #[arg(long)]
        wait: bool,
    },
    /// Compute some items of a stage, as one Slurm array task does (`drapelab run --executor slurm`
    /// writes the task list and calls this; not needed by hand, so hidden from --help).
    ///
    /// Reads line TASK (0-based) of the task list: the items to compute. Items that already have a
    /// part are skipped; the parts folder must be that of the stage's current inputs.
    #[command(hide = true)]
    Worker {
        /// The pipeline file.
        pipeline: PathBuf,
        /// The stage whose items to compute.
        #[arg(long)]
        stage: String,
        /// The task list (one line of item numbers per task).
        #[arg(long)]
        tasks: PathBuf,
        /// The task (line) to run, 0-based: $SLURM_ARRAY_TASK_ID.
        #[arg(long)]
        task: usize,
    },
    /// Say which stages of a pipeline are stale, and why.
    ///
    /// Each stage is up to date, or stale with the reason (which input or parameter changed).
    Status {
        /// The pipeline file.
        pipeline: PathBuf,
        /// Exit with 1 when a stage is stale (for scripts and CI).
        #[arg(long)]
        check: bool,
    },
    /// List the stage kinds a pipeline may use, with their input and output slots and their
    /// parameters' defaults (units are in the names).
    Kinds,
    /// Print a shell completion script, e.g. `drapelab completions bash > ~/.local/share/bash-completion/completions/drapelab`.
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// List every Parquet table drapelab writes: its columns (units in the names), types, nullability.
    ///
    /// The listing is traced from the tables' row types, the one place each schema is written; the
    /// book's Tables page (docs/src/reference/tables.md) is this output.
    Tables,
    /// Dress a drape as a smooth textured surface (seed 003 §10.8) for 3D tools and pictures.
    ///
    /// The drape (a scene, solved here, or a run folder from `simulate`) is interpolated by a bicubic
    /// B-spline surface through every particle; a disc or skirt is first extended to the rectangle
    /// and then trimmed along its outline (B-spline curves in the parameter plane). A texture (PNG or
    /// JPEG; default drapelab's woven check) is laid on the fabric's warp and weft with the given
    /// repeats. Writes DIR/drape.glb (binary glTF 2.0, metres, +Y up: Blender, three.js, any glTF
    /// viewer), drape.png (the textured drape rendered), surface.rrd (rerun) and surface.json (counts,
    /// areas, settings).
    ///
    /// Example: drapelab surface datasets/scenes/skirt_wool.toml --out runs/skirt_surface --repeats 6,6
    Surface(surface::SurfaceArgs),
    /// Solve a 4- or 2-corner hang and render it as a photo.
    ///
    /// The camera faces the sheet (along +y). Writes DIR/photo.png (or .jpg), camera.json (exact
    /// scale and corner pixels), particles.parquet, and edges_truth.parquet (the same edge fit made
    /// straight from the particles).
    ///
    /// Example: drapelab render datasets/scenes/hang4.toml --out runs/photo --px-per-cm 8 --markers --noise 4
    #[command(allow_negative_numbers = true)]
    Render(RenderArgs),
    /// Fit the edges of a photo of a hanging sheet with polynomials (seed 000).
    ///
    /// Seed 000 Figs 3, 11, 12. Writes DIR/edges.parquet (edge, power, coefficient of x^power in cm,
    /// RMS residual, points) and DIR/overlay.png (fitted curves red, reference line blue). Calibrate
    /// with --px-per-cm and --corners, or --markers and --side-cm, or --camera-json (a camera file
    /// as docs/src/guide/photos.md describes it, or the one `render` writes).
    FitEdges(FitEdgesArgs),
    /// Score simulated edges against measured ones (seed 000 Eq. 5).
    ///
    /// Per edge: Eq. 5 (coefficients in coordinates centred on the edge, in %) and the RMS distance
    /// between the curves (% of the side).
    Score {
        /// Measured edges.parquet.
        real: PathBuf,
        /// Simulated edges.parquet.
        sim: PathBuf,
        /// Side of the sample, cm.
        #[arg(long, default_value_t = 50.0, value_parser = args::positive)]
        side_cm: f64,
    },
    /// Tension-field wrinkles of vertically hung fabric (seed 002).
    ///
    /// Number n, ratio Q and depth z_max of the wrinkles for every case of CONFIG, with the deformed
    /// grids. Writes DIR/wrinkles.parquet, DIR/mesh.parquet, DIR/wrinkles.rrd and DIR/wrinkles.md
    /// (the seed's results beside ours).
    ///
    /// Example: drapelab wrinkles datasets/wrinkles/seed_tables.toml --out runs/wrinkles
    Wrinkles {
        /// The cases, e.g. datasets/wrinkles/seed_tables.toml.
        config: PathBuf,
        /// Output folder (created; files are written atomically).
        #[arg(long)]
        out: PathBuf,
        /// Points per row and rows of the deformed grid.
        #[arg(long, num_args = 2, value_names = ["NX", "NY"], default_values_t = [41, 81], value_parser = args::mesh_side())]
        mesh: Vec<usize>,
    },
    /// Time to equilibrium of hang4 against error, every solver.
    ///
    /// Each resolution with every solver, and each result's distance to the finest static solution;
    /// prints a Markdown table.
    Bench(BenchArgs),
}

/// The flags of `drapelab render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// The scene (4 or 2 pinned corners).
    pub scene: PathBuf,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Scene overrides, as for simulate.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Scale in the plane of the fixed corners, px per cm (> 0, ≤ 200).
    #[arg(long, default_value_t = 8.0, value_parser = args::px_per_cm)]
    pub px_per_cm: f64,
    /// Pinhole camera at this distance (m) in front of the corners' plane; default orthographic.
    #[arg(long, value_parser = args::positive)]
    pub pinhole_distance_m: Option<f64>,
    /// Draw red markers at the two fixed corners.
    #[arg(long)]
    pub markers: bool,
    /// Gaussian noise, grey levels (σ ≥ 0).
    #[arg(long, default_value_t = 0.0, value_parser = args::non_negative)]
    pub noise: f64,
    /// Gaussian blur, px (σ ≥ 0).
    #[arg(long, default_value_t = 0.0, value_parser = args::non_negative)]
    pub blur_px: f64,
    /// Camera rotation about its axis, degrees (negative: clockwise).
    #[arg(long, default_value_t = 0.0, value_parser = args::finite)]
    pub rotate_deg: f64,
    /// Save as JPEG with this quality (1..=100) instead of PNG.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=100))]
    pub jpeg_quality: Option<u8>,
    /// Seed of the noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// The flags of `drapelab fit-edges`.
#[derive(Debug, clap::Args)]
pub struct FitEdgesArgs {
    /// The photo (PNG or JPEG).
    pub photo: PathBuf,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Scale in the plane of the fixed corners, px per cm.
    #[arg(long, value_parser = args::positive)]
    pub px_per_cm: Option<f64>,
    /// Pixel positions of the two fixed corners: x1,y1,x2,y2 (pixel centres at integers, as
    /// image viewers and OpenCV number them).
    #[arg(long)]
    pub corners: Option<String>,
    /// Find the corners from two red markers (needs --side-cm).
    #[arg(long)]
    pub markers: bool,
    /// Distance between the fixed corners, cm (with --markers).
    #[arg(long, value_parser = args::positive)]
    pub side_cm: Option<f64>,
    /// A camera.json: view, side_cm, the scale (px_per_cm or a pinhole) and the corners
    /// (corners_px or markers); `render`'s own settings are optional.
    #[arg(long)]
    pub camera_json: Option<PathBuf>,
    /// Which hang the photo shows (ignored with --camera-json, which names it).
    #[arg(long, value_enum, default_value_t = ViewArg::Hang4)]
    pub view: ViewArg,
    /// Polynomial degree (1..=8).
    #[arg(long, default_value_t = 4, value_parser = args::degree())]
    pub degree: usize,
}

/// The flags of `drapelab bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// The hang4 scene to benchmark.
    #[arg(long, default_value = "datasets/scenes/hang4.toml")]
    pub scene: PathBuf,
    /// Particles per side to run (comma-separated, each 3..=1001).
    #[arg(long, value_delimiter = ',', default_value = "11,21,41,81", value_parser = args::grid_side())]
    pub sizes: Vec<usize>,
    /// Largest size at which the explicit and symplectic integrators are run (they are slow).
    #[arg(long, default_value_t = 21)]
    pub max_explicit_size: usize,
    /// Largest size at which implicit Euler is run.
    #[arg(long, default_value_t = 41)]
    pub max_implicit_size: usize,
    /// Force tolerance of every solver, relative to the lightest particle's weight (> 0).
    #[arg(long, default_value_t = 1e-6, value_parser = args::positive)]
    pub tol: f64,
    /// Static solves of seed 000's slack-net population (14 × 14 over Table 3's box) to run
    /// after the hang4 table, for its iterations and factorizations per solve (0: none).
    #[arg(long, default_value_t = 50)]
    pub population: usize,
    /// Run the whole benchmark pipeline instead (pipelines/benchmark.toml: every reference scene,
    /// solver, size and tolerance, the scipy/numpy peers, the skips, reports/benchmark.md; only
    /// stale stages run).
    #[arg(long)]
    pub all: bool,
}

/// `drapelab run`: runs a pipeline make-style with a progress display; returns the exit code.
/// With `quiet` (`-q`), only errors: no summary line.
fn run_pipeline_command(
    pipeline: &Path,
    quiet: bool,
    opts: crate::pipeline::RunOptions,
) -> Result<i32> {
    run_pipeline_quietly(pipeline, opts, &crate::stages::registry(), quiet)
}

/// Runs a pipeline with the stage kinds of `registry` (drapelab's own, or those plus a program's
/// own kinds); 0 when every stage ran or was up to date, 1 when one failed (an error, a panic or a
/// missing output: the run goes on as far as the graph allows), bad input an error.
pub fn run_pipeline_with(
    pipeline: &Path,
    opts: crate::pipeline::RunOptions,
    registry: &crate::pipeline::Registry,
) -> Result<i32> {
    run_pipeline_quietly(pipeline, opts, registry, false)
}

/// [`run_pipeline_with`]; with `quiet`, the summary line is left out (failures are still said).
pub fn run_pipeline_quietly(
    pipeline: &Path,
    opts: crate::pipeline::RunOptions,
    registry: &crate::pipeline::Registry,
    quiet: bool,
) -> Result<i32> {
    let plan = crate::pipeline::load_checked_plan(pipeline, registry)?;
    let progress = crate::pipeline::progress_for_terminal();
    let summary = crate::pipeline::run_pipeline(&plan, &opts, progress.as_ref())?;
    for (name, why) in &summary.would_run {
        println!("would run {name}: {why}");
    }
    if !quiet {
        eprintln!(
            "{}: {} ran, {} up to date, {} failed{}",
            plan.name,
            summary.ran.len(),
            summary.skipped.len(),
            summary.failed.len(),
            if opts.dry_run { " (dry run)" } else { "" }
        );
    }
    for (name, why) in &summary.failed {
        eprintln!("  {name}: {why}");
    }
    Ok(if summary.failed.is_empty() {
        EXIT_OK
    } else {
        EXIT_FAILED
    })
}

/// `drapelab worker`: the items of line `task` of the task list, computed into their parts.
fn worker(pipeline: &Path, stage: &str, tasks: &Path, task: usize) -> Result<i32> {
    let plan = crate::pipeline::load_plan(pipeline, &crate::stages::registry())?;
    let text = std::fs::read_to_string(tasks)
        .map_err(|e| InputError::new(tasks, "", format!("cannot read the task list: {e}")))?;
    let line = text.lines().nth(task).ok_or_else(|| {
        InputError::new(
            "--task",
            "",
            format!("{} has no line {task}", tasks.display()),
        )
    })?;
    let items = line
        .split_whitespace()
        .map(|w| w.parse::<usize>())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| InputError::new(tasks, format!("line {task}"), e.to_string()))?;
    crate::pipeline::run_worker(&plan, stage, &items)?;
    Ok(EXIT_OK)
}

/// Loads a scene with `--set KEY=VALUE` overrides; an error caused by an override names the flag.
pub fn load_scene(path: &Path, sets: &[String]) -> Result<LoadedScene, InputError> {
    let overrides = sets
        .iter()
        .map(|s| parse_override(s))
        .collect::<Result<Vec<_>, InputError>>()?;
    Scene::load(path, &overrides).map_err(|e| {
        match crate::config::override_culprit(&e.key, &overrides) {
            Some(i) => InputError::new(
                format!("--set {} (over {})", sets[i], path.display()),
                e.key,
                e.message,
            ),
            None => e,
        }
    })
}

/// Runs the parsed command line; returns the exit code.
pub fn run(cli: Cli) -> Result<i32> {
    let quiet = cli.quiet;
    match cli.command {
        Command::Simulate {
            scene,
            out,
            set,
            sensitivity,
            start,
            obj,
        } => simulate(
            &scene,
            &out,
            &set,
            (&sensitivity, start.as_deref(), obj),
            quiet,
        ),
        Command::Run {
            pipeline,
            until,
            force,
            jobs,
            dry_run,
            executor,
            wait,
        } => run_pipeline_command(
            &pipeline,
            quiet,
            crate::pipeline::RunOptions {
                until,
                force,
                jobs,
                dry_run,
                executor: executor.map(Into::into),
                wait: if wait {
                    crate::pipeline::LockWait::Yes
                } else {
                    crate::pipeline::LockWait::No
                },
            },
        ),
        Command::Worker {
            pipeline,
            stage,
            tasks,
            task,
        } => worker(&pipeline, &stage, &tasks, task),
        Command::Status { pipeline, check } => status(&pipeline, check),
        Command::Completions { shell } => {
            use clap::CommandFactory;
            let mut out = std::io::stdout();
            clap_complete::generate(shell, &mut Cli::command(), "drapelab", &mut out);
            Ok(EXIT_OK)
        }
        Command::Kinds => {
            print!("{}", kinds_text());
            Ok(EXIT_OK)
        }
        Command::Tables => {
            print!("{}", crate::app::tables_markdown()?);
            Ok(EXIT_OK)
        }
        Command::Surface(args) => surface::surface(args),
        Command::Render(a) => render(a),
        Command::FitEdges(a) => fit_edges_command(a),
        Command::Wrinkles { config, out, mesh } => wrinkles(&config, &out, &mesh),
        Command::Score { real, sim, side_cm } => score(&real, &sim, side_cm),
        Command::Bench(a) => bench_command(a),
    }
}

/// `drapelab render`: solve a hang and render it as a photo.
fn render(a: RenderArgs) -> Result<i32> {
    let loaded = load_scene(&a.scene, &a.set)?;
    let opts = render_options(
        a.px_per_cm,
        a.pinhole_distance_m,
        a.markers,
        a.noise,
        a.blur_px,
        a.rotate_deg,
        a.seed,
    )?;
    let _out = args::out_dir(&a.out)?;
    let path = crate::io::render_scene(&loaded, &a.out, &opts, a.jpeg_quality, 4)?;
    eprintln!("rendered {} → {}", loaded.scene.name, path.display());
    Ok(EXIT_OK)
}

/// `drapelab fit-edges`: the flags into a calibration, then the fit.
fn fit_edges_command(a: FitEdgesArgs) -> Result<i32> {
    let calibration = FitCalibration {
        px_per_cm: a.px_per_cm,
        corners: a.corners,
        markers: a.markers,
        side_cm: a.side_cm,
        camera_json: a.camera_json,
    };
    fit_edges(&a.photo, &a.out, calibration, a.view, a.degree)
}

/// `drapelab score`: Eq. 5 and the curve distance per edge, as a Markdown table.
fn score(real: &Path, sim: &Path, side_cm: f64) -> Result<i32> {
    let rows = crate::io::score_files(real, sim, side_cm)?;
    println!(
        "| edge | objective (Eq. 5) % | Eq. 5 uncentred % | curve distance % of side |\n|---|---|---|---|"
    );
    for r in &rows {
        println!(
            "| {} | {:.4} | {:.4} | {:.4} |",
            r.edge, r.objective_pct, r.objective_uncentred_pct, r.curve_distance_pct
        );
    }
    Ok(EXIT_OK)
}

/// `drapelab bench`: the hang4 table, or the whole benchmark pipeline with `--all`.
fn bench_command(a: BenchArgs) -> Result<i32> {
    if a.all {
        return run_pipeline_command(
            Path::new("pipelines/benchmark.toml"),
            false,
            Default::default(),
        );
    }
    bench::run_bench(
        &a.scene,
        &a.sizes,
        (a.max_explicit_size, a.max_implicit_size),
        a.tol,
        a.population,
    )?;
    Ok(EXIT_OK)
}

/// `drapelab simulate`: the result line on stdout (none with `-q`).
fn simulate(
    scene: &Path,
    out: &Path,
    set: &[String],
    (sensitivity, start, obj): (&[String], Option<&Path>, bool),
    quiet: bool,
) -> Result<i32> {
    let loaded = load_scene(scene, set)?;
    crate::build::check_something_free(&loaded)?;
    for key in sensitivity {
        crate::sensitivity::check_key(&loaded.scene, key, "--sensitivity")?;
    }
    let extras = crate::io::SimulateExtras {
        sensitivity_keys: sensitivity.to_vec(),
        start: start
            .map(|f| read_start(f, &loaded.scene.grid()))
            .transpose()?,
        obj,
    };
    let _out = args::out_dir(out)?;
    let mut progress = SolveProgress::new(&loaded.scene.name);
    let report = crate::io::simulate_to_dir_with(&loaded, out, &mut progress, &extras)?.report;
    progress.done(&report);
    if !quiet {
        // Why a solve did not converge, on the line itself (run.json has the numbers).
        let why = match (&report.divergence, report.is_converged()) {
            (Some(d), _) => format!(" ({} at step {})", d.reason, d.step),
            (None, false) if !report.message.is_empty() => format!(" ({})", report.message),
            _ => String::new(),
        };
        println!(
            "{}: {}{why} by {} in {} iterations, largest residual {:.3e} N ({:.2e} of a particle's weight), {:.3} s → {}",
            loaded.scene.name,
            report.status.as_str(),
            report.solver,
            report.iterations,
            report.max_residual_N,
            report.max_residual_rel,
            report.wall_time_s,
            out.display()
        );
    }
    Ok(if report.is_converged() {
        EXIT_OK
    } else {
        EXIT_FAILED
    })
}

/// The grid particles' positions of a saved drape (`--start FILE`), checked against the scene's
/// grid: the same particles (i, j) in the same order, finite positions.
fn read_start(
    file: &Path,
    grid: &crate::cloth::Grid,
) -> Result<(Vec<nalgebra::Vector3<f64>>, String), InputError> {
    let bad = |key: &str, m: String| InputError::new(format!("--start {}", file.display()), key, m);
    let rows = crate::io::read_particles(file).map_err(|e| bad("", format!("{e:#}")))?;
    if rows.len() != grid.len() {
        return Err(bad(
            "",
            format!(
                "{} particles, the scene's grid has {} ({} × {}): start from a drape of the same grid",
                rows.len(),
                grid.len(),
                grid.nx,
                grid.ny
            ),
        ));
    }
    let mut x = Vec::with_capacity(rows.len());
    for (p, (i, j, v)) in rows.into_iter().enumerate() {
        if (i as usize, j as usize) != grid.ij(p) {
            return Err(bad(
                "i",
                format!(
                    "row {p} is particle ({i}, {j}), expected {:?}: not particles.parquet's order",
                    grid.ij(p)
                ),
            ));
        }
        if !v.iter().all(|c| c.is_finite()) {
            return Err(bad(
                "x_m",
                format!("row {p}: a position that is not finite"),
            ));
        }
        x.push(v);
    }
    Ok((x, file.display().to_string()))
}

/// `drapelab status`: 1 with `--check` when a stage is stale.
fn status(pipeline: &Path, check: bool) -> Result<i32> {
    let plan = crate::pipeline::load_checked_plan(pipeline, &crate::stages::registry())?;
    let mut stale = 0;
    for (name, state) in crate::pipeline::stage_states(&plan) {
        let last = crate::pipeline::Manifest::read(&crate::pipeline::manifest_path(&plan, &name))
            .map(|m| format!(" [last run {:.1} s]", m.wall_time_s))
            .unwrap_or_default();
        match state {
            crate::pipeline::StageState::UpToDate => println!("{name}: up to date{last}"),
            crate::pipeline::StageState::Stale(why) => {
                stale += 1;
                println!("{name}: stale ({why}){last}")
            }
        }
    }
    Ok(if check && stale > 0 {
        EXIT_FAILED
    } else {
        EXIT_OK
    })
}

/// `drapelab kinds`: every stage kind with its slots and its parameters' defaults (units are in
/// the names); docs/src/reference/kinds.md is this output.
pub fn kinds_text() -> String {
    let mut s = String::new();
    for k in crate::stages::registry().kinds() {
        s += &format!("{}: {}\n", k.kind(), k.summary());
        for (side, slots) in [("inputs", k.inputs()), ("outputs", k.outputs())] {
            for slot in slots {
                s += &format!(
                    "  {side}.{}{}{}: {}\n",
                    slot.name,
                    if slot.many { " [list]" } else { "" },
                    if slot.required { "" } else { " (optional)" },
                    slot.doc
                );
            }
        }
        s += &params_text(k);
    }
    s
}

/// The parameters of a kind: each default (the resolved parameters of an empty table), or the
/// first key a pipeline must give.
fn params_text(k: &dyn crate::pipeline::Stage) -> String {
    match k.resolve(&toml::Table::new()) {
        Ok(serde_json::Value::Object(map)) => map
            .iter()
            .map(|(key, v)| format!("  params.{key} = {v} (default)\n"))
            .collect(),
        Ok(_) => String::new(),
        Err(e) => {
            let missing = e
                .message
                .strip_prefix("missing field `")
                .and_then(|m| m.split('`').next());
            match (e.key.is_empty(), missing) {
                (true, Some(field)) => format!(
                    "  params.{field}: required (no default); the kind's documentation lists the rest\n"
                ),
                _ => format!(
                    "  params.{}: required ({}); the kind's documentation lists the rest\n",
                    e.key, e.message
                ),
            }
        }
    }
}

/// The command-line reference (docs/src/reference/cli.md): every visible subcommand with its
/// description and options, from the clap definitions.
pub fn cli_reference() -> String {
    use clap::CommandFactory;
    let cli = Cli::command();
    let mut s = String::new();
    for sub in cli.get_subcommands().filter(|c| !c.is_hide_set()) {
        s += &format!("## `drapelab {}`\n\n", sub.get_name());
        if let Some(about) = sub.get_long_about().or(sub.get_about()) {
            s += &format!("{}\n\n", about.to_string().trim());
        }
        for a in sub.get_arguments().filter(|a| !a.is_hide_set()) {
            let name = match (a.get_long(), a.is_positional()) {
                (Some(l), _) => format!("--{l}"),
                (None, _) => a.get_id().as_str().to_uppercase(),
            };
            let help = a.get_help().map(|h| h.to_string()).unwrap_or_default();
            let defaults: Vec<String> = a
                .get_default_values()
                .iter()
                .map(|v| v.to_string_lossy().to_string())
                .collect();
            let default = if defaults.is_empty() {
                String::new()
            } else {
                format!(" Default: `{}`.", defaults.join(" "))
            };
            s += &format!("- `{name}`: {}{default}\n", help.replace('\n', " "));
        }
        s += "\n";
    }
    s
}

/// The render options of `drapelab render`, checked.
fn render_options(
    px_per_cm: f64,
    pinhole_distance_m: Option<f64>,
    markers: bool,
    noise: f64,
    blur_px: f64,
    rotate_deg: f64,
    seed: u64,
) -> Result<crate::edges::RenderOptions, InputError> {
    // The numbers were checked by their value parsers (args.rs).
    let camera = match pinhole_distance_m {
        Some(d) => crate::edges::Camera::Pinhole { distance_m: d },
        None => crate::edges::Camera::Orthographic,
    };
    Ok(crate::edges::RenderOptions {
        camera,
        px_per_cm,
        marker_radius_px: if markers { 4.0 } else { 0.0 },
        noise_sigma: noise,
        blur_sigma_px: blur_px,
        rotation_deg: rotate_deg,
        seed,
        ..Default::default()
    })
}

/// The calibration flags of `drapelab fit-edges`.
struct FitCalibration {
    px_per_cm: Option<f64>,
    corners: Option<String>,
    markers: bool,
    side_cm: Option<f64>,
    camera_json: Option<PathBuf>,
}

/// `drapelab fit-edges`.
fn fit_edges(
    photo: &Path,
    out: &Path,
    c: FitCalibration,
    view: ViewArg,
    degree: usize,
) -> Result<i32> {
    let mut view: crate::edges::View = view.into();
    let mut pinhole = None;
    let calibration = if let Some(cj) = c.camera_json {
        let cam = crate::edges::read_camera(&cj)?;
        view = cam.view;
        pinhole = cam.pinhole;
        cam.calibration(&cj)?
    } else if c.markers {
        let side = c.side_cm.ok_or_else(|| {
            InputError::new(
                "--side-cm",
                "",
                "--markers needs --side-cm (the distance between the corners)",
            )
        })?;
        crate::edges::Calibration::Markers { side_cm: side }
    } else {
        let (Some(s), Some(corners)) = (c.px_per_cm, c.corners) else {
            return Err(InputError::new(photo, "--corners", "give --px-per-cm and --corners x1,y1,x2,y2, or --markers --side-cm L, or --camera-json").into());
        };
        crate::edges::Calibration::Given {
            px_per_cm: s,
            corners: edges::parse_corners(&corners)?,
        }
    };
    let fits = crate::io::fit_photo(
        photo,
        out,
        &crate::edges::FitImageOptions {
            view,
            degree,
            calibration,
            pinhole,
        },
    )?;
    for f in &fits {
        eprintln!(
            "{}: {} points, RMS residual {:.4} cm, coefficients {:?}",
            f.edge, f.n_points, f.rms_residual_cm, f.coefficients
        );
    }
    Ok(EXIT_OK)
}

/// `drapelab wrinkles`.
fn wrinkles(config: &Path, out: &Path, mesh: &[usize]) -> Result<i32> {
    let cfg = crate::wrinkles::load_config(config)?;
    let _out = args::out_dir(out)?;
    let outputs = crate::app::wrinkles::WrinkleOutputs {
        table: Some(out.join("wrinkles.parquet")),
        mesh: Some(out.join("mesh.parquet")),
        recording: Some(out.join("wrinkles.rrd")),
        markdown: Some(out.join("wrinkles.md")),
    };
    let params = crate::app::wrinkles::WrinklesParams {
        mesh_nx: mesh[0],
        mesh_ny: mesh[1],
    };
    let solved = crate::app::wrinkles::write_wrinkles(&cfg, &outputs, &params)?;
    print!("{}", crate::app::wrinkles::report_markdown(&cfg, &solved));
    Ok(if solved.iter().all(|s| s.result.converged) {
        EXIT_OK
    } else {
        EXIT_FAILED
    })
}

/// Log lines (tracing) on stderr: stage progress (info) by default, more with `-v`, errors only
/// with `-q`; `RUST_LOG` (e.g. `RUST_LOG=drapelab_pipeline=debug`) overrides both.
pub fn init_logging(verbose: u8, quiet: bool) {
    let level = match (quiet, verbose) {
        (true, _) => "error",
        (false, 0) => "info",
        (false, 1) => "debug",
        (false, _) => "trace",
    };
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(level));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_target(false)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .try_init();
}
