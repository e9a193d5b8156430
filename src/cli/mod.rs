//! The command line: clap arguments become one validated configuration, once (ripgrep's habit);
//! [`run`] returns the process exit code. One module per subcommand: its flags and its handler.

mod args;
mod bench;
pub mod edges;
mod fit_edges;
mod pipeline;
mod progress;
mod reference;
mod render;
mod score;
mod simulate;
mod surface;
mod wrinkles;

pub use pipeline::{run_pipeline_quietly, run_pipeline_with};
pub use progress::SolveProgress;
pub use reference::{cli_reference, kinds_text};

use crate::config::parse_override;
use crate::error::{EXIT_OK, InputError};
use crate::scene::{LoadedScene, Scene};
use anyhow::Result;
use clap::{Parser, Subcommand, ValueEnum};
use std::path::Path;

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
    Simulate(simulate::SimulateArgs),
    /// Run a pipeline make-style (only stale stages).
    ///
    /// A stage runs when its inputs' content, parameters or the drapelab build changed since its
    /// manifest; items run in parallel; artifacts go under runs/<pipeline>/. A failing (or panicking)
    /// stage fails alone: the run goes on as far as the graph allows and exits 1.
    ///
    /// Example: drapelab run pipelines/main.toml --jobs 2
    Run(pipeline::RunArgs),
    /// Compute some items of a stage, as one Slurm array task does (`drapelab run --executor slurm`
    /// writes the task list and calls this; not needed by hand, so hidden from --help).
    ///
    /// Reads line TASK (0-based) of the task list: the items to compute. Items that already have a
    /// part are skipped; the parts folder must be that of the stage's current inputs.
    #[command(hide = true)]
    Worker(pipeline::WorkerArgs),
    /// Say which stages of a pipeline are stale, and why.
    ///
    /// Each stage is up to date, or stale with the reason (which input or parameter changed).
    Status(pipeline::StatusArgs),
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
    Render(render::RenderArgs),
    /// Fit the edges of a photo of a hanging sheet with polynomials (seed 000).
    ///
    /// Seed 000 Figs 3, 11, 12. Writes DIR/edges.parquet (edge, power, coefficient of x^power in cm,
    /// RMS residual, points) and DIR/overlay.png (fitted curves red, reference line blue). Calibrate
    /// with --px-per-cm and --corners, or --markers and --side-cm, or --camera-json (a camera file
    /// as docs/src/guide/photos.md describes it, or the one `render` writes).
    FitEdges(fit_edges::FitEdgesArgs),
    /// Score simulated edges against measured ones (seed 000 Eq. 5).
    ///
    /// Per edge: Eq. 5 (coefficients in coordinates centred on the edge, in %) and the RMS distance
    /// between the curves (% of the side).
    Score(score::ScoreArgs),
    /// Tension-field wrinkles of vertically hung fabric (seed 002).
    ///
    /// Number n, ratio Q and depth z_max of the wrinkles for every case of CONFIG, with the deformed
    /// grids. Writes DIR/wrinkles.parquet, DIR/mesh.parquet, DIR/wrinkles.rrd and DIR/wrinkles.md
    /// (the seed's results beside ours).
    ///
    /// Example: drapelab wrinkles datasets/wrinkles/seed_tables.toml --out runs/wrinkles
    Wrinkles(wrinkles::WrinklesArgs),
    /// Time to equilibrium of hang4 against error, every solver.
    ///
    /// Each resolution with every solver, and each result's distance to the finest static solution;
    /// prints a Markdown table.
    Bench(bench::BenchArgs),
}

/// Loads a scene with `--set KEY=VALUE` overrides; an error caused by an override names the flag.
pub fn load_scene(path: &Path, sets: &[String]) -> Result<LoadedScene, InputError> {
    let overrides = sets
        .iter()
        .map(|s| parse_override(s))
        .collect::<Result<Vec<_>, InputError>>()?;
    Scene::load(path, &overrides).map_err(|e| {
        // An error in another file (a fabric, a mesh) names that file, whatever override led there.
        match crate::config::override_culprit(&e.key, &overrides).filter(|_| e.file == path) {
            Some(i) => InputError::new(
                format!("--set {} (over {})", sets[i], path.display()),
                e.key,
                e.message,
            ),
            None => e,
        }
    })
}

/// [`load_scene`] with the scene's material replaced by the fabric file `fabric` (`--fabric`,
/// relative to the working folder).
pub fn load_scene_in_fabric(
    path: &Path,
    sets: &[String],
    fabric: &Path,
) -> Result<LoadedScene, InputError> {
    let flag = format!("--fabric {}", fabric.display());
    if !fabric.is_file() {
        return Err(InputError::new(flag, "", "not a file"));
    }
    let absolute =
        std::path::absolute(fabric).map_err(|e| InputError::new(&flag, "", e.to_string()))?;
    let mut overrides = sets
        .iter()
        .map(|s| parse_override(s))
        .collect::<Result<Vec<_>, InputError>>()?;
    let given = overrides.len();
    let mut material = toml::Table::new();
    material.insert(
        "fabric".into(),
        toml::Value::String(absolute.display().to_string()),
    );
    overrides.push(("material".into(), toml::Value::Table(material)));
    Scene::load(path, &overrides).map_err(|e| {
        let culprit = crate::config::override_culprit(&e.key, &overrides[..given]);
        match culprit.filter(|_| e.file == path) {
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
        Command::Simulate(a) => simulate::run(a, quiet),
        Command::Run(a) => pipeline::run(a, quiet),
        Command::Worker(a) => pipeline::worker(&a.pipeline, &a.stage, &a.tasks, a.task),
        Command::Status(a) => pipeline::status(&a.pipeline, a.check),
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
        Command::Surface(a) => surface::surface(a),
        Command::Render(a) => render::run(a),
        Command::FitEdges(a) => fit_edges::run(a),
        Command::Wrinkles(a) => wrinkles::run(a),
        Command::Score(a) => score::run(a),
        Command::Bench(a) => bench::run(a),
    }
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
