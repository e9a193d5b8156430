//! Which Hessian a term pushes, chosen per call by the solver that asks for it: no term keeps a
//! solver's switch (ipc-toolkit's habit: a potential's derivatives take the projection as an
//! argument, `project_hessian_to_psd`).

/// The Hessian a solver asks of the terms ([`super::EnergyTerm::add_hessian`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HessianMode {
    /// Positive semi-definite: every term's indefinite parts dropped (projected Newton; the
    /// implicit integrators' stiffness; the sagged start).
    Projected,
    /// Newton's Hessian: every term's exact one, except that a contact pair carries its distance's
    /// own curvature κ b′∇²d only as [`PairCurvature`] says (its barrier's κ b″∇d∇dᵀ always).
    Newton(PairCurvature),
    /// Every term's exact Hessian, every contact pair's whole curvature: derivatives of an
    /// equilibrium (sensitivities, adjoints) and its neutral directions.
    Exact,
}

/// Which self-contact pairs carry their distance's own curvature in Newton's Hessian
/// ([`HessianMode::Newton`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PairCurvature {
    /// None: an equilibrium solve's Hessian (with every pair's exact curvature from the first
    /// iteration l_panel_sphere took 197 → 577 iterations).
    #[default]
    NormalOnly,
    /// Pairs pinned within a small fraction of the band beyond the thickness: an implicit time
    /// step's Newton (without it, Newton did not converge in the stress box's steps where a pair
    /// sat at the thickness).
    Pinned,
    /// Every active pair: an equilibrium solve that has run long without converging
    /// ([`crate::solve::StaticOptions::exact_contact_after`]).
    All,
}

impl HessianMode {
    /// Newton's Hessian of an equilibrium solve: exact but for contact pairs' distance curvature.
    pub const NEWTON: HessianMode = HessianMode::Newton(PairCurvature::NormalOnly);

    /// Whether the indefinite parts are dropped.
    pub fn is_projected(self) -> bool {
        self == HessianMode::Projected
    }
}
