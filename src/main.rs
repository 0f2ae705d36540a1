//! The `usm-study` binary: parses the command line and hands over to [`cli`], the only part of
//! the crate that prints and the only user of clap, anyhow and indicatif.
//! Any error becomes exit code 2 with a one-line cause chain on stderr.

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    match cli::run() {
        Ok(code) => code,
        Err(err) => {
            let chain: Vec<String> = err.chain().map(|c| c.to_string()).collect();
            eprintln!("error: {}", chain.join(": "));
            ExitCode::from(2)
        }
    }
}
