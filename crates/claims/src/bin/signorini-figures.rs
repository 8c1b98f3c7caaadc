//! `signorini-figures`: the `figures` command of `signorini` (the same flags, the same
//! function), built without the solver, so that `make figures` on a fresh clone compiles only
//! what redrawing needs (the records, the claims, the plots).

use signorini_claims::commands::figures::{self, FiguresArgs};
use signorini_claims::commands::output;
use std::process::ExitCode;

/// Redraw the figures and CLAIMS.md from the stored results (`signorini figures --help`).
#[derive(clap::Parser)]
#[command(name = "signorini-figures", version)]
struct Cli {
    #[command(flatten)]
    args: FiguresArgs,
}

fn main() -> ExitCode {
    output::ignore_file_size_signal();
    let cli: Cli = match output::parse() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    output::exit_status(figures::run(&cli.args).map(|f| output::wrote_all(&f)), |_| false)
}
