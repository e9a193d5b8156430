//! The `drapelab` binary: parse → cli::run → exit code.

use clap::Parser;

fn main() {
    let cli = match drapelab::cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if e.use_stderr() => {
            // A bad flag or value: clap's first line names it; one line, exit code 2.
            // A missing argument's list follows on indented lines: kept, on the same line.
            let text = e.render().to_string();
            let mut lines = text.lines();
            let first = lines.next().unwrap_or("invalid arguments");
            let listed: Vec<&str> = lines
                .take_while(|l| !l.trim().is_empty())
                .map(str::trim)
                .collect();
            let first = first.trim_start_matches("error: ").trim();
            if listed.is_empty() {
                eprintln!("drapelab: {first} (see --help)");
            } else {
                eprintln!("drapelab: {first} {} (see --help)", listed.join(", "));
            }
            std::process::exit(drapelab::error::EXIT_BAD_INPUT);
        }
        Err(e) => e.exit(),
    };
    drapelab::cli::init_logging(cli.verbose, cli.quiet);
    let code = match drapelab::cli::run(cli) {
        Ok(code) => code,
        Err(err) => {
            let code = drapelab::error::exit_code(&err);
            match err.downcast_ref::<drapelab::error::InputError>() {
                Some(input) => eprintln!("drapelab: error: {input}"),
                None => eprintln!("drapelab: error: {}", format!("{err:#}").replace('\n', " ")),
            }
            code
        }
    };
    std::process::exit(code);
}
