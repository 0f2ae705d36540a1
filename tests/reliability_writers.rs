//! Issue 39 item 1: one writer for every file any verb writes. Every verb's outputs are
//! learnt from a clean run; then each output name is planted with a symbolic link leading out
//! of the folder (to a user's file) or a dangling one (to a name outside), each output folder
//! (`plots/`, a paper's run folder) with a link to a folder outside, and the verb is run again:
//! nothing outside the output may be written or created, whatever the verb does (replace the
//! link with its own file, or refuse with exit 2). A temporary file of a killed run (a real
//! `tcm` killed with SIGKILL, and a planted one of a dead process) is removed by the next run of
//! any verb on that folder.

mod common;

use std::path::{Path, PathBuf};

use common::{read, run, stderr, write, QUICK};

const SCENARIO: &str = r#"[scenario]
name = "w"
mode = "transport"
design = "usm-paper"
duration = 3.0

[path]
segments = [ { from = [0.0, 0.0], to = [200.0, 0.0] } ]

[uncertainty]
worlds = 2
[[uncertainty.param]]
name = "hydro.linear_damping_scale"
distribution = { kind = "uniform", low = 0.5, high = 1.5 }
"#;

const PROBLEM: &str = r#"[study]
name = "tiny"
seed = 1

[design]
preset = "usm-paper"

[scenario]
mode = "transport"
duration = 3.0

[[param]]
name = "control.look_ahead"
lower = 0.5
upper = 6.0

[objective]
[[objective.term]]
metric = "thruster_energy"
weight = 1.0

[solver]
method = "nelder-mead"
max_evals = 3
"#;

const OCP: &str = r#"design = "DESIGN"
[horizon]
duration = 1.0
knots = 8
[terminal]
ee_displacement = [0.0, 0.01, -0.01]
[bounds]
base_force = 5.0
base_moment = 5.0
joint_torque = 5.0
"#;

/// Every entry under `dir` (links not followed) with its kind and, for files, its bytes.
fn snapshot(dir: &Path) -> Vec<(String, String)> {
    let mut v = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            let ft = e.file_type().unwrap();
            let rel = p.strip_prefix(dir).unwrap().display().to_string();
            let what = if ft.is_dir() {
                stack.push(p.clone());
                "dir".to_string()
            } else if ft.is_symlink() {
                format!("link {}", std::fs::read_link(&p).unwrap().display())
            } else {
                String::from_utf8_lossy(&read(&p)).into_owned()
            };
            v.push((rel, what));
        }
    }
    v.sort();
    v
}

/// Relative paths of the regular files and of the folders under `dir`.
fn outputs(dir: &Path) -> (Vec<PathBuf>, Vec<PathBuf>) {
    let (mut files, mut dirs) = (Vec::new(), Vec::new());
    for (rel, what) in snapshot(dir) {
        if what == "dir" {
            dirs.push(PathBuf::from(rel));
        } else if !rel.starts_with('.') && !rel.contains("/.") {
            files.push(PathBuf::from(rel));
        }
    }
    (files, dirs)
}

/// A pid that no longer exists (a finished child's).
fn dead_pid() -> u32 {
    let mut c = std::process::Command::new("true").spawn().unwrap();
    let pid = c.id();
    c.wait().unwrap();
    pid
}

/// One verb: its arguments with `OUT` standing for the output folder, and how to make that
/// folder ready before the verb runs (`report` needs a finished output in it).
struct Verb {
    name: &'static str,
    args: Vec<String>,
    setup: Option<Vec<String>>,
}

fn verbs(d: &Path) -> Vec<Verb> {
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let study = write(d, "quick.toml", QUICK);
    let scenario = write(d, "worlds.toml", SCENARIO);
    let problem = write(d, "tiny.toml", PROBLEM);
    let design = std::fs::canonicalize("studies/designs/rigid_chain5.toml").unwrap();
    let ocp = write(
        d,
        "ocp.toml",
        &OCP.replace("DESIGN", design.to_str().unwrap()),
    );
    let p = |x: &Path| x.to_str().unwrap().to_string();
    let mut shards = Vec::new();
    for i in 0..2 {
        let o = d.join(format!("shard{i}"));
        let r = common::sweep(&study, &o, &["--shard", &format!("{i}/2")]);
        assert_eq!(r.status.code(), Some(0), "{}", stderr(&r));
        shards.push(p(&o));
    }
    let study_path = p(&study);
    let sweep = ["sweep", &study_path, "--out", "OUT"];
    vec![
        Verb {
            name: "simulate",
            args: s(&["simulate", &p(&scenario), "--out", "OUT"]),
            setup: None,
        },
        Verb {
            name: "sweep",
            args: s(&sweep),
            setup: None,
        },
        Verb {
            name: "report",
            args: s(&["report", "OUT"]),
            setup: Some(s(&sweep)),
        },
        Verb {
            name: "merge",
            args: s(&["merge", &shards[0], &shards[1], "--out", "OUT"]),
            setup: None,
        },
        Verb {
            name: "optimise",
            args: s(&["optimise", &p(&problem), "--out", "OUT"]),
            setup: None,
        },
        Verb {
            name: "tcm",
            args: s(&[
                "tcm",
                "usm-paper",
                "--out",
                "OUT",
                "--samples",
                "64",
                "--resolution",
                "5",
            ]),
            setup: None,
        },
        Verb {
            name: "paper drag",
            args: s(&["paper", "drag", "--out", "OUT"]),
            setup: None,
        },
        Verb {
            name: "design draw",
            args: s(&["design", "draw", "usm-paper", "--out", "OUT/drawing.svg"]),
            setup: None,
        },
        Verb {
            name: "ocp",
            args: s(&["ocp", &p(&ocp), "--out", "OUT"]),
            setup: None,
        },
    ]
}

fn run_in(args: &[String], out: &Path) -> std::process::Output {
    let a: Vec<String> = args
        .iter()
        .map(|x| x.replace("OUT", out.to_str().unwrap()))
        .collect();
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    run(&a)
}

/// Run `v` into `out` after `plant` prepared it; the outside folder must be unchanged.
fn check_planted(v: &Verb, out: &Path, outside: &Path, plant: &dyn Fn(&Path)) {
    std::fs::create_dir_all(out).unwrap();
    if let Some(setup) = &v.setup {
        let o = run_in(setup, out);
        assert_eq!(o.status.code(), Some(0), "{}: {}", v.name, stderr(&o));
    }
    plant(out);
    let before = snapshot(outside);
    let o = run_in(&v.args, out);
    let code = o.status.code();
    assert!(
        matches!(code, Some(0) | Some(2)),
        "{}: exit {code:?}: {}",
        v.name,
        stderr(&o)
    );
    assert_eq!(
        snapshot(outside),
        before,
        "{} wrote outside its output {} (exit {code:?}: {})",
        v.name,
        out.display(),
        stderr(&o)
    );
}

#[test]
fn no_verb_writes_through_a_planted_or_dangling_link() {
    let d = tempfile::tempdir().unwrap();
    let outside = d.path().join("outside");
    std::fs::create_dir(&outside).unwrap();
    for (k, v) in verbs(d.path()).iter().enumerate() {
        let clean = d.path().join(format!("clean{k}"));
        std::fs::create_dir_all(&clean).unwrap();
        if let Some(setup) = &v.setup {
            assert_eq!(run_in(setup, &clean).status.code(), Some(0));
        }
        let o = run_in(&v.args, &clean);
        assert_eq!(o.status.code(), Some(0), "{}: {}", v.name, stderr(&o));
        let (files, dirs) = outputs(&clean);
        assert!(!files.is_empty(), "{}", v.name);
        // Every output file a link: to a user's file outside, or dangling to a name outside.
        let victims = outside.join(format!("files{k}"));
        std::fs::create_dir(&victims).unwrap();
        let plant_files = |out: &Path| {
            for dir in &dirs {
                std::fs::create_dir_all(out.join(dir)).unwrap();
            }
            for (i, f) in files.iter().enumerate() {
                let at = out.join(f);
                let _ = std::fs::remove_file(&at);
                let target = victims.join(format!("f{i}"));
                if i % 2 == 0 {
                    std::fs::write(&target, "mine").unwrap();
                }
                std::os::unix::fs::symlink(&target, &at).unwrap();
            }
        };
        check_planted(
            v,
            &d.path().join(format!("files{k}")),
            &outside,
            &plant_files,
        );
        // The same with the files dangling where the others pointed at a user's file.
        let victims2 = outside.join(format!("files{k}b"));
        std::fs::create_dir(&victims2).unwrap();
        let plant_files2 = |out: &Path| {
            for dir in &dirs {
                std::fs::create_dir_all(out.join(dir)).unwrap();
            }
            for (i, f) in files.iter().enumerate() {
                let target = victims2.join(format!("f{i}"));
                if i % 2 == 1 {
                    std::fs::write(&target, "mine").unwrap();
                }
                let _ = std::fs::remove_file(out.join(f));
                std::os::unix::fs::symlink(&target, out.join(f)).unwrap();
            }
        };
        check_planted(
            v,
            &d.path().join(format!("filesb{k}")),
            &outside,
            &plant_files2,
        );
        // Every output folder a link to a folder outside (holding a user's file) or dangling.
        for (j, dir) in dirs.iter().enumerate() {
            for dangling in [false, true] {
                let target = outside.join(format!("dir{k}_{j}_{dangling}"));
                if !dangling {
                    std::fs::create_dir(&target).unwrap();
                    std::fs::write(target.join("mine.txt"), "mine").unwrap();
                }
                let plant_dir = |out: &Path| {
                    let at = out.join(dir);
                    if at.is_dir() && !at.is_symlink() {
                        std::fs::remove_dir_all(&at).unwrap();
                    }
                    std::fs::create_dir_all(at.parent().unwrap()).unwrap();
                    std::os::unix::fs::symlink(&target, &at).unwrap();
                };
                let out = d.path().join(format!("dirs{k}_{j}_{dangling}"));
                check_planted(v, &out, &outside, &plant_dir);
            }
        }
    }
}

#[test]
fn the_temporaries_of_a_killed_run_are_removed_by_the_next_run_of_any_verb() {
    let d = tempfile::tempdir().unwrap();
    let verbs = verbs(d.path());
    // A real `tcm` killed while it streams its samples leaves `.samples.csv.tmp-PID-HEX`.
    let out = d.path().join("t");
    let mut child = common::usm_study()
        .args(["tcm", "usm-paper", "--out", out.to_str().unwrap()])
        .args(["--samples", "40000000", "--jobs", "1"])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let tmp = loop {
        let found = std::fs::read_dir(&out)
            .into_iter()
            .flatten()
            .flatten()
            .find(|e| {
                let n = e.file_name().to_string_lossy().to_string();
                n.starts_with(".samples.csv.tmp-") && e.metadata().is_ok_and(|m| m.len() > 0)
            });
        if let Some(e) = found {
            break e.path();
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "tcm ended before writing"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(tmp.exists());
    for v in &verbs {
        let out = d.path().join(format!("v_{}", v.name.replace(' ', "_")));
        std::fs::create_dir_all(out.join("plots")).unwrap();
        if let Some(setup) = &v.setup {
            assert_eq!(run_in(setup, &out).status.code(), Some(0));
        }
        // The killed tcm's own file, and one of another dead process in plots/.
        std::fs::copy(&tmp, out.join(tmp.file_name().unwrap())).unwrap();
        let other = out.join(format!("plots/.x.svg.tmp-{}-ab", dead_pid()));
        std::fs::write(&other, "x").unwrap();
        std::fs::write(out.join("notes.tmp"), "mine").unwrap();
        let o = run_in(&v.args, &out);
        assert_eq!(o.status.code(), Some(0), "{}: {}", v.name, stderr(&o));
        assert!(
            !out.join(tmp.file_name().unwrap()).exists() && !other.exists(),
            "{} left a killed run's temporaries",
            v.name
        );
        assert_eq!(read(&out.join("notes.tmp")), b"mine");
    }
    // And tcm itself on the folder it was killed in.
    let o = run_in(&verbs[5].args, &out);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!tmp.exists());
}
