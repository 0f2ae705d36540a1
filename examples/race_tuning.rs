//! Racing the tuning worlds (`[tune] race`, issue 38 item 2): every design of a study tuned
//! twice, with racing on and off, one after the other per design (the order alternating, so a
//! drift of the host's load falls on both alike). Per design: seconds, fresh evaluations and
//! closed-loop runs (one per tuning world of each evaluation, fewer when raced) of each, and
//! whether the two tunings agree bit for bit (tuned values, feasibility, noise, curve). One
//! thread per tuning unless `RAYON_NUM_THREADS` says otherwise; `SHARD=i/n` tunes the cases
//! whose id is `i` modulo `n`.
//!
//! ```sh
//! RAYON_NUM_THREADS=1 cargo run --release --example race_tuning -- STUDY.toml
//! ```

use std::path::Path;
use std::time::Instant;

use usm_study::batch::tuning_hook::{CaseTuner, Tuned};
use usm_study::evaluate::{out_of_reach, Deadline};
use usm_study::optimise::case_tuner::Tuner;
use usm_study::study::cases::resolve_case;
use usm_study::study::doe::expand;
use usm_study::study::parse::parse_study;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: race_tuning STUDY.toml")?;
    let path = Path::new(&path);
    let text = std::fs::read_to_string(path)?;
    let with = |race: bool| text.replacen("[tune]\n", &format!("[tune]\nrace = {race}\n"), 1);
    let on = parse_study(&with(true), path)?;
    let off = parse_study(&with(false), path)?;
    let (tune_on, tune_off) = (
        Tuner::new(&on).ok_or("no [tune]")?,
        Tuner::new(&off).ok_or("no [tune]")?,
    );
    let shard = std::env::var("SHARD").ok().and_then(|s| {
        let (i, n) = s.split_once('/')?;
        Some((i.parse::<usize>().ok()?, n.parse::<usize>().ok()?))
    });
    let cases = expand(&on, None)?;
    println!("case,race,seconds,evaluations,runs,feasible,x");
    let (mut agree, mut total, mut t) = (0, 0, [0.0f64; 2]);
    let mut runs = [0usize; 2];
    for case in &cases {
        if shard.is_some_and(|(i, n)| case.id % n != i) {
            continue;
        }
        let r = resolve_case(&on, case)?;
        if out_of_reach(&r.design, &r.scenario, &on.name) {
            continue;
        }
        let one = |race: bool| -> Result<(Tuned, f64), Box<dyn std::error::Error>> {
            let (study, tuner) = if race {
                (&on, &tune_on)
            } else {
                (&off, &tune_off)
            };
            let r = resolve_case(study, case)?;
            let t0 = Instant::now();
            let tuned = tuner.tune(study, case, &r, Deadline::NONE)?;
            Ok((tuned, t0.elapsed().as_secs_f64()))
        };
        let order = if case.id % 2 == 0 {
            [true, false]
        } else {
            [false, true]
        };
        let mut got: Vec<(bool, Tuned, f64)> = Vec::new();
        for race in order {
            let (tuned, secs) = one(race)?;
            println!(
                "{},{},{secs:.2},{},{},{},{:?}",
                case.id, race, tuned.evaluations, tuned.runs, tuned.feasible, tuned.x
            );
            got.push((race, tuned, secs));
        }
        got.sort_by_key(|g| !g.0);
        let (a, b) = (&got[0].1, &got[1].1);
        let same = a.x == b.x
            && a.feasible == b.feasible
            && a.evaluations == b.evaluations
            && a.noise.to_bits() == b.noise.to_bits()
            && a.success_spread.to_bits() == b.success_spread.to_bits()
            && a.curve
                .iter()
                .map(|c| c.to_bits())
                .eq(b.curve.iter().map(|c| c.to_bits()));
        agree += usize::from(same);
        total += 1;
        t[0] += got[0].2;
        t[1] += got[1].2;
        runs[0] += a.runs;
        runs[1] += b.runs;
        if !same {
            eprintln!("case {}: racing changed the tuning", case.id);
        }
    }
    eprintln!(
        "{agree} of {total} designs agree bit for bit; runs {} raced vs {} full ({:.1} %); \
         {:.1} s raced vs {:.1} s full",
        runs[0],
        runs[1],
        100.0 * runs[0] as f64 / runs[1].max(1) as f64,
        t[0],
        t[1]
    );
    Ok(())
}
