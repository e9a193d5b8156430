//! The fabric sheets of `wrinkles-simulate` beyond each case's result (issue 50): a map of the
//! cases over bending length × shear rigidity, and the sheets the seed shows in a photograph
//! (Fig. 4); and the tension-field model's Eq. 7 refitted to every fabric sheet by
//! leave-one-case-out over both readings of its bending term (the plate's E t³, the fabric's 12 w c³).

use drapelab_core::wrinkles::full::{LeaveOneOut, SheetReading, leave_groups_out};
use drapelab_core::wrinkles::{SeedResult, WrinkleConfig, WrinkleInputs};

/// Why a sheet was solved: a case's result, a map point or a photograph (the `role` column).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SheetRole {
    /// A case's result under its reading.
    Table,
    /// A point of the map over bending length × shear rigidity.
    Map,
    /// A sheet of the seed's photograph (Fig. 4).
    Photograph,
}

/// How a sheet's two meshes agree (the `status` column of `wrinkles_full.parquet`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum SheetVerdict {
    /// Both meshes converged and agree on n and on z_max.
    #[serde(rename = "converged")]
    Converged,
    /// They agree on n, not on z_max.
    #[serde(rename = "converged in n only")]
    ConvergedInNOnly,
    /// They disagree on n.
    #[serde(rename = "not converged in the mesh")]
    NotConvergedInMesh,
    /// A solve stopped early (its status in `status_fine` or `status_coarse`).
    #[serde(rename = "not converged")]
    NotConverged,
}

impl SheetVerdict {
    /// Whether the meshes agree on the count n (converged, or in n only).
    pub fn agrees_on_n(self) -> bool {
        matches!(
            self,
            SheetVerdict::Converged | SheetVerdict::ConvergedInNOnly
        )
    }
    /// Its text in the table and the reports.
    pub fn as_str(self) -> &'static str {
        match self {
            SheetVerdict::Converged => "converged",
            SheetVerdict::ConvergedInNOnly => "converged in n only",
            SheetVerdict::NotConvergedInMesh => "not converged in the mesh",
            SheetVerdict::NotConverged => "not converged",
        }
    }
}

impl std::fmt::Display for SheetVerdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A fabric sheet to solve: its case, why, and its reading.
#[derive(Debug, Clone)]
pub struct PointSpec {
    /// Case name (the config's case, or the photograph's).
    pub case: String,
    /// Map point or photograph.
    pub role: SheetRole,
    /// The case's inputs.
    pub inputs: WrinkleInputs,
    /// The seed's count, where it gives one (the photograph's n).
    pub seed: Option<SeedResult>,
    /// The fabric's bending length and shear rigidity.
    pub reading: SheetReading,
}

/// Where the map's points lie: its cases, bending lengths (m) and shear rigidities (N/m).
pub struct MapAxes<'a> {
    /// The cases mapped.
    pub cases: &'a [String],
    /// Bending lengths, m.
    pub bending_lengths_m: &'a [f64],
    /// Shear rigidities, N/m.
    pub shear_N_per_m: &'a [f64],
}

/// The map's points (each named case at every bending length × shear rigidity), then the config's
/// photographs read as `fabric`; none when the sheets are not read as fabric at all.
pub fn point_specs(
    cfg: &WrinkleConfig,
    map: &MapAxes<'_>,
    fabric: Option<SheetReading>,
) -> Vec<PointSpec> {
    let Some(fabric) = fabric else {
        return Vec::new();
    };
    let spec = |c: &drapelab_core::wrinkles::WrinkleCase, role, reading| PointSpec {
        case: c.case.clone(),
        role,
        inputs: c.inputs(&cfg.defaults),
        seed: c.seed.clone(),
        reading,
    };
    let mut out = Vec::new();
    for c in cfg.cases.iter().filter(|c| map.cases.contains(&c.case)) {
        for &bending_length_m in map.bending_lengths_m {
            for &shear_N_per_m in map.shear_N_per_m {
                let reading = SheetReading::Fabric {
                    bending_length_m,
                    shear_N_per_m,
                };
                out.push(spec(c, SheetRole::Map, reading));
            }
        }
    }
    for c in &cfg.photographs {
        out.push(spec(c, SheetRole::Photograph, fabric));
    }
    out
}

/// One fabric sheet the tension field is fitted to: its case group, its reading and count.
#[derive(Debug, Clone)]
pub struct FitRow {
    /// Case name.
    pub case: String,
    /// A case's result ([`SheetRole::Table`]) or a map point.
    pub role: SheetRole,
    /// The sheet's bending length, m.
    pub bending_length_m: f64,
    /// The sheet's shear rigidity, N/m.
    pub shear_N_per_m: f64,
    /// The simulated count (finer mesh).
    pub n_simulated: usize,
    /// The tension field's count under each candidate.
    pub n_tension_field: Vec<usize>,
}

impl FitRow {
    /// For each candidate: is its count within ±1 of the simulated one?
    pub fn holds(&self) -> Vec<bool> {
        self.n_tension_field
            .iter()
            .map(|&m| m.abs_diff(self.n_simulated) <= 1)
            .collect()
    }
}

/// Eq. 7 refitted to the fabric sheets: candidates (its bending term read as the fabric's, the load
/// constant c), scored within ±1 of each sheet's count, chosen by leave-one-case-out (a case's map
/// points leave with it).
#[derive(Debug, Clone)]
pub struct TensionFieldFit {
    /// (Eq. 7 reads the fabric's bending length rather than the plate's E t³, c).
    pub candidates: Vec<(bool, f64)>,
    /// The sheets: the cases' results first, then the map's points.
    pub rows: Vec<FitRow>,
    /// The choice and each sheet's held-out outcome.
    pub loo: LeaveOneOut,
}

impl TensionFieldFit {
    /// The chosen candidate.
    pub fn chosen(&self) -> (bool, f64) {
        self.candidates[self.loo.chosen]
    }
    /// (held-out hits, sheets) among the rows of `role`.
    pub fn held_out(&self, role: SheetRole) -> (usize, usize) {
        let mine = || {
            self.rows
                .iter()
                .zip(&self.loo.held_out)
                .filter(move |(r, _)| r.role == role)
        };
        (mine().filter(|(_, h)| h.1).count(), mine().count())
    }
    /// Leave-one-case-out over the cases' own sheets alone (the map left aside): the choice and
    /// each case's held-out outcome.
    pub fn cases_only(&self) -> LeaveOneOut {
        let ok: Vec<Vec<bool>> = self
            .rows
            .iter()
            .filter(|r| r.role == SheetRole::Table)
            .map(FitRow::holds)
            .collect();
        drapelab_core::wrinkles::full::leave_one_out(&ok)
    }
    /// (hits, sheets) of candidate `k` in-sample among the rows of `role`.
    pub fn hits(&self, k: usize, role: SheetRole) -> (usize, usize) {
        let mine: Vec<&FitRow> = self.rows.iter().filter(|r| r.role == role).collect();
        let hits = mine.iter().filter(|r| r.holds()[k]).count();
        (hits, mine.len())
    }
}

/// A sheet's count under Eq. 7 read as the plate (`fabric` false) or as a fabric of bending length
/// `bending_length_m`, with load constant `c`.
fn tension_field_n(inp: &WrinkleInputs, fabric: bool, bending_length_m: f64, c: f64) -> usize {
    let inp = WrinkleInputs {
        buckling_constant: c,
        bending_length_m: fabric.then_some(bending_length_m),
        ..inp.clone()
    };
    drapelab_core::wrinkles::solve(&inp).n
}

/// A simulated fabric sheet, as the fit sees it.
pub struct FitSheet<'a> {
    /// Its case group (a case and its map points share one).
    pub group: usize,
    /// Case name.
    pub case: &'a str,
    /// A case's result or a map point.
    pub role: SheetRole,
    /// The case's inputs.
    pub inputs: &'a WrinkleInputs,
    /// Its fabric reading.
    pub reading: SheetReading,
    /// Its simulated count.
    pub n: usize,
}

/// Fits Eq. 7 to `sheets` over the load constants `constants`, both readings of its bending term.
pub fn fit_tension_field(constants: &[f64], sheets: &[FitSheet<'_>]) -> Option<TensionFieldFit> {
    if sheets.is_empty() {
        return None;
    }
    let candidates: Vec<(bool, f64)> = [false, true]
        .iter()
        .flat_map(|&f| constants.iter().map(move |&c| (f, c)))
        .collect();
    let rows: Vec<FitRow> = sheets
        .iter()
        .map(|s| {
            let (inp, c_b) = (s.inputs, s.reading.bending_length_m(s.inputs));
            FitRow {
                case: s.case.to_string(),
                role: s.role,
                bending_length_m: c_b,
                shear_N_per_m: s.reading.rigidities(inp).2,
                n_simulated: s.n,
                n_tension_field: candidates
                    .iter()
                    .map(|&(f, c)| tension_field_n(inp, f, c_b, c))
                    .collect(),
            }
        })
        .collect();
    let ok: Vec<Vec<bool>> = rows.iter().map(FitRow::holds).collect();
    let groups: Vec<usize> = sheets.iter().map(|s| s.group).collect();
    let loo = leave_groups_out(&ok, &groups);
    Some(TensionFieldFit {
        candidates,
        rows,
        loo,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every verdict is written as the text the table held when it was a string.
    #[test]
    fn a_sheets_verdict_is_written_as_its_text() {
        for v in [
            SheetVerdict::Converged,
            SheetVerdict::ConvergedInNOnly,
            SheetVerdict::NotConvergedInMesh,
            SheetVerdict::NotConverged,
        ] {
            assert_eq!(serde_json::to_value(v).unwrap(), v.as_str());
            let back: SheetVerdict = serde_json::from_value(v.as_str().into()).unwrap();
            assert_eq!(back, v);
        }
        assert!(SheetVerdict::ConvergedInNOnly.agrees_on_n());
        assert!(!SheetVerdict::NotConvergedInMesh.agrees_on_n());
    }
}
