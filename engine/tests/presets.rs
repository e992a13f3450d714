//! The preset library in `models/`: every file documents itself, parses without errors, passes
//! the stability check and renders finite, non-silent audio when excited.

mod common;

use common::{engine, render};
use ressort_engine::{parse, reference, InputUse};
use std::path::PathBuf;

fn presets() -> Vec<(String, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../models");
    let mut files: Vec<(String, String)> = std::fs::read_dir(&dir)
        .expect("models/ exists")
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "mdl"))
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&p).unwrap())
        })
        .collect();
    files.sort();
    assert!(!files.is_empty());
    files
}

#[test]
fn every_preset_starts_with_a_description() {
    for (name, text) in presets() {
        let header: Vec<&str> = text.lines().take_while(|l| l.starts_with('#')).collect();
        let joined = header.join("\n");
        for word in ["What:", "How to play:", "Source:"] {
            assert!(joined.contains(word), "{name}: header lacks `{word}`");
        }
    }
}

#[test]
fn every_preset_is_stable_and_sounds() {
    for (name, text) in presets() {
        let parsed = parse(&text);
        let errors: Vec<String> = parsed.errors().map(|d| d.to_string()).collect();
        assert!(errors.is_empty(), "{name}: {errors:?}");
        let spec = parsed.spec.unwrap();
        let mut e = engine(&spec, 48_000.0);
        let report = e.stability();
        assert!(report.is_stable(), "{name}: {:?}", report.warnings);
        // Excite: a downward force impulse on every force input, slow motion on avatars.
        let frames = 48_000;
        let inputs: Vec<Vec<f64>> = e
            .info()
            .inputs
            .iter()
            .map(|uses| match uses.first() {
                Some(InputUse::Force(_)) => {
                    let mut v = vec![0.0; frames];
                    v[0] = -0.05;
                    v
                }
                Some(InputUse::Position(_)) => (0..frames)
                    .map(|n| 0.01 * (n as f64 / 4800.0).sin())
                    .collect(),
                Some(InputUse::Param(_)) => vec![0.5; frames],
                None => vec![0.0; frames],
            })
            .collect();
        let out = render(&mut e, frames, 512, &inputs);
        assert!(
            !e.is_tripped(),
            "{name}: guard tripped {:?}",
            e.guard_event()
        );
        for (c, ch) in out.iter().enumerate() {
            assert!(
                ch.iter().all(|v| v.is_finite()),
                "{name}: out{} not finite",
                c + 1
            );
        }
        let peak = out.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(peak > 1e-6, "{name}: silent (peak {peak:e})");
    }
}

#[test]
fn canonical_scripts_equal_the_builder_reference_models() {
    let files = presets();
    let text = |n: &str| &files.iter().find(|f| f.0 == n).unwrap().1;
    for (file, spec) in [
        ("string-1000.mdl", reference::string_1000()),
        ("mesh-15x15.mdl", reference::mesh_15x15()),
        ("mesh-25x20.mdl", reference::mesh_25x20()),
        ("hammer-oscillator.mdl", reference::hammer_oscillator()),
    ] {
        let parsed = parse(text(file)).spec.unwrap();
        assert_eq!(parsed, spec, "{file} differs from the builder model");
    }
}
