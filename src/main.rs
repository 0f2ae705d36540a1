//! The `usm-study` binary: parses the command line and hands over to [`cli`], the only part of
//! the crate that prints and the only user of clap, anyhow and indicatif.
//! Any error becomes exit code 2 with a one-line cause chain on stderr.

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    quiet_on_closed_pipe();
    match cli::run() {
        Ok(code) => code,
        Err(err) => {
            let chain: Vec<String> = err.chain().map(|c| c.to_string()).collect();
            eprintln!("error: {}", chain.join(": "));
            ExitCode::from(2)
        }
    }
}

/// A closed output pipe (`usm-study … | head`) ends the program quietly, as it ends other
/// command-line tools, instead of a panic inside `println!`: restore the default action of
/// SIGPIPE, which Rust's runtime sets to "ignore".
fn quiet_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in `main`, before any other thread exists; `signal` with
    // `SIG_DFL` only changes this process's disposition of SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
