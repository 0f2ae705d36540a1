//! A profiling driver for the static TCM analysis (issue 23 item 4): `analyse` of `usm-paper`
//! with N Sobol samples (default 20 000), repeated R times, no sinks, one thread; prints the
//! checksum (the summed singular fractions, so the work cannot be optimised away) and the
//! configurations per second. Meant for instruction counts and profiles of the whole analysis
//! without criterion's own work around it:
//!
//! ```sh
//! cargo build --release --example prof_static
//! valgrind --tool=callgrind target/release/examples/prof_static 20000 1
//! perf record target/release/examples/prof_static 20000 50
//! ```

use usm_study::model::presets::usm_paper;
use usm_study::statics::{analyse, StaticSpec};
fn main() {
    let v = usm_paper();
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20000);
    let reps: usize = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let spec = StaticSpec {
        samples: n,
        worst: 0,
        ..Default::default()
    };
    let t = std::time::Instant::now();
    let mut acc = 0.0;
    for _ in 0..reps {
        let s = analyse(&v, &spec, 1, &mut |_, _, _| Ok(()), &|_| {}).unwrap();
        acc += s.singular_fraction;
    }
    let dt = t.elapsed().as_secs_f64();
    println!("{acc} {:.0} k/s", (n * reps) as f64 / dt / 1e3);
}
