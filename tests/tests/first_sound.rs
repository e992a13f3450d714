//! Time to first sound in the CLAP test host, as a DAW opening a project meets it: the host
//! loads a state whose model is a preset, then plays 10 ms blocks, a note in the first. The
//! table printed (`cargo test -p ressort-tests --test first_sound -- --nocapture`) gives, per
//! preset, how long the state load held the host's thread and when the first sample of the
//! new model came out, both from the request. A preset's analyses come from the shipped table
//! (engine/src/instrument/analyses.rs), a script loaded before from the process's memory;
//! a script never seen is analysed in the load, and is measured too.
//!
//! The times are printed, not asserted (they depend on the machine and its load): what is
//! asserted is that the load adds no block of latency: the first sound comes in the block
//! where it comes when the model was loaded long before (a strike takes a few milliseconds to
//! cross a large plate to its listening point).

use ressort_tests::presets::presets;
use ressort_tests::{state, Block, Score, TestPlugin};
use std::time::Instant;

const SR: f64 = 48_000.0;
const BLOCK: usize = 480;

struct Measured {
    load_ms: f64,
    first_ms: f64,
    /// Blocks played after the load until the first sounding one (1: the first block).
    blocks: usize,
}

/// A C4 at the start of the first block, then blocks until one sounds (1: the first), at most
/// 100. One note, not one per block: a key that throws a ball or a mallet throws it again at
/// each note, and the Bouncing Ball, tossed up every 10 ms, would never land.
fn blocks_to_sound(plugin: &mut TestPlugin, name: &str) -> Option<usize> {
    let note = Score::new().note_on(0, 60, 0.8).events;
    for blocks in 1..=100 {
        let block = Block {
            frames: BLOCK,
            events: if blocks == 1 { &note } else { &[] },
            ..Block::default()
        };
        let p = plugin.process(&block);
        assert!(p.left.iter().all(|s| s.is_finite()), "{name}: finite");
        if p.left.iter().chain(p.right).any(|s| *s != 0.0) {
            return Some(blocks);
        }
    }
    None
}

/// The blocks a note takes to sound on an instance that loaded the model long before.
fn own_onset(name: &str, script: &str) -> usize {
    let mut plugin = TestPlugin::new();
    let blob = state::with_musical_model(&plugin.save_state(), name, script);
    plugin.load_state(&blob).expect("it loads");
    plugin.activate(SR, 1, BLOCK as u32);
    for _ in 0..20 {
        plugin.process(&Block::silent(BLOCK));
    }
    let onset = blocks_to_sound(&mut plugin, name).expect("it sounds");
    plugin.deactivate();
    onset
}

/// A fresh instance (its default model silent), then the state with `script`, then a C4 and
/// blocks until one sounds.
fn first_sound(name: &str, script: &str) -> Measured {
    let mut plugin = TestPlugin::new();
    plugin.activate(SR, 1, BLOCK as u32);
    for _ in 0..3 {
        let p = plugin.process(&Block::silent(BLOCK));
        assert!(
            p.left.iter().all(|s| *s == 0.0),
            "the default model is silent at rest"
        );
    }
    let blob = state::with_musical_model(&plugin.save_state(), name, script);
    let t0 = Instant::now();
    plugin
        .load_state(&blob)
        .unwrap_or_else(|e| panic!("{name} loads: {e}"));
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let blocks = blocks_to_sound(&mut plugin, name)
        .unwrap_or_else(|| panic!("{name} does not sound within 100 blocks of its state load"));
    let first_ms = t0.elapsed().as_secs_f64() * 1e3;
    plugin.deactivate();
    Measured {
        load_ms,
        first_ms,
        blocks,
    }
}

#[test]
fn every_preset_sounds_in_the_first_block_after_its_state_load() {
    println!("| preset | state load (ms) | first sound (ms) |");
    println!("|---|---:|---:|");
    let mut slowest = (0.0f64, String::new());
    for (name, text) in presets() {
        let m = first_sound(&name, &text);
        println!("| {name} | {:.1} | {:.1} |", m.load_ms, m.first_ms);
        assert_eq!(
            m.blocks,
            own_onset(&name, &text),
            "{name}: the load delays the first sound by a block or more"
        );
        if m.first_ms > slowest.0 {
            slowest = (m.first_ms, name);
        }
    }
    println!("slowest first sound: {} at {:.1} ms", slowest.1, slowest.0);
    // A script no table knows (an edited preset) is analysed in its first load, and kept for
    // the next.
    let edited = format!(
        "{}\n# edited\n",
        include_str!("../../models/string-1000.mdl")
    );
    let first = first_sound("Custom", &edited);
    let again = first_sound("Custom", &edited);
    println!(
        "an edited string-1000: first load {:.1} ms (analysed), again {:.1} ms (kept)",
        first.first_ms, again.first_ms
    );
    let onset = own_onset("Custom", &edited);
    assert_eq!((first.blocks, again.blocks), (onset, onset));
}
