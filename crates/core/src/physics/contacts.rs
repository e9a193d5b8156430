//! The contact data of a state, built by the solve and handed to the model's energy and
//! derivatives (ipc-toolkit's `Collisions`, built by the caller and passed to its
//! `BarrierPotential`): a solve measures the contact set once per state it evaluates, from the
//! broad phase's [`CandidateSet`] it carries from state to state, and nothing in a term remembers
//! positions. The obstacle barriers need no set: each particle's distance to an analytic obstacle
//! is a function of its own position.

use super::self_contact::{CandidateSet, ContactSet};
use super::{EnergyTerm, HessianBlocks, HessianMode, Model, SelfContact, Vecs};
use nalgebra::Vector3;
use std::sync::Arc;

/// The contact set of a model at one state: the sheet's self-contact pairs within range (None
/// for a model without self-contact). Valid for the state and the coefficients it was built at.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Contacts {
    /// The self-contact pairs within the activation distance.
    pub self_pairs: Option<ContactSet>,
}

impl Contacts {
    /// The number of self-contact pairs in range.
    pub fn len(&self) -> usize {
        self.self_pairs.as_ref().map_or(0, ContactSet::len)
    }
    /// Whether no pair is in range.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The term `t` as the self-contact term with its set in `contacts`, when it is one.
fn on_set<'a>(
    t: &'a dyn EnergyTerm,
    contacts: &'a Contacts,
) -> Option<(&'a SelfContact, &'a ContactSet)> {
    let set = contacts.self_pairs.as_ref()?;
    t.as_any().downcast_ref::<SelfContact>().map(|s| (s, set))
}

impl Model {
    /// The contact set at `x`, from the narrow phase over `candidates` (the solve's candidate set,
    /// rebuilt by a broad phase where `x` left the region it covers).
    pub fn contacts_with(&self, x: &Vecs, candidates: &mut CandidateSet) -> Contacts {
        Contacts {
            self_pairs: self
                .self_contact_term()
                .map(|t| t.contact_set(x, candidates)),
        }
    }

    /// The contact set at `x` with a candidate set of its own (a broad phase at `x`): for a
    /// single evaluation; a solve carries its [`CandidateSet`] ([`Model::contacts_with`]).
    pub fn contacts(&self, x: &Vecs) -> Contacts {
        self.contacts_with(x, &mut CandidateSet::default())
    }

    /// Total potential energy in J at `x`, its contact set measured over `candidates` (the
    /// solve's candidate set): a solve's evaluation at a state it only looks at.
    pub fn energy_with(&self, x: &Vecs, candidates: &mut CandidateSet, load: f64) -> f64 {
        self.energy_on(x, &self.contacts_with(x, candidates), load)
    }

    /// The largest fraction of the step `dx` from `x` that every contact term allows
    /// ([`super::StepBound`]), the self-contact term's over `candidates` (the solve's set, made to
    /// cover the step).
    pub fn max_step_with(&self, x: &Vecs, dx: &Vecs, candidates: &mut CandidateSet) -> f64 {
        let mut bound = f64::INFINITY;
        for t in &self.terms {
            let b = match t.as_any().downcast_ref::<SelfContact>() {
                Some(s) => s.max_step_with(x, dx, candidates),
                None => t.step_bound().map_or(f64::INFINITY, |b| b.max_step(x, dx)),
            };
            bound = bound.min(b);
        }
        bound
    }

    /// Total potential energy in J at `x` with the contact set `contacts` built there, external
    /// loads scaled by `load` (1 = full load).
    pub fn energy_on(&self, x: &Vecs, contacts: &Contacts, load: f64) -> f64 {
        let term = |t: &dyn EnergyTerm| match on_set(t, contacts) {
            Some((s, set)) => s.energy_of(set, x),
            None => t.energy(x),
        };
        self.terms
            .iter()
            .map(|t| match t.is_external_load() {
                true => load * term(&**t),
                false => term(&**t),
            })
            .sum()
    }

    /// Gradient of the total energy (N) at `x` with the contact set `contacts` into `g`
    /// (overwritten), external loads scaled by `load`.
    pub fn gradient_on(&self, x: &Vecs, contacts: &Contacts, load: f64, g: &mut Vec<Vector3<f64>>) {
        g.clear();
        g.resize(x.len(), Vector3::zeros());
        let add = |t: &dyn EnergyTerm, g: &mut Vecs| match on_set(t, contacts) {
            Some((s, set)) => s.add_gradient_of(set, x, g),
            None => t.add_gradient(x, g),
        };
        let mut gl = Vec::new();
        for t in &self.terms {
            if t.is_external_load() && load != 1.0 {
                gl.clear();
                gl.resize(x.len(), Vector3::zeros());
                add(&**t, &mut gl);
                for (a, b) in g.iter_mut().zip(&gl) {
                    *a += b * load;
                }
            } else {
                add(&**t, g);
            }
        }
    }

    /// Hessian blocks of the total energy at `x` with the contact set `contacts` into `h`
    /// (cleared first), as `mode` asks ([`HessianMode`]). The exact one assembles every term
    /// afresh; the others take the constant terms' blocks computed once.
    pub fn hessian_on(
        &self,
        x: &Vecs,
        contacts: &Contacts,
        h: &mut HessianBlocks,
        mode: HessianMode,
    ) {
        h.clear();
        let add = |t: &dyn EnergyTerm, h: &mut HessianBlocks| match on_set(t, contacts) {
            Some((s, set)) => s.add_hessian_with_hints(set, x, h, mode),
            None => t.add_hessian(x, h, mode),
        };
        if mode == HessianMode::Exact {
            for t in &self.terms {
                add(&**t, h);
            }
            return;
        }
        h.constant = self
            .constant_hessian
            .get_or_init(|| {
                let mut c = HessianBlocks::default();
                for t in self.terms.iter().filter(|t| t.hessian_is_constant()) {
                    t.add_hessian(x, &mut c, HessianMode::NEWTON);
                }
                (!c.pairs.is_empty()).then(|| Arc::new(c))
            })
            .clone();
        for t in self.terms.iter().filter(|t| !t.hessian_is_constant()) {
            add(&**t, h);
        }
    }

    /// The closest self-contact pair's gap beyond the thickness in `contacts`, relative to the
    /// band ([`SelfContact::closest_gap_rel`]; infinity when no pair is in range or the model has
    /// no self-contact).
    pub fn closest_gap_rel(&self, contacts: &Contacts) -> f64 {
        let set = contacts.self_pairs.as_ref();
        self.self_contact_term()
            .zip(set)
            .and_then(|(t, set)| t.closest_gap_rel(set))
            .unwrap_or(f64::INFINITY)
    }

    /// [`SelfContact::stiffen_barrier`] at the state `contacts` was built for: true when κ grew
    /// (the energy changed; the set stays valid).
    pub fn stiffen_barriers(&mut self, contacts: &Contacts) -> bool {
        let Some(set) = contacts.self_pairs.as_ref() else {
            return false;
        };
        self.self_contact_term_mut()
            .is_some_and(|t| t.stiffen_barrier(set))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::testing::two_layers;

    /// The energy, gradient and Hessian on the contact set built at a state are the model's at
    /// that state; on another state's set they are not (the set, not the positions, says which
    /// pairs repel).
    #[test]
    fn the_model_on_a_states_contact_set_is_the_model_at_that_state() {
        let (model, x) = two_layers(8e-4);
        let here = model.contacts(&x);
        assert!(here.len() > 10, "{} pairs", here.len());
        assert_eq!(here, model.contacts(&x));
        let e = model.energy_on(&x, &here, 1.0);
        assert_eq!(e, model.energy(&x, 1.0));
        let (mut g, mut g_on) = (Vec::new(), Vec::new());
        model.gradient(&x, 1.0, &mut g);
        model.gradient_on(&x, &here, 1.0, &mut g_on);
        assert_eq!(g, g_on);
        for mode in [
            HessianMode::Projected,
            HessianMode::NEWTON,
            HessianMode::Exact,
        ] {
            let (mut h, mut h_on) = (HessianBlocks::default(), HessianBlocks::default());
            model.hessian(&x, &mut h, mode);
            model.hessian_on(&x, &here, &mut h_on, mode);
            assert_eq!(
                (&h.pairs, &h.blocks),
                (&h_on.pairs, &h_on.blocks),
                "{mode:?}"
            );
        }
        // Lifted out of range, the upper sheet's set is empty: on it the barrier adds nothing.
        let far: Vec<_> = (x.iter().enumerate())
            .map(|(p, v)| v + Vector3::z() * if p >= 16 { 0.01 } else { 0.0 })
            .collect();
        let there = model.contacts(&far);
        assert!(there.is_empty());
        let barrier = model
            .self_contact_term()
            .expect("term")
            .energy_of(here.self_pairs.as_ref().expect("set"), &x);
        assert!(barrier > 0.0);
        let without = model.energy_on(&x, &there, 1.0);
        assert!(
            (e - without - barrier).abs() <= 1e-12 * barrier,
            "{e} {without} {barrier}"
        );
    }
}
