//! Defaults shared by the parameters of several workflows (seed 000's specimens and net).

/// Particles per side of seed 000's simulated net: 14 (Table 3's 14 × 14).
pub fn grid() -> usize {
    14
}

/// Side of seed 000's square specimens, cm: 50.
pub fn side_cm() -> f64 {
    50.0
}
