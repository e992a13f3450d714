//! Projects that load forever: states saved by earlier builds of the plugin
//! (`tests/fixtures/states/`), the phrase each one is played with, and its committed render.
//!
//! `ressort-fixtures` (a binary of this crate) writes the fixtures of the plugin as built now:
//! one JSON state per recipe below, named `f<format>-<recipe>.json` after the state format
//! the build writes, and the render of the phrase as `f<format>-<recipe>.wav` (32-bit float,
//! stereo, 48 kHz). Fixtures of every earlier format stay committed; `tests/state_fixtures.rs`
//! loads each into today's plugin and compares its render with the reference.

use crate::{state, Score, Stereo, TestPlugin};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Where the fixtures live.
pub fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/states")
}

/// The committed list of parameter ids: `string id<TAB>CLAP id<TAB>name` per line.
pub fn parameter_ids_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/parameter-ids.txt")
}

pub const SAMPLE_RATE: f64 = 48_000.0;
pub const BLOCK: usize = 256;
/// The phrase's length: half a second.
pub const FRAMES: usize = 24_000;

/// How a fixture's state is made from a fresh instance's.
#[derive(Debug)]
pub struct Recipe {
    pub name: &'static str,
    /// The model's name in the state and its script.
    pub model: (&'static str, &'static str),
    /// Played by today's conventions (concert pitch, automatic levels); `false` writes a
    /// state without the `playing` field, as projects saved before them.
    pub musical: bool,
    /// Plain parameter values by string id.
    pub params: &'static [(&'static str, f64)],
    /// MIDI learn: (macro slot from 1, controller).
    pub cc_map: &'static [(u8, u8)],
    /// The A/B slot that does not run, and whether B runs (states of format 1 on).
    pub compare: Option<((&'static str, &'static str), bool)>,
}

/// The fixtures' recipes: moved macros and controls, voices, MIDI-learn bindings, A/B, a
/// project from before concert pitch, a script of the user's own.
pub const RECIPES: &[Recipe] = &[
    Recipe {
        name: "mesh-moved-controls",
        model: ("mesh-15x15", include_str!("../../models/mesh-15x15.mdl")),
        musical: true,
        params: &[
            ("stiffness", 0.5),
            ("damping", -0.75),
            ("macro_1", 0.8),
            ("macro_2", 0.3),
            ("output_gain", -3.0),
        ],
        cc_map: &[],
        compare: None,
    },
    Recipe {
        name: "felt-piano-voices",
        model: ("felt-piano", include_str!("../../models/felt-piano.mdl")),
        musical: true,
        params: &[
            ("voices", 6.0),
            ("tune", 2.0),
            ("release", 0.3),
            ("macro_3", 0.7),
        ],
        cc_map: &[],
        compare: None,
    },
    Recipe {
        name: "plucked-midi-learn",
        model: (
            "plucked-harmonics",
            include_str!("../../models/plucked-harmonics.mdl"),
        ),
        musical: true,
        params: &[("velocity_curve", 0.5)],
        cc_map: &[(1, 1), (2, 74)],
        compare: None,
    },
    Recipe {
        name: "legacy-hammer",
        model: (
            "hammer-oscillator",
            include_str!("../../models/hammer-oscillator.mdl"),
        ),
        musical: false,
        params: &[
            ("force_gain", -12.0),
            ("output_gain", 0.0),
            ("dc_filter", 1.0),
        ],
        cc_map: &[],
        compare: None,
    },
    Recipe {
        name: "custom-script",
        model: ("Custom", include_str!("../models/small-mesh.mdl")),
        musical: true,
        params: &[("macro_1", 0.25), ("macro_2", 0.9)],
        cc_map: &[],
        compare: None,
    },
    Recipe {
        name: "ab-drunk-triangles",
        model: (
            "drunk-triangles",
            include_str!("../../models/drunk-triangles.mdl"),
        ),
        musical: true,
        params: &[("voices", 0.0)],
        cc_map: &[],
        compare: Some((
            (
                "bowed-string",
                include_str!("../../models/bowed-string.mdl"),
            ),
            true,
        )),
    },
];

/// The state the recipe describes, as a fresh instance of this build saves it after loading
/// it (`None` when this build's format has no room for it: A/B before format 1).
pub fn make(recipe: &Recipe) -> Option<Vec<u8>> {
    let mut plugin = TestPlugin::new();
    let fresh = plugin.save_state();
    if recipe.compare.is_some() && format_of(&fresh) < 1 {
        return None;
    }
    let (name, script) = recipe.model;
    let mut blob = if recipe.musical {
        state::with_musical_model(&fresh, name, script)
    } else {
        state::with_model(&fresh, name, script)
    };
    for &(id, value) in recipe.params {
        let plain = match state::param(&fresh, id) {
            Some(Value::Object(m)) if m.contains_key("i32") => json!({ "i32": value as i32 }),
            Some(Value::Object(m)) if m.contains_key("bool") => json!({ "bool": value != 0.0 }),
            Some(_) => json!({ "f32": value }),
            None => panic!("recipe {}: no parameter {id}", recipe.name),
        };
        blob = state::with_param(&blob, id, plain);
    }
    if !recipe.cc_map.is_empty() {
        let map = serde_json::to_string(recipe.cc_map).expect("JSON");
        blob = state::with_field(&blob, "cc_map", &map);
    }
    if let Some(((other, other_script), b_runs)) = recipe.compare {
        let other = json!({ "name": other, "script": other_script, "playing": "musical" });
        let slots = if b_runs {
            json!([other, null])
        } else {
            json!([null, other])
        };
        let compare = json!({ "slots": slots, "active": if b_runs { 1 } else { 0 } });
        blob = state::with_field(&blob, "compare", &compare.to_string());
    }
    plugin.load_state(&blob).expect("the recipe's state loads");
    // Activated once, so that a script that does not compile shows here.
    plugin.activate(SAMPLE_RATE, 1, BLOCK as u32);
    plugin.deactivate();
    let saved = plugin.save_state();
    assert_eq!(
        state::model(&saved).map(|m| m.1).as_deref(),
        Some(script),
        "recipe {}: the plugin did not take the model",
        recipe.name
    );
    Some(saved)
}

/// The state format a blob says it has (0 before the field existed).
pub fn format_of(blob: &[u8]) -> u64 {
    state::json(blob)
        .and_then(|v| v.get("fields")?.get("format")?.as_str()?.parse().ok())
        .unwrap_or(0)
}

/// The phrase every fixture is played with: a chord built note by note, the mod wheel and
/// controller 74 moved (the MIDI-learn fixture's bindings: mass up, stiffness down), a
/// sidechain hit, the notes let go.
pub fn phrase() -> Score {
    let mut score = Score::new()
        .note_on(0, 60, 0.8)
        .note_on(4_800, 64, 0.6)
        .note_on(9_600, 67, 0.7);
    for (i, t) in (7_200u32..14_400).step_by(480).enumerate() {
        let v = 64 + 3 * i as u8;
        score = score.controller(t, 1, v).controller(t + 7, 74, 128 - v);
    }
    score
        .impulse(12_000, -0.05)
        .note_off(16_800, 60)
        .note_off(16_800, 64)
        .note_off(19_200, 67)
}

/// Loads a state into a fresh instance and plays the phrase from song position 0.
pub fn render(blob: &[u8]) -> Stereo {
    let mut plugin = TestPlugin::new();
    plugin.load_state(blob).expect("the fixture loads");
    plugin.activate(SAMPLE_RATE, 1, BLOCK as u32);
    let out = plugin.render_song(FRAMES, &[BLOCK], Some(0), &phrase());
    plugin.deactivate();
    out.audio
}

/// A state blob's JSON text (the plugin's CLAP state is a length and the JSON).
pub fn json_text(blob: &[u8]) -> String {
    let len = u64::from_le_bytes(blob[..8].try_into().expect("a state blob")) as usize;
    String::from_utf8(blob[8..8 + len].to_vec()).expect("UTF-8 JSON")
}

/// Writes a render as a 32-bit float stereo WAV.
pub fn write_wav(path: &Path, audio: &Stereo) {
    let spec = hound::WavSpec {
        channels: 2,
        sample_rate: SAMPLE_RATE as u32,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let mut w = hound::WavWriter::create(path, spec).expect("create the WAV");
    for (l, r) in audio.left.iter().zip(&audio.right) {
        w.write_sample(*l).expect("write");
        w.write_sample(*r).expect("write");
    }
    w.finalize().expect("finish the WAV");
}

/// Reads a render [`write_wav`] wrote.
pub fn read_wav(path: &Path) -> Stereo {
    let mut r =
        hound::WavReader::open(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let samples: Vec<f32> = r.samples::<f32>().map(|s| s.expect("a sample")).collect();
    Stereo {
        left: samples.iter().step_by(2).copied().collect(),
        right: samples.iter().skip(1).step_by(2).copied().collect(),
    }
}

/// Every committed fixture: (file stem, state path, reference path), sorted.
pub fn committed() -> Vec<(String, PathBuf, PathBuf)> {
    let mut out: Vec<_> = std::fs::read_dir(dir())
        .map(|d| {
            d.filter_map(Result::ok)
                .map(|e| e.path())
                .collect::<Vec<_>>()
        })
        .unwrap_or_default()
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .map(|p| {
            let stem = p
                .file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned();
            (stem, p.clone(), p.with_extension("wav"))
        })
        .collect();
    out.sort();
    out
}
