//! Extreme values through a host's state load (issue 40, analyses that always end): every
//! preset up to 200 points with all its `param`s at 10³⁰⁸, −10³⁰⁸, 10⁻³⁰⁸, 0 and 10³⁰, and the
//! two Fretted String scripts that once froze a VST3 host's state load and panicked inside
//! faer, each loaded into one running instance. Every load returns (a hang fails the run
//! after [`LOAD_LIMIT_S`]), nothing panics, and the instance keeps playing finite samples
//! within the ceiling. Prints the case count and the longest load.

use ressort_tests::presets::presets;
use ressort_tests::{state, Score, TestPlugin};
use std::time::Instant;

const SR: f64 = 48_000.0;
const VALUES: [&str; 5] = ["1e308", "-1e308", "1e-308", "0", "1e30"];
const LOAD_LIMIT_S: f64 = 60.0;

/// `text` with every `@NAME param VALUE` line's value replaced by `value`.
fn with_params_at(text: &str, value: &str) -> Option<String> {
    let mut changed = false;
    let lines: Vec<String> = text
        .lines()
        .map(|line| {
            let words: Vec<&str> = line.split_whitespace().collect();
            if words.len() >= 3 && words[0].starts_with('@') && words[1] == "param" {
                changed = true;
                let mut w: Vec<&str> = words.clone();
                w[2] = value;
                w.join(" ")
            } else {
                line.to_string()
            }
        })
        .collect();
    changed.then(|| lines.join("\n") + "\n")
}

fn fretted_variants() -> [String; 2] {
    let text = include_str!("../../models/fretted-string.mdl");
    let huge = text.replace(
        "@low_m60 osc low_M 0 low_Zosc 0. 0.",
        "@low_m60 osc low_M 0 1e308 0. 0.",
    );
    let both = huge.replace(
        "@low_r37 springDamper @low_m35 @low_m36 low_K low_Z",
        "@low_r37 springDamper @low_m35 @low_m36 low_K 0",
    );
    assert!(
        huge != text && both != huge,
        "the preset still has the lines this test edits"
    );
    [huge, both]
}

#[test]
fn extreme_values_through_a_state_load_never_panic_hang_or_blast() {
    let mut cases: Vec<(String, String)> = fretted_variants()
        .into_iter()
        .enumerate()
        .map(|(i, s)| (format!("fretted-string variant {i}"), s))
        .collect();
    for (name, text) in presets() {
        let spec = ressort_engine::lang::parse_with_files(
            &text,
            &ressort_engine::instrument::meshes::shipped,
        )
        .spec
        .expect("a preset parses");
        let engine = ressort_engine::compile(&spec, &ressort_engine::CompileOptions::at(SR))
            .expect("a preset compiles");
        if engine.positions().len() > 200 {
            // Their analyses take seconds each in a debug build; the engine's fuzz covers
            // their parameters (engine/tests/extremes.rs).
            continue;
        }
        for value in VALUES {
            if let Some(script) = with_params_at(&text, value) {
                cases.push((format!("{name} params={value}"), script));
            }
        }
    }
    let mut plugin = TestPlugin::new();
    plugin.activate(SR, 1, 512);
    let mut longest = (0.0f64, String::new());
    let (mut refused, mut loaded) = (0, 0);
    for (what, script) in &cases {
        let blob = state::with_musical_model(&plugin.save_state(), "Custom", script);
        let start = Instant::now();
        let outcome = plugin.load_state(&blob);
        let seconds = start.elapsed().as_secs_f64();
        assert!(
            seconds < LOAD_LIMIT_S,
            "{what}: the state load took {seconds:.1} s"
        );
        match outcome {
            Ok(()) => loaded += 1,
            Err(_) => refused += 1,
        }
        if seconds > longest.0 {
            longest = (seconds, what.clone());
        }
        let out = plugin.render(0.1, 512, &Score::new().note_on(0, 60, 0.9));
        assert!(out.audio.is_finite(), "{what}: non-finite output");
        assert!(out.audio.peak() <= 1.0, "{what}: peak {}", out.audio.peak());
    }
    plugin.deactivate();
    println!(
        "{} cases through a CLAP state load ({loaded} accepted, {refused} refused), 0 panics, \
         0 hangs; longest load {:.2} s ({})",
        cases.len(),
        longest.0,
        longest.1
    );
    assert!(cases.len() > 50, "only {} cases", cases.len());
}
