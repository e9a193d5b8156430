//! A study of what sets the fold count of a simulated Cusick drape (issue 31): DC and nodes over
//! perturbation seeds for every combination of start path, mesh, bending length and anisotropy.
//! `cargo run --release --example cusick_folds -- --start cone,fall --mesh template,sub1
//!  --c-mm 12,18,25 --ratio 1,2,4 --seeds 4`
use drapelab_core::cusick::{DiscMesh, DrapeParams, DrapeStart, Tester, drape_dc, subdivide_disc};
use drapelab_record::cusick::CusickDataset;
use rayon::prelude::*;
use std::time::Instant;

fn list(args: &[String], flag: &str, default: &str) -> Vec<String> {
    let v = args
        .iter()
        .position(|a| a == flag)
        .map(|i| args[i + 1].clone())
        .unwrap_or_else(|| default.to_string());
    v.split(',').map(str::to_string).collect()
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let data = CusickDataset::open(std::path::Path::new("datasets/cusick"))?;
    let t = data.template()?;
    let radius = Tester::default().specimen_radius_m;
    let seeds: u64 = list(&args, "--seeds", "4")[0].parse()?;
    let fall_time: f64 = list(&args, "--fall-s", "0.4")[0].parse()?;
    let pert: f64 = list(&args, "--pert-mm", "2")[0].parse::<f64>()? * 1e-3;
    let angle: f64 = list(&args, "--angle-deg", "0")[0].parse()?;
    let modes: usize = list(&args, "--modes", "16")[0].parse()?;
    println!("start mesh c_mm ratio | DC % per seed | nodes per seed | mean nodes | s per solve");
    for mesh_name in list(&args, "--mesh", "template") {
        let mut m = (t.rest_xy.clone(), t.triangles.clone());
        if mesh_name == "sub1" {
            m = subdivide_disc(&m.0, &m.1, radius);
        }
        let mesh = DiscMesh {
            rest_xy: &m.0,
            triangles: &m.1,
        };
        for start in list(&args, "--start", "cone") {
            for c in list(&args, "--c-mm", "18") {
                for sat in list(&args, "--sat", "inf") {
                    for ratio in list(&args, "--ratio", "1") {
                        let p = DrapeParams {
                            bending_length_m: c.parse::<f64>()? * 1e-3,
                            bending_ratio: ratio.parse()?,
                            bending_saturation: if sat == "inf" {
                                None
                            } else {
                                Some(sat.parse()?)
                            },
                            warp_angle_deg: angle,
                            perturbation_m: pert,
                            perturbation_modes: modes,
                            fall_time_s: fall_time,
                            start: if start == "fall" {
                                DrapeStart::Fall
                            } else {
                                DrapeStart::Cone
                            },
                            ..DrapeParams::default()
                        };
                        let t0 = Instant::now();
                        let r: Vec<Option<(f64, usize)>> = (0..seeds)
                            .into_par_iter()
                            .map(|seed| {
                                let q = DrapeParams { seed, ..p.clone() };
                                drape_dc(mesh, &q, &Tester::default()).map(|d| (d.0, d.1))
                            })
                            .collect();
                        let dc: Vec<String> = r
                            .iter()
                            .map(|d| d.map_or("–".into(), |d| format!("{:.1}", d.0)))
                            .collect();
                        let nodes: Vec<String> = r
                            .iter()
                            .map(|d| d.map_or("–".into(), |d| d.1.to_string()))
                            .collect();
                        let ok: Vec<usize> = r.iter().flatten().map(|d| d.1).collect();
                        let mean = ok.iter().sum::<usize>() as f64 / ok.len().max(1) as f64;
                        println!(
                            "{start} {mesh_name} {c} sat {sat} {ratio} | {} | {} | {mean:.2} | {:.2}",
                            dc.join(" "),
                            nodes.join(" "),
                            t0.elapsed().as_secs_f64() * 2.0 / seeds as f64
                        );
                    }
                }
            }
        }
    }
    Ok(())
}
