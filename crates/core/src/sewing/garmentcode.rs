//! GarmentCode's sewing pattern JSON (`*_specification.json`, Korosteleva & Sorkine-Hornung 2023;
//! the 2021 dataset's layout too), read as its simulator reads it (`pygarment/meshgen/boxmeshgen.py`):
//! panels of 2D vertices in the file's unit (`properties.units_in_meter`, default 100: cm) joined by
//! a closed loop of edges (straight, or curved by `curvature`), placed in 3D by `translation` and
//! `rotation` (XYZ Euler angles in degrees, R = Rz·Ry·Rx, y up), and `stitches` pairing two panel
//! edges (the first reversed, unless the stitch is marked `right_wrong`).

use super::curve::{Curve, P2, relative_point};
use crate::pattern::Defect;
use serde_json::Value;

/// One panel edge: its curve (in the file's unit) and its label (`""` when none).
#[derive(Debug, Clone)]
pub struct Edge {
    /// The edge's curve from its first endpoint to its second.
    pub curve: Curve,
    /// GarmentCode's edge label (e.g. `lower_interface`), empty when none.
    pub label: String,
}

/// A panel: a closed loop of edges in its own plane, and its placement.
#[derive(Debug, Clone)]
pub struct Panel {
    /// The panel's name (its key in `pattern.panels`).
    pub name: String,
    /// The edges in loop order, each starting where the one before ends.
    pub edges: Vec<Edge>,
    /// Translation in the file's unit (y up).
    pub translation: [f64; 3],
    /// XYZ Euler angles, degrees.
    pub rotation_deg: [f64; 3],
}

/// One side of a stitch: a panel (index into [`SewingPattern::panels`]) and one of its edges.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Side {
    /// Index of the panel.
    pub panel: usize,
    /// Index of the edge in the panel's loop.
    pub edge: usize,
}

/// A stitch between two edges.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Stitch {
    /// The two edges sewn together.
    pub sides: [Side; 2],
    /// Whether the first edge runs against the second (GarmentCode's default; `right_wrong`
    /// stitches keep both directions).
    pub reversed: bool,
}

/// A read sewing pattern.
#[derive(Debug, Clone)]
pub struct SewingPattern {
    /// The panels, sorted by name.
    pub panels: Vec<Panel>,
    /// The stitches.
    pub stitches: Vec<Stitch>,
    /// The file's length unit, m (1 / `units_in_meter`).
    pub unit_m: f64,
}

fn defect(key: impl Into<String>, message: impl Into<String>) -> Defect {
    Defect {
        key: key.into(),
        message: message.into(),
    }
}

/// Reads GarmentCode JSON text; a defect names the key (`pattern.panels.NAME.edges.3.curvature`).
pub fn parse(text: &str) -> Result<SewingPattern, Defect> {
    let root: Value = serde_json::from_str(text)
        .map_err(|e| defect(format!("line {}", e.line()), format!("not JSON: {e}")))?;
    let unit_m = unit(&root)?;
    let absolute = root
        .pointer("/properties/curvature_coords")
        .and_then(Value::as_str)
        == Some("absolute");
    let pattern = root.get("pattern").unwrap_or(&root);
    let panels_v = pattern
        .get("panels")
        .and_then(Value::as_object)
        .filter(|p| !p.is_empty())
        .ok_or_else(|| {
            defect(
                "pattern.panels",
                "missing or empty: a GarmentCode pattern names its panels (an object of panels by name)",
            )
        })?;
    let panels = panels_v
        .iter()
        .map(|(name, p)| panel(name, p, absolute))
        .collect::<Result<Vec<_>, _>>()?;
    let stitches = stitches(pattern.get("stitches"), &panels)?;
    Ok(SewingPattern {
        panels,
        stitches,
        unit_m,
    })
}

fn unit(root: &Value) -> Result<f64, Defect> {
    match root.pointer("/properties/units_in_meter") {
        None => Ok(0.01),
        Some(v) => match v.as_f64() {
            Some(u) if u.is_finite() && (1e-3..=1e6).contains(&u) => Ok(1.0 / u),
            _ => Err(defect(
                "properties.units_in_meter",
                format!("must be a number from 1e-3 to 1e6 (100 for centimetres), got {v}"),
            )),
        },
    }
}

/// `n` finite numbers at `key`.
fn numbers<const N: usize>(
    v: Option<&Value>,
    key: &str,
    default: Option<[f64; N]>,
) -> Result<[f64; N], Defect> {
    let Some(v) = v else {
        return default.ok_or_else(|| defect(key, format!("missing: needs {N} numbers")));
    };
    let a = v.as_array().filter(|a| a.len() == N);
    let c: Option<Vec<f64>> = a.map(|a| {
        a.iter()
            .filter_map(Value::as_f64)
            .filter(|x| x.is_finite() && x.abs() < 1e6)
            .collect()
    });
    match c {
        Some(c) if c.len() == N => Ok(std::array::from_fn(|i| c[i])),
        _ => Err(defect(
            key,
            format!("must be {N} finite numbers (under 1e6 in size), got {v}"),
        )),
    }
}

fn panel(name: &str, p: &Value, absolute: bool) -> Result<Panel, Defect> {
    let at = format!("pattern.panels.{name}");
    let verts = p
        .get("vertices")
        .and_then(Value::as_array)
        .filter(|v| v.len() >= 3)
        .ok_or_else(|| defect(format!("{at}.vertices"), "missing or under three vertices"))?;
    let verts: Vec<P2> = verts
        .iter()
        .enumerate()
        .map(|(i, v)| numbers::<2>(Some(v), &format!("{at}.vertices.{i}"), None))
        .collect::<Result<_, _>>()?;
    let edges_v = p
        .get("edges")
        .and_then(Value::as_array)
        .filter(|e| e.len() >= 2)
        .ok_or_else(|| defect(format!("{at}.edges"), "missing or under two edges"))?;
    let mut ends = Vec::new();
    let mut edges = Vec::new();
    for (i, e) in edges_v.iter().enumerate() {
        let key = format!("{at}.edges.{i}");
        let (a, b) = endpoints(e, verts.len(), &key)?;
        ends.push((a, b));
        let curve = curve(e.get("curvature"), verts[a], verts[b], absolute, &key)?;
        let label = e
            .get("label")
            .and_then(Value::as_str)
            .unwrap_or("")
            .to_string();
        edges.push(Edge { curve, label });
    }
    closed_loop(&ends, &at)?;
    Ok(Panel {
        name: name.to_string(),
        edges,
        translation: numbers(
            p.get("translation"),
            &format!("{at}.translation"),
            Some([0.0; 3]),
        )?,
        rotation_deg: numbers(p.get("rotation"), &format!("{at}.rotation"), Some([0.0; 3]))?,
    })
}

fn endpoints(e: &Value, n: usize, key: &str) -> Result<(usize, usize), Defect> {
    let ep = e.get("endpoints").and_then(Value::as_array);
    let idx: Option<Vec<usize>> = ep.map(|a| {
        a.iter()
            .filter_map(Value::as_u64)
            .map(|i| i as usize)
            .collect()
    });
    match idx.as_deref() {
        Some(&[a, b]) if a < n && b < n && a != b => Ok((a, b)),
        _ => Err(defect(
            format!("{key}.endpoints"),
            format!("must be two different vertex indices below the panel's {n} vertices"),
        )),
    }
}

/// Each edge must start where the one before ends, the last ending at the first's start.
fn closed_loop(ends: &[(usize, usize)], at: &str) -> Result<(), Defect> {
    for i in 0..ends.len() {
        let next = ends[(i + 1) % ends.len()];
        if ends[i].1 != next.0 {
            return Err(defect(
                format!("{at}.edges.{}", (i + 1) % ends.len()),
                format!(
                    "starts at vertex {} but the edge before ends at vertex {}: a panel's edges must form one closed loop in order",
                    next.0, ends[i].1
                ),
            ));
        }
    }
    Ok(())
}

fn curve(c: Option<&Value>, a: P2, b: P2, absolute: bool, key: &str) -> Result<Curve, Defect> {
    let key = format!("{key}.curvature");
    let control = |v: &Value, k: &str| -> Result<P2, Defect> {
        let p = numbers::<2>(Some(v), k, None)?;
        Ok(if absolute { p } else { relative_point(a, b, p) })
    };
    let Some(c) = c else {
        return Ok(Curve::Line { start: a, end: b });
    };
    if c.is_array() {
        return Ok(Curve::Bezier(vec![a, control(c, &key)?, b]));
    }
    let kind = c.get("type").and_then(Value::as_str).unwrap_or("");
    let params = c.get("params").and_then(Value::as_array);
    let p = |i: usize| params.and_then(|p| p.get(i)).unwrap_or(&Value::Null);
    let pk = |i: usize| format!("{key}.params.{i}");
    match kind {
        "quadratic" => Ok(Curve::Bezier(vec![a, control(p(0), &pk(0))?, b])),
        "cubic" => Ok(Curve::Bezier(vec![
            a,
            control(p(0), &pk(0))?,
            control(p(1), &pk(1))?,
            b,
        ])),
        "circle" => {
            let r = p(0).as_f64().filter(|r| r.is_finite() && *r > 0.0);
            let flag = |v: &Value| v.as_bool().or(v.as_i64().map(|i| i != 0));
            match (r, flag(p(1)), flag(p(2))) {
                (Some(r), Some(large), Some(right)) => Ok(Curve::arc(a, b, r, large, right)),
                _ => Err(defect(
                    format!("{key}.params"),
                    "a circle arc needs [radius > 0, large_arc, right] (two flags, true/false or 1/0)",
                )),
            }
        }
        other => Err(defect(
            format!("{key}.type"),
            format!("`{other}` is not a curvature GarmentCode defines: quadratic, cubic or circle"),
        )),
    }
}

fn stitches(v: Option<&Value>, panels: &[Panel]) -> Result<Vec<Stitch>, Defect> {
    let Some(list) = v else { return Ok(Vec::new()) };
    let list = list
        .as_array()
        .ok_or_else(|| defect("pattern.stitches", "must be a list of stitches"))?;
    let mut used = std::collections::HashMap::new();
    let mut out = Vec::new();
    for (k, s) in list.iter().enumerate() {
        let key = format!("pattern.stitches.{k}");
        let parts = s.as_array().filter(|a| (2..=3).contains(&a.len())).ok_or_else(|| {
            defect(&key, "must be two edges ({\"panel\": NAME, \"edge\": INDEX}), optionally then \"right_wrong\"")
        })?;
        let side = |i: usize| side(&parts[i], panels, &format!("{key}.{i}"));
        let sides = [side(0)?, side(1)?];
        for (i, sd) in sides.iter().enumerate() {
            if let Some(first) = used.insert(*sd, k) {
                return Err(defect(
                    format!("{key}.{i}"),
                    format!(
                        "edge {} of panel {} is already sewn by stitch {first}: an edge takes one stitch",
                        sd.edge, panels[sd.panel].name
                    ),
                ));
            }
        }
        let right_wrong = parts.get(2).and_then(Value::as_str) == Some("right_wrong");
        out.push(Stitch {
            sides,
            reversed: !right_wrong,
        });
    }
    Ok(out)
}

fn side(v: &Value, panels: &[Panel], key: &str) -> Result<Side, Defect> {
    let name = v.get("panel").and_then(Value::as_str).unwrap_or("");
    let panel = panels.iter().position(|p| p.name == name).ok_or_else(|| {
        defect(
            format!("{key}.panel"),
            format!("`{name}` is no panel of the pattern"),
        )
    })?;
    let n = panels[panel].edges.len();
    match v.get("edge").and_then(Value::as_u64) {
        Some(e) if (e as usize) < n => Ok(Side {
            panel,
            edge: e as usize,
        }),
        _ => Err(defect(
            format!("{key}.edge"),
            format!("must be an edge index of panel {name} (it has {n} edges)"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square panel of side 10 with one quadratic edge, and a copy sewn to it.
    pub(crate) fn two_squares(stitch: &str) -> String {
        let panel = |z: f64| {
            format!(
                r#"{{"translation": [0, 0, {z}], "rotation": [0, 0, 0],
                "vertices": [[0, 0], [10, 0], [10, 10], [0, 10]],
                "edges": [{{"endpoints": [0, 1]}}, {{"endpoints": [1, 2]}},
                          {{"endpoints": [2, 3], "curvature": {{"type": "quadratic", "params": [[0.5, 0.2]]}}}},
                          {{"endpoints": [3, 0]}}]}}"#
            )
        };
        format!(
            r#"{{"pattern": {{"panels": {{"front": {}, "back": {}}}, "stitches": [{stitch}]}},
            "properties": {{"units_in_meter": 100, "curvature_coords": "relative"}}}}"#,
            panel(5.0),
            panel(-5.0)
        )
    }

    #[test]
    fn panels_edges_and_stitches_are_read() {
        let s = two_squares(r#"[{"panel": "front", "edge": 1}, {"panel": "back", "edge": 3}]"#);
        let p = parse(&s).unwrap();
        assert_eq!(p.panels.len(), 2);
        assert_eq!(p.unit_m, 0.01);
        let back = p.panels.iter().position(|pn| pn.name == "back").unwrap();
        assert_eq!(
            p.stitches[0].sides[1],
            Side {
                panel: back,
                edge: 3
            }
        );
        assert!(p.stitches[0].reversed);
        // The curved edge bulges by 0.2 × 10 / 2 = 1 at its middle (a quadratic's midpoint is half
        // way to its control point's offset).
        let mid = p.panels[0].edges[2].curve.point(0.5);
        assert!(
            (mid[0] - 5.0).abs() < 1e-12 && (mid[1] - 9.0).abs() < 1e-12,
            "{mid:?}"
        );
    }

    #[test]
    fn bad_stitches_are_refused_naming_them() {
        let cases = [
            (
                r#"[{"panel": "front", "edge": 1}, {"panel": "sleeve", "edge": 3}]"#,
                "pattern.stitches.0.1.panel",
            ),
            (
                r#"[{"panel": "front", "edge": 1}, {"panel": "back", "edge": 9}]"#,
                "pattern.stitches.0.1.edge",
            ),
            (
                r#"[{"panel": "front", "edge": 1}, {"panel": "back", "edge": 3}],
                   [{"panel": "front", "edge": 1}, {"panel": "back", "edge": 0}]"#,
                "pattern.stitches.1.0",
            ),
        ];
        for (stitch, key) in cases {
            let e = parse(&two_squares(stitch)).unwrap_err();
            assert_eq!(e.key, key, "{}", e.message);
        }
    }
}
