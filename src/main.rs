//! The `usm-study` binary: parses the command line and hands over to the library's CLI layer.
//! Any error becomes exit code 2 with a one-line cause chain on stderr.

use std::process::ExitCode;

fn main() -> ExitCode {
    match usm_study::cli::run() {
        Ok(code) => code,
        Err(err) => {
            let chain: Vec<String> = err.chain().map(|c| c.to_string()).collect();
            eprintln!("error: {}", chain.join(": "));
            ExitCode::from(2)
        }
    }
}
