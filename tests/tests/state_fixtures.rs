//! Projects that load forever: the states earlier builds saved (`tests/fixtures/states/`, see
//! `ressort_tests::fixtures`) load into today's plugin, keep what they hold, and play their
//! committed reference phrase bit for bit; parameter ids never change; a state of a newer
//! format is refused and the running model keeps playing.

use ressort_tests::fixtures::{self, RECIPES};
use ressort_tests::{state, TestPlugin};
use serde_json::Value;

/// Fixtures whose render a deliberate change of a law or of the engine moved: (file stem,
/// largest sample difference allowed, why). A change that moves a fixture adds its line here
/// with the figure the test printed, and a migration note in docs/design/plugin.md.
const MIGRATIONS: &[(&str, f32, &str)] = &[
    (
        "f0-custom-script",
        2e-6,
        "analysed reference pitches are rounded to 20 bits of mantissa (8.8e-7 measured)",
    ),
    (
        "f0-legacy-hammer",
        4e-6,
        "analysed reference pitches are rounded to 20 bits of mantissa (1.65e-6 measured)",
    ),
    (
        "f0-mesh-moved-controls",
        1e-4,
        "analysed reference pitches are rounded to 20 bits of mantissa (5.2e-5 measured)",
    ),
    (
        "f1-ab-drunk-triangles",
        1e-7,
        "analysed reference pitches are rounded to 20 bits of mantissa (1.5e-8 measured)",
    ),
    (
        "f1-custom-script",
        2e-6,
        "analysed reference pitches are rounded to 20 bits of mantissa (8.8e-7 measured)",
    ),
    (
        "f1-legacy-hammer",
        4e-6,
        "analysed reference pitches are rounded to 20 bits of mantissa (1.65e-6 measured)",
    ),
    (
        "f1-mesh-moved-controls",
        1e-4,
        "analysed reference pitches are rounded to 20 bits of mantissa (5.2e-5 measured)",
    ),
];

fn blob(path: &std::path::Path) -> Vec<u8> {
    let text = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    state::blob(&text)
}

#[test]
fn every_fixture_plays_its_reference_phrase() {
    let committed = fixtures::committed();
    assert!(
        committed.len() >= RECIPES.len(),
        "expected the committed fixtures in {}, found {}",
        fixtures::dir().display(),
        committed.len()
    );
    for (stem, json, wav) in &committed {
        let reference = fixtures::read_wav(wav);
        let audio = fixtures::render(&blob(json));
        assert!(audio.is_finite(), "{stem}: non-finite output");
        assert_eq!(audio.len(), reference.len(), "{stem}: length");
        let max_diff = audio
            .samples()
            .zip(reference.samples())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        let first = audio.first_difference(&reference);
        println!(
            "{stem:>28}: peak {:.3}, reference peak {:.3}, first difference {first:?}, \
             largest {max_diff:e}",
            audio.peak(),
            reference.peak()
        );
        match MIGRATIONS.iter().find(|m| m.0 == stem) {
            Some((_, tolerance, why)) => assert!(
                max_diff <= *tolerance,
                "{stem}: differs by {max_diff:e}, more than the {tolerance:e} of its migration \
                 ({why})"
            ),
            None => assert_eq!(
                first, None,
                "{stem}: the render differs from the reference (largest difference \
                 {max_diff:e}); a deliberate change needs a line in MIGRATIONS"
            ),
        }
    }
}

/// The persisted fields of a saved state, each parsed (they are JSON texts).
fn fields(blob: &[u8]) -> serde_json::Map<String, Value> {
    let v = state::json(blob).expect("a state");
    v["fields"]
        .as_object()
        .expect("fields")
        .iter()
        .map(|(k, text)| {
            let parsed = serde_json::from_str(text.as_str().expect("a JSON text")).expect("JSON");
            (k.clone(), parsed)
        })
        .collect()
}

/// The parsed fields without the analyses saved with the model and the A/B slots.
fn strip_analyses(fields: &mut serde_json::Map<String, Value>) {
    if let Some(m) = fields.get_mut("model").and_then(Value::as_object_mut) {
        m.remove("analyses");
    }
    if let Some(slots) = fields
        .get_mut("compare")
        .and_then(|c| c.get_mut("slots"))
        .and_then(Value::as_array_mut)
    {
        for slot in slots.iter_mut().filter_map(Value::as_object_mut) {
            slot.remove("analyses");
        }
    }
}

/// A saved project's fields and parameters, without the analyses saved with its scripts
/// (those of a script analysed since the save come along when it is saved again).
fn project(blob: &[u8]) -> (serde_json::Map<String, Value>, Value) {
    let mut f = fields(blob);
    strip_analyses(&mut f);
    (f, state::json(blob).expect("a state")["params"].clone())
}

#[test]
fn a_fixture_saved_again_keeps_its_model_parameters_bindings_and_slots() {
    for (stem, json, _) in fixtures::committed() {
        let old = blob(&json);
        let mut plugin = TestPlugin::new();
        plugin.load_state(&old).expect("the fixture loads");
        plugin.activate(fixtures::SAMPLE_RATE, 1, fixtures::BLOCK as u32);
        plugin.deactivate();
        let again = plugin.save_state();
        let (before, mut after) = (fields(&old), fields(&again));
        // A script the plugin does not ship is saved again with its analyses (the
        // `analyses` member, new since these fixtures): the rest is as it was.
        strip_analyses(&mut after);
        for key in ["model", "cc_map", "compare"] {
            if let Some(saved) = before.get(key) {
                assert_eq!(after.get(key), Some(saved), "{stem}: field {key}");
            }
        }
        let params = |b: &[u8]| state::json(b).expect("a state")["params"].clone();
        assert_eq!(params(&again), params(&old), "{stem}: parameters");
        println!(
            "{stem:>28}: format {} saved again as format {}; fields {:?} kept",
            fixtures::format_of(&old),
            fixtures::format_of(&again),
            before.keys().collect::<Vec<_>>()
        );
    }
}

/// Every recipe has a fixture in the format this build writes, so a new format cannot land
/// without the states that pin it.
#[test]
fn the_current_format_has_its_fixtures() {
    let format = fixtures::format_of(&TestPlugin::new().save_state());
    let committed = fixtures::committed();
    for recipe in RECIPES {
        let stem = format!("f{format}-{}", recipe.name);
        assert!(
            committed.iter().any(|c| c.0 == stem),
            "no fixture {stem}: run `cargo run -p ressort-tests --bin ressort-fixtures` and \
             commit what it writes"
        );
    }
    println!("state format {format}: {} fixtures in all", committed.len());
}

#[test]
fn parameter_ids_never_change() {
    let path = fixtures::parameter_ids_path();
    let text = std::fs::read_to_string(&path).expect("the committed parameter ids");
    let committed: Vec<(String, u32, String)> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .map(|l| {
            let mut f = l.split('\t');
            let id = f.next().expect("an id").to_string();
            let host = f.next().and_then(|h| h.parse().ok()).expect("a host id");
            let name = f.next().expect("a name").to_string();
            (id, host, name)
        })
        .collect();
    let mut plugin = TestPlugin::new();
    let saved = state::json(&plugin.save_state()).expect("a state");
    let saved_ids: Vec<&String> = saved["params"]
        .as_object()
        .expect("params")
        .keys()
        .collect();
    let host: Vec<(u32, String)> = plugin
        .params()
        .iter()
        .map(|p| (p.id.get(), p.name.clone()))
        .collect();
    for (id, host_id, name) in &committed {
        assert!(
            saved_ids.contains(&id),
            "parameter id {id} is gone from the state"
        );
        assert!(
            host.iter().any(|h| h.0 == *host_id && h.1 == *name),
            "the host no longer sees {id} as {host_id} \"{name}\""
        );
    }
    for id in &saved_ids {
        assert!(
            committed.iter().any(|c| &&c.0 == id),
            "new parameter {id}: add it to {} (rerun ressort-fixtures)",
            path.display()
        );
    }
    assert_eq!(host.len(), committed.len(), "the host's parameter count");
    println!("{} parameter ids as committed", committed.len());
}

#[test]
fn a_state_of_a_newer_format_is_refused_and_the_model_keeps_playing() {
    let (_, json, _) = fixtures::committed()
        .into_iter()
        .find(|c| c.0.ends_with("custom-script"))
        .expect("a custom-script fixture");
    let running = blob(&json);
    let mut victim = TestPlugin::new();
    let mut twin = TestPlugin::new();
    victim.load_state(&running).expect("loads");
    twin.load_state(&running).expect("loads");
    let before = victim.save_state();

    // A newer Ressort's project: another model, other parameters, a format beyond ours.
    let mut newer = state::with_model(&running, "from the future", "@m mass 1. 0. 0.\n");
    newer = state::with_param(&newer, "stiffness", serde_json::json!({ "f32": 3.0 }));
    newer = state::with_field(&newer, "format", "1000");
    newer = state::with_field(&newer, "cc_map", "[[1, 7]]");
    for active in [false, true] {
        if active {
            victim.activate(fixtures::SAMPLE_RATE, 1, fixtures::BLOCK as u32);
            twin.activate(fixtures::SAMPLE_RATE, 1, fixtures::BLOCK as u32);
        }
        let result = victim.load_state(&newer);
        println!(
            "newer state while {}: {result:?}",
            if active { "active" } else { "inactive" }
        );
        assert!(result.is_err(), "the host was told a refused state loaded");
        assert_eq!(
            project(&victim.save_state()),
            project(&before),
            "the refused state changed the project"
        );
    }
    let score = fixtures::phrase();
    let a = victim.render_song(fixtures::FRAMES, &[fixtures::BLOCK], Some(0), &score);
    let b = twin.render_song(fixtures::FRAMES, &[fixtures::BLOCK], Some(0), &score);
    assert!(a.audio.peak() > 1e-3, "the running model went silent");
    assert_eq!(
        a.audio.first_difference(&b.audio),
        None,
        "the refused state changed the sound"
    );
}
