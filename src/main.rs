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
            eprintln!("error: {}", one_line(&err));
            ExitCode::from(2)
        }
    }
}

/// The error and its causes on one line, `a: b: c`; a cause whose text its parent's message
/// already ends with (an error that prints its source too) is not repeated.
fn one_line(err: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if line.is_empty() {
            line = text;
        } else if !line.ends_with(&text) {
            line.push_str(": ");
            line.push_str(&text);
        }
    }
    line
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

#[cfg(test)]
mod tests {
    use super::one_line;

    #[derive(Debug, thiserror::Error)]
    #[error("disk full")]
    struct Inner;

    #[derive(Debug, thiserror::Error)]
    #[error("writing x: {0}")]
    struct Outer(#[source] Inner);

    #[test]
    fn each_cause_is_printed_once() {
        // An error that prints its source too: the source is not repeated.
        assert_eq!(
            one_line(&anyhow::Error::new(Outer(Inner))),
            "writing x: disk full"
        );
        // Context added by the caller: the chain, joined.
        let e = anyhow::Error::new(Inner).context("reading y");
        assert_eq!(one_line(&e), "reading y: disk full");
    }
}
