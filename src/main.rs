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
    // Ctrl-C: what the run has not finished (temporary files, staging folders, output folders
    // still empty) is removed, and it says so; exit 130 as shells expect of SIGINT.
    let _ = ctrlc::set_handler(|| {
        drapelab::atomic::remove_unfinished();
        eprintln!("drapelab: interrupted (Ctrl-C): stopped, unfinished outputs removed");
        std::process::exit(drapelab::error::EXIT_INTERRUPTED);
    });
    let code = match on_worker(|| drapelab::cli::run(cli)) {
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

/// Stack of rayon's workers, bytes: the main thread's (8 MiB), since the CLI runs on one of them.
const WORKER_STACK_BYTES: usize = 8 << 20;

/// Runs `op` on a worker of rayon's global pool (`RAYON_NUM_THREADS` workers, as before): a
/// parallel loop started there splits onto the pool at once, where one started on the main thread
/// first waits for a worker to take it over (~60 µs here). A solve starts many short ones —
/// self-contact's broad phase at every long Newton step — and sphere_wool's self-contact time fell
/// from 0.55 to 0.42 s with this alone (docs/src/benchmarks.md, session 42).
fn on_worker<T: Send>(op: impl FnOnce() -> T + Send) -> T {
    // Fails only when the pool was built already (never at this point): then it is used as it is.
    let _ = rayon::ThreadPoolBuilder::new()
        .stack_size(WORKER_STACK_BYTES)
        .build_global();
    rayon::scope(|_| op())
}
