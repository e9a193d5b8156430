//! Parsing of the photo commands' flags.

use drapelab_core::error::InputError;

/// Parses `x1,y1,x2,y2`.
pub fn parse_corners(s: &str) -> Result<[(f64, f64); 2], InputError> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            InputError::new(
                "--corners",
                "",
                format!("expected x1,y1,x2,y2 in pixels, got `{s}`"),
            )
        })?;
    if v.len() != 4 {
        return Err(InputError::new(
            "--corners",
            "",
            format!("expected four numbers x1,y1,x2,y2, got {}", v.len()),
        ));
    }
    Ok([(v[0], v[1]), (v[2], v[3])])
}
