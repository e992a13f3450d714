//! Instances with a model loaded from a state, as a project would open them, and the
//! transport a playing host sends.

use super::*;

/// The default preset (Mesh 15×15) as a project saved before concert pitch and the automatic
/// levels: Output Gain +24 dB and the sidechain as raw force, so a one-sample impulse of
/// −0.05 on `@in1` throws its hammer (the automatic sidechain trim of a new project scales a
/// drum to strike like a note; a single sample carries too little of a drum's push). For the
/// tests of the plugin's mechanics (block sizes, sample rates, bad input, sleeping) that
/// strike it with impulses.
pub fn struck_default() -> TestPlugin {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/mesh-15x15.mdl"),
    )
    .expect("models/mesh-15x15.mdl");
    plugin_with_model(
        "mesh-15x15",
        &text,
        &[("output_gain", serde_json::json!({ "f32": 24.0 }))],
    )
}

/// A new instance running `script` (loaded through the plugin state while inactive), with
/// plain parameter values set in the same state (`(string id, JSON value)`).
/// The state has no `playing` field: the model plays as in a project saved before concert
/// pitch and the automatic levels (relative tuning, raw sidechain, no trim).
pub fn plugin_with_model(
    name: &str,
    script: &str,
    params: &[(&str, serde_json::Value)],
) -> TestPlugin {
    plugin_with(name, script, params, false)
}

/// [`plugin_with_model`] for a model chosen today: concert pitch and the automatic levels (the
/// state says `"playing": "musical"`).
pub fn plugin_with_musical_model(
    name: &str,
    script: &str,
    params: &[(&str, serde_json::Value)],
) -> TestPlugin {
    plugin_with(name, script, params, true)
}

pub(crate) fn plugin_with(
    name: &str,
    script: &str,
    params: &[(&str, serde_json::Value)],
    musical: bool,
) -> TestPlugin {
    let mut plugin = TestPlugin::new();
    let mut blob = if musical {
        state::with_musical_model(&plugin.save_state(), name, script)
    } else {
        state::with_model(&plugin.save_state(), name, script)
    };
    for (id, value) in params {
        blob = state::with_param(&blob, id, value.clone());
    }
    plugin
        .load_state(&blob)
        .unwrap_or_else(|e| panic!("loading model {name}: {e}"));
    let saved = plugin.save_state();
    assert_eq!(
        state::model(&saved).map(|m| m.1).as_deref(),
        Some(script),
        "the plugin did not take model {name}"
    );
    // While inactive the plugin only parses a script; it compiles it at activation and runs
    // the default preset instead when that fails. Activate once so a script that parses but
    // does not compile fails here, not as a test of the default preset.
    plugin.activate(48_000.0, 1, 512);
    let compiled = plugin.save_state();
    plugin.deactivate();
    assert_eq!(
        state::model(&compiled).map(|m| m.1).as_deref(),
        Some(script),
        "model {name} parses but does not compile: the plugin fell back to {:?}",
        state::model(&compiled).map(|m| m.0)
    );
    plugin
}

/// A playing transport at `position` samples: seconds, and beats at 120 BPM in 4/4.
pub(crate) fn playing_transport(position: u64, sample_rate: f64) -> TransportEvent {
    let seconds = position as f64 / sample_rate;
    let beats = seconds * 2.0;
    TransportEvent {
        header: EventHeader::new_core(0, EventFlags::empty()),
        flags: TransportFlags::IS_PLAYING
            | TransportFlags::HAS_SECONDS_TIMELINE
            | TransportFlags::HAS_BEATS_TIMELINE
            | TransportFlags::HAS_TEMPO
            | TransportFlags::HAS_TIME_SIGNATURE,
        song_pos_beats: BeatTime::from_float(beats),
        song_pos_seconds: SecondsTime::from_float(seconds),
        tempo: 120.0,
        tempo_inc: 0.0,
        loop_start_beats: BeatTime::from_int(0),
        loop_end_beats: BeatTime::from_int(0),
        loop_start_seconds: SecondsTime::from_int(0),
        loop_end_seconds: SecondsTime::from_int(0),
        bar_start: BeatTime::from_float((beats / 4.0).floor() * 4.0),
        bar_number: (beats / 4.0).floor() as i32,
        time_signature_numerator: 4,
        time_signature_denominator: 4,
    }
}
