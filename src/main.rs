//! The `drapelab` binary: parse → cli::run → exit code.

use clap::Parser;

fn main() {
    let cli = drapelab::cli::Cli::parse();
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
