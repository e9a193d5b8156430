//! The bending length of a fabric from its drape coefficient: a bisection on log c over the
//! simulated drapes (DC rises with c), and the interval the DC's uncertainty leaves on c by the
//! delta method, c · exp(± k σ_DC / (dDC/d ln c)). One scalar (DC) pins down one parameter: the
//! isotropic bending length; warp and weft apart would need the outline's direction, which the
//! captures do not give.

use super::{DiscMesh, DrapeParams, Tester, drape_dc};

/// A calibrated bending length with every solve the search made.
#[derive(Debug, Clone, PartialEq)]
pub struct BendingCalibration {
    /// The calibrated bending length c, m.
    pub bending_length_m: f64,
    /// Every (c in m, simulated DC in %) the search solved, in order.
    pub evaluations: Vec<(f64, f64)>,
}

impl BendingCalibration {
    /// The sensitivity dDC/d ln c (% per unit of ln c): the least-squares slope over the evaluated
    /// points within a factor `span` of c (the final bracket at least). None if it is not positive.
    pub fn sensitivity_pct(&self, span: f64) -> Option<f64> {
        let c = self.bending_length_m;
        let mut near: Vec<(f64, f64)> = self
            .evaluations
            .iter()
            .filter(|e| (e.0 / c).ln().abs() <= span.ln())
            .map(|e| (e.0.ln(), e.1))
            .collect();
        if near.len() < 2 {
            // The two evaluations nearest c in log (the final bracket).
            let mut all: Vec<(f64, f64)> =
                self.evaluations.iter().map(|e| (e.0.ln(), e.1)).collect();
            all.sort_by(|a, b| (a.0 - c.ln()).abs().total_cmp(&(b.0 - c.ln()).abs()));
            near = all.into_iter().take(2).collect();
        }
        let n = near.len() as f64;
        let (mx, my) = near
            .iter()
            .fold((0.0, 0.0), |a, e| (a.0 + e.0 / n, a.1 + e.1 / n));
        let sxx: f64 = near.iter().map(|e| (e.0 - mx).powi(2)).sum();
        let sxy: f64 = near.iter().map(|e| (e.0 - mx) * (e.1 - my)).sum();
        let slope = sxy / sxx;
        (slope.is_finite() && slope > 0.0).then_some(slope)
    }

    /// The interval [c_lo, c_hi] (m) of c for a DC uncertainty `sigma_dc_pct` at `k` standard
    /// deviations: c · exp(± k σ / s), s the sensitivity over a factor 1.3 of c.
    pub fn interval_m(&self, sigma_dc_pct: f64, k: f64) -> Option<[f64; 2]> {
        let s = self.sensitivity_pct(1.3)?;
        let d = k * sigma_dc_pct / s;
        let c = self.bending_length_m;
        Some([c * (-d).exp(), c * d.exp()])
    }
}

/// The c in `bracket_m` where `dc(c)` (increasing) meets `target_dc_pct`: bisection on log c to a
/// relative width of `rel_tol`. Err when the target lies outside the bracket's DCs or `dc` fails
/// (at the low end: three times, moving inwards).
pub fn bisect_bending_length(
    mut dc: impl FnMut(f64) -> Result<f64, String>,
    target_dc_pct: f64,
    bracket_m: [f64; 2],
    rel_tol: f64,
) -> Result<BendingCalibration, String> {
    let mut evaluations = Vec::new();
    let mut eval = |c: f64| -> Result<f64, String> {
        let d = dc(c)?;
        evaluations.push((c, d));
        Ok(d)
    };
    let [mut lo, mut hi] = bracket_m;
    // A limp end whose drape does not settle is moved inwards (by an eighth of the bracket in
    // ln c, at most three times); the error names the last one tried.
    let step = (hi / lo).ln() / 8.0;
    let mut d_lo = eval(lo);
    for _ in 0..3 {
        if d_lo.is_ok() {
            break;
        }
        lo *= step.exp();
        d_lo = eval(lo);
    }
    let (d_lo, d_hi) = (d_lo?, eval(hi)?);
    if !(d_lo..=d_hi).contains(&target_dc_pct) {
        return Err(format!(
            "DC {target_dc_pct:.1} % lies outside [{d_lo:.1}, {d_hi:.1}] %, the drapes of c in [{lo}, {hi}] m"
        ));
    }
    while hi / lo > 1.0 + rel_tol {
        let mid = (lo * hi).sqrt();
        if eval(mid)? < target_dc_pct {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(BendingCalibration {
        bending_length_m: (lo * hi).sqrt(),
        evaluations,
    })
}

/// The bending length whose simulated drape (seed `p.seed`) on `mesh` has the drape coefficient
/// `target_dc_pct` ([`bisect_bending_length`] over [`drape_dc`]).
pub fn calibrate_bending_length(
    mesh: DiscMesh<'_>,
    target_dc_pct: f64,
    p: &DrapeParams,
    tester: &Tester,
    bracket_m: [f64; 2],
    rel_tol: f64,
) -> Result<BendingCalibration, String> {
    let dc = |c: f64| {
        let q = DrapeParams {
            bending_length_m: c,
            ..p.clone()
        };
        drape_dc(mesh, &q, tester)
            .map(|r| r.0)
            .ok_or_else(|| format!("the drape at c = {c} m did not converge"))
    };
    bisect_bending_length(dc, target_dc_pct, bracket_m, rel_tol)
}

#[cfg(test)]
mod tests {
    use super::super::polar_disc;
    use super::*;

    #[test]
    fn bisection_and_interval_are_exact_on_a_logarithmic_dc() {
        // DC = 60 + 25 ln(c / 0.02): c = 0.02 · exp((DC − 60) / 25), dDC/d ln c = 25.
        let dc = |c: f64| Ok(60.0 + 25.0 * (c / 0.02).ln());
        let cal = bisect_bending_length(dc, 70.0, [0.01, 0.06], 1e-4).expect("inside");
        let truth = 0.02 * (10.0f64 / 25.0).exp();
        assert!((cal.bending_length_m / truth - 1.0).abs() < 1e-4);
        let s = cal.sensitivity_pct(1.3).expect("increasing");
        assert!((s - 25.0).abs() < 1e-9, "{s}");
        // σ_DC = 2.5 points at 2σ: ln c moves by ±0.2.
        let [lo, hi] = cal.interval_m(2.5, 2.0).expect("interval");
        assert!((lo / cal.bending_length_m - (-0.2f64).exp()).abs() < 1e-9);
        assert!((hi / cal.bending_length_m - 0.2f64.exp()).abs() < 1e-9);
        assert!(bisect_bending_length(dc, 20.0, [0.01, 0.06], 0.01).is_err());
        // A low end that does not settle is moved inwards until one does.
        let limp_fails = |c: f64| {
            if c < 0.012 {
                Err(format!("c = {c} did not converge"))
            } else {
                dc(c)
            }
        };
        let cal = bisect_bending_length(limp_fails, 70.0, [0.01, 0.06], 1e-4).expect("moved in");
        assert!((cal.bending_length_m / truth - 1.0).abs() < 1e-4);
        assert!(cal.evaluations[0].0 > 0.012);
    }

    #[test]
    fn the_bending_length_of_a_synthetic_drape_is_recovered_from_its_dc() {
        let (rest, tris) = polar_disc(0.15, 20);
        let mesh = DiscMesh {
            rest_xy: &rest,
            triangles: &tris,
        };
        let t = Tester::default();
        let truth = DrapeParams {
            bending_length_m: 0.022,
            seed: 7,
            ..DrapeParams::default()
        };
        let (dc, _, _) = drape_dc(mesh, &truth, &t).expect("converged");
        // Calibrated from another perturbation than the one that made the "measurement".
        let p = DrapeParams {
            seed: 1,
            ..DrapeParams::default()
        };
        let c = calibrate_bending_length(mesh, dc, &p, &t, [0.01, 0.06], 0.01)
            .expect("calibrated")
            .bending_length_m;
        eprintln!("DC {dc:.2} %: c = {c:.5} m against 0.022");
        assert!((c / 0.022 - 1.0).abs() < 0.05, "{c}");
    }
}
