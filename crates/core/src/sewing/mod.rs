//! Garments from sewing patterns (issue 91): GarmentCode's JSON read ([`garmentcode`]), its edges'
//! curves ([`curve`]), the panels triangulated and placed ([`panels`]), and the seams welded into
//! one sheet ([`weld`]) that the rest of drapelab drapes as a sewn garment
//! ([`crate::pattern::Pattern`]).

pub mod curve;
pub mod garmentcode;
pub mod panels;
pub mod sew;
pub mod weld;

pub use garmentcode::{SewingPattern, parse};
pub use panels::{Unsewn, unsewn};

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(name: &str) -> SewingPattern {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets/garments");
        let text = std::fs::read_to_string(dir.join(format!("{name}_specification.json"))).unwrap();
        parse(&text).unwrap()
    }

    #[test]
    fn explore_samples() {
        for name in ["shirt_mean", "hoody_mean", "dress_pencil", "js_mean_all"] {
            let p = sample(name);
            let u = unsewn(&p, 0.02).unwrap();
            let gap = weld::largest_gap_m(&u.seams, &u.start_m);
            let w = weld::weld(&u, &u.start_m);
            eprintln!("{name}: {} panels {} stitches, {} vertices {} triangles {} seam pairs, gap {gap:.3} m, weld {:?}",
                p.panels.len(), p.stitches.len(), u.start_m.len(), u.triangles.len(), u.seams.len(), w.as_ref().map(|w| w.vertex_count()).map_err(|e| e.clone()));
            for (k, pn) in p.panels.iter().enumerate() {
                let vs: Vec<usize> = (0..u.start_m.len()).filter(|&v| u.panel_of[v] == k).collect();
                let c: [f64; 3] = std::array::from_fn(|i| vs.iter().map(|&v| u.start_m[v][i]).sum::<f64>() / vs.len() as f64);
                eprintln!("  {} {:?}", pn.name, c.map(|x| (x * 1000.0).round() / 1000.0));
            }
        }
    }
}
