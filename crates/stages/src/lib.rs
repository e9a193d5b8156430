//! drapelab-stages: the stage kinds of drapelab's pipelines, one adapter file each: the kind's slots
//! and parameters, and a call of its workflow (`drapelab-app`) or report (`drapelab-reports`) with
//! the stage's files. [`registry`] lists every kind: adding one is a file here and a line there.

#![warn(missing_docs)]
#![allow(non_snake_case)]

mod benchmark;
mod benchmark_report;
mod calibrate;
mod calibration_report;
mod cusick_fabric;
mod cusick_measure;
mod cusick_predict;
mod cusick_report;
mod fit_edges;
mod garment;
mod garment_report;
mod knitted_fabric;
mod peers;
pub mod report;
mod score;
mod seed003_report;
mod seed003_solve;
mod simulate;
mod skips;
mod surface;
mod sweep;
mod tune;
mod validate;
mod wrinkles;
mod wrinkles_simulate;

pub use benchmark::{Benchmark, BenchmarkParams};
pub use benchmark_report::{BenchmarkReport, BenchmarkReportParams};
pub use calibrate::{Calibrate, CalibrateParams};
pub use calibration_report::{CalibrationReport, CalibrationReportParams};
pub use cusick_fabric::{CusickFabric, CusickFabricParams};
pub use cusick_measure::{CusickMeasure, CusickMeasureParams, ShadowRow, measure_dataset};
pub use cusick_predict::{CusickPredict, CusickPredictParams};
pub use cusick_report::{CusickReport, CusickReportParams, dc_within, nodes_within};
pub use drapelab_app::cusick::tables::{OutlineRow, PredictionRow, ProfileRow};
pub use fit_edges::{FitEdges, FitEdgesParams};
pub use garment::{Garment, GarmentParams};
pub use garment_report::{GarmentReport, GarmentReportParams};
pub use knitted_fabric::{KnittedFabric, KnittedFabricParams};
pub use peers::{Peers, PeersParams};
pub use report::{Report, ReportParams};
pub use score::{Score, ScoreParams};
pub use seed003_report::{Seed003Report, Seed003ReportParams};
pub use seed003_solve::{Seed003Solve, Seed003SolveParams};
pub use simulate::{Simulate, SimulateParams};
pub use skips::{Skips, SkipsParams};
pub use surface::{
    Drape, Dressed, Surface, SurfaceOutputs, SurfaceParams, SurfaceSummary, dress, load_run,
    load_texture, make_surface, picture, solve_drape,
};
pub use sweep::{Axis, Design, Sweep, SweepParams, sweep_points};
pub use tune::{Levels, Tune, TuneParams};
pub use validate::{Validate, ValidateParams};
pub use wrinkles::{
    SolvedCase, WrinkleOutputs, Wrinkles, WrinklesParams, report_markdown, write_wrinkles,
};
pub use wrinkles_simulate::{WrinklesSimulate, WrinklesSimulateParams};

use drapelab_pipeline::{Registry, Slot};

/// The measured edges of the calibration stages (a fit-edges table).
const EDGES_SLOT: Slot = Slot::one(
    "edges",
    "measured edges of every sample (a fit-edges table)",
);
/// Table 2's densities of the calibration stages.
const SAMPLES_SLOT: Slot = Slot::one("samples", "Table 2's densities (knitted_samples.csv)");
/// The hang scene of the calibration stages.
const SCENE_SLOT: Slot = Slot::one("scene", "the hang scene each sample is simulated in");

/// The three files of the calibration stages from their slots (edges, samples, scene in order).
fn sample_inputs(
    ctx: &drapelab_pipeline::StageContext<'_>,
    [edges, samples, scene]: [&Slot; 3],
) -> anyhow::Result<drapelab_app::calibration::calibrate::SampleInputs> {
    Ok(drapelab_app::calibration::calibrate::SampleInputs {
        edges: ctx.file(edges)?,
        samples: ctx.file(samples)?,
        scene: ctx.file(scene)?,
    })
}

/// The index of a Cusick dataset, for the Cusick stages.
const CUSICK_INDEX_SLOT: Slot = Slot::one(
    "index",
    "captures_index.csv of a Cusick dataset (its folder holds the rest)",
);

/// The wrinkle config of the wrinkles stages.
const WRINKLE_CONFIG_SLOT: Slot = Slot::one("config", "the wrinkle config TOML");

/// The workflow's view of a stage's context: its typed inputs (built from the kind's slots), its
/// outputs, its name, and progress forwarded to the engine's display.
pub(crate) fn job<'c, I>(
    ctx: &'c drapelab_pipeline::StageContext<'_>,
    inputs: I,
) -> drapelab_app::Job<'c, I> {
    drapelab_app::Job {
        stage: ctx.stage.clone(),
        source: ctx.pipeline_file.clone(),
        root: ctx.root.clone(),
        inputs,
        outputs: ctx.outputs.clone(),
        progress: Box::new(Forward(ctx)),
    }
}

/// Progress of a workflow, forwarded to the stage's.
struct Forward<'c, 'p>(&'c drapelab_pipeline::StageContext<'p>);

impl drapelab_app::Progress for Forward<'_, '_> {
    fn started(&self, items: usize) {
        self.0.started(items);
    }
    fn item_done(&self) {
        self.0.item_done();
    }
}

/// Every stage kind drapelab knows.
pub fn registry() -> Registry {
    Registry::new()
        .with::<Simulate>()
        .with_items::<Sweep>()
        .with::<Report>()
        .with::<FitEdges>()
        .with::<Score>()
        .with_items::<Calibrate>()
        .with::<Validate>()
        .with::<Tune>()
        .with::<CalibrationReport>()
        .with::<Wrinkles>()
        .with::<WrinklesSimulate>()
        .with::<Seed003Solve>()
        .with::<Seed003Report>()
        .with::<Benchmark>()
        .with::<Peers>()
        .with::<BenchmarkReport>()
        .with::<Skips>()
        .with::<CusickMeasure>()
        .with::<CusickPredict>()
        .with::<CusickFabric>()
        .with::<Garment>()
        .with::<GarmentReport>()
        .with::<KnittedFabric>()
        .with::<CusickReport>()
        .with::<Surface>()
}
