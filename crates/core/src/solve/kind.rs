//! Which solver runs a scene: its names in scenes and in reports, and the integrator it is.

use serde::{Deserialize, Serialize};

/// A time integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Hash)]
#[serde(rename_all = "kebab-case")]
pub enum Integrator {
    /// Forward Euler with Provot's correction (seed 000).
    ExplicitEuler,
    /// Semi-implicit (symplectic) Euler.
    SymplecticEuler,
    /// Implicit Euler as an optimisation of the incremental potential (Newton, adaptive steps).
    ImplicitEuler,
    /// Implicit Euler linearised once per step (Baraff–Witkin, conjugate gradients, fixed steps).
    BaraffWitkin,
}

impl Integrator {
    /// The name written into outputs: its [`SolverKind`]'s.
    pub fn as_str(self) -> &'static str {
        SolverKind::from(self).name()
    }
}

/// Which solver runs the scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default, Hash)]
#[serde(rename_all = "kebab-case")]
pub enum SolverKind {
    /// Newton on the total potential energy with line search.
    #[default]
    Static,
    /// Explicit Euler with Provot's correction (seed 000).
    ExplicitEuler,
    /// Symplectic Euler.
    SymplecticEuler,
    /// Implicit Euler as an optimisation of the incremental potential (Newton, adaptive steps).
    ImplicitEuler,
    /// Implicit Euler linearised once per step (Baraff–Witkin), fixed steps.
    BaraffWitkin,
}

impl SolverKind {
    /// The name as written in scenes.
    pub const fn name(self) -> &'static str {
        match self {
            SolverKind::Static => "static",
            SolverKind::ExplicitEuler => "explicit-euler",
            SolverKind::SymplecticEuler => "symplectic-euler",
            SolverKind::ImplicitEuler => "implicit-euler",
            SolverKind::BaraffWitkin => "baraff-witkin",
        }
    }
    /// Whether the solver handles the sheet's self-contact (a barrier with a bounded step): the
    /// static solve and implicit Euler.
    pub fn supports_self_contact(self) -> bool {
        matches!(self, SolverKind::Static | SolverKind::ImplicitEuler)
    }
    /// The dynamic integrator, if this is one.
    pub fn integrator(self) -> Option<Integrator> {
        match self {
            SolverKind::Static => None,
            SolverKind::ExplicitEuler => Some(Integrator::ExplicitEuler),
            SolverKind::SymplecticEuler => Some(Integrator::SymplecticEuler),
            SolverKind::ImplicitEuler => Some(Integrator::ImplicitEuler),
            SolverKind::BaraffWitkin => Some(Integrator::BaraffWitkin),
        }
    }
}

impl SolverKind {
    /// The name in a [`super::SolveReport`] and the outputs: "static-newton" for the static solve,
    /// the scene's name otherwise.
    pub const fn report_name(self) -> &'static str {
        match self {
            SolverKind::Static => "static-newton",
            other => other.name(),
        }
    }
    /// The kind of a report name ([`Self::report_name`]) or of a scene name.
    pub fn from_name(name: &str) -> Option<Self> {
        [
            SolverKind::Static,
            SolverKind::ExplicitEuler,
            SolverKind::SymplecticEuler,
            SolverKind::ImplicitEuler,
            SolverKind::BaraffWitkin,
        ]
        .into_iter()
        .find(|k| k.name() == name || k.report_name() == name)
    }
}

impl From<Integrator> for SolverKind {
    fn from(i: Integrator) -> Self {
        match i {
            Integrator::ExplicitEuler => SolverKind::ExplicitEuler,
            Integrator::SymplecticEuler => SolverKind::SymplecticEuler,
            Integrator::ImplicitEuler => SolverKind::ImplicitEuler,
            Integrator::BaraffWitkin => SolverKind::BaraffWitkin,
        }
    }
}

/// (De)serializes a [`SolverKind`] by its report name, as `SolveReport.solver` is written.
pub mod by_report_name {
    use super::SolverKind;
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes the report name.
    pub fn serialize<S: Serializer>(k: &SolverKind, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(k.report_name())
    }
    /// Reads a report or scene name.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<SolverKind, D::Error> {
        let name = String::deserialize(d)?;
        SolverKind::from_name(&name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown solver `{name}`")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One name table: every kind reads back from its scene name and its report name, an
    /// integrator is named as its kind, and a report writes and reads its solver by report name.
    #[test]
    fn every_kind_reads_back_from_its_names_and_a_report_writes_its_report_name() {
        for k in [
            SolverKind::Static,
            SolverKind::ExplicitEuler,
            SolverKind::SymplecticEuler,
            SolverKind::ImplicitEuler,
            SolverKind::BaraffWitkin,
        ] {
            assert_eq!(SolverKind::from_name(k.name()), Some(k));
            assert_eq!(SolverKind::from_name(k.report_name()), Some(k));
            if let Some(i) = k.integrator() {
                assert_eq!(i.as_str(), k.name());
                assert_eq!(SolverKind::from(i), k);
            }
        }
        assert_eq!(SolverKind::from_name("newton"), None);
        let r = super::super::SolveReport::unsolved(SolverKind::Static);
        let json = serde_json::to_value(&r).unwrap();
        assert_eq!(json["solver"], "static-newton");
        let back = by_report_name::deserialize(json["solver"].clone()).unwrap();
        assert_eq!(back, SolverKind::Static);
    }
}
