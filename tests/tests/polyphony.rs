//! Polyphony in a CLAP host: with Voices above 1 every note plays its own copy of the model.
//! A chord is the sum of its notes, voices end themselves with CLAP note-end events, a storm
//! of notes runs under the allocation check, the setting survives the state, and a new
//! Voices value from the host takes effect.

use ressort_tests::{plugin_with_model, Score, Stereo, TestPlugin};
use serde_json::json;

const SR: f64 = 48_000.0;

/// An oscillator struck through a hammer: each voice is nonlinear on its own (shared with
/// the engine's voice tests and the VST3 hosts).
const STRUCK: &str = include_str!("../models/struck-oscillator.mdl");

/// A strongly damped oscillator struck directly: at rest within a second.
const DAMPED: &str = "\
# A damped oscillator (polyphony tests).
@o osc 1. 0.02 0.002 0. 0.
@in1 frcInput @o
@out1 posOutput @o
";

fn poly(script: &str, voices: i32) -> TestPlugin {
    plugin_with_model(
        "poly",
        script,
        &[
            ("voices", json!({ "i32": voices })),
            ("output_gain", json!({ "f32": -12.0 })),
        ],
    )
}

fn render(plugin: &mut TestPlugin, frames: usize, score: &Score) -> Stereo {
    plugin.activate(SR, 1, 512);
    plugin.render_frames(frames, 333, score).audio
}

#[test]
fn a_chord_is_the_sum_of_its_notes() {
    let notes = [(0u32, 60u8), (12_000, 64), (24_001, 67)];
    let frames = 48_000;
    let mut plugin = poly(STRUCK, 8);
    let chord = notes
        .iter()
        .fold(Score::new(), |s, &(t, k)| s.note_on(t, k, 0.9));
    let together = render(&mut plugin, frames, &chord);
    let mut sum = vec![0.0f64; frames];
    for &(t, k) in &notes {
        let alone = render(&mut plugin, frames, &Score::new().note_on(t, k, 0.9));
        for (s, x) in sum.iter_mut().zip(&alone.left) {
            *s += *x as f64;
        }
    }
    let peak = together.peak() as f64;
    let err = together
        .left
        .iter()
        .zip(&sum)
        .fold(0.0f64, |m, (a, b)| m.max((*a as f64 - b).abs()));
    println!("chord peak {peak:.4}; largest difference from the sum of its notes {err:.2e}");
    assert!(peak > 1e-3 && peak < 0.5);
    assert!(err <= 1e-6 * peak, "relative error {:.2e}", err / peak);

    // Voices 1 plays the model monophonically: the chord is not the sum.
    let mut mono = poly(STRUCK, 1);
    let mono_chord = render(&mut mono, frames, &chord);
    let diff = mono_chord
        .left
        .iter()
        .zip(&sum)
        .fold(0.0f64, |m, (a, b)| m.max((*a as f64 - b).abs()));
    assert!(
        diff > 0.1 * peak,
        "one voice cannot play a chord ({diff:.2e})"
    );
}

#[test]
fn voices_end_themselves_with_note_end_events() {
    let mut plugin = poly(DAMPED, 8);
    let score = (0..6).fold(Score::new(), |s, i| s.note_on(i * 2_400, 55 + i as u8, 1.0));
    plugin.take_note_ends();
    let out = render(&mut plugin, 3 * 48_000, &score);
    let mut ends = plugin.take_note_ends();
    ends.sort_unstable();
    println!(
        "note ends: {ends:?}; tail peak {:e}",
        out.slice(140_000..144_000).peak()
    );
    assert!(out.peak() > 1e-3);
    assert_eq!(
        ends,
        [55, 56, 57, 58, 59, 60],
        "every voice ends once, and says so"
    );
}

#[test]
fn a_storm_of_notes_runs_without_allocating() {
    // The bundle under test aborts on any allocation in process() (assert_process_allocs).
    let mut plugin = poly(STRUCK, 16);
    let frames = 10_000 * 4;
    let score = (0..10_000u32).fold(Score::new(), |s, i| {
        let key = 24 + (i % 80) as u8;
        let s = s.note_on(i * 4, key, 0.5);
        if i % 3 == 0 {
            s.note_off(i * 4 + 1, key)
        } else {
            s
        }
    });
    let out = render(&mut plugin, frames, &score);
    assert!(out.is_finite());
    assert!(out.peak() <= 1.0);
    assert!(!plugin.take_note_ends().is_empty(), "voices were stolen");
}

#[test]
fn the_voices_setting_survives_the_state_and_follows_the_host() {
    let chord = Score::new()
        .note_on(0, 60, 0.9)
        .note_on(6_000, 64, 0.9)
        .note_on(12_000, 67, 0.9);
    let frames = 24_000;
    let mut first = poly(STRUCK, 6);
    let a = render(&mut first, frames, &chord);
    first.deactivate();
    let saved = first.save_state();
    assert_eq!(
        ressort_tests::state::param(&saved, "voices"),
        Some(json!({ "i32": 6 }))
    );
    let mut second = TestPlugin::new();
    second.load_state(&saved).unwrap();
    let b = render(&mut second, frames, &chord);
    assert!(
        a.bit_identical(&b),
        "a reloaded project plays the same chord"
    );

    // The host sets Voices to 1 while active: the model is re-prepared on the main thread and
    // the chord becomes monophonic.
    let voices = second.param("Voices").id;
    second.activate(SR, 1, 512);
    // A stepped parameter's CLAP value counts steps from its minimum: 0 is the script's
    // count, 1 here (no `~voices`).
    second.render_frames(512, 512, &Score::new().param(0, voices, 0.0));
    second.idle();
    second.render_frames(4_800, 512, &Score::new());
    second.idle();
    // A reset puts the re-prepared model at rest and restarts the control grid, so the render
    // can be compared with a fresh monophonic instance.
    second.reset();
    let after = second.render_frames(frames, 333, &chord).audio;
    let mut mono = poly(STRUCK, 1);
    let expected_mono = render(&mut mono, frames, &chord);
    println!(
        "after Voices → 1: first difference from a monophonic instance {:?}, from the \
         polyphonic render {:?}",
        after.first_difference(&expected_mono),
        after.first_difference(&a)
    );
    assert!(
        after.bit_identical(&expected_mono),
        "the host's new Voices setting must take effect at once"
    );
}
