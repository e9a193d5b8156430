//! Smooth drape surfaces (seed 003 §10.8): a drape's grid extended to the rectangle, interpolated by a
//! bicubic B-spline surface, trimmed along B-spline curves in the parameter plane, evaluated at any
//! resolution with exact normals, texture-mapped on its material coordinates, and rendered.

mod bspline;
mod extend;
mod mesh;
mod render;
mod texture;
mod trim;

pub use bspline::{BSplineSurface, Basis, Parametrization};
pub use extend::extend_to_rectangle;
pub use mesh::{DrapeSurface, SurfaceMesh, projected_area};
pub use render::{Paint, View, render_surface};
pub use texture::{TextureMapping, checkerboard, sample, warp_stripes, woven_check};
pub use trim::{Trim, outline};
