//! Parsing of comma-separated flags (the photo commands, `surface`).

use drapelab_core::error::InputError;

/// Parses comma-separated numbers given to `flag`; the error says what was `expected`.
pub fn numbers(s: &str, flag: &str, expected: &str) -> Result<Vec<f64>, InputError> {
    s.split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| InputError::new(format!("{flag} {s}"), "", format!("expected {expected}")))
}

/// Parses `x1,y1,x2,y2`.
pub fn parse_corners(s: &str) -> Result<[(f64, f64); 2], InputError> {
    let v = numbers(s, "--corners", "x1,y1,x2,y2 in pixels")?;
    if v.len() != 4 {
        return Err(InputError::new(
            "--corners",
            "",
            format!("expected four numbers x1,y1,x2,y2, got {}", v.len()),
        ));
    }
    Ok([(v[0], v[1]), (v[2], v[3])])
}
