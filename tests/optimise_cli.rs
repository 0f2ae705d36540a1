//! `usm-study optimise` end to end: bad problem files exit 2 naming the file, the line and
//! the key before any evaluation (no output directory is made); a tiny problem writes every
//! output, and `simulate best.toml` reproduces the best objective to 1e-9 relative.

mod common;

use common::{arg, metric, run, stderr, summary, write};

/// A tiny problem: two transport gains, an 8 s run, five evaluations.
const TINY: &str = r#"[study]
name = "tiny"
seed = 1

[design]
preset = "usm-paper"

[scenario]
mode = "transport"
duration = 8.0

[allocation]
method = "pinv"
lambda = 0.1

[[param]]
name = "control.k_psi"
lower = 0.1
upper = 1.0
scale = "log"

[[param]]
name = "control.look_ahead"
lower = 0.5
upper = 6.0

[objective]
[[objective.term]]
metric = "thruster_energy"
weight = 1.0

[[objective.term]]
metric = "overshoot"
weight = 0.5

[[constraint]]
metric = "completed"
op = "=="
value = 1

[solver]
method = "nelder-mead"
max_evals = 5
"#;

/// `TINY` with the first line starting with `old` replaced by `new`, and that line's number.
fn edited(old: &str, new: &str) -> (String, usize) {
    let mut lines: Vec<&str> = TINY.lines().collect();
    let n = lines.iter().position(|l| l.starts_with(old)).expect(old);
    lines[n] = new;
    (lines.join("\n"), n + 1)
}

#[test]
fn bad_problem_files_exit_2_naming_file_line_and_key_before_any_evaluation() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        edited("name = \"control.k_psi\"", "name = \"control.k_spi\""),
        edited("metric = \"overshoot\"", "metric = \"overshot\""),
        edited("upper = 6.0", "upper = 0.2"),
        edited("lower = 0.1", "lower = 0.5"),
    ];
    let keys = [
        ("param[0].name", "unknown parameter"),
        ("objective.term[1].metric", "unknown metric"),
        ("param[1].upper", "needs lower < upper"),
        ("param[0].name", "outside [0.5, 1]"),
    ];
    for (i, ((text, line), (key, message))) in cases.iter().zip(keys).enumerate() {
        let p = write(dir.path(), &format!("bad{i}.toml"), text);
        let out_dir = dir.path().join(format!("out{i}"));
        let o = run(&["optimise", arg(&p), "--out", arg(&out_dir)]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{e}");
        let want_line = if key == "param[0].name" && message.starts_with("outside") {
            // The file's current value is outside the bounds: named at the parameter.
            TINY.lines()
                .position(|l| l.starts_with("name = \"control.k_psi\""))
                .unwrap()
                + 1
        } else {
            *line
        };
        assert!(
            e.contains(&format!("{}:{want_line}:", p.display())),
            "case {i}: line {want_line}: {e}"
        );
        assert!(e.contains(&format!(": {key}: ")), "case {i}: {e}");
        assert!(e.contains(message), "case {i}: {e}");
        assert!(
            !out_dir.exists(),
            "case {i}: nothing runs before the checks"
        );
    }
    // A start outside the bounds, and an empty parameter list.
    let text = TINY.replace("scale = \"log\"\n", "scale = \"log\"\nstart = 2.0\n");
    let p = write(dir.path(), "start.toml", &text);
    let e = stderr(&run(&[
        "optimise",
        arg(&p),
        "--out",
        arg(&dir.path().join("s")),
    ]));
    let n = text
        .lines()
        .position(|l| l.starts_with("start = 2.0"))
        .unwrap()
        + 1;
    assert!(
        e.contains(&format!("start.toml:{n}:")) && e.contains(": param[0].start: "),
        "{e}"
    );
    let start = TINY.find("[[param]]").unwrap();
    let end = TINY.find("[objective]").unwrap();
    let text = format!("{}{}", &TINY[..start], &TINY[end..]);
    let p = write(dir.path(), "empty.toml", &text);
    let o = run(&["optimise", arg(&p), "--out", arg(&dir.path().join("e"))]);
    let e = stderr(&o);
    let n = text
        .lines()
        .position(|l| l.starts_with("[objective]"))
        .unwrap()
        + 1;
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains(&format!("empty.toml:{n}:")) && e.contains(": param: "),
        "{e}"
    );
    assert!(e.contains("parameter list is empty"), "{e}");
}

#[test]
fn a_tiny_problem_writes_every_output_and_best_toml_reproduces_the_best_objective() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "tiny.toml", TINY);
    let out = dir.path().join("out");
    let o = run(&["optimise", arg(&p), "--out", arg(&out), "--jobs", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in [
        "history.csv",
        "history.parquet",
        "best.toml",
        "summary.md",
        "manifest.json",
        "progress.svg",
        "parameters.svg",
        "runs.svg",
        "journal.jsonl",
        "report.html",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    // Five recorded points within max_evals = 5: the start, Nelder–Mead's simplex (whose
    // first vertex repeats the start, served from memory but counted) and one step.
    assert_eq!(m["fresh_evaluations"], 4);
    let best = m["best"]["score"]["objective"].as_f64().unwrap();
    let scales: Vec<f64> = m["scales"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let sim = dir.path().join("sim");
    let o = run(&[
        "simulate",
        arg(&out.join("best.toml")),
        "--out",
        arg(&sim),
        "--no-plots",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = summary(&sim);
    let again =
        metric(&s, "thruster_energy") / scales[0] + 0.5 * metric(&s, "overshoot") / scales[1];
    assert!(
        ((again - best) / best).abs() <= 1e-9,
        "simulate: {again}, optimise: {best}"
    );
    // --resume of a finished run replays it without new evaluations and writes the same history.
    let before = std::fs::read(out.join("history.csv")).unwrap();
    let o = run(&[
        "optimise",
        arg(&p),
        "--out",
        arg(&out),
        "--resume",
        "--no-plots",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("4 replayed"));
    assert_eq!(before, std::fs::read(out.join("history.csv")).unwrap());
}
