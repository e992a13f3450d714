//! The plugin in a CLAP host plays exactly what `ressort_engine::instrument` plays, which is
//! what `ressort render --as-plugin` runs: one signal path for both (the command line's own
//! test checks its WAV against the instrument). And a note retunes at its own sample.

use ressort_engine::instrument::{self, Controls, Event, Instrument, Timed, MAX_HOST_INPUTS};
use ressort_tests::{plugin_with_model, plugin_with_musical_model, Score, Stereo};
use serde_json::json;

const SMALL_MESH: &str = include_str!("../models/small-mesh.mdl");
const LOW_OSCILLATOR: &str = include_str!("../models/low-oscillator.mdl");
const SR: f64 = 48_000.0;

/// A 14-bit MIDI pitch bend as nice-plug hands it to the plugin (0 … 1).
fn bend_value(value: f64) -> f32 {
    let v = ressort_tests::HostEvent::pitch_bend_14bit(value);
    v as f32 / ((1 << 14) - 1) as f32
}

/// Renders `frames` through the instrument directly, in blocks of `block`.
fn instrument_render(
    script: &str,
    controls: &Controls,
    events: &[(u32, Event)],
    sidechain: &Stereo,
    frames: usize,
    block: usize,
) -> Stereo {
    let model = instrument::prepare("test", script, SR).expect("the test model prepares");
    let mut inst = Instrument::new(SR, *controls);
    inst.set_model(Box::new(model));
    let mut out = Stereo::silence(frames);
    let mut start = 0;
    while start < frames {
        let n = block.min(frames - start);
        let mut block_events = events
            .iter()
            .filter(|(t, _)| (*t as usize) >= start && (*t as usize) < start + n)
            .map(|&(t, e)| Timed::new(t - start as u32, e));
        let mut host_in: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
        host_in[2] = sidechain.left.get(start..start + n);
        host_in[3] = sidechain.right.get(start..start + n);
        let (l, r) = (
            &mut out.left[start..start + n],
            &mut out.right[start..start + n],
        );
        let mut channels: [&mut [f32]; 2] = [l, r];
        inst.process(
            n,
            &host_in,
            false,
            &mut block_events,
            controls,
            &mut channels,
        );
        start += n;
    }
    out
}

#[test]
fn the_plugin_plays_what_the_instrument_plays() {
    // Non-default knobs, a macro, notes at odd samples, a bend, and sidechain strikes.
    let params = [
        ("stiffness", json!({ "f32": 1.0 })),
        ("output_gain", json!({ "f32": -6.0 })),
        ("macro_1", json!({ "f32": 0.7 })),
    ];
    let mut plugin = plugin_with_musical_model("small-mesh", SMALL_MESH, &params);
    let frames = 24_000;
    let mut sidechain = Stereo::silence(frames);
    sidechain.left[5_001] = -0.05;
    sidechain.right[9_777] = -0.03;
    let score = Score::new()
        .note_on(101, 60, 0.9)
        .pitch_bend(2_003, 0.5)
        .note_on(3_001, 67, 0.5)
        .note_off(4_000, 60)
        .note_on(12_345, 55, 1.0)
        .with_sidechain(sidechain.clone());
    plugin.activate(SR, 1, 333);
    let from_plugin = plugin.render_frames(frames, 333, &score).audio;

    let mut controls = Controls::DEFAULT;
    controls.stiffness_octaves = 1.0;
    controls.output_db = -6.0;
    // The plugin stores parameters as f32.
    controls.macros[0] = 0.7f32 as f64;
    let events = [
        (
            101,
            Event::NoteOn {
                channel: 0,
                voice_id: None,
                note: 60,
                velocity: 0.9,
            },
        ),
        (
            2_003,
            Event::PitchBend {
                value: bend_value(0.5),
                channel: 0,
            },
        ),
        (
            3_001,
            Event::NoteOn {
                channel: 0,
                voice_id: None,
                note: 67,
                velocity: 0.5,
            },
        ),
        (
            4_000,
            Event::NoteOff {
                channel: 0,
                voice_id: None,
                note: 60,
            },
        ),
        (
            12_345,
            Event::NoteOn {
                channel: 0,
                voice_id: None,
                note: 55,
                velocity: 1.0,
            },
        ),
    ];
    let from_instrument =
        instrument_render(SMALL_MESH, &controls, &events, &sidechain, frames, 512);
    println!(
        "plugin peak {:.4}, instrument peak {:.4}, first difference {:?}",
        from_plugin.peak(),
        from_instrument.peak(),
        from_plugin.first_difference(&from_instrument)
    );
    assert!(from_plugin.peak() > 1e-3, "the score must sound");
    assert!(
        from_plugin.bit_identical(&from_instrument),
        "the plugin and the instrument differ from sample {:?}",
        from_plugin.first_difference(&from_instrument)
    );
}

#[test]
fn a_note_retunes_at_its_own_sample() {
    // A ringing oscillator; a second note at sample 1003, inside a control chunk. Everything
    // before it must be exactly what the first note alone plays, and the pitch must change
    // after it.
    // Below the soft ceiling, where a change shows in every sample.
    let gain = [("output_gain", json!({ "f32": -12.0 }))];
    let mut plugin = plugin_with_model("low-oscillator", LOW_OSCILLATOR, &gain);
    let frames = 4_800;
    let one = Score::new().note_on(0, 60, 1.0);
    let two = Score::new().note_on(0, 60, 1.0).note_on(1_003, 72, 0.0);
    plugin.activate(SR, 1, 4_800);
    let a = plugin.render_frames(frames, 4_800, &one).audio;
    plugin.activate(SR, 1, 4_800);
    let b = plugin.render_frames(frames, 4_800, &two).audio;
    let first = a.first_difference(&b);
    println!("first difference at {first:?} (the note is at 1003)");
    assert_eq!(
        first,
        Some(1_003),
        "a note must change nothing before its sample and act at it"
    );
}

#[test]
fn bend_range_and_velocity_curve_shape_the_notes() {
    // Bend Range 12: a full bend up plays an octave higher.
    let quiet = ("output_gain", json!({ "f32": -12.0 }));
    let mut plugin = plugin_with_model(
        "low-oscillator",
        LOW_OSCILLATOR,
        &[quiet.clone(), ("bend_range", json!({ "f32": 12.0 }))],
    );
    let frames = 48_000;
    let pitch =
        |audio: &Stereo| ressort_tests::peak_frequency(&audio.left[4_800..], SR, 50.0, 2_000.0);
    plugin.activate(SR, 1, 512);
    let straight = plugin
        .render_frames(frames, 512, &Score::new().note_on(0, 60, 1.0))
        .audio;
    plugin.activate(SR, 1, 512);
    let bent = plugin
        .render_frames(
            frames,
            512,
            &Score::new().pitch_bend(0, 1.0).note_on(0, 60, 1.0),
        )
        .audio;
    let cents = ressort_tests::cents(pitch(&bent), pitch(&straight));
    println!("Bend Range 12, full bend: {cents:+.2} cents");
    assert!((cents - 1200.0).abs() < 2.0, "{cents} cents, not an octave");

    // Velocity Curve 2 (stored as its log₂, 1): velocity 0.5 strikes as hard as 0.25 does on
    // the linear curve, to the bit (0.5² is exact).
    let mut curved = plugin_with_model(
        "low-oscillator",
        LOW_OSCILLATOR,
        &[quiet.clone(), ("velocity_curve", json!({ "f32": 1.0 }))],
    );
    let mut linear = plugin_with_model("low-oscillator", LOW_OSCILLATOR, &[quiet]);
    curved.activate(SR, 1, 512);
    linear.activate(SR, 1, 512);
    let a = curved
        .render_frames(frames, 512, &Score::new().note_on(0, 60, 0.5))
        .audio;
    let b = linear
        .render_frames(frames, 512, &Score::new().note_on(0, 60, 0.25))
        .audio;
    linear.activate(SR, 1, 512);
    let c = linear
        .render_frames(frames, 512, &Score::new().note_on(0, 60, 0.5))
        .audio;
    println!(
        "velocity 0.5: curve 2 rms {:.5}, linear 0.25 rms {:.5}, linear 0.5 rms {:.5}",
        a.rms(),
        b.rms(),
        c.rms()
    );
    assert!(a.rms() > 1e-4);
    assert!(
        a.bit_identical(&b),
        "velocity 0.5 through curve 2 is not 0.25"
    );
    assert!(!a.bit_identical(&c), "the curve changed nothing");
}

#[test]
fn a_learned_controller_moves_its_macro_like_the_knob() {
    // CC 74 on Macro 1 (saved in the state as MIDI learn leaves it). A full CC at the first
    // sample plays exactly what automating Macro 1 to its top at that sample plays (both
    // glide through the 15 ms smoother); an unmapped controller changes nothing.
    let with_map = |params: &[(&str, serde_json::Value)]| {
        let mut plugin = plugin_with_model("small-mesh", SMALL_MESH, params);
        let blob = ressort_tests::state::with_field(&plugin.save_state(), "cc_map", "[[1,74]]");
        plugin
            .load_state(&blob)
            .expect("state with a controller map");
        let saved = plugin.save_state();
        let field = ressort_tests::state::json(&saved).unwrap()["fields"]["cc_map"].clone();
        assert_eq!(
            field,
            json!("[[1,74]]"),
            "the map is saved with the project"
        );
        plugin
    };
    let frames = 12_000;
    let strike = Score::new().note_on(0, 60, 1.0);
    let mut mapped = with_map(&[]);
    mapped.activate(SR, 1, 512);
    let by_cc = mapped
        .render_frames(frames, 512, &strike.clone().controller(0, 74, 127))
        .audio;
    mapped.activate(SR, 1, 512);
    let other_cc = mapped
        .render_frames(frames, 512, &strike.clone().controller(0, 1, 127))
        .audio;
    let mut knob = plugin_with_model("small-mesh", SMALL_MESH, &[]);
    let macro_1 = knob.param("Macro 1").id;
    let strike = &strike;
    knob.activate(SR, 1, 512);
    let by_knob = knob
        .render_frames(frames, 512, &strike.clone().param(0, macro_1, 1.0))
        .audio;
    let mut plain = plugin_with_model("small-mesh", SMALL_MESH, &[]);
    plain.activate(SR, 1, 512);
    let untouched = plain.render_frames(frames, 512, strike).audio;
    println!(
        "CC 74 → Macro 1: first difference from the knob {:?}, from the untouched model {:?}",
        by_cc.first_difference(&by_knob),
        by_cc.first_difference(&untouched)
    );
    assert!(untouched.rms() > 1e-4);
    assert!(
        by_cc.bit_identical(&by_knob),
        "CC 74 = 127 must play Macro 1 at 1"
    );
    assert!(!by_cc.bit_identical(&untouched));
    assert!(other_cc.bit_identical(&untouched), "CC 1 is not mapped");

    // The host moves the knob after the controller: its value takes over.
    mapped.activate(SR, 1, 512);
    let handed_back = mapped
        .render_frames(
            frames,
            512,
            &strike
                .clone()
                .controller(0, 74, 127)
                .param(6_000, macro_1, 0.2),
        )
        .audio;
    // A fresh instance: the first one's Macro 1 stands at 1 since its automation.
    let mut knob = plugin_with_model("small-mesh", SMALL_MESH, &[]);
    knob.activate(SR, 1, 512);
    let knob_only = knob
        .render_frames(
            frames,
            512,
            &strike
                .clone()
                .param(0, macro_1, 1.0)
                .param(6_000, macro_1, 0.2),
        )
        .audio;
    assert!(
        handed_back.bit_identical(&knob_only),
        "the host's automation must take the slot back from the controller"
    );
}
