//! The Imperialist Competitive Algorithm (Atashpaz-Gargari & Lucas 2007; seed 000 §"Imperialistic
//! Competitive Algorithm") on the unit box [0, 1]^d. The caller maps the box to physical bounds and
//! categorical choices (a coordinate's third for each of three topologies, say).
//!
//! Random numbers are drawn only in the serial parts, in a fixed order, and costs of a decade are
//! evaluated in parallel (rayon) in a fixed order: a seed gives the same result on any thread count.

use crate::error::KeyError;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// ICA's control factors (seed 000 Table 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IcaSettings {
    /// Maximum number of decades (MaxIt).
    pub decades: usize,
    /// Number of countries (population), imperialists included.
    pub countries: usize,
    /// Number of initial imperialists.
    pub imperialists: usize,
    /// Assimilation coefficient β: a colony moves U(0, β) of the way to its imperialist.
    pub beta: f64,
    /// Assimilation deviation angle γ in radians: the move deviates by U(−γ, γ).
    pub gamma: f64,
    /// Revolution rate: the probability that a colony jumps to a random position each decade.
    pub revolution_rate: f64,
    /// Colonies' share ξ of an empire's total cost.
    pub xi: f64,
    /// Random seed.
    pub seed: u64,
}

impl IcaSettings {
    /// Checks the settings: Err(KeyError::new(key, message)).
    pub fn check(&self) -> Result<(), KeyError> {
        let bad = |k: &str, m: &str| Err(KeyError::new(k.to_string(), m.to_string()));
        if self.countries == 0 {
            return bad("countries", "must be ≥ 1");
        }
        if self.imperialists == 0 || self.imperialists > self.countries {
            return bad("imperialists", "must be in 1..=countries");
        }
        if self.decades == 0 {
            return bad("decades", "must be ≥ 1");
        }
        for (k, v) in [
            ("beta", self.beta),
            ("gamma", self.gamma),
            ("revolution_rate", self.revolution_rate),
            ("xi", self.xi),
        ] {
            if !v.is_finite() || v < 0.0 {
                return bad(k, "must be a finite number ≥ 0");
            }
        }
        if self.revolution_rate > 1.0 {
            return bad("revolution_rate", "must be ≤ 1");
        }
        Ok(())
    }
}

/// A country: a position in the unit box and its cost.
#[derive(Debug, Clone, PartialEq)]
pub struct Country {
    /// Position in [0, 1]^d.
    pub x: Vec<f64>,
    /// Cost at x.
    pub cost: f64,
}

/// An empire: an imperialist and its colonies.
#[derive(Debug, Clone, PartialEq)]
pub struct Empire {
    /// The imperialist.
    pub imperialist: Country,
    /// The colonies.
    pub colonies: Vec<Country>,
}

impl Empire {
    /// Total cost: the imperialist's plus ξ times the mean of its colonies'.
    pub fn total_cost(&self, xi: f64) -> f64 {
        if self.colonies.is_empty() {
            self.imperialist.cost
        } else {
            self.imperialist.cost
                + xi * self.colonies.iter().map(|c| c.cost).sum::<f64>()
                    / self.colonies.len() as f64
        }
    }
}

/// What observers see after each decade.
pub struct DecadeEvent<'a> {
    /// Decade number (0 = the initial empires).
    pub decade: usize,
    /// The empires.
    pub empires: &'a [Empire],
    /// Best cost so far.
    pub best_cost: f64,
    /// Mean cost of all countries.
    pub mean_cost: f64,
    /// Cost evaluations so far.
    pub evaluations: usize,
}

impl<'a> DecadeEvent<'a> {
    /// The event after `decade` with the `empires`, the best cost so far and the evaluations.
    fn of(decade: usize, empires: &'a [Empire], best_cost: f64, evaluations: usize) -> Self {
        Self {
            decade,
            empires,
            best_cost,
            mean_cost: mean_cost(empires),
            evaluations,
        }
    }
}

/// The result of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct IcaReport {
    /// Best position found.
    pub best_x: Vec<f64>,
    /// Its cost.
    pub best_cost: f64,
    /// Decades run.
    pub decades: usize,
    /// Cost evaluations.
    pub evaluations: usize,
    /// Best cost after each decade (index 0: initial).
    pub history: Vec<f64>,
}

/// An ICA run on a cost over [0, 1]^dim.
pub struct Ica {
    /// Settings.
    pub settings: IcaSettings,
    /// Dimension of the box.
    pub dim: usize,
}

/// Clamps to the unit box.
fn clamp01(x: &mut [f64]) {
    for v in x {
        *v = v.clamp(0.0, 1.0);
    }
}

/// Assimilation: moves `colony` towards `imperialist` by U(0, β) of the distance, deviated by an angle
/// U(−γ, γ) (a perpendicular component of length |move|·tan θ in a random direction), kept in the box.
pub fn assimilate(
    colony: &[f64],
    imperialist: &[f64],
    beta: f64,
    gamma: f64,
    rng: &mut impl Rng,
) -> Vec<f64> {
    let d: Vec<f64> = imperialist.iter().zip(colony).map(|(a, b)| a - b).collect();
    let dn = d.iter().map(|v| v * v).sum::<f64>().sqrt();
    let step = rng.random::<f64>() * beta;
    let theta = (rng.random::<f64>() * 2.0 - 1.0) * gamma;
    let r: Vec<f64> = (0..d.len())
        .map(|_| rng.random::<f64>() * 2.0 - 1.0)
        .collect();
    let mut x: Vec<f64> = colony.iter().zip(&d).map(|(c, dv)| c + step * dv).collect();
    if dn > 0.0 && d.len() > 1 {
        // Perpendicular part of r, scaled to |move| tan θ.
        let proj = r.iter().zip(&d).map(|(a, b)| a * b).sum::<f64>() / (dn * dn);
        let perp: Vec<f64> = r.iter().zip(&d).map(|(a, b)| a - proj * b).collect();
        let pn = perp.iter().map(|v| v * v).sum::<f64>().sqrt();
        if pn > 0.0 {
            let len = step * dn * theta.tan();
            for (xi, p) in x.iter_mut().zip(&perp) {
                *xi += len * p / pn;
            }
        }
    }
    clamp01(&mut x);
    x
}

/// Imperialistic competition: the weakest colony of the weakest empire goes to an empire drawn with
/// probability proportional to its normalised power (D = P − U(0, 1), largest D wins). An empire left
/// without colonies is eliminated: its imperialist becomes a colony of the winner. Returns the winner.
pub fn compete(empires: &mut Vec<Empire>, xi: f64, rng: &mut impl Rng) -> Option<usize> {
    if empires.len() < 2 {
        return None;
    }
    let tc: Vec<f64> = empires.iter().map(|e| e.total_cost(xi)).collect();
    let worst = tc
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(k, _)| k)?;
    let max = tc[worst];
    let ntc: Vec<f64> = tc.iter().map(|c| max - c).collect();
    let sum: f64 = ntc.iter().sum();
    let p: Vec<f64> = if sum > 0.0 {
        ntc.iter().map(|v| v / sum).collect()
    } else {
        vec![1.0 / tc.len() as f64; tc.len()]
    };
    let draws: Vec<f64> = (0..p.len()).map(|_| rng.random::<f64>()).collect();
    let mut winner = (0..p.len())
        .filter(|&k| k != worst)
        .max_by(|&a, &b| (p[a] - draws[a]).total_cmp(&(p[b] - draws[b])))?;
    if let Some(k) = empires[worst]
        .colonies
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.cost.total_cmp(&b.1.cost))
        .map(|(k, _)| k)
    {
        let c = empires[worst].colonies.remove(k);
        empires[winner].colonies.push(c);
    }
    if empires[worst].colonies.is_empty() {
        let e = empires.remove(worst);
        if winner > worst {
            winner -= 1;
        }
        empires[winner].colonies.push(e.imperialist);
    }
    Some(winner)
}

impl Ica {
    /// Runs ICA on `cost` (evaluated in parallel); `observe` sees every decade.
    pub fn run(
        &self,
        cost: &(dyn Fn(&[f64]) -> f64 + Sync),
        mut observe: impl FnMut(&DecadeEvent<'_>),
    ) -> IcaReport {
        let s = &self.settings;
        let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
        let eval = |xs: Vec<Vec<f64>>| -> Vec<Country> {
            let costs: Vec<f64> = xs.par_iter().map(|x| cost(x)).collect();
            xs.into_iter()
                .zip(costs)
                .map(|(x, c)| Country {
                    x,
                    cost: if c.is_nan() { f64::INFINITY } else { c },
                })
                .collect()
        };
        let init: Vec<Vec<f64>> = (0..s.countries)
            .map(|_| (0..self.dim).map(|_| rng.random::<f64>()).collect())
            .collect();
        let countries = eval(init);
        let mut evaluations = countries.len();
        let mut empires = first_empires(countries, s.imperialists, &mut rng);
        let mut best_c = best_country(&empires).expect("at least one imperialist");
        let mut history = vec![best_c.cost];
        observe(&DecadeEvent::of(0, &empires, best_c.cost, evaluations));
        let mut decade = 0;
        let several = empires.len() > 1;
        while decade < s.decades {
            decade += 1;
            // Assimilation and revolution (serial draws), then parallel evaluation in a fixed order.
            let mut moved: Vec<Vec<f64>> = Vec::new();
            for e in &empires {
                for c in &e.colonies {
                    let x = if rng.random::<f64>() < s.revolution_rate {
                        (0..self.dim).map(|_| rng.random::<f64>()).collect()
                    } else {
                        assimilate(&c.x, &e.imperialist.x, s.beta, s.gamma, &mut rng)
                    };
                    moved.push(x);
                }
            }
            evaluations += moved.len();
            let mut moved = eval(moved).into_iter();
            for e in empires.iter_mut() {
                for c in e.colonies.iter_mut() {
                    *c = moved.next().expect("one per colony");
                }
                promote_best_colony(e);
            }
            compete(&mut empires, s.xi, &mut rng);
            if let Some(b) = best_country(&empires)
                && b.cost < best_c.cost
            {
                best_c = b;
            }
            history.push(best_c.cost);
            observe(&DecadeEvent::of(decade, &empires, best_c.cost, evaluations));
            // Stop when one empire remains (a run started with one empire runs all its decades).
            if several && empires.len() == 1 {
                break;
            }
        }
        IcaReport {
            best_x: best_c.x,
            best_cost: best_c.cost,
            decades: decade,
            evaluations,
            history,
        }
    }
}
/// The first empires: the `imperialists` best countries, the rest shuffled among them as colonies.
fn first_empires(
    mut countries: Vec<Country>,
    imperialists: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<Empire> {
    countries.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    let mut colonies: Vec<Country> = countries.split_off(imperialists);
    colonies.shuffle(rng);
    form_empires(countries, colonies)
}

/// A colony better than its imperialist takes its place.
fn promote_best_colony(e: &mut Empire) {
    if let Some(k) = e
        .colonies
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.cost.total_cmp(&b.1.cost))
        .map(|(k, _)| k)
        && e.colonies[k].cost < e.imperialist.cost
    {
        std::mem::swap(&mut e.colonies[k], &mut e.imperialist);
    }
}

/// The first empires (Atashpaz-Gargari & Lucas 2007): the colonies shared among the imperialists
/// by normalised power (the best cost's distance from the worst), the rounding remainder to the
/// strongest.
fn form_empires(countries: Vec<Country>, mut colonies: Vec<Country>) -> Vec<Empire> {
    let max = countries
        .iter()
        .map(|c| c.cost)
        .fold(f64::NEG_INFINITY, f64::max);
    let norm: Vec<f64> = countries.iter().map(|c| max - c.cost).collect();
    let sum: f64 = norm.iter().sum();
    let ncol = colonies.len();
    let mut shares: Vec<usize> = norm
        .iter()
        .map(|v| {
            if sum > 0.0 {
                (v / sum * ncol as f64).round() as usize
            } else {
                ncol / countries.len()
            }
        })
        .collect();
    let mut assigned: usize = shares.iter().sum();
    while assigned > ncol {
        let k = shares
            .iter()
            .enumerate()
            .rev()
            .find(|(_, v)| **v > 0)
            .map(|(k, _)| k)
            .unwrap_or(0);
        shares[k] -= 1;
        assigned -= 1;
    }
    shares[0] += ncol - assigned;
    countries
        .into_iter()
        .zip(&shares)
        .map(|(imp, &n)| Empire {
            imperialist: imp,
            colonies: colonies.drain(..n.min(colonies.len())).collect(),
        })
        .collect()
}

/// The best imperialist of all empires.
fn best_country(empires: &[Empire]) -> Option<Country> {
    empires
        .iter()
        .map(|e| &e.imperialist)
        .min_by(|a, b| a.cost.total_cmp(&b.cost))
        .cloned()
}

/// The mean cost over every country of every empire.
fn mean_cost(empires: &[Empire]) -> f64 {
    let all: Vec<f64> = empires
        .iter()
        .flat_map(|e| std::iter::once(e.imperialist.cost).chain(e.colonies.iter().map(|c| c.cost)))
        .collect();
    all.iter().sum::<f64>() / all.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(seed: u64) -> IcaSettings {
        IcaSettings {
            decades: 60,
            countries: 40,
            imperialists: 5,
            beta: 2.0,
            gamma: 0.5,
            revolution_rate: 0.2,
            xi: 0.1,
            seed,
        }
    }

    fn sphere(x: &[f64]) -> f64 {
        x.iter()
            .enumerate()
            .map(|(k, v)| (v - 0.2 - 0.15 * k as f64).powi(2))
            .sum()
    }

    #[test]
    fn finds_the_minimum_of_a_shifted_sphere() {
        let r = Ica {
            settings: settings(7),
            dim: 4,
        }
        .run(&sphere, |_| {});
        assert!(r.best_cost < 1e-3, "{r:?}");
        assert!(
            r.history.windows(2).all(|w| w[1] <= w[0]),
            "best cost must never rise"
        );
    }

    #[test]
    fn same_seed_same_result_on_one_and_two_threads() {
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                Ica {
                    settings: settings(11),
                    dim: 3,
                }
                .run(&sphere, |_| {})
            })
        };
        assert_eq!(run(1), run(2));
        assert_ne!(
            run(1).best_x,
            Ica {
                settings: settings(12),
                dim: 3
            }
            .run(&sphere, |_| {})
            .best_x
        );
    }

    #[test]
    fn assimilation_keeps_countries_in_the_box() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..2000 {
            let c: Vec<f64> = (0..5).map(|_| rng.random()).collect();
            let i: Vec<f64> = (0..5).map(|_| rng.random()).collect();
            let x = assimilate(&c, &i, 4.0, 1.2, &mut rng);
            assert!(x.iter().all(|v| (0.0..=1.0).contains(v)), "{x:?}");
        }
    }

    fn country(cost: f64) -> Country {
        Country {
            x: vec![cost],
            cost,
        }
    }

    #[test]
    fn competition_moves_the_weakest_colony_of_the_weakest_empire_and_eliminates_empty_empires() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let strong = Empire {
            imperialist: country(0.1),
            colonies: vec![country(0.2), country(0.3)],
        };
        let weak = Empire {
            imperialist: country(0.5),
            colonies: vec![country(0.6), country(0.9)],
        };
        let mut empires = vec![strong.clone(), weak];
        let w = compete(&mut empires, 0.1, &mut rng).unwrap();
        assert_eq!(w, 0);
        assert_eq!(
            empires[1].colonies,
            vec![country(0.6)],
            "the weakest colony (0.9) left the weakest empire"
        );
        assert!(empires[0].colonies.contains(&country(0.9)));
        // Next: the weak empire loses its last colony and is eliminated; its imperialist joins the winner.
        compete(&mut empires, 0.1, &mut rng).unwrap();
        assert_eq!(empires.len(), 1);
        assert!(
            empires[0].colonies.contains(&country(0.5))
                && empires[0].colonies.contains(&country(0.6))
        );
    }
}
