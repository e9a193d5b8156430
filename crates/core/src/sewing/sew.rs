//! Sewing (issue 91): the pieces start where the pattern places them, moved clear of the body
//! ([`arrange`]); each stitch's vertex pairs are pulled together by capped zero-rest-length springs
//! ([`crate::physics::Seams`]) whose stiffness a continuation raises ten-fold a stage, integrated
//! by implicit Euler without gravity (each step a minimisation of the incremental potential,
//! [`crate::solve::solve_dynamic`]), while the body's barrier keeps the pieces off the body and
//! self-contact keeps them off each other (every pair but those joined through a seam's paired
//! vertices, which must meet: [`crate::physics::SelfContact::with_twins`]). When the largest seam gap is below the tolerance the pairs are welded
//! ([`super::weld`]): one sheet, hinges across its seams, ready to drape.

use super::panels::Unsewn;
use crate::material::Rigidities;
use crate::obstacle::Obstacle;
use crate::pattern::{Defect, Pattern};
use crate::physics::{BodyEdgeBarrier, Contacts, EnergyTerm};
use crate::physics::{Model, PatternSheet, Seams, Vecs, pattern_builder, seam_hinge_bending};
use crate::solve::{Inertia, Observer, StaticOptions, solve_static};
use nalgebra::Vector3;

/// What sewing needs of the scene: the fabric, the body and the contact's distances.
pub struct SewSetup<'a> {
    /// The fabric's rigidities (SI).
    pub rigidities: &'a Rigidities,
    /// Areal density, kg/m².
    pub areal_density_kg_per_m2: f64,
    /// The warp's angle from each panel's +x, rad.
    pub warp_angle_rad: f64,
    /// The bodies.
    pub obstacles: &'a [Obstacle],
    /// The body barrier's activation distance, m.
    pub distance_m: f64,
    /// Self-contact thickness (and band), m.
    pub thickness_m: f64,
}

/// How sewing went: the numbers run.json reports.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SewReport {
    /// Seam vertex pairs.
    pub seam_pairs: usize,
    /// The largest seam gap where the pattern places the pieces, m.
    pub start_gap_m: f64,
    /// How far each panel was moved out to clear the body, m (by panel name; absent: not moved).
    pub moved_out_m: Vec<(String, f64)>,
    /// The largest seam gap when the pairs were welded, m.
    pub gap_before_weld_m: f64,
    /// The seam stiffness of each stage, N/m, and the largest gap after it, m.
    pub stages: Vec<(f64, f64)>,
    /// Newton iterations over all stages.
    pub iterations: usize,
    /// Edges of the welded garment crossing one of its triangles (an independent edge–triangle test).
    pub crossing_edges: usize,
    /// The deepest particle inside a body before welding, m (0: none).
    pub penetration_m: f64,
    /// Wall time, s.
    pub time_s: f64,
    /// The unsewn pieces' triangles (for a recording of the stages; not in run.json).
    #[serde(skip)]
    pub pieces: Vec<[u32; 3]>,
    /// The pieces' positions at the arranged start and after each stage, m (for a recording).
    #[serde(skip)]
    pub stage_positions: Vec<Vec<[f32; 3]>>,
}

/// Welded when every seam gap is below this, m.
pub const GAP_TOLERANCE_M: f64 = 1e-3;
/// The first stage's seam stiffness, N/m per pair; each stage ten times the one before.
const FIRST_STIFFNESS_N_PER_M: f64 = 1.0;
/// The most a seam pair pulls, N: beyond SEAM_FORCE_N / k the spring's pull stays at it.
const SEAM_FORCE_N: f64 = 0.5;
/// The most a seam pair pulls in the last stages, N: where the stiffest seams stall (the cloth
/// round a neckline must stretch a little to close), the cap is raised four-fold a stage to this.
const LAST_SEAM_FORCE_N: f64 = 32.0;
/// The widest gap a raised cap is tried on, m: wider, the seam is held open by something the pull
/// cannot move (a body part between its sides), and sewing refuses at once.
const STRETCH_GAP_M: f64 = 0.02;
/// Stages of the continuation at most.
const STAGES: usize = 12;
/// The stiffest seams, N/m per pair: later stages repeat it (re-anchored) until the seams close.
const LAST_STIFFNESS_N_PER_M: f64 = 1e4;
/// Newton iterations per stage at most.
const STAGE_ITERATIONS: usize = 200;
/// The proximal term's time, s: its weight per particle is m/h² (a 60 µg particle: 6 mN/m).
const PROXIMAL_H_S: f64 = 0.1;

/// Whether the last stage closed the widest gap by under 5 %: something (the body, another
/// panel, the cloth's own stretch) holds the seam open against the present cap.
fn stalled(stages: &[(f64, f64)]) -> bool {
    let n = stages.len();
    n >= 2 && stages[n - 1].1 > 0.95 * stages[n - 2].1
}

/// The unsewn pieces as a pattern (no vertex shared; the caller's start positions `x`).
pub fn unsewn_pattern(u: &Unsewn, x: &[[f64; 3]]) -> Pattern {
    Pattern {
        rest_m: u.rest_m.clone(),
        rest_triangles: u.triangles.clone(),
        triangles: u.triangles.clone(),
        vertex_of_rest: (0..u.rest_m.len()).collect(),
        start_m: x.to_vec(),
        groups: u.groups.clone(),
    }
}

/// The sewing model: the pieces' membrane and bending, no gravity, the body's barrier,
/// self-contact but across the seams' pairs, and the seams at `stiffness` N/m.
fn sewing_model(
    u: &Unsewn,
    s: &SewSetup<'_>,
    x: &Vecs,
    (stiffness, cap): (f64, f64),
) -> Result<Model, Defect> {
    let pattern = unsewn_pattern(u, &x.iter().map(|v| [v.x, v.y, v.z]).collect::<Vec<_>>());
    let sheet = PatternSheet {
        pattern: &pattern,
        rigidities: s.rigidities,
        warp_angle_rad: s.warp_angle_rad,
        bending_saturation_per_m: f64::INFINITY,
        curl_per_m: None,
        areal_density_kg_per_m2: s.areal_density_kg_per_m2,
    };
    let mut b = pattern_builder(&sheet, 0.0, &[]).map_err(|e| Defect {
        key: "pattern".into(),
        message: format!("a panel's triangles cannot carry the membrane: {e:?}"),
    })?;
    // The barriers as stiff as a hundred times a particle's weight in the band: they hold the
    // seams' pull (up to SEAM_FORCE_N a pair) off the body.
    let g = 100.0 * crate::STANDARD_GRAVITY_M_PER_S2;
    b.obstacles(s.obstacles.to_vec(), s.distance_m, g);
    let all: Vec<[u32; 3]> = u.triangles.iter().map(|t| t.map(|v| v as u32)).collect();
    let edges = BodyEdgeBarrier::new(s.obstacles, &all, &b.masses, &b.fixed, (s.distance_m, g));
    b.terms
        .extend(edges.map(|t| Box::new(t) as Box<dyn EnergyTerm>));
    let class = super::weld::classes(x.len(), &u.seams);
    let r = s.rigidities;
    b.term(Box::new(seam_hinge_bending(
        &u.rest_m,
        &u.triangles,
        &class,
        [r.bending_warp_N_m, r.bending_weft_N_m],
        s.warp_angle_rad,
    )));
    let twins = class.into_iter().map(|c| c as u32).collect();
    b.self_contact_twinned(all, x, (s.thickness_m, s.thickness_m), g, twins);
    b.term(Box::new(Seams::new(&u.seams, stiffness, cap / stiffness)));
    Ok(b.build())
}

fn as_f32(x: &Vecs) -> Vec<[f32; 3]> {
    x.iter()
        .map(|v| [v.x as f32, v.y as f32, v.z as f32])
        .collect()
}

fn as_arrays(x: &Vecs) -> Vec<[f64; 3]> {
    x.iter().map(|v| [v.x, v.y, v.z]).collect()
}

/// Sews `u` (its start as placed, moved clear by [`arrange`]) in `s`'s fabric on `s`'s bodies.
/// `progress` hears a line per stage; `observer` sees the stages' states.
pub fn sew(
    u: &Unsewn,
    s: &SewSetup<'_>,
    progress: &mut dyn FnMut(String),
    observer: &mut dyn Observer,
) -> Result<(Pattern, SewReport), Defect> {
    let clock = std::time::Instant::now();
    let (start, moved_out_m) = arrange(u, s)?;
    refuse_crossed_start(u, &start)?;
    let mut x: Vec<Vector3<f64>> = start.iter().map(|p| Vector3::from(*p)).collect();
    let mut report = SewReport {
        seam_pairs: u.seams.len(),
        start_gap_m: super::weld::largest_gap_m(&u.seams, &start),
        moved_out_m,
        gap_before_weld_m: f64::NAN,
        stages: Vec::new(),
        iterations: 0,
        crossing_edges: 0,
        penetration_m: 0.0,
        time_s: 0.0,
        pieces: u.triangles.iter().map(|t| t.map(|v| v as u32)).collect(),
        stage_positions: vec![as_f32(&x)],
    };
    let opts = StaticOptions {
        residual_tol_rel: 1e-3,
        max_iterations: STAGE_ITERATIONS,
        ..StaticOptions::default()
    };
    let (mut k, mut cap) = (FIRST_STIFFNESS_N_PER_M, SEAM_FORCE_N);
    for _ in 0..STAGES {
        let r = stage(u, s, (&mut x, k, cap), &opts, observer)?;
        report.iterations += r.iterations;
        let gap = super::weld::largest_gap_m(&u.seams, &as_arrays(&x));
        report.stages.push((k, gap));
        report.stage_positions.push(as_f32(&x));
        progress(format!(
            "sewing: seam stiffness {k:e} N/m, largest gap {:.2} mm ({}), {} Newton iterations, {:.1} s ({})",
            1e3 * gap,
            widest_seam(u, &x),
            r.iterations,
            clock.elapsed().as_secs_f64(),
            r.message
        ));
        if gap < GAP_TOLERANCE_M || r.divergence.is_some() {
            break;
        }
        if k < LAST_STIFFNESS_N_PER_M {
            k *= 10.0;
        } else if stalled(&report.stages) {
            // A seam held wide open (a body part between its sides) does not close by pulling
            // harder; only the last few millimetres a little stretch closes.
            if cap >= LAST_SEAM_FORCE_N || gap > STRETCH_GAP_M {
                break;
            }
            cap *= 4.0;
        }
    }
    let xs = as_arrays(&x);
    report.gap_before_weld_m = super::weld::largest_gap_m(&u.seams, &xs);
    report.penetration_m = crate::physics::max_penetration_m(s.obstacles, &x);
    report.time_s = clock.elapsed().as_secs_f64();
    if report.gap_before_weld_m >= GAP_TOLERANCE_M {
        return Err(not_closed(u, &x, &report));
    }
    let welded = super::weld::weld(u, &xs)?;
    report.crossing_edges = crossing_edges(&welded);
    Ok((welded, report))
}

/// One stage: the model at seam stiffness `k` with a weak tether to the stage's start (a proximal
/// term m/(2h²)|x − x_k|², which holds the garment's free rigid motions and, re-anchored every
/// stage, leaves no bias behind), solved from `x`.
fn stage(
    u: &Unsewn,
    s: &SewSetup<'_>,
    (x, k, cap): (&mut Vec<Vector3<f64>>, f64, f64),
    opts: &StaticOptions,
    observer: &mut dyn Observer,
) -> Result<crate::solve::SolveReport, Defect> {
    let mut model = sewing_model(u, s, x, (k, cap))?;
    let zeros = vec![Vector3::zeros(); x.len()];
    let tether = Inertia::new(
        &model,
        (x, &Contacts::default()),
        &zeros,
        PROXIMAL_H_S,
        (0.0, 0.0, 0.0),
    );
    model.terms.push(Box::new(tether));
    let infinite: Vec<String> = model
        .terms
        .iter()
        .filter(|t| !t.energy(x).is_finite())
        .map(|t| t.name())
        .collect();
    if !infinite.is_empty() {
        return Err(Defect {
            key: "pattern.panels".into(),
            message: format!(
                "the pieces cannot be sewn from where they are: the {} energy is infinite there (a body's edge through a panel, or two panels nearer than the cloth's thickness); place the panels apart and clear of the body",
                infinite.join(", ")
            ),
        });
    }
    Ok(solve_static(&mut model, x, opts, observer))
}

/// Why the seams did not close, naming the widest.
fn not_closed(u: &Unsewn, x: &Vecs, report: &SewReport) -> Defect {
    Defect {
        key: "pattern.stitches".into(),
        message: format!(
            "the seams did not close: the largest gap is {:.1} mm after {} stages (seam stiffness up to {:e} N/m); \
             something holds it open ({}): a body part between a seam's sides that the panels cannot slide round (a shoulder seam placed below the shoulder), or a stitch joining edges that cannot meet; place the panels so that each seam's sides meet round the body",
            1e3 * report.gap_before_weld_m,
            report.stages.len(),
            report.stages.last().map_or(0.0, |s| s.0),
            widest_seam(u, x)
        ),
    }
}

/// Refuses a start whose pieces pass through each other (an edge of one through a triangle of
/// another, or of itself) where the pattern places them: sewing keeps whatever crossing it starts
/// from, so it would weld a garment through itself. Names the two panels.
fn refuse_crossed_start(u: &Unsewn, x: &[[f64; 3]]) -> Result<(), Defect> {
    let tris = u.triangles.iter().map(|t| t.map(|v| v as u32)).collect();
    let topo = crate::proximity::MeshTopology::from_triangles(tris);
    let xs: Vec<Vector3<f64>> = x.iter().map(|p| Vector3::from(*p)).collect();
    let Some(&(e, t)) = crate::proximity::edge_triangle_crossings(&topo, &xs).first() else {
        return Ok(());
    };
    let name = |v: u32| &u.panel_names[u.panel_of[v as usize]];
    let (a, b) = (
        name(topo.edges[e as usize][0]),
        name(topo.triangles[t as usize][0]),
    );
    Err(Defect {
        key: format!("pattern.panels.{a}"),
        message: format!(
            "passes through panel {b} where the pattern places them (translation, rotation): sewing would keep the crossing; place the panels apart"
        ),
    })
}

/// Edges of a welded garment at its start that cross one of its triangles.
fn crossing_edges(welded: &Pattern) -> usize {
    let tris = welded
        .triangles
        .iter()
        .map(|t| t.map(|v| v as u32))
        .collect();
    let topo = crate::proximity::MeshTopology::from_triangles(tris);
    let xw: Vec<Vector3<f64>> = welded.start_m.iter().map(|p| Vector3::from(*p)).collect();
    let crossings = crate::proximity::edge_triangle_crossings(&topo, &xw);
    crossings
        .iter()
        .map(|c| c.0)
        .collect::<std::collections::BTreeSet<_>>()
        .len()
}

/// An arranged start: the positions, m, and the moves made (by panel name, or `lift`), m.
pub type Arranged = (Vec<[f64; 3]>, Vec<(String, f64)>);

/// The pieces' start: each panel moved out from the body (horizontally, away from the vertical
/// line through the bodies' centre) in steps of a centimetre until every vertex is clear of every
/// body by twice the barrier's distance; then the whole garment raised, in steps of a centimetre,
/// to the lowest height at which no seam's straight pull passes through a body (a shoulder seam
/// placed below the shoulder would pull its sides into it; GarmentCode merges such seams at once
/// and repairs what crosses). The start, and the moves made (by panel name, `lift` for the
/// garment). A panel still inside a body 30 cm out is refused, naming it.
pub fn arrange(u: &Unsewn, s: &SewSetup<'_>) -> Result<Arranged, Defect> {
    let mut x = u.start_m.clone();
    let mut moved = Vec::new();
    for k in 0..u.panel_names.len() {
        if let Some(shift) = move_out(u, s, k, &mut x)? {
            moved.push((u.panel_names[k].clone(), shift));
        }
    }
    let blocked = |x: &[[f64; 3]], dz: f64| {
        let at = |v: usize| Vector3::new(x[v][0], x[v][1], x[v][2] + dz);
        u.seams
            .iter()
            .filter(|&&[a, b]| pull_blocked(s.obstacles, &at(a), &at(b)))
            .count()
    };
    let lift = (0..=MAX_LIFT_CM)
        .map(|cm| (blocked(&x, cm as f64 * 0.01), cm))
        .min()
        .map_or(0, |(_, cm)| cm);
    if lift > 0 {
        let dz = lift as f64 * 0.01;
        x.iter_mut().for_each(|p| p[2] += dz);
        moved.push(("lift".into(), dz));
    }
    Ok((x, moved))
}

/// Whether the straight pull from `p` to `q` passes within [`PULL_CLEARANCE_M`] of a body (or
/// through it), sampled every 5 mm.
fn pull_blocked(obstacles: &[Obstacle], p: &Vector3<f64>, q: &Vector3<f64>) -> bool {
    let n = ((q - p).norm() / 0.005).ceil().max(1.0) as usize;
    obstacles.iter().any(|o| {
        o.segment_enters(p, q)
            || (0..=n).any(|i| {
                o.signed_distance(&(p + (q - p) * (i as f64 / n as f64))).0 <= PULL_CLEARANCE_M
            })
    })
}

/// How far a seam's straight pull must pass from the body at the start, m: its sides move towards
/// each other along it and slide round what they meet.
const PULL_CLEARANCE_M: f64 = 0.0;

/// The highest the garment is raised to clear its seams' pulls, cm.
const MAX_LIFT_CM: usize = 30;

/// Moves panel `k` out until clear of the bodies; how far, where it moved.
fn move_out(
    u: &Unsewn,
    s: &SewSetup<'_>,
    k: usize,
    x: &mut [[f64; 3]],
) -> Result<Option<f64>, Defect> {
    let centre = body_centre(s.obstacles);
    let clear = |p: &[f64; 3]| {
        let q = Vector3::from(*p);
        s.obstacles
            .iter()
            .all(|o| o.signed_distance(&q).0 > 2.0 * s.distance_m)
    };
    let vs: Vec<usize> = (0..x.len()).filter(|&v| u.panel_of[v] == k).collect();
    let c = vs
        .iter()
        .fold(Vector3::zeros(), |a, &v| a + Vector3::from(x[v]))
        / vs.len() as f64;
    let mut out = Vector3::new(c.x - centre.x, c.y - centre.y, 0.0);
    if out.norm() < 1e-9 {
        out = Vector3::new(0.0, -1.0, 0.0);
    }
    let out = out.normalize();
    let mut shift = 0.0;
    while !vs.iter().all(|&v| clear(&x[v])) {
        if shift > 0.3 {
            return Err(Defect {
                key: format!("pattern.panels.{}", u.panel_names[k]),
                message: "starts inside the body and is still inside it 30 cm further out: place it outside the body (translation)".into(),
            });
        }
        shift += 0.01;
        for &v in &vs {
            x[v] = [x[v][0] + 0.01 * out.x, x[v][1] + 0.01 * out.y, x[v][2]];
        }
    }
    Ok((shift > 0.0).then_some(shift))
}

/// The centre of the mesh bodies' bounding box, or the origin.
fn body_centre(obstacles: &[Obstacle]) -> Vector3<f64> {
    let pts: Vec<Vector3<f64>> = obstacles
        .iter()
        .filter_map(|o| match o {
            Obstacle::Mesh { body: Some(b), .. } => {
                let bx = b.bounds();
                Some(vec![bx.lo, bx.hi])
            }
            _ => None,
        })
        .flatten()
        .collect();
    if pts.is_empty() {
        return Vector3::zeros();
    }
    let lo = pts
        .iter()
        .fold(Vector3::repeat(f64::INFINITY), |a, p| a.inf(p));
    let hi = pts
        .iter()
        .fold(Vector3::repeat(f64::NEG_INFINITY), |a, p| a.sup(p));
    (lo + hi) / 2.0
}

/// Where the widest seam gap is: the panels of its two vertices and their positions.
fn widest_seam(u: &Unsewn, x: &Vecs) -> String {
    let Some(&[a, b]) = u.seams.iter().max_by(|p, q| {
        (x[p[0]] - x[p[1]])
            .norm()
            .total_cmp(&(x[q[0]] - x[q[1]]).norm())
    }) else {
        return "no seams".into();
    };
    let at = |v: usize| {
        format!(
            "{} at [{:.3}, {:.3}, {:.3}] m",
            u.panel_names[u.panel_of[v]], x[v].x, x[v].y, x[v].z
        )
    };
    format!("between {} and {}", at(a), at(b))
}
