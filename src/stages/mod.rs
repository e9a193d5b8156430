//! Stage kinds: one thin file each, glue over the library. A kind checks its parameters when the
//! plan is loaded (so typos are refused before anything runs) and runs with a [`StageContext`].

mod benchmark;
mod calibrate;
mod calibration_report;
mod fit_edges;
mod report;
mod score;
mod seed003_report;
mod simulate;
mod sweep;
mod tune;
mod validate;
mod wrinkles;

pub use benchmark::{BenchmarkParams, BenchmarkReportParams, PeersParams, SkipsParams};
pub use calibrate::CalibrateParams;
pub use calibration_report::CalibrationReportParams;
pub use fit_edges::FitEdgesParams;
pub use report::ReportParams;
pub use score::ScoreParams;
pub use seed003_report::Seed003ReportParams;
pub use simulate::SimulateParams;
pub use sweep::{Axis, Design, SweepParams, sweep_points};
pub use tune::{Levels, TuneParams};
pub use validate::ValidateParams;
pub use wrinkles::{SolvedCase, WrinklesParams, report_markdown, write_wrinkles};

use crate::pipeline::{Plan, PlannedStage, Progress};
use anyhow::Result;
use std::path::PathBuf;

/// What a stage gets to run.
pub struct StageContext<'a> {
    /// The plan (for the root and run folder).
    pub plan: &'a Plan,
    /// The stage.
    pub stage: &'a PlannedStage,
    /// Input files, absolute, sorted.
    pub inputs: Vec<PathBuf>,
    /// Declared outputs, absolute, in declared order.
    pub outputs: Vec<PathBuf>,
    /// Where to report items.
    pub progress: &'a dyn Progress,
}

impl StageContext<'_> {
    /// "Made by `drapelab run PIPELINE` (drapelab VERSION)": the provenance line of every report.
    pub fn made_by(&self) -> String {
        let file = &self.plan.file;
        format!(
            "Made by `drapelab run {}` (drapelab {})",
            file.strip_prefix(&self.plan.root).unwrap_or(file).display(),
            crate::VERSION
        )
    }
    /// The input file called `name`.
    pub fn input_named(&self, name: &str) -> Result<&PathBuf> {
        self.inputs
            .iter()
            .find(|f| f.file_name().is_some_and(|n| n == name))
            .ok_or_else(|| anyhow::anyhow!("an input named {name} is needed"))
    }
    /// The first input file with extension `ext`.
    pub fn input_with_extension(&self, ext: &str) -> Result<&PathBuf> {
        self.inputs
            .iter()
            .find(|f| f.extension().is_some_and(|e| e == ext))
            .ok_or_else(|| anyhow::anyhow!("an input ending in .{ext} is needed"))
    }
    /// The scene file and Table 2's densities that the calibration stages read.
    pub fn knitted_inputs(&self) -> Result<(&PathBuf, std::collections::HashMap<u32, f64>)> {
        Ok((
            self.input_with_extension("toml")?,
            crate::calibrate::read_sample_densities(self.input_named("knitted_samples.csv")?)?,
        ))
    }
}

/// The known stage kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StageKind {
    /// Solve one scene.
    Simulate,
    /// Solve scenes over a grid or Latin hypercube of scene keys.
    Sweep,
    /// Summaries and plots over Parquet tables, as Markdown.
    Report,
    /// Edge polynomials from photos.
    FitEdges,
    /// Eq. 5 and curve distance of measured against simulated edges.
    Score,
    /// ICA calibration of mass-spring parameters against measured edges.
    Calibrate,
    /// Calibrated parameters on the 2-corner hang against its measured edges.
    Validate,
    /// Taguchi L27 tuning of ICA's settings.
    Tune,
    /// The Markdown report of a calibration.
    CalibrationReport,
    /// Seed 002's tension-field wrinkles of every case of a config.
    Wrinkles,
    /// Seed 003's drape scenes beside the seed's numbers.
    Seed003Report,
    /// Every scene × size × tolerance × solver: time, work, memory, error.
    Benchmark,
    /// scipy and numpy peers run beside drapelab.
    Peers,
    /// Pareto fronts, scaling exponents and peer ratios from the benchmark tables.
    BenchmarkReport,
    /// Each skip the engine makes, measured on and off.
    Skips,
}

/// Deserializes a stage's params table into `T`, naming the bad key.
pub(crate) fn typed_params<T: serde::de::DeserializeOwned>(
    params: &toml::Table,
) -> Result<T, (String, String)> {
    serde_path_to_error::deserialize(toml::Value::Table(params.clone())).map_err(|e| {
        let path = e.path().to_string();
        (
            if path == "." { String::new() } else { path },
            e.into_inner()
                .to_string()
                .lines()
                .next()
                .unwrap_or("invalid")
                .to_string(),
        )
    })
}

impl StageKind {
    /// Names of all kinds.
    pub const ALL: [&'static str; 15] = [
        "simulate",
        "sweep",
        "report",
        "fit-edges",
        "score",
        "calibrate",
        "validate",
        "tune",
        "calibration-report",
        "wrinkles",
        "seed003-report",
        "benchmark",
        "peers",
        "benchmark-report",
        "skips",
    ];

    /// The kind of a name.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "simulate" => Some(Self::Simulate),
            "sweep" => Some(Self::Sweep),
            "report" => Some(Self::Report),
            "fit-edges" => Some(Self::FitEdges),
            "score" => Some(Self::Score),
            "calibrate" => Some(Self::Calibrate),
            "validate" => Some(Self::Validate),
            "tune" => Some(Self::Tune),
            "calibration-report" => Some(Self::CalibrationReport),
            "wrinkles" => Some(Self::Wrinkles),
            "seed003-report" => Some(Self::Seed003Report),
            "benchmark" => Some(Self::Benchmark),
            "peers" => Some(Self::Peers),
            "benchmark-report" => Some(Self::BenchmarkReport),
            "skips" => Some(Self::Skips),
            _ => None,
        }
    }
    /// The kind's name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Simulate => "simulate",
            Self::Sweep => "sweep",
            Self::Report => "report",
            Self::FitEdges => "fit-edges",
            Self::Score => "score",
            Self::Calibrate => "calibrate",
            Self::Validate => "validate",
            Self::Tune => "tune",
            Self::CalibrationReport => "calibration-report",
            Self::Wrinkles => "wrinkles",
            Self::Seed003Report => "seed003-report",
            Self::Benchmark => "benchmark",
            Self::Peers => "peers",
            Self::BenchmarkReport => "benchmark-report",
            Self::Skips => "skips",
        }
    }
    /// Checks parameters: Err((key, message)).
    pub fn check_params(self, params: &toml::Table) -> Result<(), (String, String)> {
        match self {
            Self::Simulate => typed_params::<SimulateParams>(params).map(|_| ()),
            Self::Sweep => typed_params::<SweepParams>(params).and_then(|p| p.check()),
            Self::Report => typed_params::<ReportParams>(params).map(|_| ()),
            Self::FitEdges => typed_params::<FitEdgesParams>(params).map(|_| ()),
            Self::Score => typed_params::<ScoreParams>(params).map(|_| ()),
            Self::Calibrate => typed_params::<CalibrateParams>(params).and_then(|p| p.check()),
            Self::Validate => typed_params::<ValidateParams>(params).map(|_| ()),
            Self::CalibrationReport => typed_params::<CalibrationReportParams>(params).map(|_| ()),
            Self::Wrinkles => typed_params::<WrinklesParams>(params).map(|_| ()),
            Self::Seed003Report => typed_params::<Seed003ReportParams>(params).map(|_| ()),
            Self::Benchmark => typed_params::<BenchmarkParams>(params).map(|_| ()),
            Self::Peers => typed_params::<PeersParams>(params).map(|_| ()),
            Self::BenchmarkReport => typed_params::<BenchmarkReportParams>(params).map(|_| ()),
            Self::Skips => typed_params::<SkipsParams>(params).map(|_| ()),
            Self::Tune => typed_params::<TuneParams>(params).and_then(|p| {
                if p.repeats == 0 {
                    Err(("repeats".into(), "must be ≥ 1".into()))
                } else {
                    Ok(())
                }
            }),
        }
    }
    /// The parameters with defaults filled in, as JSON (part of the up-to-date key).
    pub fn resolve_params(self, params: &toml::Table) -> serde_json::Value {
        fn resolved<T: serde::de::DeserializeOwned + serde::Serialize>(
            params: &toml::Table,
        ) -> serde_json::Value {
            typed_params::<T>(params)
                .ok()
                .and_then(|p| serde_json::to_value(p).ok())
                .unwrap_or(serde_json::Value::Null)
        }
        match self {
            Self::Simulate => resolved::<SimulateParams>(params),
            Self::Sweep => resolved::<SweepParams>(params),
            Self::Report => resolved::<ReportParams>(params),
            Self::FitEdges => resolved::<FitEdgesParams>(params),
            Self::Score => resolved::<ScoreParams>(params),
            Self::Calibrate => resolved::<CalibrateParams>(params),
            Self::Validate => resolved::<ValidateParams>(params),
            Self::Tune => resolved::<TuneParams>(params),
            Self::CalibrationReport => resolved::<CalibrationReportParams>(params),
            Self::Wrinkles => resolved::<WrinklesParams>(params),
            Self::Seed003Report => resolved::<Seed003ReportParams>(params),
            Self::Benchmark => resolved::<BenchmarkParams>(params),
            Self::Peers => resolved::<PeersParams>(params),
            Self::BenchmarkReport => resolved::<BenchmarkReportParams>(params),
            Self::Skips => resolved::<SkipsParams>(params),
        }
    }
    /// Runs the stage.
    pub fn run(self, ctx: &StageContext<'_>) -> Result<()> {
        let params = &ctx.stage.spec.params;
        let bad = |(k, m): (String, String)| anyhow::anyhow!("params.{k}: {m}");
        match self {
            Self::Simulate => simulate::run(ctx, &typed_params(params).map_err(bad)?),
            Self::Sweep => sweep::run(ctx, &typed_params(params).map_err(bad)?),
            Self::Report => report::run(ctx, &typed_params(params).map_err(bad)?),
            Self::FitEdges => fit_edges::run(ctx, &typed_params(params).map_err(bad)?),
            Self::Score => score::run(ctx, &typed_params(params).map_err(bad)?),
            Self::Calibrate => calibrate::run(ctx, &typed_params(params).map_err(bad)?),
            Self::Validate => validate::run(ctx, &typed_params(params).map_err(bad)?),
            Self::Tune => tune::run(ctx, &typed_params(params).map_err(bad)?),
            Self::CalibrationReport => {
                calibration_report::run(ctx, &typed_params(params).map_err(bad)?)
            }
            Self::Wrinkles => wrinkles::run(ctx, &typed_params(params).map_err(bad)?),
            Self::Seed003Report => seed003_report::run(ctx, &typed_params(params).map_err(bad)?),
            Self::Benchmark => benchmark::run(ctx, &typed_params(params).map_err(bad)?),
            Self::Peers => benchmark::run_peers(ctx, &typed_params(params).map_err(bad)?),
            Self::BenchmarkReport => {
                benchmark::run_report(ctx, &typed_params(params).map_err(bad)?)
            }
            Self::Skips => benchmark::run_skips(ctx, &typed_params(params).map_err(bad)?),
        }
    }
}
