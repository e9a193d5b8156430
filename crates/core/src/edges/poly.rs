//! Least-squares polynomial fits (QR of a Vandermonde matrix in scaled x, for conditioning).

use nalgebra::{DMatrix, DVector};

/// A polynomial Σ c_p x^p.
#[derive(Debug, Clone, PartialEq)]
pub struct Polynomial {
    /// Coefficients of x^0 .. x^degree.
    pub coefficients: Vec<f64>,
}

impl Polynomial {
    /// Value at x (Horner).
    pub fn eval(&self, x: f64) -> f64 {
        self.coefficients
            .iter()
            .rev()
            .fold(0.0, |acc, c| acc * x + c)
    }
}

/// Fits y(x) by least squares with a polynomial of `degree`; returns it and the RMS residual.
/// None when there are fewer points than coefficients or the points are degenerate.
pub fn fit_polynomial(points: &[(f64, f64)], degree: usize) -> Option<(Polynomial, f64)> {
    let m = degree + 1;
    if points.len() < m {
        return None;
    }
    let s = points
        .iter()
        .map(|p| p.0.abs())
        .fold(0.0, f64::max)
        .max(1e-300);
    let a = DMatrix::from_fn(points.len(), m, |r, c| (points[r].0 / s).powi(c as i32));
    let y = DVector::from_iterator(points.len(), points.iter().map(|p| p.1));
    let qr = a.clone().qr();
    let r = qr.r();
    if (0..m).any(|k| r[(k, k)].abs() < 1e-12 * r[(0, 0)].abs().max(1e-300)) {
        return None;
    }
    let qty = qr.q().transpose() * &y;
    let z = r.solve_upper_triangular(&qty)?;
    let coefficients: Vec<f64> = (0..m).map(|p| z[p] / s.powi(p as i32)).collect();
    let poly = Polynomial { coefficients };
    let rms = (points
        .iter()
        .map(|&(x, yv)| (poly.eval(x) - yv).powi(2))
        .sum::<f64>()
        / points.len() as f64)
        .sqrt();
    rms.is_finite().then_some((poly, rms))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_an_exact_quartic() {
        let c = [-0.5, 0.3, -0.04, 0.0011, -0.00002];
        let pts: Vec<(f64, f64)> = (0..60)
            .map(|k| {
                let x = k as f64 * 50.0 / 59.0;
                (
                    x,
                    c.iter()
                        .enumerate()
                        .map(|(p, a)| a * x.powi(p as i32))
                        .sum(),
                )
            })
            .collect();
        let (p, rms) = fit_polynomial(&pts, 4).unwrap();
        assert!(rms < 1e-9);
        for (a, b) in p.coefficients.iter().zip(c) {
            assert!((a - b).abs() < 1e-9 * (1.0 + b.abs()), "{a} vs {b}");
        }
        assert!(fit_polynomial(&pts[..3], 4).is_none());
    }
}
