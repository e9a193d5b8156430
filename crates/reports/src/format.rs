//! Number formatting the reports share.

/// A number with `digits` decimals, or a dash where there is none.
pub fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("–".into(), |x| format!("{x:.digits$}"))
}
