//! A fuzz harness on stable Rust: seeded mutations of the shipped input files (study files,
//! problem files, design files and presets, scenario presets, `--set KEY=VALUE` lists, an
//! allocation case, a sweep journal) at the byte and token level, fed to every parser and, for inputs that
//! parse, to the allocator (all four methods), the study's case resolution, the optimiser's
//! parameter space, and the scenario a `--set` list edits. Nothing may panic, abort or hang.
//!
//! The problem-file grammar comes from the shipped problems (`studies/*.toml` with
//! `[[param]]`) plus generated `[solver]` / `[[variant]]` / `[[axis]]` sections with nasty
//! values; the `--set` grammar from every key path of the scenario presets (`key=value`
//! lines, values from the preset, nasty values and bare words).
//!
//! CI runs 20 000 inputs (the default). The long run, documented in `docs/reliability.md`:
//!
//! ```text
//! FUZZ_INPUTS=1000000 cargo test --release --test fuzz -- --nocapture
//! ```
//!
//! `FUZZ_SEED` picks another input stream, `FUZZ_THREADS` the worker count (default 2).
//! Input `i` is a pure function of `(seed, i)`: a failure names its index, and
//! `FUZZ_ONLY=i` reruns that one input and prints it. A watchdog ends the run (exit code 3,
//! the input printed) if an input makes no progress for `HANG_S` seconds: that is a hang,
//! not a slow input (no timing is asserted otherwise).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};
use usm_study::allocation::Method;
use usm_study::input::keypath::{parse_override, set};
use usm_study::kinematics::{forward_kinematics, thruster_matrix_owned, KinWorkspace};
use usm_study::model::design::{design_to_toml, parse_design, parse_design_table};
use usm_study::model::presets::preset;
use usm_study::optimise::parse_problem;
use usm_study::pipeline::allocate::{parse_case, solve_case};
use usm_study::study::cases::resolve_case;
use usm_study::study::doe::{case_count, expand};
use usm_study::study::parse::parse_study;
use usm_study::study::runner::check_case;

/// A stalled input for this long is a hang [s].
const HANG_S: u64 = 120;

fn hang_s() -> u64 {
    env_u64("FUZZ_HANG_S", HANG_S)
}

/// The kind of input, i.e. which parser it goes to.
#[derive(Clone, Copy, Debug)]
enum Kind {
    Study,
    Problem,
    Design,
    Scenario,
    /// `--set KEY=VALUE` lines applied to a scenario preset.
    Overrides,
    AllocationCase,
    /// A sweep journal (`cases.partial.csv`) as `--resume` reads it.
    JournalRows,
}

/// The raw schema of the shipped transport study (its journal has packed scenario metrics).
fn journal_schema() -> &'static [(String, usm_study::report::ColumnKind)] {
    static S: std::sync::OnceLock<Vec<(String, usm_study::report::ColumnKind)>> =
        std::sync::OnceLock::new();
    S.get_or_init(|| {
        let study = parse_study(
            &std::fs::read_to_string("studies/thrusters.toml").unwrap(),
            Path::new("studies/thrusters.toml"),
        )
        .unwrap();
        usm_study::batch::records::raw_schema(&study)
    })
}

/// A journal of `journal_schema` with a header and three rows.
fn journal_text() -> String {
    use usm_study::report::ColumnKind;
    let schema = journal_schema();
    let header: Vec<&str> = schema.iter().map(|(n, _)| n.as_str()).collect();
    let mut text = header.join(",") + "\n";
    for (r, status) in ["ok", "failed", "skipped"].iter().enumerate() {
        let cells: Vec<String> = schema
            .iter()
            .map(|(n, k)| match (n.as_str(), k) {
                ("status", _) => status.to_string(),
                ("hash", _) => format!("ab{r}f"),
                ("scenario_metrics", _) => {
                    format!("world.0.mission_cost={r}.25;x=NaN;y=-inf;seg0_time=1e308")
                }
                (_, ColumnKind::I64) => r.to_string(),
                (_, ColumnKind::F64) => format!("{r}.5"),
                (_, ColumnKind::Bool) => "true".into(),
                (_, ColumnKind::Str) => "\"a, \"\"b\"\"\"".into(),
            })
            .collect();
        text.push_str(&cells.join(","));
        text.push('\n');
    }
    text
}

/// Key paths and values of `table` as `--set` lines (`control.k_psi=0.45`), arrays by element.
fn set_lines(table: &toml::Table, prefix: &str, out: &mut Vec<String>) {
    for (k, v) in table {
        let key = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            toml::Value::Table(t) => set_lines(t, &key, out),
            toml::Value::Array(a) => {
                out.push(format!("{key}={v}"));
                for (i, x) in a.iter().enumerate().take(3) {
                    out.push(format!("{key}[{i}]={x}"));
                }
            }
            other => out.push(format!("{key}={other}")),
        }
    }
}

/// Generated problem-file sections: solver budgets, variants and a stray axis, with values
/// that stress the bounds (the mutations then edit them further).
const PROBLEM_TAILS: [&str; 4] = [
    "\n[solver]\nmethod = \"particle-swarm\"\nparticles = 1000000000\nmax_evals = 4\nrestarts = 1000000000\n",
    "\n[[variant]]\nname = \"v\"\nset = {\"control.k_psi\" = 0.3, \"scenario.duration\" = 1e-9}\n",
    "\n[[axis]]\nname = \"control.look_ahead\"\nvalues = [1.0, \"a\\nb\"]\n",
    "\n[study]\nobjective = \"\"\nmaximise = [\"bogus\", \"success\"]\npareto = [\"x\", \"y\"]\n",
];

/// The seed corpus: the shipped files and presets.
fn corpus() -> Vec<(Kind, String)> {
    let mut c = Vec::new();
    for dir in ["studies", "studies/designs"] {
        let mut paths: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
        paths.sort();
        for p in paths {
            let text = std::fs::read_to_string(p).unwrap();
            let kind = if dir != "studies" {
                Kind::Design
            } else if text.contains("[[param]]") {
                for tail in PROBLEM_TAILS {
                    c.push((Kind::Problem, format!("{text}{tail}")));
                }
                Kind::Problem
            } else {
                Kind::Study
            };
            c.push((kind, text));
        }
    }
    for name in ["usm-paper", "uvms-planar"] {
        c.push((Kind::Design, design_to_toml(&preset(name).unwrap())));
    }
    for name in usm_study::scenario::preset_names() {
        let text = usm_study::scenario::preset_text(name).unwrap();
        let table: toml::Table = toml::from_str(&text).unwrap();
        let mut lines = Vec::new();
        set_lines(&table, "", &mut lines);
        lines.extend(
            [
                "scenario.name=~",
                "scenario.name=",
                "scenario.duration=1e-9",
                "control.k_psi=nan",
                "allocation.method=qp",
                "path.waypoints[0][1]=1e308",
                "x[99999999999999999999]=1",
                "=1",
            ]
            .map(String::from),
        );
        // Several short lists per preset, so that one input applies a handful of overrides.
        for chunk in lines.chunks(6) {
            c.push((Kind::Overrides, format!("{name}\n{}", chunk.join("\n"))));
        }
        c.push((Kind::Scenario, text));
    }
    c.push((Kind::JournalRows, journal_text()));
    c.push((
        Kind::AllocationCase,
        r#"{"T": [[1,0,0,1,0,0,1],[0,1,0,0,1,0,0],[0,0,1,0,0,1,0],[0,0,0.3,0,0,-0.3,0],
        [0,-0.3,0,0,0.3,0,0.1],[0.2,0,0,-0.2,0,0,0]], "tau": [10, 2, -3, 0, 1, 0.5],
        "u_min": [-40,-40,-40,-40,-40,-40,-40], "u_max": [40,40,40,40,40,40,40],
        "weights": [1,1,1,1,1,1,1], "lambda": 0.1, "u_prev": [0,0,0,0,0,0,0],
        "rate_limit": [5,5,5,5,5,5,5]}"#
            .to_string(),
    ));
    c
}

/// Values that break naive code: extremes, non-finite, signs, huge counts.
const NASTY: [&str; 24] = [
    "0",
    "-1",
    "1",
    "0.0",
    "-0.0",
    "1e308",
    "-1e308",
    "1e-308",
    "5e-324",
    "1e150",
    "1e151",
    "nan",
    "inf",
    "-inf",
    "9223372036854775807",
    "-9223372036854775808",
    "4294967296",
    "1000000000",
    "\"\"",
    "\"../../x\"",
    "[]",
    "[1e308, -1e308, 0]",
    "{}",
    "true",
];

/// Bytes the byte-level mutation inserts: TOML and JSON structure, digits.
const INSERTED: &[u8] = b"[]{}=,.\"'#\n0123456789-e";

/// Number tokens of `text`: byte ranges of maximal runs of `[0-9.eE+-]` that start with a
/// digit or a sign followed by a digit.
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit()
            || ((b[i] == b'-' || b[i] == b'+') && b.get(i + 1).is_some_and(u8::is_ascii_digit));
        let boundary = i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if starts && boundary {
            let mut j = i + 1;
            while j < b.len() && (b[j].is_ascii_digit() || b".eE+-_".contains(&b[j])) {
                j += 1;
            }
            spans.push((i, j));
            i = j;
        } else {
            i += 1;
        }
    }
    spans
}

/// One mutation of `text`, chosen by `rng`; `donor` is another corpus text for splices.
fn mutate(text: &str, donor: &str, rng: &mut ChaCha8Rng) -> String {
    let lines: Vec<&str> = text.lines().collect();
    match rng.random_range(0..10) {
        // Token level: a number replaced by a nasty value or a scaled one.
        0..=3 => {
            let spans = number_spans(text);
            if spans.is_empty() {
                return text.to_string();
            }
            let (a, b) = spans[rng.random_range(0..spans.len())];
            let new = if rng.random_bool(0.7) {
                NASTY[rng.random_range(0..NASTY.len())].to_string()
            } else {
                let x: f64 = text[a..b].parse().unwrap_or(1.0);
                format!("{:e}", x * 10f64.powi(rng.random_range(-12..=12)))
            };
            format!("{}{new}{}", &text[..a], &text[b..])
        }
        // Line level: delete, duplicate, or swap lines.
        4 | 5 if !lines.is_empty() => {
            let mut l: Vec<&str> = lines.clone();
            let i = rng.random_range(0..l.len());
            match rng.random_range(0..3) {
                0 => {
                    l.remove(i);
                }
                1 => l.insert(i, lines[i]),
                _ => {
                    let j = rng.random_range(0..l.len());
                    l.swap(i, j);
                }
            }
            l.join("\n")
        }
        // Splice: a line of another corpus file inserted.
        6 => {
            let d: Vec<&str> = donor.lines().collect();
            if d.is_empty() || lines.is_empty() {
                return text.to_string();
            }
            let mut l = lines.clone();
            l.insert(
                rng.random_range(0..=l.len()),
                d[rng.random_range(0..d.len())],
            );
            l.join("\n")
        }
        // Byte level: flip, insert or delete bytes (kept valid UTF-8 by lossy conversion).
        _ => {
            let mut b = text.as_bytes().to_vec();
            for _ in 0..rng.random_range(1..4) {
                if b.is_empty() {
                    b.push(rng.random());
                    continue;
                }
                let i = rng.random_range(0..b.len());
                match rng.random_range(0..3) {
                    0 => b[i] = rng.random(),
                    1 => b.insert(i, INSERTED[rng.random_range(0..INSERTED.len())]),
                    _ => {
                        b.remove(i);
                    }
                }
            }
            String::from_utf8_lossy(&b).into_owned()
        }
    }
}

/// Input `i` of the stream `seed`: a corpus entry with 1–4 mutations.
fn input(corpus: &[(Kind, String)], seed: u64, i: u64) -> (Kind, String) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let (kind, base) = &corpus[rng.random_range(0..corpus.len())];
    let donor = &corpus[rng.random_range(0..corpus.len())].1;
    let mut text = base.clone();
    for _ in 0..rng.random_range(1..=4) {
        text = mutate(&text, donor, &mut rng);
    }
    (*kind, text)
}

/// Run one input through its parser and, when it parses, the code behind it.
fn exercise(kind: Kind, text: &str) {
    match kind {
        Kind::Design => {
            if let Ok(v) = parse_design(text, "fuzz.toml") {
                let mut ws = KinWorkspace::new(&v);
                forward_kinematics(&v, &vec![0.0; v.n_joints()], &mut ws);
                let t = thruster_matrix_owned(&v, &ws);
                let _ = usm_study::metrics::singularity::tcm_svd_metrics(&t, 1.0, 1e-6);
            }
        }
        Kind::Scenario => {
            if let Ok((t, src)) = usm_study::scenario::parse_text(text, "fuzz.toml") {
                if let Ok(f) = usm_study::scenario::parse_table(&t, &src) {
                    let _ = usm_study::scenario::resolve_design(&f, &src);
                }
            }
        }
        Kind::Problem => {
            let Ok(p) = parse_problem(text, Path::new("studies/fuzz.toml")) else {
                return;
            };
            let space = &p.spec.space;
            let n = space.dim();
            for u in [space.start(), vec![0.0; n], vec![1.0; n], vec![-1e308; n]] {
                let (u, _) = space.project(&u);
                let _ = space.values(&u);
            }
            let _ = p.spec.metrics();
        }
        Kind::Overrides => {
            let mut lines = text.lines();
            let preset = lines.next().unwrap_or_default();
            let Some(base) = usm_study::scenario::preset_text(preset) else {
                return;
            };
            let Ok((mut t, src)) = usm_study::scenario::parse_text(&base, "fuzz.toml") else {
                return;
            };
            for line in lines.take(8) {
                if let Ok((path, value)) = parse_override(line) {
                    let _ = set(&mut t, &path.0, value, line);
                }
            }
            if let Ok(f) = usm_study::scenario::parse_table(&t, &src) {
                let _ = usm_study::scenario::resolve_design(&f, &src);
            }
        }
        Kind::JournalRows => {
            // As `--resume` reads it: repaired (malformed rows dropped), then read typed.
            thread_local! {
                static DIR: tempfile::TempDir = tempfile::tempdir().unwrap();
            }
            DIR.with(|d| {
                let p = d.path().join("cases.partial.csv");
                std::fs::write(&p, text).unwrap();
                let schema = journal_schema();
                if usm_study::batch::journal::repair(&p, schema).is_ok() {
                    let _ = usm_study::report::read_csv_typed(&p, schema);
                }
            });
        }
        Kind::AllocationCase => {
            if let Ok(case) = parse_case(text) {
                let _ = solve_case(&case, &Method::ALL);
            }
        }
        Kind::Study => {
            let Ok(study) = parse_study(text, Path::new("studies/fuzz.toml")) else {
                return;
            };
            if case_count(&study) > 64 {
                return;
            }
            for case in expand(&study, None).unwrap_or_default().iter().take(2) {
                if let Ok(r) = resolve_case(&study, case) {
                    if let Ok(v) = parse_design_table(&r.design, "case") {
                        let _ = check_case(&v, &r.scenario);
                    }
                }
            }
        }
    }
}

fn env_u64(key: &str, default: u64) -> u64 {
    std::env::var(key)
        .ok()
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(default)
}

#[test]
fn no_input_panics_aborts_or_hangs() {
    let corpus = corpus();
    let n = env_u64("FUZZ_INPUTS", 20_000);
    let seed = env_u64("FUZZ_SEED", 0x5EED_0015);
    if let Ok(i) = std::env::var("FUZZ_ONLY") {
        let i: u64 = i.trim().parse().expect("FUZZ_ONLY=index");
        let (kind, text) = input(&corpus, seed, i);
        eprintln!("input {i} ({kind:?}):\n{text}");
        exercise(kind, &text);
        return;
    }
    let threads = env_u64("FUZZ_THREADS", 2).max(1) as usize;
    // Silence the default hook's output for caught panics; they are collected below.
    std::panic::set_hook(Box::new(|_| {}));
    let next = AtomicU64::new(0);
    let failures = Mutex::new(Vec::<String>::new());
    // Per worker: the input it is on and when it started it (ms since `t0`), for the watchdog.
    let t0 = Instant::now();
    let current: Vec<(AtomicU64, AtomicU64)> = (0..threads)
        .map(|_| (AtomicU64::new(u64::MAX), AtomicU64::new(0)))
        .collect();
    let done = AtomicUsize::new(0);
    std::thread::scope(|s| {
        let next = &next;
        for slot in &current {
            let (corpus, failures, done) = (&corpus, &failures, &done);
            s.spawn(move || loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= n {
                    slot.0.store(u64::MAX, Ordering::Relaxed);
                    done.fetch_add(1, Ordering::Relaxed);
                    return;
                }
                slot.1
                    .store(t0.elapsed().as_millis() as u64, Ordering::Relaxed);
                slot.0.store(i, Ordering::Relaxed);
                let (kind, text) = input(corpus, seed, i);
                if catch_unwind(AssertUnwindSafe(|| exercise(kind, &text))).is_err() {
                    failures
                        .lock()
                        .unwrap()
                        .push(format!("input {i} ({kind:?}) panicked"));
                }
            });
        }
        // The watchdog: an input without progress for HANG_S is a hang.
        let (corpus, current, done, failures) = (&corpus, &current, &done, &failures);
        s.spawn(move || {
            let mut last_report = Instant::now();
            while done.load(Ordering::Relaxed) < threads {
                std::thread::sleep(Duration::from_millis(200));
                let now = t0.elapsed().as_millis() as u64;
                for slot in current {
                    let i = slot.0.load(Ordering::Relaxed);
                    let since = slot.1.load(Ordering::Relaxed);
                    if i != u64::MAX && now.saturating_sub(since) > hang_s() * 1000 {
                        let (kind, text) = input(corpus, seed, i);
                        eprintln!("HANG: input {i} ({kind:?}) ran {} s:\n{text}", hang_s());
                        std::process::exit(3);
                    }
                }
                if last_report.elapsed() > Duration::from_secs(30) {
                    last_report = Instant::now();
                    // Failures so far too: a run cut short still says what it found.
                    eprintln!(
                        "[fuzz] {} of {n} inputs started, {:.0} s, {} failures so far",
                        next.load(Ordering::Relaxed).min(n),
                        t0.elapsed().as_secs_f64(),
                        failures.lock().map_or(0, |f| f.len())
                    );
                }
            }
        });
    });
    let _ = std::panic::take_hook();
    let failures = failures.into_inner().unwrap();
    eprintln!(
        "[fuzz] {n} inputs (seed {seed:#x}, {threads} threads) in {:.1} s: {} failures",
        t0.elapsed().as_secs_f64(),
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn mutations_are_deterministic_and_touch_numbers() {
    let corpus = corpus();
    assert!(corpus.len() >= 12, "{} corpus files", corpus.len());
    for kind in ["Problem", "Overrides", "Study", "Design", "Scenario"] {
        assert!(
            corpus.iter().any(|(k, _)| format!("{k:?}") == kind),
            "no {kind} input in the corpus"
        );
    }
    assert_eq!(input(&corpus, 1, 7).1, input(&corpus, 1, 7).1);
    assert_eq!(
        number_spans("a = 1.5e-3, b_2 = [-4, x7]"),
        [(4, 10), (19, 21)]
    );
}
