//! Polyphony in a CLAP host: with Voices above 1 every note plays its own copy of the model.
//! A chord is the sum of its notes, a stolen voice fades out without a click, voices end
//! themselves with CLAP note-end events, a storm of notes runs under the allocation check,
//! the setting survives the state, and a new Voices value from the host takes effect.

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

/// Stealing makes no click: with two voices the third note steals the quieter voice, which
/// fades out over a few milliseconds. The difference from a bank with room for all three is
/// minus the stolen voice times (1 − its fade gain): it moves smoothly, where a cut would
/// jump by the stolen voice's whole value.
#[test]
fn a_stolen_voice_fades_out_without_a_click() {
    let notes = [(0u32, 60u8), (4_800, 64), (9_600, 67)];
    let score = notes
        .iter()
        .fold(Score::new(), |s, &(t, k)| s.note_on(t, k, 1.0));
    let frames = 24_000;
    let mut two = poly(STRUCK, 2);
    two.take_note_ends();
    let stolen = render(&mut two, frames, &score);
    let ends = two.take_note_ends();
    assert_eq!(ends.len(), 1, "one voice was stolen: {ends:?}");
    let &(at, victim) = notes
        .iter()
        .find(|&&(_, k)| u16::from(k) == ends[0])
        .expect("the stolen voice is one of the notes");
    let roomy = render(&mut poly(STRUCK, 3), frames, &score);
    let alone = render(
        &mut poly(STRUCK, 3),
        frames,
        &Score::new().note_on(at, victim, 1.0),
    );
    let d: Vec<f32> = stolen
        .left
        .iter()
        .zip(&roomy.left)
        .map(|(a, b)| a - b)
        .collect();
    let step = d.windows(2).fold(0.0f32, |m, w| m.max((w[1] - w[0]).abs()));
    let level = alone.slice(9_000..10_200).peak();
    println!(
        "note {victim} stolen; its level there {level:.3e}; largest step of the difference \
         {step:.3e} ({:.1} % of it)",
        100.0 * step / level
    );
    assert!(
        level > 1e-3,
        "the stolen voice must still sound when it is stolen"
    );
    assert!(step < 0.2 * level, "the stolen voice was cut, not faded");
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

/// MPE through the host: with the MPE switch on, MIDI channel 1 is the master channel and
/// channels 2 … 16 carry one note each with a ±48-semitone bend. A bend on one member channel
/// moves only the voice of that channel: measured by FFT.
#[test]
fn an_mpe_bend_moves_only_its_channels_voice() {
    use ressort_tests::{cents, peak_frequency};
    let frames = 48_000;
    let mut plugin = plugin_with_model(
        "poly",
        DAMPED_SLOWLY,
        &[
            ("voices", json!({ "i32": 8 })),
            ("output_gain", json!({ "f32": -12.0 })),
            ("mpe", json!({ "bool": true })),
        ],
    );
    // CLAP channels count from 0: 1 and 2 are the MIDI member channels 2 and 3. The bend
    // (+12 semitones: a quarter of the ±48 range) comes before its note, as MPE controllers
    // send it.
    let score = Score::new()
        .note_on_channel(0, 60, 0.9, 1)
        .pitch_bend_channel(0, 0.25, 2)
        .note_on_channel(0, 67, 0.9, 2);
    let bent = render(&mut plugin, frames, &score);
    let alone = |key: u8, plugin: &mut TestPlugin| {
        render(
            plugin,
            frames,
            &Score::new().note_on_channel(0, key, 0.9, 1),
        )
        .left
    };
    let f60 = peak_frequency(&alone(60, &mut plugin), SR, 20.0, 20_000.0);
    let f67 = peak_frequency(&alone(67, &mut plugin), SR, 20.0, 20_000.0);
    let f79 = peak_frequency(&alone(79, &mut plugin), SR, 20.0, 20_000.0);
    // The bent voice sounds at note 79, the other one stays at 60, nothing is left at 67.
    let near = |f: f64| peak_frequency(&bent.left, SR, f / 1.03, f * 1.03);
    let (low, high) = (near(f60), near(f79));
    println!(
        "alone: 60 → {f60:.2} Hz, 67 → {f67:.2} Hz, 79 → {f79:.2} Hz; bent chord peaks \
         {low:.2} Hz ({:+.2} ct) and {high:.2} Hz ({:+.2} ct)",
        cents(low, f60),
        cents(high, f79)
    );
    assert!(cents(low, f60).abs() < 2.0, "channel 2's voice moved");
    assert!(
        cents(high, f79).abs() < 2.0,
        "the bend did not reach channel 3's voice"
    );
    let share = ressort_tests::band_energy_share(&bent.left, SR, f67 / 1.01, f67 * 1.01);
    println!("energy share at note 67: {share:.2e}");
    assert!(share < 1e-3, "the unbent note 67 still sounds: {share:.2e}");

    // Off, the same bend on channel 3 moves the whole instrument (by the Bend Range).
    let mut plain = plugin_with_model(
        "poly",
        DAMPED_SLOWLY,
        &[
            ("voices", json!({ "i32": 8 })),
            ("output_gain", json!({ "f32": -12.0 })),
        ],
    );
    let global = render(&mut plain, frames, &score);
    let moved = peak_frequency(&global.left, SR, f60 / 1.03, f60 * 1.03);
    println!(
        "MPE off: the voice of note 60 at {moved:.2} Hz ({:+.1} ct)",
        cents(moved, f60)
    );
    assert!(cents(moved, f60) > 40.0, "without MPE a bend is global");
}

/// A lightly damped oscillator struck directly: one clean partial per voice.
/// MPE channel pressure presses only the voices of its channel: with `~pressure in1`, the
/// pressed voice gets a sustained force, whose step response rings at that voice's pitch.
/// The difference between a chord with and without pressure on one member channel is that
/// voice's step response alone (FFT), with nothing at the other voice's pitch.
#[test]
fn mpe_channel_pressure_presses_only_its_channels_voice() {
    use ressort_tests::{band_energy_share, cents, peak_frequency};
    let frames = 48_000;
    let script = format!("{DAMPED_SLOWLY}~pressure in1 0.001\n");
    let settings = [
        ("voices", json!({ "i32": 8 })),
        ("output_gain", json!({ "f32": -12.0 })),
        ("mpe", json!({ "bool": true })),
        ("dc_filter", json!({ "bool": false })),
    ];
    let chord = Score::new()
        .note_on_channel(0, 60, 0.9, 1)
        .note_on_channel(0, 67, 0.9, 2);
    let mut plugin = plugin_with_model("poly", &script, &settings);
    let plain = render(&mut plugin, frames, &chord);
    let mut plugin = plugin_with_model("poly", &script, &settings);
    let pressed = render(
        &mut plugin,
        frames,
        &chord.clone().channel_pressure(4_800, 1.0, 2),
    );
    let diff: Vec<f32> = pressed
        .left
        .iter()
        .zip(&plain.left)
        .map(|(a, b)| a - b)
        .collect();
    let alone = |key: u8| {
        let mut p = plugin_with_model("poly", &script, &settings);
        render(
            &mut p,
            frames,
            &Score::new().note_on_channel(0, key, 0.9, 1),
        )
        .left
    };
    let (f60, f67) = (
        peak_frequency(&alone(60), SR, 20.0, 20_000.0),
        peak_frequency(&alone(67), SR, 20.0, 20_000.0),
    );
    let peak = diff.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    let ring = peak_frequency(&diff[4_800..], SR, 20.0, 20_000.0);
    let share60 = band_energy_share(&diff[4_800..], SR, f60 / 1.01, f60 * 1.01);
    println!(
        "pressure on channel 3: difference peak {peak:.2e}, rings at {ring:.2} Hz \
         ({:+.2} ct from note 67), energy share at note 60 {share60:.2e}",
        cents(ring, f67)
    );
    assert!(peak > 1e-4, "the pressure did not move anything ({peak:e})");
    assert!(
        cents(ring, f67).abs() < 5.0,
        "the pressed voice is not note 67's"
    );
    assert!(
        share60 < 1e-3,
        "note 60's voice was pressed too ({share60:e})"
    );
    assert!(
        diff[..4_800].iter().all(|v| *v == 0.0),
        "pressure acted before it was sent"
    );
}

const DAMPED_SLOWLY: &str = "\
# A lightly damped oscillator (MPE tests).
@o osc 1. 0.02 0.0002 0. 0.
@in1 frcInput @o
@out1 posOutput @o
";
