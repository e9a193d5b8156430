//! An obstacle's real-valued shape parameters, for derivatives of a drape in them (the
//! sensitivities and gradients of `obstacles.N.*` keys).

use super::Obstacle;

impl Obstacle {
    /// The obstacle's real-valued shape parameters (its points, directions, radii, heights and
    /// profile, in the order the scene file writes them), for derivatives in them: mutable, so that
    /// one list serves reading ([`Obstacle::parameters`]) and setting
    /// ([`Obstacle::set_parameters`]).
    pub fn parameters_mut(&mut self) -> Vec<&mut f64> {
        use std::iter::once;
        match self {
            Obstacle::Plane { point_m, normal } => point_m.iter_mut().chain(normal).collect(),
            Obstacle::Box { min_m, max_m } => min_m.iter_mut().chain(max_m).collect(),
            Obstacle::Cylinder {
                point_m,
                axis,
                radius_m,
            } => point_m
                .iter_mut()
                .chain(axis)
                .chain(once(radius_m))
                .collect(),
            Obstacle::Sphere { centre_m, radius_m } => {
                centre_m.iter_mut().chain(once(radius_m)).collect()
            }
            Obstacle::Pedestal {
                centre_m,
                radius_m,
                height_m,
            } => centre_m
                .iter_mut()
                .chain(once(radius_m))
                .chain(once(height_m))
                .collect(),
            Obstacle::Revolution { axis_m, profile_m } => axis_m
                .iter_mut()
                .chain(profile_m.iter_mut().flatten())
                .collect(),
            Obstacle::Mesh { offset_m, .. } => offset_m.iter_mut().collect(),
        }
    }

    /// The shape parameters ([`Obstacle::parameters_mut`]), SI units.
    pub fn parameters(&self) -> Vec<f64> {
        self.clone()
            .parameters_mut()
            .into_iter()
            .map(|p| *p)
            .collect()
    }

    /// Sets the shape parameters (the layout of [`Obstacle::parameters`]).
    pub fn set_parameters(&mut self, values: &[f64]) {
        for (p, v) in self.parameters_mut().into_iter().zip(values) {
            *p = *v;
        }
    }
}
