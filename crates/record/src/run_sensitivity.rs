//! The sensitivities a simulate run writes (`--sensitivity KEY`): dx*/dθ per key at the converged
//! drape, made as accurate as the derivative needs, and what run.json says of them.

use anyhow::Result;
use drapelab_core::scene::LoadedScene;
use drapelab_core::solve::SolveReport;
use serde::Serialize;
use std::path::Path;

/// Sensitivities key by key: dx*/dθ of the grid particles, m per unit of the key.
pub type KeyedSensitivities = Vec<(String, Vec<nalgebra::Vector3<f64>>)>;

/// What `run.json` says of the sensitivities asked for.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct SensitivityRecord {
    /// The keys asked for, as given.
    keys: Vec<String>,
    /// Whether sensitivity.parquet was written.
    pub(crate) written: bool,
    /// Why not, when not (the state is no converged minimum, a key changes the model's structure).
    reason: Option<String>,
    /// Per key (in the order of `keys`), dE*/dθ: the equilibrium energy's derivative, J per unit of
    /// the key (the envelope theorem: ∂E/∂θ at x*); empty when none were written.
    d_energy_J_per_unit: Vec<f64>,
    /// Per key, an estimate of the written sensitivity's relative error (2-norm): how far it moved
    /// when the equilibrium took one more Newton step (the written one is the one after it, whose
    /// error is smaller still); None where that step could not be taken (a neutral mode).
    accuracy_rel: Vec<Option<f64>>,
    /// Wall time of the factorizations and the keys' solves, s.
    time_s: f64,
}

/// The sensitivities of `keys` at the converged `x`, made as accurate as the derivative needs: a
/// solve stops at its tolerance, and a sensitivity at that state carries an error of the order of
/// the state's (6·10⁻⁴ on table_wool_quarter's bending at the scene's tolerance); one more Newton
/// step x − H⁻¹g (with the factor the sensitivities use) squares the state's error, and the
/// sensitivities there are written, with how far each moved as its accuracy estimate.
fn accurate_sensitivities(
    loaded: &LoadedScene,
    model: &drapelab_core::physics::Model,
    x: &[nalgebra::Vector3<f64>],
    report: &SolveReport,
    keys: &[String],
) -> Result<
    (
        Vec<drapelab_core::sensitivity::KeySensitivity>,
        Vec<Option<f64>>,
    ),
    drapelab_core::sensitivity::NoSensitivity,
> {
    use drapelab_core::sensitivity::Equilibrium;
    let mut eq = Equilibrium::new(&loaded.scene, model, x, report, "--sensitivity")?;
    let first = keys
        .iter()
        .map(|k| eq.sensitivity(k))
        .collect::<Result<Vec<_>, _>>()?;
    let mut g = Vec::new();
    model.gradient(x, 1.0, &mut g);
    let (step, residual) = eq.factor_mut().solve_checked(&g);
    if !(residual < 1e-6 && step.iter().all(|v| v.iter().all(|c| c.is_finite()))) {
        return Ok((first, vec![None; keys.len()]));
    }
    let stepped: Vec<nalgebra::Vector3<f64>> = x.iter().zip(&step).map(|(a, d)| a - d).collect();
    let Ok(mut eq2) = Equilibrium::new(&loaded.scene, model, &stepped, report, "--sensitivity")
    else {
        return Ok((first, vec![None; keys.len()]));
    };
    let second = keys
        .iter()
        .map(|k| eq2.sensitivity(k))
        .collect::<Result<Vec<_>, _>>()?;
    let size =
        |v: &[nalgebra::Vector3<f64>]| v.iter().map(|a| a.norm_squared()).sum::<f64>().sqrt();
    let accuracy = first
        .iter()
        .zip(&second)
        .map(|(a, b)| {
            let diff: Vec<_> = a.dx.iter().zip(&b.dx).map(|(p, q)| p - q).collect();
            Some(size(&diff) / size(&b.dx).max(f64::MIN_POSITIVE))
        })
        .collect();
    Ok((second, accuracy))
}

/// The sensitivities of `asked` (`simulate --sensitivity KEY`, in the order asked), written into `out/sensitivity.parquet` when the state is a
/// converged minimum; what run.json says of them (None when none were asked for).
pub(crate) fn sensitivities(
    loaded: &LoadedScene,
    grid: &drapelab_core::cloth::Grid,
    model: &drapelab_core::physics::Model,
    x: &[nalgebra::Vector3<f64>],
    report: &SolveReport,
    asked: &[String],
    out: &Path,
) -> Result<(Option<SensitivityRecord>, KeyedSensitivities)> {
    if asked.is_empty() {
        return Ok((None, Vec::new()));
    }
    let start = std::time::Instant::now();
    // A key asked for twice is computed and written once, in the order first asked.
    let mut keys: Vec<String> = Vec::new();
    for k in asked {
        if !keys.contains(k) {
            keys.push(k.clone());
        }
    }
    let result = accurate_sensitivities(loaded, model, x, report, &keys);
    let mut accuracy = Vec::new();
    let (written, reason, data, d_energy) = match result {
        Ok((s, acc)) => {
            accuracy = acc;
            let d_energy = s.iter().map(|k| k.d_energy).collect();
            crate::sensitivity_table::write_sensitivities(
                &out.join("sensitivity.parquet"),
                grid,
                &s,
            )?;
            let data = s
                .into_iter()
                .map(|k| (k.key, k.dx[..grid.len()].to_vec()))
                .collect();
            (true, None, data, d_energy)
        }
        Err(e) => (false, Some(e.to_string()), Vec::new(), Vec::new()),
    };
    let record = SensitivityRecord {
        keys,
        written,
        reason,
        d_energy_J_per_unit: d_energy,
        accuracy_rel: accuracy,
        time_s: start.elapsed().as_secs_f64(),
    };
    Ok((Some(record), data))
}
