//! Projects saved before concert pitch, automatic levels and the calibrated sidechain still
//! sound as they did. Their state carries no playing conventions, so the plugin prepares their
//! script with [`Conventions::Legacy`]: the relative tuning of `~key`, no output trim, the raw
//! sidechain force. The digests below were taken from the instrument as it played before those
//! changes (commit 6cd9438), on every preset: a note at C4 and one at G4 on the same model,
//! and a kick on the sidechain. A change to the legacy path changes a digest.

use ressort_engine::instrument::{
    self, Controls, Conventions, Event, Instrument, Timed, MAX_HOST_INPUTS,
};
use std::path::PathBuf;

const SR: f64 = 48_000.0;
const FRAMES: usize = 12_000;
const BLOCK: usize = 480;

/// The kick of the drum test, quieter (−20 dBFS), so that it does not reach the ceiling.
fn kick(frames: usize) -> Vec<f32> {
    let mut phase = 0.0f64;
    (0..frames)
        .map(|n| {
            let t = n as f64 / SR;
            let f = 50.0 + 70.0 * (-t / 0.03).exp();
            phase += std::f64::consts::TAU * f / SR;
            (0.1 * (-t / 0.06).exp() * phase.sin()) as f32
        })
        .collect()
}

/// FNV-1a over the bits of every output sample.
fn digest(channels: &[Vec<f32>]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for c in channels {
        for s in c {
            for b in s.to_bits().to_le_bytes() {
                h ^= b as u64;
                h = h.wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
    }
    h
}

fn play(script: &str, events: &[(u32, Event)], sidechain: Option<&[f32]>) -> u64 {
    let mut model = instrument::prepare_with("legacy", script, SR, Conventions::Legacy)
        .expect("the preset prepares");
    if let Some(v) = model.facts().settings.voices {
        model.set_voices(v as usize);
    }
    let controls = Controls::LEGACY;
    let mut inst = Instrument::new(SR, controls);
    inst.set_model(Box::new(model));
    let mut out = vec![vec![0.0f32; FRAMES]; 2];
    let mut done = 0;
    while done < FRAMES {
        let len = BLOCK.min(FRAMES - done);
        let mut evs = events
            .iter()
            .filter(|(t, _)| (*t as usize) >= done && (*t as usize) < done + len)
            .map(|&(t, e)| Timed::new(t - done as u32, e));
        let mut host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
        if let Some(s) = sidechain {
            host[2] = Some(&s[done..]);
            host[3] = Some(&s[done..]);
        }
        let (l, r) = out.split_at_mut(1);
        let mut slices: [&mut [f32]; 2] =
            [&mut l[0][done..done + len], &mut r[0][done..done + len]];
        inst.process(len, &host, false, &mut evs, &controls, &mut slices);
        done += len;
    }
    digest(&out)
}

/// (preset, digest of C4 then G4, digest of the kick) as played before the change.
///
/// Eight note digests (chladni-150x150, fretted-string, harmonic-oscillator, mesh-15x15,
/// mesh-25x20, oscillator-bank, rolling-mesh, string-1000) were taken again when analysed
/// reference pitches began to be rounded to 20 bits of mantissa (`instrument::pitch::
/// settle_pitch`, at most 0.83 thousandths of a cent), so that a project tunes alike on every
/// processor; the kick digests did not move.
const DIGESTS: &[(&str, u64, u64)] = &[
    ("bowed-oscillator", 0x3dccfc48fb05e91e, 0xb8f680f29b85bea3),
    ("bowed-string", 0x5eac53d274f9ef25, 0x1800fd53d3f3e0bb),
    ("brokendown-string", 0xc505b9459d8b24c5, 0x4143d25d9944028e),
    ("chladni-150x150", 0xbf71a9b4cb263965, 0x2fba98005daf963d),
    (
        "coupled-strings-bowed",
        0xdd8bea797cc1cbda,
        0x5eac53d274f9ef25,
    ),
    ("drunk-triangles", 0x6f384fc0214b3636, 0x9e0e20c433de5354),
    ("drunk-triangles-xl", 0x236aa5aae42f771f, 0x025ae94911a077cc),
    ("fretted-string", 0x4d37c46c719ec086, 0x434f746563b1c5c7),
    ("gravity-oscillator", 0x6f384fc0214b3636, 0x9e0e20c433de5354),
    ("hammer-oscillator", 0x098b678c26f23bff, 0xc43ab8f35dec6f3b),
    (
        "harmonic-oscillator",
        0x58b6b9c2e552984d,
        0xf17b610a073b2921,
    ),
    ("mesh-15x15", 0x0ed6c9d65963a31d, 0x069a245250554739),
    ("mesh-25x20", 0x4b9f0839a8da15c5, 0x0e80f6fc7f6abc61),
    ("nofx-drone", 0xe0f97bc5dad4addd, 0x07d9cdd4fc3280de),
    (
        "nonlinear-oscillator",
        0x9394aa925b723bc3,
        0x8258b77b061bfbf5,
    ),
    ("oscillator-bank", 0x00df3cec65ae79a4, 0x699d14bbbb5cf041),
    ("plucked-harmonics", 0x5eac53d274f9ef25, 0xcb5e5062a908cf11),
    ("plucked-oscillator", 0x3dccfc48fb05e91e, 0xa216a8864d047336),
    ("resonant-strings", 0x5eac53d274f9ef25, 0xe1889bfacd4e0b7d),
    ("rolling-mesh", 0x4c0926e3e27ea76f, 0x5eac53d274f9ef25),
    ("string-1000", 0xff444e8802d0784d, 0x65b0896d83a8aebd),
    ("struck-string", 0x2d1955a2eab4e031, 0xef364e4432d539e5),
    ("two-fingers-string", 0x5eac53d274f9ef25, 0x39dc84d9aa16a2d8),
];

#[test]
fn old_projects_play_as_they_did() {
    // The presets such projects can hold: the ones that existed then, every one still
    // shipped. A preset added since has no legacy project.
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../models");
    let names: Vec<String> = DIGESTS.iter().map(|d| d.0.to_string()).collect();
    let notes = [
        (0, Event::note_on(60, 0.8)),
        (6_000, Event::note_on(67, 0.5)),
    ];
    let drum = kick(FRAMES);
    let mut table = String::new();
    let mut wrong = Vec::new();
    for name in &names {
        let script = std::fs::read_to_string(dir.join(format!("{name}.mdl"))).unwrap();
        let script = legacy_script(name, &script);
        let a = play(&script, &notes, None);
        let b = play(&script, &[], Some(&drum));
        table.push_str(&format!("    (\"{name}\", {a:#018x}, {b:#018x}),\n"));
        match DIGESTS.iter().find(|d| d.0 == name) {
            Some(&(_, da, db)) if (da, db) == (a, b) => {}
            Some(_) => wrong.push(name.clone()),
            None => wrong.push(format!("{name} (no digest)")),
        }
    }
    assert!(
        wrong.is_empty(),
        "legacy renders changed for {wrong:?}; today's digests:\n{table}"
    );
}

/// The preset's script as the projects saved it: the files of `models/` as they were at the
/// commit of the digests. Presets changed since keep their old text in `tests/legacy/`.
fn legacy_script(name: &str, current: &str) -> String {
    let old = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/legacy")
        .join(format!("{name}.mdl"));
    std::fs::read_to_string(old).unwrap_or_else(|_| current.to_string())
}
