//! The log barrier of incremental potential contact (Li et al. 2020, Eq. 6), shared by the sheet's
//! contact with rigid obstacles ([`super::obstacle_barrier`]) and with itself
//! ([`super::self_contact`]): b(d) = −(d − d̂)² ln(d/d̂) for 0 < d < d̂, zero beyond.

/// b(d), b'(d), b''(d) of the barrier (zero for d ≥ d̂; infinite energy for d ≤ 0).
pub(crate) fn barrier(d: f64, dh: f64) -> (f64, f64, f64) {
    if d >= dh {
        return (0.0, 0.0, 0.0);
    }
    if d <= 0.0 {
        return (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY);
    }
    let l = (d / dh).ln();
    let e = d - dh;
    (
        -e * e * l,
        -2.0 * e * l - e * e / d,
        -2.0 * l - 4.0 * e / d + e * e / (d * d),
    )
}

/// ∂b/∂d̂ and ∂b′/∂d̂ of the barrier at distance d (zero beyond d̂, where b and b′ vanish for
/// every d̂, and inside an obstacle).
pub(crate) fn barrier_band_derivatives(d: f64, dh: f64) -> (f64, f64) {
    if d >= dh || d <= 0.0 {
        return (0.0, 0.0);
    }
    let (l, e) = ((d / dh).ln(), d - dh);
    (
        2.0 * e * l + e * e / dh,
        2.0 * l + 2.0 * e / dh + 2.0 * e / d,
    )
}
