//! The bundled plugin in a CLAP host, played as a musician first plays it: a fresh instance
//! (its default preset, today's conventions) plays C4 in the level band and A4 at 440 Hz, a
//! kick on the sidechain strikes it like a medium note, trigger mode turns a drum loop into
//! strikes, a bowed preset bows while its key is held; and a project saved before concert
//! pitch and automatic levels still loads and plays as it did.

use ressort_tests::state;
use ressort_tests::{
    cents, oscillator_frequency, peak_frequency, plugin_with_model, Score, Stereo, TestPlugin,
};
use serde_json::json;

const SR: f64 = 48_000.0;

fn db(x: f64) -> f64 {
    20.0 * x.max(1e-12).log10()
}

/// The kick of the issue: a sine gliding 120 → 50 Hz under a 60 ms decay, at `hits` (seconds),
/// peaking at −6 dBFS, on both sidechain channels.
fn kick(seconds: f64, hits: &[f64]) -> Stereo {
    let frames = (seconds * SR) as usize;
    let mut x = vec![0.0f64; frames];
    for &start in hits {
        let mut phase = 0.0f64;
        for n in 0..(0.4 * SR) as usize {
            let t = n as f64 / SR;
            phase += std::f64::consts::TAU * (50.0 + 70.0 * (-t / 0.03).exp()) / SR;
            if let Some(s) = x.get_mut((start * SR) as usize + n) {
                *s += (-t / 0.06).exp() * phase.sin();
            }
        }
    }
    let peak = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let left: Vec<f32> = x
        .iter()
        .map(|v| (v * 10f64.powf(-6.0 / 20.0) / peak) as f32)
        .collect();
    Stereo {
        right: left.clone(),
        left,
    }
}

fn peak_between(audio: &Stereo, from: f64, to: f64) -> f64 {
    let (a, b) = (
        (from * SR) as usize,
        ((to * SR) as usize).min(audio.left.len()),
    );
    audio.left[a..b]
        .iter()
        .chain(&audio.right[a..b])
        .fold(0.0f64, |m, v| m.max(v.abs() as f64))
}

#[test]
fn a_fresh_instance_plays_in_tune_at_a_sane_level_and_a_kick_strikes_it() {
    let mut plugin = TestPlugin::new();
    let saved = plugin.save_state();
    assert_eq!(state::playing(&saved).as_deref(), Some("musical"));
    let mut play = |score: Score, seconds: f64| {
        plugin.activate(SR, 1, 512);
        let out = plugin.render(seconds, 512, &score);
        assert!(out.audio.is_finite());
        out.audio
    };
    let c4 = play(Score::new().note_on(0, 60, 0.8), 1.5);
    let soft = play(Score::new().note_on(0, 60, 0.2), 1.5);
    let a4 = play(Score::new().note_on(0, 69, 0.8), 1.5);
    let f = peak_frequency(&a4.left[(0.2 * SR) as usize..], SR, 415.0, 466.0);
    let hits: Vec<f64> = (0..6).map(|i| 0.5 * i as f64).collect();
    let drum = play(Score::new().with_sidechain(kick(3.0, &hits)), 3.0);
    println!(
        "default preset: C4 at 0.8 {:.1} dBFS, at 0.2 {:.1} dBFS; A4 {f:.2} Hz ({:+.2} cents); \
         a -6 dBFS kick {:.1} dBFS",
        db(c4.peak() as f64),
        db(soft.peak() as f64),
        cents(f, 440.0),
        db(drum.peak() as f64)
    );
    let level = db(c4.peak() as f64);
    assert!((-18.0..=-6.0).contains(&level), "C4 at {level:.1} dBFS");
    assert!(
        db(soft.peak() as f64) < level - 3.0,
        "velocity 0.2 is softer"
    );
    assert!(cents(f, 440.0).abs() < 5.0, "A4 at {f} Hz");
    let kick_level = db(drum.peak() as f64);
    assert!(
        (kick_level - level).abs() <= 6.0,
        "the kick at {kick_level:.1} dBFS"
    );
    assert!(kick_level < -6.0, "the kick reaches the soft ceiling");
}

#[test]
fn trigger_mode_turns_a_drum_loop_into_strikes() {
    let hits = [0.25, 0.75, 1.25, 1.75];
    let mut plugin = TestPlugin::new();
    let trigger = plugin.param("Sidechain Trigger").id;
    plugin.activate(SR, 1, 512);
    let raw = plugin.render(2.2, 512, &Score::new().with_sidechain(kick(2.2, &hits)));
    plugin.activate(SR, 1, 512);
    let struck = plugin.render(
        2.2,
        512,
        &Score::new()
            .param(0, trigger, 1.0)
            .with_sidechain(kick(2.2, &hits)),
    );
    assert!(struck.audio.is_finite());
    assert_ne!(
        struck.audio.left, raw.audio.left,
        "trigger mode plays differently"
    );
    for &t in &hits {
        let before = peak_between(&struck.audio, t - 0.1, t);
        let hit = peak_between(&struck.audio, t, t + 0.1);
        println!(
            "strike at {t} s: {:.1} dBFS (before {:.1})",
            db(hit),
            db(before)
        );
        assert!(hit > before && db(hit) > -18.0, "no strike at {t} s");
    }
}

#[test]
fn a_bowed_preset_bows_while_its_key_is_held() {
    let script = include_str!("../../models/bowed-string.mdl");
    let mut plugin = TestPlugin::new();
    let blob = state::with_musical_model(&plugin.save_state(), "bowed-string", script);
    plugin.load_state(&blob).expect("the state loads");
    plugin.activate(SR, 1, 512);
    let out = plugin.render(
        2.5,
        512,
        &Score::new()
            .note_on(0, 45, 0.8)
            .note_off((1.5 * SR) as u32, 45),
    );
    assert!(out.audio.is_finite());
    let held = peak_between(&out.audio, 1.0, 1.5);
    let f = peak_frequency(
        &out.audio.left[(0.5 * SR) as usize..(1.5 * SR) as usize],
        SR,
        105.0,
        115.0,
    );
    println!(
        "bowed-string, A2 held: {:.1} dBFS, {f:.2} Hz ({:+.2} cents)",
        db(held),
        cents(f, 110.0)
    );
    assert!(
        (-18.0..=-6.0).contains(&db(held)),
        "the bow sustains at {:.1}",
        db(held)
    );
    assert!(cents(f, 110.0).abs() < 12.0, "A2 bowed at {f} Hz");
}

#[test]
fn a_project_saved_before_concert_pitch_plays_as_it_did() {
    // A state without `playing`, with the old default Output Gain (+24 dB): relative tuning
    // (key 60 plays the model as written) and no trim.
    let script = include_str!("../models/low-oscillator.mdl");
    let mut plugin = plugin_with_model(
        "low-oscillator",
        script,
        &[("output_gain", json!({ "f32": 24.0 }))],
    );
    let saved = plugin.save_state();
    assert_eq!(
        state::playing(&saved).as_deref(),
        Some("legacy"),
        "saved as it was loaded"
    );
    plugin.activate(SR, 1, 512);
    let out = plugin.render(1.2, 512, &Score::new().note_on(0, 60, 1.0));
    let f = peak_frequency(&out.audio.left[(0.1 * SR) as usize..], SR, 100.0, 400.0);
    // The low oscillator as written, K = 0.001 at 44.1 kHz: about 222 Hz, not C4.
    let written = oscillator_frequency(1.0, 0.001, 1.0, SR);
    println!("legacy project: key 60 at {f:.2} Hz (the model as written {written:.2} Hz)");
    assert!(
        cents(f, written).abs() < 3.0,
        "key 60 plays the model as written"
    );
    // The same script chosen today plays key 60 at C4.
    let mut today = TestPlugin::new();
    let blob = state::with_musical_model(&today.save_state(), "low-oscillator", script);
    today.load_state(&blob).expect("the state loads");
    today.activate(SR, 1, 512);
    let out = today.render(1.2, 512, &Score::new().note_on(0, 60, 1.0));
    let c4 = peak_frequency(&out.audio.left[(0.1 * SR) as usize..], SR, 100.0, 400.0);
    assert!(
        cents(c4, 261.6256).abs() < 5.0,
        "today key 60 plays C4: {c4} Hz"
    );
}
