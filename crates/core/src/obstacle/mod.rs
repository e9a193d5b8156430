//! Rigid obstacles of seed 003's drape scenes (§10.5–10.7): a plane, a box table, a cylindrical rod
//! along any axis, a sphere, a disc pedestal and a body form of revolution given by its meridional
//! profile. Each gives a signed distance (positive outside, m) with its outward normal, and the height
//! of its upper surface above a point (for the vertical-gap method of §10.7.1).

pub(crate) mod mesh;
mod mesh_defect;
mod parameters;
mod segment;

pub use mesh::{BodyDefect, TriangleBody};

use crate::error::KeyError;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// A rigid obstacle. Every length in m; positions in the scene's frame (z up).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Obstacle {
    /// The half-space below a plane through `point_m` with upward normal `normal`.
    Plane {
        /// A point of the plane, m.
        point_m: [f64; 3],
        /// The outward normal (normalised on use).
        normal: [f64; 3],
    },
    /// An axis-aligned box (a table): from `min_m` to `max_m`.
    Box {
        /// Lower corner, m.
        min_m: [f64; 3],
        /// Upper corner, m.
        max_m: [f64; 3],
    },
    /// An infinite round rod: axis through `point_m` along `axis`, radius `radius_m`.
    Cylinder {
        /// A point of the axis, m.
        point_m: [f64; 3],
        /// Axis direction (normalised on use), e.g. [1, -1, 0] for a diagonal rod.
        axis: [f64; 3],
        /// Radius, m.
        radius_m: f64,
    },
    /// A sphere.
    Sphere {
        /// Centre, m.
        centre_m: [f64; 3],
        /// Radius, m.
        radius_m: f64,
    },
    /// A disc pedestal: a vertical cylinder of radius `radius_m` whose top face is at `centre_m` and
    /// which extends `height_m` below it.
    Pedestal {
        /// Centre of the top face, m.
        centre_m: [f64; 3],
        /// Radius, m.
        radius_m: f64,
        /// Height below the top face, m.
        height_m: f64,
    },
    /// A solid of revolution about the vertical through `axis_m` (x, y): `profile_m` lists
    /// (height z, radius r) pairs, z increasing; the solid ends at the first and last heights.
    Revolution {
        /// (x, y) of the vertical axis, m.
        axis_m: [f64; 2],
        /// Meridional profile: (z, r) pairs in m, z strictly increasing, r ≥ 0.
        profile_m: Vec<[f64; 2]>,
    },
    /// A rigid body given as a triangle mesh (a dress form, a mannequin, a scanned table): a
    /// Wavefront OBJ file whose faces (polygons split into fans) face outward, counter-clockwise
    /// seen from outside. Cloth vertices are kept out of it by the barrier on their signed distance
    /// to its surface ([`TriangleBody`]); the surface's edges and corners are not sharper than the
    /// cloth's spacing for that to keep the cloth's edges out too.
    Mesh {
        /// The OBJ file, relative to the scene file's folder.
        mesh: std::path::PathBuf,
        /// The file's length unit in m: 1 for metres (default), 0.01 for centimetres, 0.001 for
        /// millimetres.
        #[serde(default = "unit_metre")]
        mesh_unit_m: f64,
        /// Where the file's origin lies in the scene, m: the body is translated by it. Default
        /// [0, 0, 0]. A continuous key (`--sensitivity obstacles.0.offset_m.2`).
        #[serde(default)]
        offset_m: [f64; 3],
        /// The body read from `mesh` (set when the scene is loaded; never written).
        #[serde(skip)]
        body: Option<std::sync::Arc<TriangleBody>>,
    },
}

fn unit_metre() -> f64 {
    1.0
}

/// How far outside a table's or pedestal's top face a point still counts as above it (m): grid lines
/// that fall on the edge by construction must not depend on round-off.
const EDGE_SLACK_M: f64 = 1e-9;

fn v(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

/// Signed distance from a point to a 2D segment-polygon boundary (the meridional section of a solid of
/// revolution: axis, profile, caps) and the closest point's outward direction; positive outside.
fn revolution_sdf(profile: &[[f64; 2]], r: f64, z: f64) -> (f64, f64, f64) {
    // The closed section: (0, z0) → profile → (0, zn) → back along the axis.
    let mut poly: Vec<[f64; 2]> = Vec::with_capacity(profile.len() + 2);
    poly.push([0.0, profile[0][0]]);
    poly.extend(profile.iter().map(|p| [p[1], p[0]]));
    poly.push([0.0, profile[profile.len() - 1][0]]);
    let (mut best, mut dir) = (f64::INFINITY, (0.0, 1.0));
    let mut inside = false;
    for k in 0..poly.len() {
        let a = poly[k];
        let b = poly[(k + 1) % poly.len()];
        let (ex, ez) = (b[0] - a[0], b[1] - a[1]);
        let len2 = ex * ex + ez * ez;
        let t = if len2 > 0.0 {
            (((r - a[0]) * ex + (z - a[1]) * ez) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (qx, qz) = (a[0] + t * ex, a[1] + t * ez);
        let d = ((r - qx).powi(2) + (z - qz).powi(2)).sqrt();
        if d < best {
            best = d;
            dir = if d > 1e-15 {
                ((r - qx) / d, (z - qz) / d)
            } else {
                (ez, -ex)
            };
        }
        // Even-odd rule for the inside test.
        if (a[1] > z) != (b[1] > z) && r < a[0] + (z - a[1]) / (b[1] - a[1]) * (b[0] - a[0]) {
            inside = !inside;
        }
    }
    if inside {
        (-best, -dir.0, -dir.1)
    } else {
        (best, dir.0, dir.1)
    }
}

/// One share of an obstacle's barrier at a point: distance (m), outward unit normal, the normal's
/// derivative (1/m) where known in closed form (none: left to the caller, or zero inside a mesh
/// body's face), and the share's weight ([`TriangleBody::pieces_within`]).
pub type BarrierPiece = (f64, Vector3<f64>, Option<nalgebra::Matrix3<f64>>, f64);

impl Obstacle {
    /// Whether the solid is convex (every kind but a solid of revolution, whose profile may narrow).
    pub fn is_convex(&self) -> bool {
        !matches!(self, Obstacle::Revolution { .. } | Obstacle::Mesh { .. })
    }

    /// Signed distance (m, positive outside) and the unit outward normal at the closest point.
    pub fn signed_distance(&self, p: &Vector3<f64>) -> (f64, Vector3<f64>) {
        match self {
            Obstacle::Plane { point_m, normal } => {
                let n = v(*normal).normalize();
                ((p - v(*point_m)).dot(&n), n)
            }
            Obstacle::Box { min_m, max_m } => box_sdf(v(*min_m), v(*max_m), p),
            Obstacle::Cylinder {
                point_m,
                axis,
                radius_m,
            } => {
                let a = v(*axis).normalize();
                let q = p - v(*point_m);
                let radial = q - a * q.dot(&a);
                let r = radial.norm();
                let n = if r > 1e-15 { radial / r } else { Vector3::z() };
                (r - radius_m, n)
            }
            Obstacle::Sphere { centre_m, radius_m } => {
                let q = p - v(*centre_m);
                let r = q.norm();
                let n = if r > 1e-15 { q / r } else { Vector3::z() };
                (r - radius_m, n)
            }
            Obstacle::Pedestal {
                centre_m,
                radius_m,
                height_m,
            } => pedestal_sdf(p - v(*centre_m), *radius_m, *height_m),
            Obstacle::Revolution { axis_m, profile_m } => {
                let q = Vector3::new(p.x - axis_m[0], p.y - axis_m[1], p.z);
                let rr = (q.x * q.x + q.y * q.y).sqrt();
                let radial = if rr > 1e-15 {
                    Vector3::new(q.x / rr, q.y / rr, 0.0)
                } else {
                    Vector3::x()
                };
                let (d, nr, nz) = revolution_sdf(profile_m, rr, p.z);
                (d, (radial * nr + Vector3::z() * nz).normalize())
            }
            Obstacle::Mesh { offset_m, body, .. } => match body {
                Some(b) => b.signed_distance(&(p - v(*offset_m))),
                // Not read (a scene built in code without loading): nothing to touch.
                None => (f64::INFINITY, Vector3::z()),
            },
        }
    }

    /// [`Obstacle::signed_distance`] where the surface lies nearer than `reach` (m), else none: a
    /// mesh body answers far points from its hierarchy's root ([`TriangleBody::signed_distance_within`]).
    pub fn signed_distance_within(&self, p: &Vector3<f64>, r: f64) -> Option<(f64, Vector3<f64>)> {
        match self {
            Obstacle::Mesh {
                offset_m,
                body: Some(b),
                ..
            } => b.signed_distance_within(&(p - v(*offset_m)), r),
            _ => Some(self.signed_distance(p)).filter(|(d, _)| *d < r),
        }
    }

    /// What a barrier of band `r` sums over at `p` ([`BarrierPiece`]). A mesh body outside its
    /// surface gives its faces, edges and vertices within `r`, weighted ±1
    /// ([`TriangleBody::pieces_within`]); every other case the closest point alone
    /// ([`Obstacle::signed_distance_within`]), weight 1, its normal's derivative left to the caller.
    pub fn barrier_pieces(&self, p: &Vector3<f64>, r: f64) -> Vec<BarrierPiece> {
        if let Obstacle::Mesh {
            offset_m,
            body: Some(b),
            ..
        } = self
            && let Some(pieces) = b.pieces_within(&(p - v(*offset_m)), r)
        {
            return pieces;
        }
        self.signed_distance_within(p, r)
            .map(|(d, n)| (d, n, None, 1.0))
            .into_iter()
            .collect()
    }

    /// Height of the obstacle's upper surface on the vertical through (x, y), if the vertical meets it
    /// (the vertical-gap method of §10.7.1 pulls a node that went inside back up to it).
    pub fn top_at(&self, x: f64, y: f64) -> Option<f64> {
        match self {
            Obstacle::Plane { point_m, normal } => {
                let n = v(*normal).normalize();
                (n.z.abs() > 1e-12)
                    .then(|| point_m[2] - (n.x * (x - point_m[0]) + n.y * (y - point_m[1])) / n.z)
            }
            Obstacle::Box { min_m, max_m } => {
                let e = EDGE_SLACK_M;
                (x >= min_m[0] - e && x <= max_m[0] + e && y >= min_m[1] - e && y <= max_m[1] + e)
                    .then_some(max_m[2])
            }
            Obstacle::Cylinder {
                point_m,
                axis,
                radius_m,
            } => {
                // Points (x, y, z) with |radial| = R: solve the quadratic in z.
                let a = v(*axis).normalize();
                let q0 = Vector3::new(x - point_m[0], y - point_m[1], -point_m[2]);
                let ez = Vector3::z();
                let u = q0 - a * q0.dot(&a);
                let w = ez - a * ez.dot(&a);
                let (qa, qb, qc) = (w.dot(&w), 2.0 * u.dot(&w), u.dot(&u) - radius_m * radius_m);
                if qa < 1e-15 {
                    return None;
                }
                let disc = qb * qb - 4.0 * qa * qc;
                (disc >= 0.0).then(|| (-qb + disc.sqrt()) / (2.0 * qa))
            }
            Obstacle::Sphere { centre_m, radius_m } => {
                let r2 = (x - centre_m[0]).powi(2) + (y - centre_m[1]).powi(2);
                (r2 <= radius_m * radius_m).then(|| centre_m[2] + (radius_m * radius_m - r2).sqrt())
            }
            Obstacle::Pedestal {
                centre_m, radius_m, ..
            } => (((x - centre_m[0]).powi(2) + (y - centre_m[1]).powi(2)).sqrt()
                <= radius_m + EDGE_SLACK_M)
                .then_some(centre_m[2]),
            Obstacle::Revolution { axis_m, profile_m } => {
                let r = ((x - axis_m[0]).powi(2) + (y - axis_m[1]).powi(2)).sqrt();
                // The highest profile point whose radius reaches r: scan the profile from the top.
                let mut top = None;
                for w in profile_m.windows(2).rev() {
                    let ([z0, r0], [z1, r1]) = (w[0], w[1]);
                    if (r0 - r) * (r1 - r) <= 0.0 && (r1 - r0).abs() > 1e-15 {
                        top = Some(z0 + (r - r0) / (r1 - r0) * (z1 - z0));
                        break;
                    }
                    if r <= r1.min(r0) {
                        top = Some(z1);
                        break;
                    }
                }
                top
            }
            Obstacle::Mesh { offset_m, body, .. } => body
                .as_ref()?
                .top_at(x - offset_m[0], y - offset_m[1])
                .map(|z| z + offset_m[2]),
        }
    }

    /// The height of a horizontal upper face on the vertical through (x, y): a table's or
    /// pedestal's top where the vertical meets it, a mesh body's where its highest face there is
    /// horizontal; None for other shapes (the supports rule, `contact.fix_supported`).
    pub fn flat_top_at(&self, x: f64, y: f64) -> Option<f64> {
        match self {
            Obstacle::Box { .. } | Obstacle::Pedestal { .. } => self.top_at(x, y),
            Obstacle::Mesh { offset_m, body, .. } => body
                .as_ref()?
                .flat_top_at(x - offset_m[0], y - offset_m[1])
                .map(|z| z + offset_m[2]),
            _ => None,
        }
    }

    /// Checks the definition: Err(KeyError::new(key, message)).
    pub fn check(&self) -> Result<(), KeyError> {
        let positive = KeyError::positive;
        match self {
            Obstacle::Plane { point_m, normal } => {
                finite("point_m", point_m)?;
                nonzero("normal", *normal)
            }
            Obstacle::Box { min_m, max_m } => {
                finite("min_m", min_m)?;
                finite("max_m", max_m)?;
                if (0..3).all(|k| max_m[k] > min_m[k]) {
                    Ok(())
                } else {
                    Err(KeyError::new("max_m", "must exceed min_m in x, y and z"))
                }
            }
            Obstacle::Cylinder {
                point_m,
                axis,
                radius_m,
            } => {
                finite("point_m", point_m)?;
                nonzero("axis", *axis)?;
                positive("radius_m", *radius_m)
            }
            Obstacle::Sphere { centre_m, radius_m } => {
                finite("centre_m", centre_m)?;
                positive("radius_m", *radius_m)
            }
            Obstacle::Pedestal {
                centre_m,
                radius_m,
                height_m,
            } => {
                finite("centre_m", centre_m)?;
                positive("radius_m", *radius_m)?;
                positive("height_m", *height_m)
            }
            Obstacle::Revolution { axis_m, profile_m } => {
                finite("axis_m", axis_m)?;
                check_profile(profile_m)
            }
            Obstacle::Mesh {
                offset_m,
                mesh_unit_m,
                body,
                ..
            } => {
                finite("offset_m", offset_m)?;
                positive("mesh_unit_m", *mesh_unit_m)?;
                match body {
                    Some(_) => Ok(()),
                    None => Err(KeyError::new(
                        "mesh",
                        "was not read (load the scene from its file)",
                    )),
                }
            }
        }
    }
}

/// Signed distance and outward normal of the axis-aligned box from `lo` to `hi` at `p`.
fn box_sdf(lo: Vector3<f64>, hi: Vector3<f64>, p: &Vector3<f64>) -> (f64, Vector3<f64>) {
    let c = (lo + hi) * 0.5;
    let half = (hi - lo) * 0.5;
    let q = p - c;
    let d = q.abs() - half;
    let outside = d.map(|x| x.max(0.0));
    if outside.norm() > 0.0 {
        let dir = Vector3::new(
            outside.x * q.x.signum(),
            outside.y * q.y.signum(),
            outside.z * q.z.signum(),
        );
        (outside.norm(), dir.normalize())
    } else {
        // Inside: the nearest face.
        let k = d.imax();
        let mut n = Vector3::zeros();
        n[k] = q[k].signum();
        (d[k], n)
    }
}

/// Signed distance and outward normal of a pedestal (radius `radius_m`, `height_m` below its top
/// face) at `q`, relative to the centre of its top face.
fn pedestal_sdf(q: Vector3<f64>, radius_m: f64, height_m: f64) -> (f64, Vector3<f64>) {
    let rr = (q.x * q.x + q.y * q.y).sqrt();
    let radial = if rr > 1e-15 {
        Vector3::new(q.x / rr, q.y / rr, 0.0)
    } else {
        Vector3::x()
    };
    // 2D box in (r, z) with r ∈ [0, R], z ∈ [−H, 0].
    let zc = -0.5 * height_m;
    let (dr, dz) = (rr - radius_m, (q.z - zc).abs() - 0.5 * height_m);
    let zs = (q.z - zc).signum();
    if dr > 0.0 || dz > 0.0 {
        let (or, oz) = (dr.max(0.0), dz.max(0.0));
        let d = (or * or + oz * oz).sqrt();
        let n = radial * (or / d) + Vector3::z() * (oz * zs / d);
        (d, n)
    } else if dr > dz {
        (dr, radial)
    } else {
        (dz, Vector3::z() * zs)
    }
}

/// Ok when every number of `a` is finite; else the error naming `key`.
fn finite(key: &str, a: &[f64]) -> Result<(), KeyError> {
    if a.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(KeyError::new(key, "must be finite"))
    }
}

/// Ok when `a` is a finite, non-zero vector; else the error naming `key`.
fn nonzero(key: &str, a: [f64; 3]) -> Result<(), KeyError> {
    finite(key, &a)?;
    if v(a).norm() > 1e-12 {
        Ok(())
    } else {
        Err(KeyError::new(key, "must be a non-zero vector"))
    }
}

/// Ok when a body of revolution's profile has at least two (z, r) points, finite, r ≥ 0, heights
/// rising strictly; else the error naming the first bad point.
fn check_profile(profile_m: &[[f64; 2]]) -> Result<(), KeyError> {
    if profile_m.len() < 2 {
        return Err(KeyError::new(
            "profile_m",
            "needs at least two (z, r) points",
        ));
    }
    for (k, p) in profile_m.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite() && p[1] >= 0.0) {
            return Err(KeyError::new(
                format!("profile_m.{k}"),
                "needs finite z and r ≥ 0",
            ));
        }
        if k > 0 && p[0] <= profile_m[k - 1][0] {
            return Err(KeyError::new(
                format!("profile_m.{k}"),
                "heights must increase strictly",
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The normal is the gradient of the signed distance (finite differences).
    #[test]
    fn normals_are_gradients_of_the_distance() {
        let obstacles = [
            Obstacle::Box {
                min_m: [-0.05, -0.05, -0.3],
                max_m: [0.05, 0.05, -0.001],
            },
            Obstacle::Cylinder {
                point_m: [0.0, 0.0, -0.026],
                axis: [1.0, -1.0, 0.0],
                radius_m: 0.025,
            },
            Obstacle::Sphere {
                centre_m: [0.0, 0.0, -0.03],
                radius_m: 0.025,
            },
            Obstacle::Pedestal {
                centre_m: [0.0, 0.0, -0.001],
                radius_m: 0.06,
                height_m: 0.3,
            },
            Obstacle::Revolution {
                axis_m: [0.0, 0.0],
                profile_m: vec![[-0.5, 0.1], [-0.2, 0.14], [-0.05, 0.12], [0.0, 0.0]],
            },
        ];
        let pts = [
            Vector3::new(0.07, 0.02, 0.01),
            Vector3::new(-0.03, 0.08, -0.04),
            Vector3::new(0.01, -0.02, 0.05),
            Vector3::new(0.2, 0.1, -0.3),
        ];
        for o in &obstacles {
            for p in &pts {
                let (d, n) = o.signed_distance(p);
                let h = 1e-7;
                let fd = Vector3::from_fn(|k, _| {
                    let mut q = *p;
                    q[k] += h;
                    (o.signed_distance(&q).0 - d) / h
                });
                assert!((fd - n).norm() < 1e-4, "{o:?} at {p:?}: {fd:?} vs {n:?}");
                assert!((n.norm() - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn the_top_surface_lies_on_the_obstacle() {
        let s = Obstacle::Sphere {
            centre_m: [0.0, 0.0, -0.03],
            radius_m: 0.025,
        };
        let c = Obstacle::Cylinder {
            point_m: [0.0, 0.0, -0.026],
            axis: [1.0, -1.0, 0.0],
            radius_m: 0.025,
        };
        for o in [&s, &c] {
            for (x, y) in [(0.0, 0.0), (0.01, 0.005), (-0.012, 0.003)] {
                let z = o.top_at(x, y).unwrap();
                let (d, n) = o.signed_distance(&Vector3::new(x, y, z));
                assert!(d.abs() < 1e-12 && n.z > 0.0, "{o:?}: {d} {n:?}");
            }
        }
        assert!(s.top_at(0.1, 0.0).is_none());
    }
}
