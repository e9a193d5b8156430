//! `drapelab kinds`, `drapelab tables`, `drapelab completions` and the command-line reference:
//! what the program can tell about itself, from the registry and the clap definitions.

use super::Cli;

/// `drapelab kinds`: every stage kind with its slots and its parameters' defaults (units are in
/// the names); docs/src/reference/kinds.md is this output.
pub fn kinds_text() -> String {
    let mut s = String::new();
    for k in crate::stages::registry().kinds() {
        s += &format!("{}: {}\n", k.kind(), k.summary());
        for (side, slots) in [("inputs", k.inputs()), ("outputs", k.outputs())] {
            for slot in slots {
                s += &format!(
                    "  {side}.{}{}{}: {}\n",
                    slot.name,
                    if slot.many { " [list]" } else { "" },
                    if slot.required { "" } else { " (optional)" },
                    slot.doc
                );
            }
        }
        s += &params_text(k);
    }
    s
}

/// The parameters of a kind: each default (the resolved parameters of an empty table), or the
/// first key a pipeline must give.
fn params_text(k: &dyn crate::pipeline::Stage) -> String {
    match k.resolve(&toml::Table::new()) {
        Ok(serde_json::Value::Object(map)) => map
            .iter()
            .map(|(key, v)| format!("  params.{key} = {v} (default)\n"))
            .collect(),
        Ok(_) => String::new(),
        Err(e) => {
            let missing = e
                .message
                .strip_prefix("missing field `")
                .and_then(|m| m.split('`').next());
            match (e.key.is_empty(), missing) {
                (true, Some(field)) => format!(
                    "  params.{field}: required (no default); the kind's documentation lists the rest\n"
                ),
                _ => format!(
                    "  params.{}: required ({}); the kind's documentation lists the rest\n",
                    e.key, e.message
                ),
            }
        }
    }
}

/// The command-line reference (docs/src/reference/cli.md): every visible subcommand with its
/// description and options, from the clap definitions.
pub fn cli_reference() -> String {
    use clap::CommandFactory;
    let cli = Cli::command();
    let mut s = String::new();
    for sub in cli.get_subcommands().filter(|c| !c.is_hide_set()) {
        s += &format!("## `drapelab {}`\n\n", sub.get_name());
        if let Some(about) = sub.get_long_about().or(sub.get_about()) {
            s += &format!("{}\n\n", about.to_string().trim());
        }
        for a in sub.get_arguments().filter(|a| !a.is_hide_set()) {
            let name = match (a.get_long(), a.is_positional()) {
                (Some(l), _) => format!("--{l}"),
                (None, _) => a.get_id().as_str().to_uppercase(),
            };
            let help = a.get_help().map(|h| h.to_string()).unwrap_or_default();
            let defaults: Vec<String> = a
                .get_default_values()
                .iter()
                .map(|v| v.to_string_lossy().to_string())
                .collect();
            let default = if defaults.is_empty() {
                String::new()
            } else {
                format!(" Default: `{}`.", defaults.join(" "))
            };
            s += &format!("- `{name}`: {}{default}\n", help.replace('\n', " "));
        }
        s += "\n";
    }
    s
}
