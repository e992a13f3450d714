//! The `ressort` binary as a user runs it: exit codes, diagnostics format, WAV output, bench line.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const STRING_1000: &str = "\
# 1000-mass string (canonical definition, spec §7.10)
@K param 0.1
@Z param 0.001
@s string 1002 1. K Z 0. 0.
@gh ground 0.1
@h mass 1. 0.1 0.
@sh springDamper @gh @h 0.0001 0.05
@hit contact [@s 0.13] @h 0.1 0.001
@in1 frcInput @h
@out1 posOutput [@s 0.77]
";

fn ressort(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ressort"))
        .args(args)
        .output()
        .expect("run ressort")
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn check_valid_model_prints_summary_and_exits_0() {
    let dir = tempfile::tempdir().unwrap();
    let model = write(dir.path(), "s.mdl", STRING_1000);
    let out = ressort(&["check", model.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.contains("points        1004"), "{stdout}");
    assert!(stdout.contains("interactions  1003"), "{stdout}");
    assert!(stdout.contains("stable"), "{stdout}");
}

#[test]
fn check_reports_errors_with_file_line_col_and_exits_1() {
    let dir = tempfile::tempdir().unwrap();
    let model = write(
        dir.path(),
        "bad.mdl",
        "@o osc 1. 0.1 0.0003 0. 0.\n@sp springDamper @o @nowhere 0.1 0.1\n@out1 posOutput @o\n",
    );
    let out = ressort(&["check", model.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = text(&out.stderr);
    let expected = format!("{}:2:21: error:", model.display());
    assert!(stderr.contains(&expected), "{stderr}");
    assert!(stderr.contains("nowhere"), "{stderr}");
}

#[test]
fn check_reports_stability_warnings_at_the_element_line() {
    let dir = tempfile::tempdir().unwrap();
    let model = write(
        dir.path(),
        "u.mdl",
        "@K param 5\n@o osc 1. K 0. 0. 0.\n@out1 posOutput @o\n",
    );
    let out = ressort(&["check", model.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "a stability warning is not an error"
    );
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains(&format!("{}:2:1: warning:", model.display())),
        "{stderr}"
    );
    assert!(text(&out.stdout).contains("UNSTABLE"));
}

#[test]
fn check_reports_link_warnings_at_the_interaction_line() {
    let dir = tempfile::tempdir().unwrap();
    // The unbounded spring is on line 4, its endpoints on lines 1 and 2.
    let model = write(
        dir.path(),
        "n.mdl",
        "@g ground 0.\n@m mass 1. 0. 0.\n# a spring that stiffens without bound\n\
         @n3 nlSpring3 @g @m 0.1 2. 0.\n@out1 posOutput @m\n",
    );
    let out = ressort(&["check", model.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "a warning is not an error");
    let stderr = text(&out.stderr);
    let expected = format!(
        "{}:4:1: warning: @n3: @g–m: nlSpring3 has no",
        model.display()
    );
    assert!(stderr.contains(&expected), "{stderr}");
}

#[test]
fn usage_and_io_errors_exit_2() {
    assert_eq!(
        ressort(&["check", "/nonexistent/model.mdl"]).status.code(),
        Some(2)
    );
    assert_eq!(ressort(&["frobnicate"]).status.code(), Some(2));
    let dir = tempfile::tempdir().unwrap();
    let model = write(dir.path(), "s.mdl", STRING_1000);
    let m = model.to_str().unwrap();
    let wav = dir.path().join("o.wav");
    let w = wav.to_str().unwrap();
    for args in [
        vec!["render", m, "-o", w, "--sample-rate", "0"],
        vec!["render", m, "-o", w, "--impulse", "in7=1"],
        vec!["render", m, "-o", w, "--set", "nope=1"],
        vec!["render", m, "-o", w, "--set", "K=abc"],
        vec!["render", m, "-o", w, "--input", "in1=/nonexistent.wav"],
        vec!["render", m, "-o", w, "--seconds", "-1"],
    ] {
        let out = ressort(&args);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?}: {}",
            text(&out.stderr)
        );
        assert!(text(&out.stderr).starts_with("ressort: "), "{args:?}");
    }
}

#[test]
fn render_writes_one_float_channel_per_output() {
    let dir = tempfile::tempdir().unwrap();
    let model = write(dir.path(), "s.mdl", STRING_1000);
    let wav = dir.path().join("o.wav");
    let out = ressort(&[
        "render",
        model.to_str().unwrap(),
        "-o",
        wav.to_str().unwrap(),
        "--sample-rate",
        "48000",
        "--samples",
        "9600",
        "--impulse",
        "in1=-0.01",
        "--set",
        "K=0.2",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let reader = hound::WavReader::open(&wav).unwrap();
    let spec = reader.spec();
    assert_eq!(spec.channels, 1);
    assert_eq!(spec.sample_rate, 48_000);
    assert_eq!(spec.bits_per_sample, 32);
    assert_eq!(spec.sample_format, hound::SampleFormat::Float);
    let samples: Vec<f32> = reader.into_samples().map(Result::unwrap).collect();
    assert_eq!(samples.len(), 9600);
    assert!(samples.iter().all(|v| v.is_finite()));
    assert!(
        samples.iter().any(|v| v.abs() > 1e-5),
        "the struck string is silent"
    );

    // Without the impulse the model stays at rest.
    let quiet = dir.path().join("q.wav");
    let out = ressort(&[
        "render",
        model.to_str().unwrap(),
        "-o",
        quiet.to_str().unwrap(),
        "--samples",
        "1000",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let r = hound::WavReader::open(&quiet).unwrap();
    assert!(r.into_samples::<f32>().all(|v| v.unwrap() == 0.0));
}

#[test]
fn render_holds_unfed_position_inputs_where_the_script_puts_them() {
    // A finger resting on a mass through a damper: pulled to 0, it would kick the mass.
    let dir = tempfile::tempdir().unwrap();
    let model = write(
        dir.path(),
        "p.mdl",
        "@m mass 1. 0. 0.\n@in1 posInput 1.\n@d damper @m @in1 0.1\n@out1 posOutput @m\n",
    );
    let out = dir.path().join("p.wav");
    let m = model.to_str().unwrap();
    let render = |extra: &[&str]| -> Vec<f32> {
        let mut args = vec!["render", m, "-o", out.to_str().unwrap(), "--samples", "500"];
        args.extend_from_slice(extra);
        assert!(ressort(&args).status.success());
        hound::WavReader::open(&out)
            .unwrap()
            .into_samples()
            .map(Result::unwrap)
            .collect()
    };
    let held = render(&[]);
    assert!(
        held.iter().all(|&v| v == 0.0),
        "an unfed avatar moved the mass"
    );
    // A fed input still drives it: an impulse feeds 0 after its first sample.
    let fed = render(&["--impulse", "in1=1"]);
    assert!(fed.iter().any(|&v| v != 0.0));
}

#[test]
fn render_feeds_wav_inputs() {
    // A force signal from a file drives the hammer like the impulse does.
    let dir = tempfile::tempdir().unwrap();
    let model = write(dir.path(), "s.mdl", STRING_1000);
    let force = dir.path().join("f.wav");
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: 44_100,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let mut w = hound::WavWriter::create(&force, spec).unwrap();
    w.write_sample(-0.01f32).unwrap();
    for _ in 0..99 {
        w.write_sample(0.0f32).unwrap();
    }
    w.finalize().unwrap();
    let a = dir.path().join("a.wav");
    let b = dir.path().join("b.wav");
    let m = model.to_str().unwrap();
    let input = format!("in1={}", force.display());
    assert!(ressort(&[
        "render",
        m,
        "-o",
        a.to_str().unwrap(),
        "--samples",
        "4000",
        "--input",
        &input
    ])
    .status
    .success());
    assert!(ressort(&[
        "render",
        m,
        "-o",
        b.to_str().unwrap(),
        "--samples",
        "4000",
        "--impulse",
        "in1=-0.01"
    ])
    .status
    .success());
    let read = |p: &Path| -> Vec<f32> {
        hound::WavReader::open(p)
            .unwrap()
            .into_samples()
            .map(Result::unwrap)
            .collect()
    };
    // −0.01 as f32 then widened differs slightly from the f64 literal; compare closely.
    let (x, y) = (read(&a), read(&b));
    let peak = y.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    assert!(peak > 1e-5);
    for (p, q) in x.iter().zip(&y) {
        assert!((p - q).abs() <= 1e-5 * peak, "{p} vs {q}");
    }
}

/// A small model runs on native code, which `--no-jit` turns off; `check` says which.
#[test]
fn a_small_model_runs_on_native_code() {
    let dir = tempfile::tempdir().unwrap();
    let model = write(
        dir.path(),
        "osc.mdl",
        "@g ground 0.\n@m mass 1. 0. 0.\n@l springDamper @g @m 0.01 0.0001\n\
         @in1 frcInput @m\n@out1 posOutput @m\n",
    );
    let path = model.to_str().unwrap();
    let native_bytes = |extra: &[&str]| {
        let mut args = vec!["bench", path, "--seconds", "0.05"];
        args.extend_from_slice(extra);
        let out = ressort(&args);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        let stdout = text(&out.stdout);
        let last = stdout.lines().last().unwrap().to_string();
        let bytes = last.rsplit_once("native_bytes=").unwrap().1.to_string();
        bytes.parse::<usize>().unwrap()
    };
    assert!(native_bytes(&[]) > 0);
    assert_eq!(native_bytes(&["--no-jit"]), 0);
    let out = ressort(&["check", path]);
    let stdout = text(&out.stdout);
    assert!(stdout.contains("sample loop   native code, "), "{stdout}");
    let out = ressort(&[
        "check",
        &write(dir.path(), "s.mdl", STRING_1000).to_string_lossy(),
    ]);
    assert!(text(&out.stdout).contains("sample loop   interpreter"));
}

#[test]
fn bench_ends_with_the_machine_readable_line() {
    let dir = tempfile::tempdir().unwrap();
    let model = write(dir.path(), "s.mdl", STRING_1000);
    let out = ressort(&["bench", model.to_str().unwrap(), "--seconds", "0.05"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let last = stdout.lines().last().unwrap();
    let fields: Vec<(&str, &str)> = last
        .split(' ')
        .map(|kv| kv.split_once('=').unwrap())
        .collect();
    let keys: Vec<&str> = fields.iter().map(|f| f.0).collect();
    assert_eq!(
        keys,
        [
            "ns_per_sample",
            "realtime_factor",
            "points",
            "interactions",
            "compile_ms",
            "mean_ns",
            "native_bytes"
        ]
    );
    for (k, v) in &fields[..6] {
        let x: f64 = v
            .parse()
            .unwrap_or_else(|_| panic!("{k}={v} is not a number"));
        assert!(x.is_finite() && x > 0.0, "{k}={v}");
    }
    assert_eq!(fields[2].1, "1004");
    assert_eq!(fields[3].1, "1003");
    // The 1000-mass string runs on the interpreter.
    assert_eq!(fields[6].1, "0");
}

const STRING_10: &str = "\
@K param 0.2
@s string 12 1. K 0. 0. 0.
@in1 frcInput [@s 0.3]
@out1 posOutput [@s 0.7]
";

/// f_k = SR/π·asin(√(K/M)·sin(kπ/2(N+1))) (spec §5.3).
fn string_mode(k: f64, n: f64, k_over_m: f64, sr: f64) -> f64 {
    sr / std::f64::consts::PI
        * (k_over_m.sqrt() * (k * std::f64::consts::PI / (2.0 * (n + 1.0))).sin()).asin()
}

#[test]
fn modes_prints_the_closed_form_frequencies_and_csv() {
    let dir = tempfile::tempdir().unwrap();
    let model = write(dir.path(), "s.mdl", STRING_10);
    let out = ressort(&["modes", model.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.contains("10 moving masses"), "{stdout}");
    assert!(stdout.contains("in1→out1"), "{stdout}");
    assert!(stdout.contains("stiffness gain limit"), "{stdout}");
    let f1 = format!("{:.4}", string_mode(1.0, 10.0, 0.2, 44_100.0));
    assert!(stdout.contains(&f1), "{f1} not in\n{stdout}");

    let out = ressort(&["modes", model.to_str().unwrap(), "--csv", "--count", "3"]);
    assert_eq!(out.status.code(), Some(0));
    let csv = text(&out.stdout);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "mode,frequency_hz,note,cents,t60_s,gain_in1_out1");
    assert_eq!(lines.len(), 4);
    let f3: f64 = lines[3].split(',').nth(1).unwrap().parse().unwrap();
    assert!((f3 - string_mode(3.0, 10.0, 0.2, 44_100.0)).abs() < 1e-4);
}

#[test]
fn tune_finds_the_param_value_and_the_gain() {
    let dir = tempfile::tempdir().unwrap();
    let model = write(dir.path(), "s.mdl", STRING_10);
    let out = ressort(&[
        "tune",
        model.to_str().unwrap(),
        "--mode",
        "2",
        "--to",
        "A4",
        "--param",
        "K",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.contains(":1: @K param 0.2"), "{stdout}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("change to: @K param "))
        .unwrap_or_else(|| panic!("{stdout}"));
    let k: f64 = line.rsplit(' ').next().unwrap().parse().unwrap();
    // sin²(π·440/SR) = (K/M)·sin²(2π/22): K exactly.
    let s = (2.0 * std::f64::consts::PI / 22.0).sin();
    let expect = ((std::f64::consts::PI * 440.0 / 44_100.0).sin() / s).powi(2);
    assert!((k - expect).abs() < 1e-7 * expect, "{k} vs {expect}");
    // The tuned model's mode 2 is on A4.
    let tuned = write(
        dir.path(),
        "t.mdl",
        &STRING_10.replace("0.2", &k.to_string()),
    );
    let out = ressort(&["modes", tuned.to_str().unwrap(), "--csv"]);
    let csv = text(&out.stdout);
    let f2: f64 = csv
        .lines()
        .nth(2)
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    assert!((f2 - 440.0).abs() < 1e-5, "{f2}");

    // Without --param: the K-class gain, λ_target/λ.
    let out = ressort(&[
        "tune",
        model.to_str().unwrap(),
        "--mode",
        "1",
        "--to",
        "100Hz",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let f1 = string_mode(1.0, 10.0, 0.2, 44_100.0);
    let c = ((std::f64::consts::PI * 100.0 / 44_100.0).sin()
        / (std::f64::consts::PI * f1 / 44_100.0).sin())
    .powi(2);
    let shown: f64 = stdout
        .split("K-class gain ×")
        .nth(1)
        .and_then(|t| t.split(',').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!((shown - c).abs() < 1e-7 * c, "{shown} vs {c}");

    let out = ressort(&["tune", model.to_str().unwrap(), "--mode", "1", "--to", "H9"]);
    assert_eq!(out.status.code(), Some(2));
}

/// The `ressort modes` and `ressort tune` examples of the language guide's "Tuning by maths"
/// are what the commands print.
#[test]
fn tuning_by_maths_examples_are_real() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let guide = std::fs::read_to_string(root.join("docs/LANGUAGE.md")).unwrap();
    let section = guide
        .split("## 18. Tuning by maths")
        .nth(1)
        .expect("the guide has a Tuning by maths section");
    let mut checked = 0;
    let mut parts = section.split("```sh\n").skip(1);
    for part in parts.by_ref() {
        let (command, rest) = part.split_once("```\n").unwrap();
        let shown = rest
            .trim_start()
            .strip_prefix("```text\n")
            .and_then(|t| t.split_once("```\n"))
            .map(|(t, _)| t)
            .expect("a text block after the command");
        let args: Vec<&str> = command.split_whitespace().skip(1).collect();
        let out = Command::new(env!("CARGO_BIN_EXE_ressort"))
            .args(&args)
            .current_dir(&root)
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{command}: {}",
            text(&out.stderr)
        );
        assert_eq!(text(&out.stdout), shown, "{command}");
        checked += 1;
    }
    assert!(checked >= 2);
}

/// docs/LANGUAGE.md §18 shows `ressort modes` on the 15 × 15 mesh preset: the command prints
/// what the guide says (the gains of a repeated pair split by the solver's basis, so only
/// their frequencies and decays are compared).
#[test]
fn the_guides_modes_table_is_what_the_command_prints() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let guide = std::fs::read_to_string(root.join("docs/LANGUAGE.md")).unwrap();
    let command = "ressort modes models/mesh-15x15.mdl --count 8\n```\n\n```text\n";
    let start = guide.find(command).expect("the example in §18") + command.len();
    let shown = &guide[start..start + guide[start..].find("```").unwrap()];
    let out = Command::new(env!("CARGO_BIN_EXE_ressort"))
        .current_dir(&root)
        .args(["modes", "models/mesh-15x15.mdl", "--count", "8"])
        .output()
        .expect("run ressort");
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let printed = text(&out.stdout);
    assert_eq!(printed.lines().count(), shown.lines().count(), "{printed}");
    for (p, s) in printed.lines().zip(shown.lines()) {
        let paired = s.trim_start().starts_with("3 ") || s.trim_start().starts_with("4 ");
        if paired {
            let fields = |l: &str| l.split_whitespace().take(5).collect::<Vec<_>>().join(" ");
            assert_eq!(fields(p), fields(s));
        } else {
            assert_eq!(p, s);
        }
    }
}

#[test]
fn bench_sweep_prints_steady_and_swept_costs() {
    let dir = tempfile::tempdir().unwrap();
    let model = write(dir.path(), "s.mdl", STRING_1000);
    let out = ressort(&[
        "bench",
        model.to_str().unwrap(),
        "--seconds",
        "0.05",
        "--sweep",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let fields: Vec<(&str, f64)> = stdout
        .lines()
        .last()
        .unwrap()
        .split(' ')
        .map(|kv| {
            let (k, v) = kv.split_once('=').unwrap();
            (k, v.trim_end_matches('x').parse().unwrap())
        })
        .collect();
    let keys: Vec<&str> = fields.iter().map(|f| f.0).collect();
    assert_eq!(
        keys,
        [
            "steady_ns_per_sample",
            "sweep_ns_per_sample",
            "sweep_cost",
            "points",
            "interactions",
            "compile_ms"
        ]
    );
    assert!(
        fields.iter().all(|f| f.1.is_finite() && f.1 > 0.0),
        "{stdout}"
    );
    let ratio = fields[1].1 / fields[0].1;
    assert!((fields[2].1 - ratio).abs() < 1e-2 * ratio, "{stdout}");
    // With voices: the bank under a Stiffness sweep, marked on its last line.
    let out = ressort(&[
        "bench",
        model.to_str().unwrap(),
        "--seconds",
        "0.05",
        "--sweep",
        "--voices",
        "2",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let last = text(&out.stdout).lines().last().unwrap().to_string();
    assert!(last.ends_with("voices=2 sweep=1"), "{last}");
}

/// `ressort modes … | head -1`: the command ends by the broken pipe's signal, quietly, where it
/// used to panic in `println!` with a backtrace.
#[cfg(unix)]
#[test]
fn a_reader_that_stops_early_ends_the_command_quietly() {
    use std::io::{BufRead, BufReader};
    use std::os::unix::process::ExitStatusExt;
    use std::process::Stdio;
    let dir = std::env::temp_dir().join(format!("ressort-cli-pipe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = write(&dir, "string.mdl", STRING_1000);
    let mut child = Command::new(env!("CARGO_BIN_EXE_ressort"))
        .args(["modes", model.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run ressort");
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.contains("moving masses"), "{first}");
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.signal(), Some(libc::SIGPIPE), "{:?}", out.status);
    let _ = std::fs::remove_dir_all(&dir);
}
