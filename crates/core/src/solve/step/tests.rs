use super::*;
use crate::physics::testing::two_layers;
use crate::solve::SolveReport;

/// Newton's workspace carries the contact set of the state it stands at: after every iteration
/// (accepted steps, curved and chord ones alike) its set is the one measured afresh there, so the
/// gradient and Hessian it assembles are the model's at that state.
#[test]
fn the_workspace_carries_the_contact_set_of_its_state() {
    for reuse in [FactorReuse::Fresh, FactorReuse::Chord] {
        let (model, mut x) = two_layers(1.2e-3);
        let opts = StaticOptions {
            factor_reuse: reuse,
            ..StaticOptions::default()
        };
        let mut ws = Workspace::new(&model, &x, &opts, (None, CandidateSet::default()));
        let mut e = ws.enter(&model, &x, 1.0);
        let mut report = SolveReport::unsolved(crate::solve::SolverKind::Static);
        let tol = 1e-9 * model.reference_weight();
        let (mut touched, mut iterations) = (0, 0);
        for _ in 0..60 {
            ws.gradient_here(&model, &x, 1.0);
            let r = model.max_residual(&ws.g);
            if r <= tol {
                break;
            }
            iterations += 1;
            let taken = ws.iterate(&model, &mut x, 1.0, &mut e, (r, tol), &mut report);
            assert_eq!(taken, Iteration::Stepped, "{reuse:?}");
            let fresh = model.contacts(&x);
            assert!(
                ws.contacts == fresh,
                "{reuse:?}: the set is not the state's"
            );
            assert_eq!(e, model.energy(&x, 1.0), "{reuse:?}");
            touched += usize::from(!ws.contacts.is_empty());
        }
        ws.gradient_here(&model, &x, 1.0);
        let r = model.max_residual(&ws.g);
        assert!(
            r <= tol,
            "{reuse:?}: {r:e} N after {} iterations",
            report.linear_solves
        );
        assert!(touched > 0, "the layers never came within range");
        // The run's candidate set is carried from state to state: few broad phases for its many
        // measured states (each iteration measures one or more).
        let phases = ws.candidates.broad_phases();
        assert!(
            (1..=iterations / 4).contains(&phases),
            "{reuse:?}: {phases} broad phases in {iterations} iterations"
        );
        if reuse == FactorReuse::Chord {
            assert!(ws.stats.chord_steps > 0, "no chord step taken");
        }
    }
}
