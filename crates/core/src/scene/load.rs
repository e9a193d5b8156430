//! Loading a scene: the file read, `--set` overrides applied (a grid override moves the particles
//! named by index), the keys renamed since read as their successors, and the result validated.

use super::{LoadedScene, Scene, ValidatedScene};
use crate::config::{from_table, read_toml_table, set_dotted};
use crate::error::{InputError, KeyError};
use std::path::Path;

impl Scene {
    /// Reads, overrides and validates a scene file.
    ///
    /// A grid override (`cloth.nx`, `cloth.ny`) moves the particles the file names by grid index
    /// (pins, holds, point loads) to the same material points on the new grid, as [`Scene::regridded`]
    /// does; index lists given among the overrides themselves are taken as indices of the new grid.
    pub fn load(
        path: &Path,
        overrides: &[(String, toml::Value)],
    ) -> Result<LoadedScene, InputError> {
        Self::load_table(path, read_toml_table(path)?, overrides)
    }

    /// [`Scene::load`] of a scene already parsed into a TOML table (the Python package's dict
    /// scenes); `path` names it in errors and resolves nothing.
    pub fn load_table(
        path: &Path,
        file: toml::Table,
        overrides: &[(String, toml::Value)],
    ) -> Result<LoadedScene, InputError> {
        let is_grid = |k: &str| k == "cloth.nx" || k == "cloth.ny";
        let with = |keep: &dyn Fn(&str) -> bool| -> Result<Scene, InputError> {
            let mut table = file.clone();
            for (k, v) in overrides.iter().filter(|(k, _)| keep(k)) {
                set_dotted(&mut table, k, v.clone()).map_err(|m| InputError::new(path, k, m))?;
            }
            read_renamed_keys(&mut table).map_err(|e| InputError::new(path, e.key, e.message))?;
            let mut scene: Scene = from_table(path, "", table)?;
            scene.cloth.read_mesh(path)?;
            super::body::read_bodies(&mut scene.obstacles, path)?;
            super::fabric::apply_fabric(&mut scene, path)?;
            super::sew::sew_pattern(&mut scene, path)?;
            Ok(scene)
        };
        let mut scene = with(&|_| true)?;
        if overrides.iter().any(|(k, _)| is_grid(k)) {
            let on_file_grid = with(&|k| !is_grid(k))?;
            on_file_grid.validate(path)?;
            let given = |prefix: &str| {
                overrides
                    .iter()
                    .any(|(k, _)| k == prefix || k.starts_with(&format!("{prefix}.")))
            };
            let mut moved = on_file_grid.regridded(scene.cloth.nx, scene.cloth.ny);
            if given("boundary.pin_particles") || given("boundary") {
                moved.boundary.pin_particles = scene.boundary.pin_particles.clone();
            }
            if given("boundary.holds") || given("boundary") {
                moved.boundary.holds = scene.boundary.holds.clone();
            }
            let load_particle_given = overrides.iter().any(|(k, _)| {
                k == "loads" || (k.starts_with("loads.") && k.ends_with(".particle"))
            });
            if load_particle_given {
                moved.loads = scene.loads.clone();
            }
            scene = moved;
        }
        scene.validate(path)?;
        Ok(LoadedScene {
            scene: ValidatedScene(scene),
            path: path.to_path_buf(),
        })
    }
}

/// The solver keys issue 46 turned from booleans into strategies, read as their successors: (table,
/// old boolean, new key, its value for true, for false).
const RENAMED_KEYS: [(&str, &str, &str, &str, &str); 4] = [
    ("static", "curvilinear", "direction", "curved", "straight"),
    (
        "static",
        "carried_damping",
        "regularization",
        "carried-damping",
        "shift-ladder",
    ),
    (
        "static",
        "reuse_factorization",
        "factor_reuse",
        "chord",
        "fresh",
    ),
    (
        "dynamic",
        "reuse_factorization",
        "factor_reuse",
        "chord",
        "fresh",
    ),
];

/// Rewrites the old boolean solver keys of a scene table (`solver.static.curvilinear`,
/// `carried_damping`, `reuse_factorization`, `coarse_start` and `sag_start`,
/// `solver.dynamic.reuse_factorization`) into the strategy keys that replaced them, so that scene
/// files written before keep their meaning. Err (key, message) for a non-boolean value or an old
/// key given together with its successor.
fn read_renamed_keys(table: &mut toml::Table) -> Result<(), KeyError> {
    let Some(toml::Value::Table(solver)) = table.get_mut("solver") else {
        return Ok(());
    };
    let flag = |t: &mut toml::Table, sub: &str, old: &str| -> Result<Option<bool>, _> {
        let key = format!("solver.{sub}.{old}");
        match t.remove(old) {
            None => Ok(None),
            Some(toml::Value::Boolean(b)) => Ok(Some(b)),
            Some(v) => Err(KeyError::new(
                key,
                format!("expected a boolean, got the {} {v}", v.type_str()),
            )),
        }
    };
    for (sub, old, new, yes, no) in RENAMED_KEYS {
        let Some(toml::Value::Table(t)) = solver.get_mut(sub) else {
            continue;
        };
        if let Some(b) = flag(t, sub, old)? {
            rename_into(t, (sub, old, new), if b { yes } else { no })?;
        }
    }
    if let Some(toml::Value::Table(t)) = solver.get_mut("static") {
        let (nested, shaped) = (
            flag(t, "static", "coarse_start")?,
            flag(t, "static", "sag_start")?,
        );
        if nested.is_some() || shaped.is_some() {
            let start =
                crate::solve::Start::from_flags(nested.unwrap_or(true), shaped.unwrap_or(true));
            let name = serde_json::to_value(start)
                .map_err(|e| KeyError::new("solver.static.start", e.to_string()))?;
            let old = if nested.is_some() {
                "coarse_start"
            } else {
                "sag_start"
            };
            rename_into(
                t,
                ("static", old, "start"),
                name.as_str().unwrap_or_default(),
            )?;
        }
    }
    Ok(())
}

/// Sets `new` to `value` in the solver table `t` unless the file gives `new` itself.
fn rename_into(
    t: &mut toml::Table,
    (sub, old, new): (&str, &str, &str),
    value: &str,
) -> Result<(), KeyError> {
    if t.contains_key(new) {
        return Err(KeyError::new(
            format!("solver.{sub}.{old}"),
            format!("replaced by solver.{sub}.{new}, which is given too: keep only `{new}`"),
        ));
    }
    t.insert(new.into(), toml::Value::String(value.into()));
    Ok(())
}
