//! A panel edge's curve (GarmentCode's edge `curvature`, read as its simulator
//! `pygarment/meshgen/boxmeshgen.py` reads it): a straight line, a quadratic or cubic Bézier whose
//! control points are given relative to the edge (along it, and across it by its length turned a
//! quarter counter-clockwise), or a circular arc (radius, large-arc and sweep flags as in SVG's
//! arc command, `sweep` the counter-clockwise one). Lengths by composite Gauss–Legendre
//! quadrature; samples equally spaced in arc length.

use std::f64::consts::PI;

/// A point of the panel's plane.
pub type P2 = [f64; 2];

/// One edge's curve from `start` to `end`.
#[derive(Debug, Clone, PartialEq)]
pub enum Curve {
    /// The straight segment.
    Line {
        /// The first endpoint.
        start: P2,
        /// The second endpoint.
        end: P2,
    },
    /// Bézier curve of degree 2 or 3: its control points, endpoints included.
    Bezier(Vec<P2>),
    /// Circular arc about `centre` of `radius` from angle `from_rad` through `sweep_rad`
    /// (positive counter-clockwise).
    Arc {
        /// The circle's centre.
        centre: P2,
        /// Its radius.
        radius: f64,
        /// The start's angle, rad.
        from_rad: f64,
        /// The angle swept to the end, rad (negative: clockwise).
        sweep_rad: f64,
    },
}

/// A point given relative to the edge `start`→`end` (GarmentCode's `rel_to_abs_2d`): `rel[0]`
/// along the edge, `rel[1]` across it, both in units of the edge's length.
pub fn relative_point(start: P2, end: P2, rel: P2) -> P2 {
    let e = [end[0] - start[0], end[1] - start[1]];
    let perp = [-e[1], e[0]];
    [
        start[0] + rel[0] * e[0] + rel[1] * perp[0],
        start[1] + rel[0] * e[1] + rel[1] * perp[1],
    ]
}

impl Curve {
    /// The arc from `start` to `end` of `radius` (SVG's endpoint form with no rotation: a radius
    /// under half the chord is raised to it); `large` picks the arc over π, `ccw` its direction.
    pub fn arc(start: P2, end: P2, radius: f64, large: bool, ccw: bool) -> Curve {
        let v = [end[0] - start[0], end[1] - start[1]];
        let d = v[0].hypot(v[1]);
        let r = radius.abs().max(d / 2.0);
        let h = (r * r - d * d / 4.0).max(0.0).sqrt();
        let n = [-v[1] / d, v[0] / d];
        let side = if large != ccw { 1.0 } else { -1.0 };
        let m = [(start[0] + end[0]) / 2.0, (start[1] + end[1]) / 2.0];
        let centre = [m[0] + side * h * n[0], m[1] + side * h * n[1]];
        let angle = |p: P2| (p[1] - centre[1]).atan2(p[0] - centre[0]);
        let (a0, a1) = (angle(start), angle(end));
        let mut sweep = (a1 - a0).rem_euclid(2.0 * PI);
        if !ccw {
            sweep -= 2.0 * PI;
        }
        Curve::Arc {
            centre,
            radius: r,
            from_rad: a0,
            sweep_rad: sweep,
        }
    }

    /// The point at parameter `t` ∈ [0, 1].
    pub fn point(&self, t: f64) -> P2 {
        match self {
            Curve::Line { start, end } => [
                start[0] + t * (end[0] - start[0]),
                start[1] + t * (end[1] - start[1]),
            ],
            Curve::Bezier(cp) => de_casteljau(cp, t),
            Curve::Arc {
                centre,
                radius,
                from_rad,
                sweep_rad,
            } => {
                let a = from_rad + t * sweep_rad;
                [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()]
            }
        }
    }

    /// |dC/dt| at `t`.
    fn speed(&self, t: f64) -> f64 {
        match self {
            Curve::Line { start, end } => (end[0] - start[0]).hypot(end[1] - start[1]),
            Curve::Arc {
                radius, sweep_rad, ..
            } => radius * sweep_rad.abs(),
            Curve::Bezier(cp) => {
                let k = (cp.len() - 1) as f64;
                let diff: Vec<P2> = cp
                    .windows(2)
                    .map(|w| [k * (w[1][0] - w[0][0]), k * (w[1][1] - w[0][1])])
                    .collect();
                let d = de_casteljau(&diff, t);
                d[0].hypot(d[1])
            }
        }
    }

    /// The length from parameter `a` to `b`: 5-point Gauss–Legendre on each of `PIECES` pieces.
    fn length_between(&self, a: f64, b: f64) -> f64 {
        const X: [f64; 5] = [
            0.0,
            -0.538_469_310_105_683,
            0.538_469_310_105_683,
            -0.906_179_845_938_664,
            0.906_179_845_938_664,
        ];
        const W: [f64; 5] = [
            0.568_888_888_888_889,
            0.478_628_670_499_366,
            0.478_628_670_499_366,
            0.236_926_885_056_189,
            0.236_926_885_056_189,
        ];
        let (m, h) = ((a + b) / 2.0, (b - a) / 2.0);
        X.iter()
            .zip(W)
            .map(|(x, w)| w * self.speed(m + h * x))
            .sum::<f64>()
            * h
    }

    /// The curve's length.
    pub fn length(&self) -> f64 {
        cumulative(self).last().copied().unwrap_or(0.0)
    }

    /// `n` ≥ 2 points from start to end, equally spaced in arc length.
    pub fn samples(&self, n: usize) -> Vec<P2> {
        let n = n.max(2);
        let s = cumulative(self);
        let total = *s.last().expect("pieces");
        let mut out = Vec::with_capacity(n);
        let mut k = 0;
        for i in 0..n {
            let target = total * i as f64 / (n - 1) as f64;
            while k + 1 < PIECES && s[k + 1] < target {
                k += 1;
            }
            let span = (s[k + 1] - s[k]).max(f64::MIN_POSITIVE);
            let f = ((target - s[k]) / span).clamp(0.0, 1.0);
            out.push(self.point((k as f64 + f) / PIECES as f64));
        }
        out
    }
}

/// The pieces a curve's length is integrated over (and its samples placed by).
const PIECES: usize = 256;

/// The length from the start at each of the `PIECES + 1` piece ends.
fn cumulative(c: &Curve) -> Vec<f64> {
    let mut s = vec![0.0; PIECES + 1];
    for k in 0..PIECES {
        let (a, b) = (k as f64 / PIECES as f64, (k + 1) as f64 / PIECES as f64);
        s[k + 1] = s[k] + c.length_between(a, b);
    }
    s
}

fn de_casteljau(cp: &[P2], t: f64) -> P2 {
    let mut p = cp.to_vec();
    for level in (1..p.len()).rev() {
        for i in 0..level {
            p[i] = [
                p[i][0] + t * (p[i + 1][0] - p[i][0]),
                p[i][1] + t * (p[i + 1][1] - p[i][1]),
            ];
        }
    }
    p[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quadratic_bezier_has_its_closed_form_length() {
        // B(t) = (2t, 2·0.5·2·t(1−t))… the parabola from (0,0) via (1, 1) to (2, 0): its length is
        // ∫₀¹ |(2, 2 − 4t)| dt = ∫ 2√(1 + (1 − 2t)²) dt = √2 + asinh(1).
        let c = Curve::Bezier(vec![[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]]);
        let exact = 2f64.sqrt() + 1f64.asinh();
        assert!((c.length() - exact).abs() < 1e-12 * exact, "{}", c.length());
    }

    #[test]
    fn arcs_have_radius_times_angle_and_their_flags_pick_the_arc() {
        let (a, b) = ([1.0, 0.0], [0.0, 1.0]);
        let small_ccw = Curve::arc(a, b, 1.0, false, true);
        let large_ccw = Curve::arc(a, b, 1.0, true, true);
        let small_cw = Curve::arc(a, b, 1.0, false, false);
        assert!((small_ccw.length() - PI / 2.0).abs() < 1e-12);
        assert!((large_ccw.length() - 1.5 * PI).abs() < 1e-12);
        assert!((small_cw.length() - PI / 2.0).abs() < 1e-12);
        // The small counter-clockwise arc from (1,0) to (0,1) turns about the origin, through
        // (√½, √½); the clockwise one about (1, 1), through (1 − √½, 1 − √½).
        let h = 0.5f64.sqrt();
        let mid = small_ccw.point(0.5);
        assert!((mid[0] - h).abs() < 1e-12 && (mid[1] - h).abs() < 1e-12);
        let mid = small_cw.point(0.5);
        assert!((mid[0] - (1.0 - h)).abs() < 1e-12 && (mid[1] - (1.0 - h)).abs() < 1e-12);
        for c in [small_ccw, large_ccw, small_cw] {
            let (p, q) = (c.point(0.0), c.point(1.0));
            assert!((p[0] - a[0]).hypot(p[1] - a[1]) < 1e-12);
            assert!((q[0] - b[0]).hypot(q[1] - b[1]) < 1e-12);
        }
    }

    #[test]
    fn samples_are_equally_spaced_along_a_curve() {
        let c = Curve::Bezier(vec![[0.0, 0.0], [0.3, 1.0], [0.7, -0.5], [1.0, 0.0]]);
        let s = c.samples(21);
        let chords: Vec<f64> = s
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .collect();
        let (lo, hi) = chords
            .iter()
            .fold((f64::MAX, 0f64), |(l, h), &c| (l.min(c), h.max(c)));
        assert!(hi / lo < 1.02, "chords {lo}..{hi}");
        assert!((chords.iter().sum::<f64>() - c.length()).abs() < 0.01 * c.length());
    }

    #[test]
    fn relative_control_points_follow_the_edge_frame() {
        // Half-way along (0,0)→(2,0) and a quarter of its length to the left: (1, 0.5).
        assert_eq!(
            relative_point([0.0, 0.0], [2.0, 0.0], [0.5, 0.25]),
            [1.0, 0.5]
        );
    }
}
