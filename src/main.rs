//! The `drapelab` binary: parse → cli::run → exit code.

use clap::Parser;

fn main() {
    let cli = match drapelab::cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if e.use_stderr() => {
            // A bad flag or value: clap's first line names it; one line, exit code 2.
            let text = e.render().to_string();
            let first = text.lines().next().unwrap_or("invalid arguments");
            eprintln!(
                "drapelab: {} (see --help)",
                first.trim_start_matches("error: ").trim()
            );
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
