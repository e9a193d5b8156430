//! Smooth drape surfaces (seed 003 §10.8, issue 20 — started): bicubic B-spline interpolation of a
//! drape's grid with exact derivatives and normals. Trimming, texture mapping and glTF export are not
//! built yet.

mod bspline;

pub use bspline::{BSplineSurface, Basis, Parametrization};
