//! The one progress display of the binary: renders the library's progress reports (items done
//! of a known total) as an indicatif bar on a terminal, and as a line every few seconds
//! otherwise (logs, batch jobs).

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Progress display: an indicatif bar on a terminal, periodic lines on stderr otherwise.
pub struct Progress {
    bar: Option<indicatif::ProgressBar>,
    label: &'static str,
    unit: &'static str,
    total: usize,
    start: Instant,
    last: Mutex<Instant>,
    every: Duration,
    quiet: bool,
}

impl Progress {
    /// A progress display for `total` items; hidden entirely when `show` is false.
    pub fn new(label: &'static str, unit: &'static str, total: usize, show: bool) -> Self {
        let bar = (show && std::io::stderr().is_terminal()).then(|| {
            let b = indicatif::ProgressBar::new(total as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{prefix} [{elapsed_precise}] {wide_bar} {pos}/{len} {msg} ({per_sec}, ETA {eta})",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            b.set_prefix(format!("[{label}]"));
            b.set_message(unit);
            b
        });
        let now = Instant::now();
        Self {
            bar,
            label,
            unit,
            total,
            start: now,
            last: Mutex::new(now),
            every: Duration::from_secs(5),
            quiet: !show,
        }
    }

    /// Report `done` items finished, `rate_done` of them counted for the rate.
    pub fn update(&self, done: usize, rate_done: usize) {
        if let Some(b) = &self.bar {
            b.set_position(done as u64);
            return;
        }
        if self.quiet {
            return;
        }
        let Ok(mut last) = self.last.lock() else {
            return;
        };
        let now = Instant::now();
        if now < *last + self.every && done < self.total {
            return;
        }
        *last = now;
        let secs = self.start.elapsed().as_secs_f64().max(1e-9);
        let rate = rate_done as f64 / secs;
        let eta = if rate > 0.0 {
            format!("{:.0} s", (self.total - done.min(self.total)) as f64 / rate)
        } else {
            "?".into()
        };
        eprintln!(
            "[{}] {done}/{} {}, {}, ETA {eta}",
            self.label,
            self.total,
            self.unit,
            rate_text(rate, self.unit)
        );
    }

    /// Remove the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// A throughput readable at any speed: `12.3 cases/s`, or `25.4 s per case` below 0.5 per
/// second (a robust study's cases take tens of seconds; "0.0 cases/s" says nothing).
/// `unit` is the plural noun; its singular drops a trailing `s`.
pub fn rate_text(per_second: f64, unit: &str) -> String {
    if per_second >= 0.5 || per_second <= 0.0 || !per_second.is_finite() {
        format!("{per_second:.1} {unit}/s")
    } else {
        let one = unit.strip_suffix('s').unwrap_or(unit);
        format!("{:.1} s per {one}", 1.0 / per_second)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn slow_rates_read_as_seconds_per_item() {
        assert_eq!(super::rate_text(12.34, "cases"), "12.3 cases/s");
        assert_eq!(super::rate_text(0.04, "cases"), "25.0 s per case");
        assert_eq!(super::rate_text(0.0, "cases"), "0.0 cases/s");
    }
}
