//! What a solve adapts in its model beyond the scene: the state a restart takes up to continue the
//! run it restarts. Today that is one number, the self-contact barrier's κ growth (IPC's adaptive
//! κ, Li et al. 2020 §4.3; [`SelfContact::stiffen_barrier`](super::SelfContact)); every other
//! term is fixed by the scene, and friction's lagged anchors are re-set from the start itself.

use super::Model;

/// The state a solve grew in its model, written with every drape (`particles.parquet`'s metadata)
/// and taken up by a restart (`simulate --start`, Python's `start=`, warm starts).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Adapted {
    /// The self-contact barrier's κ over κ as built (1: not stiffened; 1 too where the model has
    /// no self-contact). Dimensionless.
    pub kappa_growth: f64,
}

impl Default for Adapted {
    fn default() -> Self {
        Self { kappa_growth: 1.0 }
    }
}

/// The metadata key of [`Adapted::kappa_growth`] in a drape's Parquet file.
pub const KAPPA_GROWTH_KEY: &str = "self_contact_kappa_growth";

impl Adapted {
    /// What `model`'s solve adapted.
    pub fn of(model: &Model) -> Self {
        Self {
            kappa_growth: model.self_contact_term().map_or(1.0, |t| t.kappa_growth()),
        }
    }
    /// Gives `model` this state (a model without self-contact has nothing to take up).
    pub fn apply_to(&self, model: &mut Model) {
        if let Some(t) = model.self_contact_term_mut() {
            t.set_kappa_growth(self.kappa_growth);
        }
    }
    /// The key-value pairs written with a drape.
    pub fn metadata(&self) -> Vec<(&'static str, String)> {
        vec![(KAPPA_GROWTH_KEY, format!("{}", self.kappa_growth))]
    }
    /// The state in a drape's key-value metadata: None where the file carries none (a table
    /// written elsewhere), an error naming the key where its value is no growth (≥ 1, finite).
    pub fn from_metadata(
        get: impl Fn(&str) -> Option<String>,
    ) -> Result<Option<Self>, (&'static str, String)> {
        let Some(text) = get(KAPPA_GROWTH_KEY) else {
            return Ok(None);
        };
        match text.trim().parse::<f64>() {
            Ok(g) if g.is_finite() && g >= 1.0 => Ok(Some(Self { kappa_growth: g })),
            _ => Err((
                KAPPA_GROWTH_KEY,
                format!("{text:?} is not a κ growth (a finite number ≥ 1)"),
            )),
        }
    }
}
