//! Sews a GarmentCode pattern on a body and prints each stage: `cargo run --release --example
//! sew_trace -- PATTERN.json BODY.obj RESOLUTION_M`.

use drapelab_core::material::Rigidities;
use drapelab_core::obstacle::{Obstacle, TriangleBody};
use drapelab_core::sewing::sew::{SewSetup, sew};
use std::sync::Arc;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let spec = drapelab_core::sewing::parse(&std::fs::read_to_string(&a[1]).unwrap()).unwrap();
    let u = drapelab_core::sewing::unsewn(&spec, a[3].parse().unwrap()).unwrap();
    let (v, f) = drapelab_core::pattern::parse_obj_triangles(&std::fs::read_to_string(&a[2]).unwrap()).unwrap();
    let body = TriangleBody::new(
        v.iter().map(|p| (*p).into()).collect(),
        f.iter().map(|t| t.0.map(|i| i as u32)).collect(),
    )
    .unwrap();
    let obstacle = Obstacle::Mesh {
        mesh: a[2].clone().into(),
        mesh_unit_m: 1.0,
        offset_m: [0.0; 3],
        body: Some(Arc::new(body)),
    };
    // Seed 003's wool (datasets/fabrics/wool_seed003.toml) in SI.
    let r = Rigidities {
        tensile_warp_N_per_m: 1000.0,
        tensile_weft_N_per_m: 1000.0,
        shear_N_per_m: 41.0,
        bending_warp_N_m: 1e-5,
        bending_weft_N_m: 1e-5,
        bending_twist_N_m: 1e-5,
    };
    let setup = SewSetup {
        rigidities: &r,
        areal_density_kg_per_m2: 0.2,
        warp_angle_rad: std::f64::consts::FRAC_PI_2,
        obstacles: &[obstacle],
        distance_m: 0.005,
        thickness_m: 1e-3,
    };
    eprintln!("{} vertices, {} triangles, {} seam pairs", u.start_m.len(), u.triangles.len(), u.seams.len());
    eprintln!("arranged: {:?}", drapelab_core::sewing::sew::arrange(&u, &setup).map(|a| a.1).map_err(|e| e.message));
    let clock = std::time::Instant::now();
    let mut trace = Trace { clock, seams: u.seams.clone() };
    match sew(&u, &setup, &mut |l| eprintln!("{l}"), &mut trace) {
        Ok((p, rep)) => {
            eprintln!("welded: {} particles; {rep:?}", p.vertex_count());
            let o = &setup.obstacles[0];
            let x: Vec<nalgebra::Vector3<f64>> = p.start_m.iter().map(|q| (*q).into()).collect();
            let mut n = 0;
            for t in &p.triangles {
                for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                    if a < b && o.segment_enters(&x[a], &x[b]) {
                        n += 1;
                        if n < 6 {
                            eprintln!("edge {a}-{b}: {:?} {:?} distances {:.4} {:.4} length {:.4}", x[a].as_slice(), x[b].as_slice(), o.signed_distance(&x[a]).0, o.signed_distance(&x[b]).0, (x[a]-x[b]).norm());
                        }
                    }
                }
            }
            eprintln!("{n} edges through the body");
            for g in ["waist", "hem"] {
                if let Some(vs) = p.groups.get(g) {
                    let mut ring: Vec<nalgebra::Vector3<f64>> = vs.iter().map(|&v| x[v]).collect();
                    let c = ring.iter().fold(nalgebra::Vector3::zeros(), |a, b| a + b) / ring.len() as f64;
                    ring.sort_by(|a, b| (a.y - c.y).atan2(a.x - c.x).total_cmp(&(b.y - c.y).atan2(b.x - c.x)));
                    let per: f64 = (0..ring.len()).map(|i| (ring[i] - ring[(i + 1) % ring.len()]).norm()).sum();
                    eprintln!("{g}: {} vertices, perimeter {per:.3} m, centre {:?}", ring.len(), c.as_slice());
                }
            }
        }
        Err(e) => eprintln!("failed: {} {}", e.key, e.message),
    }
}

struct Trace {
    clock: std::time::Instant,
    seams: Vec<[usize; 2]>,
}

impl drapelab_core::solve::Observer for Trace {
    fn wants(&self, index: usize) -> bool {
        index % 100 == 0
    }
    fn observe(&mut self, e: &drapelab_core::solve::StateEvent<'_>) -> anyhow::Result<()> {
        let x: Vec<[f64; 3]> = e.x.iter().map(|v| [v.x, v.y, v.z]).collect();
        let gap = drapelab_core::sewing::weld::largest_gap_m(&self.seams, &x);
        eprintln!(
            "  step {} t {:?} residual {:.2e} N gap {:.1} mm alpha {:?} wall {:.1} s",
            e.index,
            e.time_s,
            e.max_residual_N,
            gap * 1e3,
            e.step.as_ref().map(|s| s.alpha),
            self.clock.elapsed().as_secs_f64()
        );
        Ok(())
    }
}
