//! Polyphony in a CLAP host: with Voices above 1 every note plays its own copy of the model.
//! A chord is the sum of its notes, a stolen voice fades out without a click, voices end
//! themselves with CLAP note-end events, a storm of notes runs under the allocation check,
//! the setting survives the state, and a new Voices value from the host takes effect. MPE
//! bends and pressure, CLAP note expressions and CLAP polyphonic modulation each reach only
//! the voice they address. Release damps a released voice, and the sustain pedal holds it.

use ressort_tests::{
    band_energy_share, cents, peak_frequency, plugin_with_model, NoteExpressionType, Score, Stereo,
    TestPlugin,
};
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
    // Voices counts notes (0: the script's `~voices`), is not automatable (a new count
    // re-prepares the model), and Release is an ordinary automatable control.
    const CLAP_PARAM_IS_AUTOMATABLE: u32 = 1 << 5;
    let (voices, release) = (first.param("Voices"), first.param("Release"));
    println!(
        "Voices: {} … {}, flags {:#x}; Release: {} … {}, flags {:#x}",
        voices.min, voices.max, voices.flags, release.min, release.max, release.flags
    );
    assert!(voices.min <= 1.0 && voices.max >= 64.0);
    assert_eq!(voices.flags & CLAP_PARAM_IS_AUTOMATABLE, 0);
    assert_ne!(release.flags & CLAP_PARAM_IS_AUTOMATABLE, 0);
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
    only_one_voice_moved(
        "MPE pressure on channel 3",
        &pressed,
        &plain,
        4_800,
        f67,
        f60,
    );
}

/// Checks that an event sent at frame `at` changed exactly one voice of a chord: `changed`
/// and `plain` (the chord without the event) are equal before `at`; after it their
/// difference rings at `f_moved`, the pitch of the voice the event addressed, and holds
/// nothing at `f_other`, the other voice's pitch.
fn only_one_voice_moved(
    what: &str,
    changed: &Stereo,
    plain: &Stereo,
    at: usize,
    f_moved: f64,
    f_other: f64,
) {
    let diff: Vec<f32> = changed
        .left
        .iter()
        .zip(&plain.left)
        .map(|(a, b)| a - b)
        .collect();
    let peak = diff.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    let ring = peak_frequency(&diff[at..], SR, 20.0, 20_000.0);
    let other = band_energy_share(&diff[at..], SR, f_other / 1.01, f_other * 1.01);
    println!(
        "{what}: difference peak {peak:.2e}, rings at {ring:.2} Hz ({:+.2} ct from the \
         addressed voice), energy share at the other voice's pitch {other:.2e}",
        cents(ring, f_moved)
    );
    assert!(peak > 1e-4, "{what} did not move anything ({peak:e})");
    assert!(
        cents(ring, f_moved).abs() < 5.0,
        "{what} moved another voice than the one it addressed"
    );
    assert!(other < 1e-3, "{what} moved the other voice too ({other:e})");
    assert!(
        diff[..at].iter().all(|v| *v == 0.0),
        "{what} acted before it was sent"
    );
}

/// The frequency of note `key` of `script` played alone on channel 0 (8 voices).
fn pitch_alone(script: &str, key: u8) -> f64 {
    let mut p = poly(script, 8);
    let alone = render(&mut p, 48_000, &Score::new().note_on(0, key, 0.9));
    peak_frequency(&alone.left, SR, 20.0, 20_000.0)
}

/// CLAP note expressions address one voice by its note id. The tuning expression (+12
/// semitones, sent with the note) plays note 60's voice as note 72, bit for bit, next to an
/// untouched note 55. Sent later to one voice of a sounding chord, it retunes that voice only.
#[test]
fn a_clap_tuning_expression_retunes_only_its_note() {
    let frames = 24_000;
    let mut plugin = poly(STRUCK, 8);
    let tuned = render(
        &mut plugin,
        frames,
        &Score::new()
            .note_on_id(0, 60, 0.9, 7)
            .note_expression(0, 60, 7, NoteExpressionType::Tuning, 12.0)
            .note_on_id(0, 55, 0.9, 8),
    );
    let played = render(
        &mut plugin,
        frames,
        &Score::new()
            .note_on_id(0, 72, 0.9, 7)
            .note_on_id(0, 55, 0.9, 8),
    );
    println!(
        "tuning +12 on note id 7 (note 60) against note 72 played: first difference {:?}",
        tuned.first_difference(&played)
    );
    assert!(
        tuned.bit_identical(&played),
        "tuning +12 must play note 60 as 72"
    );

    // Mid-note, on a lightly damped chord: only the addressed voice moves.
    let chord = Score::new()
        .note_on_id(0, 60, 0.9, 1)
        .note_on_id(0, 67, 0.9, 2);
    let mut plugin = poly(DAMPED_SLOWLY, 8);
    let plain = render(&mut plugin, 48_000, &chord);
    let bent = render(
        &mut plugin,
        48_000,
        &chord
            .clone()
            .note_expression(4_800, 67, 2, NoteExpressionType::Tuning, 5.0),
    );
    let (f60, f67, f72) = (
        pitch_alone(DAMPED_SLOWLY, 60),
        pitch_alone(DAMPED_SLOWLY, 67),
        pitch_alone(DAMPED_SLOWLY, 72),
    );
    let high = peak_frequency(&bent.left[4_800..], SR, f72 / 1.03, f72 * 1.03);
    let left67 = band_energy_share(&bent.left[4_800..], SR, f67 / 1.01, f67 * 1.01);
    println!(
        "tuning +5 on note id 2 (note 67) at 0.1 s: peak at {high:.2} Hz ({:+.2} ct from note \
         72); energy share left at note 67 {left67:.2e}",
        cents(high, f72)
    );
    assert!(left67 < 1e-3, "note 67 still sounds ({left67:e})");
    assert!(
        cents(high, f72).abs() < 2.0,
        "note 67 + 5 semitones must sound as note 72"
    );
    // The difference rings at both the old and the new pitch of voice 2; none of it at note 60.
    only_one_voice_moved("tuning on note id 2", &bent, &plain, 4_800, f72, f60);
}

/// The CLAP pressure expression presses the voice of its note id through the script's
/// `~pressure` input: a sustained force whose step response rings at that voice's pitch only.
#[test]
fn a_clap_pressure_expression_presses_only_its_note() {
    let script = format!("{DAMPED_SLOWLY}~pressure in1 0.001\n");
    let settings = [
        ("voices", json!({ "i32": 8 })),
        ("output_gain", json!({ "f32": -12.0 })),
        ("dc_filter", json!({ "bool": false })),
    ];
    let chord = Score::new()
        .note_on_id(0, 60, 0.9, 11)
        .note_on_id(0, 67, 0.9, 12);
    let mut plugin = plugin_with_model("poly", &script, &settings);
    let plain = render(&mut plugin, 48_000, &chord);
    let pressed = render(
        &mut plugin,
        48_000,
        &chord
            .clone()
            .note_expression(4_800, 67, 12, NoteExpressionType::Pressure, 1.0),
    );
    let (f60, f67) = (pitch_alone(&script, 60), pitch_alone(&script, 67));
    only_one_voice_moved("pressure on note id 12", &pressed, &plain, 4_800, f67, f60);
}

/// CLAP polyphonic modulation of Stiffness and Damping (Ressort declares both modulatable per
/// note id) reaches only the voice of its note id. Stiffness +2 octaves (+0.25 of the
/// knob's 8-octave span) multiplies that voice's K by 4: in the discrete oscillator,
/// sin(ω/2) = √(K/4M), its pitch moves from ω to 2·asin(2·sin(ω/2)), a little above an octave.
/// Damping +2 octaves makes it decay four times as fast (the envelope's rate is Z/2M per
/// sample). The other voice stays as it was.
#[test]
fn clap_polyphonic_modulation_moves_only_its_note() {
    const CLAP_PARAM_IS_MODULATABLE: u32 = 1 << 10;
    const CLAP_PARAM_IS_MODULATABLE_PER_NOTE_ID: u32 = 1 << 11;
    let mut plugin = poly(DAMPED_SLOWLY, 8);
    let (stiffness, damping) = (plugin.param("Stiffness"), plugin.param("Damping"));
    for p in [&stiffness, &damping] {
        println!(
            "{}: range {} … {}, flags {:#x}",
            p.name, p.min, p.max, p.flags
        );
        let per_note = CLAP_PARAM_IS_MODULATABLE | CLAP_PARAM_IS_MODULATABLE_PER_NOTE_ID;
        assert_eq!(
            p.flags & per_note,
            per_note,
            "{} is not poly-modulatable",
            p.name
        );
    }
    // A quarter of the span: 2 of the knob's ±4 octaves.
    let quarter = (stiffness.max - stiffness.min) / 4.0;
    let chord = Score::new()
        .note_on_id(0, 60, 0.9, 3)
        .note_on_id(0, 67, 0.9, 4);
    let plain = render(&mut plugin, 48_000, &chord);
    let (f60, f67, f72) = (
        pitch_alone(DAMPED_SLOWLY, 60),
        pitch_alone(DAMPED_SLOWLY, 67),
        pitch_alone(DAMPED_SLOWLY, 72),
    );

    let stiffer = render(
        &mut plugin,
        48_000,
        &chord
            .clone()
            .poly_modulation(0, stiffness.id, 60, 3, quarter),
    );
    let half_angle = std::f64::consts::PI * f60 / SR;
    let f4k = SR / std::f64::consts::PI * (2.0 * half_angle.sin()).asin();
    let high = peak_frequency(&stiffer.left, SR, f72 / 1.03, f72 * 1.03);
    let kept = peak_frequency(&stiffer.left, SR, f67 / 1.03, f67 * 1.03);
    let left60 = band_energy_share(&stiffer.left, SR, f60 / 1.01, f60 * 1.01);
    println!(
        "Stiffness +2 octaves on note id 3 (note 60 at {f60:.2} Hz): {high:.2} Hz, {:+.2} ct \
         from 4K's {f4k:.2} Hz ({:+.2} ct from note 72); note 67 at {kept:.2} Hz ({:+.2} ct); \
         energy share left at note 60 {left60:.2e}",
        cents(high, f4k),
        cents(high, f72),
        cents(kept, f67)
    );
    assert!(
        cents(high, f4k).abs() < 1.0,
        "the modulated voice's K must be ×4"
    );
    assert!(cents(kept, f67).abs() < 2.0, "the other voice moved");
    assert!(
        left60 < 1e-3,
        "note 60 still sounds at its own pitch ({left60:e})"
    );

    // Damping, sent a tenth of a second into the chord.
    let damped = render(
        &mut plugin,
        48_000,
        &chord
            .clone()
            .poly_modulation(4_800, damping.id, 60, 3, quarter),
    );
    only_one_voice_moved("Damping on note id 3", &damped, &plain, 4_800, f60, f67);
    // The decay rate of note 60's voice, from its level in two windows, with and without.
    let alone = Score::new().note_on_id(0, 60, 0.9, 3);
    let rate = |score: &Score, plugin: &mut TestPlugin| {
        let y = render(plugin, 48_000, score).left;
        let rms = |r: std::ops::Range<usize>| {
            (y[r.clone()]
                .iter()
                .map(|v| (*v as f64).powi(2))
                .sum::<f64>()
                / r.len() as f64)
                .sqrt()
        };
        (rms(6_000..10_000) / rms(14_000..18_000)).ln() / 8_000.0
    };
    let free = rate(&alone, &mut plugin);
    let modulated = rate(
        &alone.clone().poly_modulation(0, damping.id, 60, 3, quarter),
        &mut plugin,
    );
    println!(
        "decay rate of note 60: {free:.3e} per sample free, {modulated:.3e} with Damping +2 \
         octaves on its note id: {:.3}×",
        modulated / free
    );
    assert!(
        (modulated / free - 4.0).abs() < 0.2,
        "Damping ×4 must make the voice decay 4× as fast"
    );
}

const DAMPED_SLOWLY: &str = "\
# A lightly damped oscillator (MPE tests).
@o osc 1. 0.02 0.0002 0. 0.
@in1 frcInput @o
@out1 posOutput @o
";

/// Release and the sustain pedal through the host: with Release at 100 %, a note-off lays a
/// damper on its voice (Damping × 16), so the voice is nearly silent half a second later,
/// while a held note still rings; with the pedal (CC 64) down, the note-off waits and the
/// voice rings as if held, bit for bit.
#[test]
fn release_damps_a_released_voice_and_the_pedal_holds_it() {
    let settings = [
        ("voices", json!({ "i32": 8 })),
        ("output_gain", json!({ "f32": -12.0 })),
        ("release", json!({ "f32": 1.0 })),
    ];
    let frames = 48_000;
    let tail = |score: &Score| {
        let mut plugin = plugin_with_model("poly", DAMPED_SLOWLY, &settings);
        let out = render(&mut plugin, frames, score);
        (out.slice(36_000..frames).peak(), out)
    };
    let held = Score::new().note_on(0, 60, 0.9);
    let (held_peak, held_out) = tail(&held);
    let (released_peak, _) = tail(&held.clone().note_off(4_800, 60));
    let (pedal_peak, pedal_out) = tail(&held.clone().controller(100, 64, 127).note_off(4_800, 60));
    println!(
        "tail peak (0.75 … 1 s): held {held_peak:.3e}, released at 0.1 s {released_peak:.3e}, \
         released under the pedal {pedal_peak:.3e}"
    );
    assert!(
        held_peak > 1e-3,
        "the held note must still ring ({held_peak:e})"
    );
    assert!(
        released_peak < held_peak * 1e-3,
        "Release must damp the released voice ({released_peak:e} vs {held_peak:e})"
    );
    assert!(
        pedal_out.bit_identical(&held_out),
        "under the pedal a note-off must wait"
    );
}
