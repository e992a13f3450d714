//! `ressort modes` and `ressort render --as-plugin` on scripts with extreme values: they end
//! without a panic (issue 40, analyses that always end).

use std::process::Command;

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn read_wav(path: &std::path::Path) -> Vec<Vec<f32>> {
    let mut r = hound::WavReader::open(path).unwrap();
    let n = r.spec().channels as usize;
    let all: Vec<f32> = r.samples::<f32>().map(Result::unwrap).collect();
    (0..n)
        .map(|c| all.iter().skip(c).step_by(n).copied().collect())
        .collect()
}

/// The two scripts that froze a host's state load and panicked inside faer (issue 40): Fretted
/// String with its osc's damping at 10³⁰⁸, and with a link's damping at 0 besides. `ressort
/// modes` and `render --as-plugin` end on both, each within [`EXTREME_LIMIT_S`], without a
/// panic, and the render is finite.
#[test]
fn the_scripts_that_froze_a_host_end_in_modes_and_render() {
    const EXTREME_LIMIT_S: f64 = 120.0;
    let preset = include_str!("../../models/fretted-string.mdl");
    let huge = preset.replace(
        "@low_m60 osc low_M 0 low_Zosc 0. 0.",
        "@low_m60 osc low_M 0 1e308 0. 0.",
    );
    let both = huge.replace(
        "@low_r37 springDamper @low_m35 @low_m36 low_K low_Z",
        "@low_r37 springDamper @low_m35 @low_m36 low_K 0",
    );
    assert!(
        huge != preset && both != huge,
        "the preset still has the lines this test edits"
    );
    let dir = tempfile::tempdir().unwrap();
    let mut longest = 0.0f64;
    for (i, script) in [huge, both].iter().enumerate() {
        let model = dir.path().join(format!("fretted-{i}.mdl"));
        let out = dir.path().join(format!("fretted-{i}.wav"));
        std::fs::write(&model, script).unwrap();
        let m = model.to_str().unwrap();
        for args in [
            vec!["modes", m, "--count", "10"],
            vec![
                "render",
                m,
                "--as-plugin",
                "--seconds",
                "0.3",
                "--note",
                "60",
                "-o",
                out.to_str().unwrap(),
            ],
        ] {
            let start = std::time::Instant::now();
            let mut child = Command::new(env!("CARGO_BIN_EXE_ressort"))
                .args(&args)
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("run ressort");
            let status = loop {
                if let Some(status) = child.try_wait().unwrap() {
                    break status;
                }
                if start.elapsed().as_secs_f64() > EXTREME_LIMIT_S {
                    let _ = child.kill();
                    panic!(
                        "`ressort {}` on variant {i} still runs after {EXTREME_LIMIT_S} s",
                        args[0]
                    );
                }
                std::thread::sleep(std::time::Duration::from_millis(20));
            };
            let output = child.wait_with_output().unwrap();
            let stderr = text(&output.stderr);
            assert!(
                !stderr.contains("panicked"),
                "`ressort {}` panicked: {stderr}",
                args[0]
            );
            assert!(
                status.success(),
                "`ressort {}` on variant {i}: {stderr}",
                args[0]
            );
            longest = longest.max(start.elapsed().as_secs_f64());
        }
        let wav = read_wav(&out);
        assert!(
            wav.iter().flatten().all(|s| s.is_finite()),
            "variant {i} renders finite"
        );
    }
    println!("both variants end in `modes` and `render --as-plugin`; longest {longest:.2} s");
}
