//! `tune`: the Taguchi L27 design over ICA's seven control factors at three levels (seed 000 Table 1),
//! each row an ICA calibration of one sample (`repeats` seeds), scored by the smaller-the-better S/N of
//! its final costs; the mean S/N of every factor level (Fig. 10) and the best level of each factor.
//! Outputs: `tune.parquet` (one row per design row), `main_effects.parquet`, `best_ica.json` (the best
//! combination, which `calibrate` reads from its `ica` input) and `main_effects.svg`.

use crate::Panels;
use crate::calibration::calibrate::SampleInputs;
use crate::job::Job;
use anyhow::Result;
use drapelab_core::calibrate::{Problem, read_sample_densities, sample_scene};
use drapelab_core::edges::EdgeFit;
use drapelab_core::optim::{Ica, IcaSettings, l27, main_effects, sn_smaller_the_better};
use drapelab_record::{Table, read_edges, write_table, write_text};
use serde::{Deserialize, Serialize};

/// The seven factors of Table 1 and their three levels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Levels {
    /// A: decades.
    pub decades: [usize; 3],
    /// B: imperialists (Table 1 prints 15..25 for B and 2..10 for C; the rows look swapped and are read so).
    pub imperialists: [usize; 3],
    /// C: countries.
    pub countries: [usize; 3],
    /// D: assimilation coefficient β.
    pub beta: [f64; 3],
    /// E: assimilation angle γ, rad.
    pub gamma: [f64; 3],
    /// F: revolution rate.
    pub revolution_rate: [f64; 3],
    /// G: colonies' share ξ.
    pub xi: [f64; 3],
}

impl Default for Levels {
    fn default() -> Self {
        Self {
            decades: [10, 20, 40],
            imperialists: [2, 5, 10],
            countries: [15, 20, 25],
            beta: [0.5, 1.0, 2.0],
            gamma: [0.1, 0.3, 0.5],
            revolution_rate: [0.2, 0.3, 0.4],
            xi: [0.1, 0.15, 0.2],
        }
    }
}

/// Parameters of a tune stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TuneParams {
    /// The sample to tune on, as its folder in the fit-edges table, e.g. "datasets/knitted/sample_03/hang4".
    pub sample: String,
    /// ICA runs (seeds) per design row. Default 1.
    #[serde(default = "one")]
    pub repeats: usize,
    /// Seed of the first run.
    #[serde(default)]
    pub seed: u64,
    /// Factor levels. Default: Table 1.
    #[serde(default)]
    pub levels: Levels,
    /// Particles per side. Default 14.
    #[serde(default = "crate::defaults::grid")]
    pub grid: usize,
    /// Side of the samples, cm. Default 50.
    #[serde(default = "crate::defaults::side_cm")]
    pub side_cm: f64,
}

/// Default of `runs`: 1 ICA run per design row.
pub fn one() -> usize {
    1
}
/// L27 columns used for the factors A..G (any seven columns of L27 are pairwise orthogonal).
pub const COLUMNS: [usize; 7] = [0, 1, 4, 2, 5, 7, 8];
/// The seven ICA settings the Taguchi L27 design varies (seed 000), in the design's column order.
pub const FACTORS: [&str; 7] = [
    "A decades",
    "B imperialists",
    "C countries",
    "D beta",
    "E gamma",
    "F revolution_rate",
    "G xi",
];

/// One row of the L27 array: the ICA settings' levels and what they cost (seed 000 §3.3).
#[allow(non_snake_case)]
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TuneRow {
    /// L27 row, 1..27.
    pub row: u32,
    /// Level (1..3) of factor A, the decades.
    pub level_A: u32,
    /// Level of factor B, the imperialists.
    pub level_B: u32,
    /// Level of factor C, the countries.
    pub level_C: u32,
    /// Level of factor D, β (assimilation).
    pub level_D: u32,
    /// Level of factor E, γ (deviation).
    pub level_E: u32,
    /// Level of factor F, the revolution rate.
    pub level_F: u32,
    /// Level of factor G, ξ (colonies' share of an empire's power).
    pub level_G: u32,
    /// Mean best cost over the row's runs, % of the side.
    pub mean_cost_pct: f64,
    /// Smaller-the-better signal-to-noise ratio, dB.
    pub sn_db: f64,
}

impl Table for TuneRow {
    const FILE: &'static str = "tune.parquet";
    const ROW: &'static str =
        "One row of the Taguchi L27 design over ICA's seven settings (seed 000 §3.3).";
}

/// One factor level's mean S/N over the rows at that level.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MainEffectRow {
    /// Factor (e.g. "A decades").
    pub factor: String,
    /// Level, 1..3.
    pub level: u32,
    /// Mean S/N of the rows at this level, dB.
    pub mean_sn_db: f64,
}

impl Table for MainEffectRow {
    const FILE: &'static str = "main_effects.parquet";
    const ROW: &'static str =
        "One level of one ICA setting: its mean S/N over the L27 rows (seed 000 Fig. 5).";
}

/// The ICA settings of one row `l` of the design at `levels`.
pub fn settings(levels: &Levels, l: &[u8], seed: u64) -> IcaSettings {
    let k = |f: usize| l[f] as usize;
    let countries = levels.countries[k(2)];
    IcaSettings {
        decades: levels.decades[k(0)],
        imperialists: levels.imperialists[k(1)].min(countries),
        countries,
        beta: levels.beta[k(3)],
        gamma: levels.gamma[k(4)],
        revolution_rate: levels.revolution_rate[k(5)],
        xi: levels.xi[k(6)],
        seed,
    }
}

/// What a tuning found beyond its tables: each factor's mean S/N per level, as lines by factor
/// (level 1..3 → dB) on one panel, "main effects" (the adapter draws them).
pub struct TuneOutcome {
    /// Panel → factor → (level, mean S/N dB).
    pub main_effects: Panels,
}

/// Runs the L27 experiments and writes the tables and the best settings.
pub fn run(ctx: &Job<'_, SampleInputs>, p: &TuneParams) -> Result<TuneOutcome> {
    let densities = read_sample_densities(&ctx.inputs.samples)?;
    let scene_file = &ctx.inputs.scene;
    let measured: Vec<EdgeFit> = read_edges(&ctx.inputs.edges)?
        .into_iter()
        .filter(|(s, _)| *s == p.sample)
        .map(|(_, e)| e)
        .collect();
    anyhow::ensure!(
        !measured.is_empty(),
        "sample `{}` is not in the edges table",
        p.sample
    );
    let scene = sample_scene(scene_file, &densities, &p.sample, p.grid)?;
    let problem = Problem::new(scene, measured, p.side_cm);
    let table = l27();
    let rows: Vec<Vec<u8>> = table
        .iter()
        .map(|r| COLUMNS.iter().map(|&c| r[c]).collect())
        .collect();
    ctx.started(rows.len());
    let mut sn = Vec::new();
    let mut costs = Vec::new();
    for l in &rows {
        let finals: Vec<f64> = (0..p.repeats)
            .map(|r| {
                Ica {
                    settings: settings(&p.levels, l, p.seed + r as u64),
                    dim: 5,
                }
                .run(&|u: &[f64]| problem.cost(u), |_| {})
                .best_cost
            })
            .collect();
        sn.push(sn_smaller_the_better(&finals));
        costs.push(finals.iter().sum::<f64>() / finals.len() as f64);
        ctx.item_done();
    }
    let effects = main_effects(&rows, &sn);
    let best_levels: Vec<u8> = effects
        .iter()
        .map(|e| (0..3).max_by(|&a, &b| e[a].total_cmp(&e[b])).unwrap_or(0) as u8)
        .collect();
    let best = settings(&p.levels, &best_levels, p.seed);
    let table = tune_rows(&rows, &costs, &sn);
    write_table(ctx.output("table")?, &table)?;
    let (me, panels) = main_effect_rows(&effects);
    write_table(ctx.output("main_effects")?, &me)?;
    write_text(
        ctx.output("best_ica")?,
        &serde_json::to_string_pretty(&best)?,
    )?;
    Ok(TuneOutcome {
        main_effects: panels,
    })
}

/// tune.parquet's rows: each L27 row's levels (1–3), its runs' mean cost and its S/N ratio.
fn tune_rows(rows: &[Vec<u8>], costs: &[f64], sn: &[f64]) -> Vec<TuneRow> {
    let level = |r: &[u8], f: usize| r[f] as u32 + 1;
    rows.iter()
        .zip(costs.iter().zip(sn))
        .enumerate()
        .map(|(k, (r, (&mean_cost_pct, &sn_db)))| TuneRow {
            row: k as u32 + 1,
            level_A: level(r, 0),
            level_B: level(r, 1),
            level_C: level(r, 2),
            level_D: level(r, 3),
            level_E: level(r, 4),
            level_F: level(r, 5),
            level_G: level(r, 6),
            mean_cost_pct,
            sn_db,
        })
        .collect()
}

/// main_effects.parquet's rows (the mean S/N of each factor's level) and the same as plot panels.
fn main_effect_rows(effects: &[[f64; 3]]) -> (Vec<MainEffectRow>, Panels) {
    let mut me = Vec::new();
    let mut panels = Panels::new();
    for (f, e) in effects.iter().enumerate() {
        for (k, v) in e.iter().enumerate() {
            me.push(MainEffectRow {
                factor: FACTORS[f].to_string(),
                level: k as u32 + 1,
                mean_sn_db: *v,
            });
        }
        panels.entry("main effects".into()).or_default().insert(
            FACTORS[f].to_string(),
            e.iter()
                .enumerate()
                .map(|(k, v)| (k as f64 + 1.0, *v))
                .collect(),
        );
    }
    (me, panels)
}
