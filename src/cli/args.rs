//! Value parsers of the command line's numbers: clap refuses a value out of range with one line
//! naming the flag (exit 2), before any work starts.

use clap::builder::RangedU64ValueParser;

/// A number parsed, or clap's one-line reason.
fn number(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .map_err(|_| format!("`{s}` is not a number"))
}

/// A finite number (angles, offsets).
pub fn finite(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("must be a finite number, got {s}"))
    }
}

/// A finite number > 0 (scales, lengths, tolerances).
pub fn positive(s: &str) -> Result<f64, String> {
    let v = finite(s)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(format!("must be > 0, got {s}"))
    }
}

/// A finite number ≥ 0 (noise and blur σ).
pub fn non_negative(s: &str) -> Result<f64, String> {
    let v = finite(s)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("must be ≥ 0, got {s}"))
    }
}

/// The largest scale a photo may be rendered at, px per cm (a 50 cm sheet is then 10,000 px wide).
pub const MAX_PX_PER_CM: f64 = 200.0;

/// A photo's scale: > 0 and at most [`MAX_PX_PER_CM`].
pub fn px_per_cm(s: &str) -> Result<f64, String> {
    let v = positive(s)?;
    if v <= MAX_PX_PER_CM {
        Ok(v)
    } else {
        Err(format!(
            "must be ≤ {MAX_PX_PER_CM} px/cm (a 50 cm sheet is then 10,000 px wide), got {s}"
        ))
    }
}

/// Particles per side of a grid: 3 to 1,001.
pub fn grid_side() -> RangedU64ValueParser<usize> {
    RangedU64ValueParser::<usize>::new().range(3..=1001)
}

/// Points per row or rows of a deformed wrinkle grid: 2 to 10,001.
pub fn mesh_side() -> RangedU64ValueParser<usize> {
    RangedU64ValueParser::<usize>::new().range(2..=10_001)
}

/// A polynomial degree of the edge fits: 1 to 8.
pub fn degree() -> RangedU64ValueParser<usize> {
    RangedU64ValueParser::<usize>::new().range(1..=8)
}

/// Creates the output folder `out` and checks that it can be written into; else an input error
/// naming `--out` and the folder. Hold the guard while writing: a folder it made and nothing was
/// written into is removed when the guard drops.
pub fn out_dir(out: &std::path::Path) -> Result<crate::atomic::MadeDirs, crate::error::InputError> {
    let bad = |e: std::io::Error| {
        crate::error::InputError::new(
            "--out",
            "",
            format!(
                "cannot write into {}: {e}; choose a folder you can write",
                out.display()
            ),
        )
    };
    let guard = crate::atomic::MadeDirs::create(out).map_err(bad)?;
    tempfile::Builder::new()
        .prefix(".drapelab-write-check")
        .tempfile_in(out)
        .map_err(bad)?;
    Ok(guard)
}
