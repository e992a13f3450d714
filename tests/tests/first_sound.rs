//! Time to first sound in the CLAP test host, as a DAW opening a project meets it: the host
//! loads a state whose model is a preset, then plays 10 ms blocks, a note in the first. The
//! table printed (`cargo test -p ressort-tests --test first_sound -- --nocapture`) gives, per
//! preset, how long the state load held the host's thread and when the first sample of the
//! new model came out, both from the request. A preset's analyses come from the shipped table
//! (engine/src/instrument/analyses.rs), a script loaded before from the process's memory;
//! a script never seen plays at once on provisional facts while its exact analyses run on a
//! thread of the plugin (a realtime host), or is analysed in the load (an offline one), and
//! is measured both ways.
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

/// A fresh instance (its default model silent), live (`realtime`) or bouncing, then the state
/// with `script`, then a C4 and blocks until one sounds.
fn first_sound(name: &str, script: &str, realtime: bool) -> Measured {
    let mut plugin = if realtime {
        TestPlugin::realtime()
    } else {
        TestPlugin::new()
    };
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
        let m = first_sound(&name, &text, true);
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
    // A script no table knows (an edited preset): offline it is analysed in its first load;
    // live it plays at once on provisional facts. Either way its analyses are kept for the
    // next load.
    let string = include_str!("../../models/string-1000.mdl");
    let edited = |tag: &str| format!("{string}\n# edited {tag}\n");
    let bounced = first_sound("Custom", &edited("offline"), false);
    let again = first_sound("Custom", &edited("offline"), true);
    let live = first_sound("Custom", &edited("live"), true);
    println!(
        "an edited string-1000: first load {:.1} ms offline (analysed in the load), {:.1} ms \
         live (provisional), again {:.1} ms (kept)",
        bounced.first_ms, live.first_ms, again.first_ms
    );
    let onset = own_onset("Custom", &edited("offline"));
    assert_eq!((bounced.blocks, again.blocks), (onset, onset));
    // The provisional model's stiffness is tuned on its own pitch, not yet the analysed one: a
    // strike crosses the string at another speed.
    assert!(
        live.blocks <= onset + 1,
        "the provisional string sounds in block {} (the analysed one in {onset})",
        live.blocks
    );
}

#[test]
fn live_a_new_script_plays_at_once_and_takes_its_exact_analyses_while_it_plays() {
    // A DAW playing live loads a project whose script the plugin has never seen: it sounds at
    // once, its exact analyses arrive while it plays (the saved state then carries them), and
    // nothing it plays meanwhile is out of bounds.
    let script = format!(
        "{}\n# edited live\n",
        include_str!("../../models/mesh-25x20.mdl")
    );
    let mut plugin = TestPlugin::realtime();
    plugin.activate(SR, 1, BLOCK as u32);
    let blob = state::with_musical_model(&plugin.save_state(), "Custom", &script);
    plugin.load_state(&blob).expect("it loads");
    assert!(
        !state::has_analyses(&plugin.save_state()),
        "the exact analyses are still running"
    );
    let note = Score::new().note_on(0, 60, 0.8).events;
    let t0 = Instant::now();
    let mut blocks = 0;
    let mut sounded = false;
    while !state::has_analyses(&plugin.save_state()) {
        assert!(
            t0.elapsed().as_secs() < 300,
            "the exact analyses never came"
        );
        let block = Block {
            frames: BLOCK,
            events: if blocks == 0 { &note } else { &[] },
            ..Block::default()
        };
        let p = plugin.process(&block);
        for s in p.left.iter().chain(p.right) {
            assert!(s.is_finite() && s.abs() <= 1.0, "block {blocks}: {s}");
        }
        sounded |= p.left.iter().any(|s| *s != 0.0);
        blocks += 1;
    }
    assert!(sounded, "the provisional model sounds");
    println!(
        "an edited mesh-25x20, live: exact analyses after {:.0} ms ({blocks} blocks played)",
        t0.elapsed().as_secs_f64() * 1e3
    );
    // The exact model plays on, and a new note sounds on it.
    let mut peak = 0.0f32;
    for b in 0..100 {
        let block = Block {
            frames: BLOCK,
            events: if b == 10 { &note } else { &[] },
            ..Block::default()
        };
        let p = plugin.process(&block);
        for s in p.left.iter().chain(p.right) {
            assert!(s.is_finite() && s.abs() <= 1.0);
            peak = peak.max(s.abs());
        }
    }
    assert!(peak > 1e-3, "the refined model plays ({peak})");
    plugin.deactivate();
}

/// The environment variable that makes [`a_project_reopens_with_its_scripts_analyses`] the
/// child process: the state file to reopen.
const REOPEN_ENV: &str = "RESSORT_REOPEN_STATES";
/// The preset whose edited script the reopen test saves (harmonic-oscillator unless set:
/// `RESSORT_REOPEN_PRESET=string-1000` shows what a large model saves).
const REOPEN_PRESET_ENV: &str = "RESSORT_REOPEN_PRESET";

/// A C4 for half a second from a loaded state: the peak and the FNV-1a hash of its bits.
fn reopen_phrase(plugin: &mut TestPlugin) -> (f32, u64) {
    let r = plugin.render(0.5, BLOCK, &Score::new().note_on(0, 60, 0.8));
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for s in r.audio.samples() {
        for b in s.to_bits().to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }
    (r.audio.peak(), h)
}

/// The child's part: each state in a fresh instance of a fresh process (no analysis kept in
/// its memory), loaded while active, as a DAW switching projects does.
fn reopen(path: &str) -> String {
    let blob = std::fs::read(path).expect("the saved state");
    let mut plugin = TestPlugin::new();
    plugin.activate(SR, 1, BLOCK as u32);
    let t0 = Instant::now();
    plugin.load_state(&blob).expect("the saved state loads");
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let (peak, hash) = reopen_phrase(&mut plugin);
    plugin.deactivate();
    format!("reopened {load_ms} {peak} {hash:016x}")
}

/// A user's own script is analysed the first time it loads, and the project saves what the
/// analyses found with it: reopened in a new process, it plays the same bits without
/// analysing again. That the saved analyses are the ones used shows in a copy whose output
/// trim was halved (it plays at half the level); a copy from a build with other analyses (its
/// fingerprint) and one whose trim is not a number are analysed afresh.
#[test]
fn a_project_reopens_with_its_scripts_analyses() {
    if let Ok(file) = std::env::var(REOPEN_ENV) {
        println!("{}", reopen(&file));
        return;
    }
    let preset = std::env::var(REOPEN_PRESET_ENV).unwrap_or("harmonic-oscillator".into());
    let text = presets()
        .into_iter()
        .find(|p| p.0 == preset)
        .unwrap_or_else(|| panic!("no preset {preset}"))
        .1;
    let edited = format!("{text}\n# a user's own copy\n");
    let mut plugin = TestPlugin::new();
    plugin.activate(SR, 1, BLOCK as u32);
    let blob = state::with_musical_model(&plugin.save_state(), "Custom", &edited);
    let t0 = Instant::now();
    plugin.load_state(&blob).expect("the edited script loads");
    let first_ms = t0.elapsed().as_secs_f64() * 1e3;
    let here = reopen_phrase(&mut plugin);
    let saved = plugin.save_state();
    plugin.deactivate();

    let mut v = state::json(&saved).expect("a state");
    let model: serde_json::Value =
        serde_json::from_str(v["fields"]["model"].as_str().expect("a model")).expect("JSON");
    let analyses = model["analyses"]
        .as_str()
        .expect("the saved model carries its analyses")
        .to_string();
    assert!(analyses.starts_with("fingerprint "), "{analyses}");
    let compare: serde_json::Value =
        serde_json::from_str(v["fields"]["compare"].as_str().expect("the slots")).expect("JSON");
    let active = compare["active"].as_u64().expect("the running slot") as usize;
    assert!(
        compare["slots"][active].get("analyses").is_none(),
        "the running slot's analyses are the model's, saved once"
    );
    let with_analyses = |v: &mut serde_json::Value, text: String| {
        let mut m = model.clone();
        m["analyses"] = serde_json::Value::String(text);
        v["fields"]["model"] = serde_json::Value::String(m.to_string());
        state::blob_from(v)
    };
    let trims = analyses
        .lines()
        .find(|l| l.starts_with("trims "))
        .expect("a trims line");
    let words: Vec<&str> = trims.split_whitespace().collect();
    let out: f64 = words[1].parse().expect("the output trim");
    let halved = analyses.replace(trims, &format!("trims {:?} {}", out / 2.0, words[2]));
    let stale = format!("fingerprint 0000000000000000\n{}", {
        let (_, rest) = analyses.split_once('\n').expect("more lines");
        rest
    });
    let not_a_number = analyses.replace(trims, &format!("trims NaN {}", words[2]));
    let blobs = [
        saved.clone(),
        with_analyses(&mut v, halved),
        with_analyses(&mut v, stale),
        with_analyses(&mut v, not_a_number),
    ];
    let dir = std::env::temp_dir().join(format!("ressort-reopen-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let files: Vec<String> = blobs
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let f = dir.join(format!("state-{i}.bin"));
            std::fs::write(&f, b).expect("writes the state");
            f.to_string_lossy().into_owned()
        })
        .collect();
    // Each state in a process of its own, as a DAW opening the project anew.
    let rows: Vec<(f64, f32, String)> = files
        .iter()
        .map(|f| {
            let out = ressort_tests::run_child(
                "a_project_reopens_with_its_scripts_analyses",
                REOPEN_ENV,
                f,
            );
            let stdout = String::from_utf8_lossy(&out.stdout);
            let row = stdout
                .lines()
                .find_map(|l| l.split_once("reopened ").map(|(_, row)| row))
                .unwrap_or_else(|| {
                    panic!(
                        "the child printed\n{stdout}\n{}",
                        String::from_utf8_lossy(&out.stderr)
                    )
                })
                .to_string();
            let w: Vec<&str> = row.split_whitespace().collect();
            (
                w[0].parse().unwrap(),
                w[1].parse().unwrap(),
                w[2].to_string(),
            )
        })
        .collect();
    let _ = std::fs::remove_dir_all(&dir);
    let here_hash = format!("{:016x}", here.1);
    println!(
        "edited {preset}: first load {first_ms:.1} ms (analysed); reopened in a new process \
         {:.1} ms (saved analyses), {:.1} ms (stale fingerprint), {:.1} ms (a NaN trim)",
        rows[0].0, rows[2].0, rows[3].0
    );
    println!(
        "peak {} here, reopened {} (hash {} / {})",
        here.0, rows[0].1, here_hash, rows[0].2
    );
    assert_eq!(
        rows[0].2, here_hash,
        "the reopened project plays the same bits"
    );
    let ratio = f64::from(rows[1].1) / f64::from(here.0);
    println!("a halved saved trim plays at {ratio:.4} of the level");
    assert!(
        (ratio - 0.5).abs() < 0.01,
        "the saved trim is the one used: {ratio}"
    );
    for (row, what) in [(&rows[2], "a stale fingerprint"), (&rows[3], "a NaN trim")] {
        let r = f64::from(row.1) / f64::from(here.0);
        assert!(
            (r - 1.0).abs() < 1e-3,
            "{what} is analysed afresh: level {r}"
        );
    }
}
