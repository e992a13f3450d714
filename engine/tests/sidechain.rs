//! The sidechain as a musician feeds it, through the instrument the plugin runs: a kick
//! strikes like a medium note and never reaches the ceiling, trigger mode turns a drum loop
//! into strikes, and a host signal on a connection point's coordinate glides the point
//! (`instrument::PLACE_GLIDE_MS`) instead of teleporting it.

mod common;

use common::player::{db, preset, Player};
use common::presets;
use ressort_engine::instrument::dsp::CEILING_KNEE;
use ressort_engine::instrument::{self, Controls, Event, Prepared, MAX_HOST_INPUTS};

/// The kick of issue 36: a sine gliding 120 → 50 Hz under a 60 ms decay, twice a second,
/// peaking at −6 dBFS.
fn kick_loop(seconds: f64, sr: f64, hits: &[f64]) -> Vec<f32> {
    let frames = (seconds * sr) as usize;
    let mut x = vec![0.0f64; frames];
    for &start in hits {
        let mut phase = 0.0f64;
        for n in 0..(0.4 * sr) as usize {
            let t = n as f64 / sr;
            let f = 50.0 + 70.0 * (-t / 0.03).exp();
            phase += std::f64::consts::TAU * f / sr;
            if let Some(s) = x.get_mut((start * sr) as usize + n) {
                *s += (-t / 0.06).exp() * phase.sin();
            }
        }
    }
    let peak = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scale = 10f64.powf(-6.0 / 20.0) / peak;
    x.iter().map(|v| (v * scale) as f32).collect()
}

#[test]
fn a_kick_on_the_sidechain_strikes_like_a_medium_note() {
    const SR: f64 = 48_000.0;
    let mut p = Player::new(&preset("mesh-15x15"), SR);
    let note = p.note(60, 0.8, 2.0).peak_db();
    let hits: Vec<f64> = (0..8).map(|i| 0.5 * i as f64).collect();
    let kick = kick_loop(4.0, SR, &hits);
    let take = p.play(Controls::DEFAULT, &[], Some(&kick), 4.0);
    let struck = take.peak_db();
    println!("mesh-15x15: note {note:.1} dBFS, kick {struck:.1} dBFS");
    assert!(
        (struck - note).abs() <= 6.0,
        "kick {struck:.1} vs note {note:.1} dBFS"
    );
    assert!(
        struck < db(CEILING_KNEE),
        "the kick reaches the ceiling: {struck:.1} dBFS"
    );
    // The same kick through every preset: where the sidechain pushes the model it strikes,
    // and nowhere does it reach the ceiling.
    let mut hot = Vec::new();
    for (name, script) in presets() {
        let mut p = Player::new(&script, SR);
        let note = p.note(60, 0.8, 2.0).peak_db();
        let struck = p
            .play(Controls::DEFAULT, &[], Some(&kick[..96_000]), 2.0)
            .peak_db();
        println!("{name:<26} note {note:6.1} dBFS, kick {struck:6.1} dBFS");
        if struck >= db(CEILING_KNEE) {
            hot.push(format!("{name}: {struck:.1} dBFS"));
        }
    }
    assert!(hot.is_empty(), "a kick reaches the ceiling: {hot:?}");
}

#[test]
fn trigger_mode_turns_a_four_hit_drum_loop_into_four_strikes() {
    const SR: f64 = 48_000.0;
    let hits = [0.25, 0.75, 1.25, 1.75];
    let kick = kick_loop(2.2, SR, &hits);
    let trigger = Controls {
        trigger: true,
        ..Controls::DEFAULT
    };
    // A model without voices: each hit strikes it where the drum hits.
    let mut p = Player::new(&preset("mesh-15x15"), SR);
    let take = p.play(trigger, &[], Some(&kick), 2.2);
    assert_eq!(take.triggered, 4, "four hits, four strikes");
    let note = p.note(60, 0.8, 0.5).peak();
    for &t in &hits {
        let before = take.peak_between(SR, t - 0.1, t);
        let hit = take.peak_between(SR, t, t + 0.1);
        println!(
            "hit at {t} s: {:.1} dBFS (before {:.1})",
            db(hit),
            db(before)
        );
        assert!(hit > before, "a strike at {t} s");
        // A −6 dBFS hit plays velocity 0.8: a medium note, within 3 dB.
        assert!(
            (db(hit) - db(note)).abs() < 3.0,
            "{:.1} vs {:.1}",
            db(hit),
            db(note)
        );
    }
    // Without trigger mode the same loop pushes the model as a force: no strikes.
    let raw = p.play(Controls::DEFAULT, &[], Some(&kick), 2.2);
    assert_eq!(raw.triggered, 0);
    assert_ne!(raw.channels, take.channels);
    // With voices: each hit plays a voice of its own.
    let mut v = Player::new(&preset("struck-string"), SR);
    let take = v.play(trigger, &[], Some(&kick), 2.2);
    assert_eq!(take.triggered, 4);
    assert!(take.peak() > 1e-3);
}

/// Full-scale white noise, the same every run (a 64-bit LCG's high bits).
fn white_noise(frames: usize, seed: u64) -> Vec<f32> {
    let mut s = seed;
    (0..frames)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) as f32
        })
        .collect()
}

/// A sidechain routed to a finger's place (an `audioParam` in a connection point's
/// coordinate) slides the finger instead of teleporting it: full-scale noise there blew Two
/// Fingers String up at 192 kHz (its contacts injecting energy at every jump, spec §2.8).
#[test]
fn noise_on_a_fingers_place_slides_it_and_trips_no_guard() {
    for sr in [48_000.0, 192_000.0] {
        let mut p = Player::new(&preset("two-fingers-string"), sr);
        let noise = white_noise((1.5 * sr) as usize, 7);
        let take = p.play(
            Controls::DEFAULT,
            &[(0, Event::note_on(60, 0.8))],
            Some(&noise),
            1.5,
        );
        let finite = take.channels.iter().flatten().all(|v| v.is_finite());
        println!(
            "two-fingers-string at {sr} Hz, noise on the fingers: peak {:.3}, {} trip(s)",
            take.peak(),
            take.trips
        );
        assert_eq!(take.trips, 0, "the guard tripped at {sr} Hz");
        assert!(finite, "non-finite output at {sr} Hz");
        assert!(take.peak() > 1e-3, "the note went silent at {sr} Hz");
    }
}

/// A model whose `@in2` is an `audioParam` that places `@in1`'s force along a string: in1
/// reads the sidechain's left channel (host channel 2), in2 its right (3).
fn glide_model() -> Prepared {
    let script = "@f audioParam @in2\n@s string 10 1. 0.1 0.001 0. 0.\n\
                  @in1 frcInput [@s f]\n@out1 posOutput [@s 0.5]\n";
    instrument::prepare("glide", script, 48_000.0).expect("it prepares")
}

/// One chunk of the host's channels into `m`'s inputs.
fn fill(m: &mut Prepared, host: &[[f64; instrument::CHUNK]]) {
    let order = ressort_engine::instrument::host::default_order(false);
    m.fill_inputs(host, order, instrument::CHUNK, 1.0, 1.0, false);
}

/// The glide of a coordinate input: a step reaches 1 − 1/e of its height after
/// `PLACE_GLIDE_MS`, inputs that are no coordinate take the host signal as it comes, and a
/// host gone silent lets the coordinate glide back towards its rest.
#[test]
fn a_step_on_a_coordinate_input_glides_and_other_inputs_do_not() {
    let mut m = glide_model();
    let chunk = instrument::CHUNK;
    let mut host = vec![[0.0f64; instrument::CHUNK]; MAX_HOST_INPUTS];
    host[2] = [0.25; instrument::CHUNK];
    host[3] = [1.0; instrument::CHUNK];
    let frames = (instrument::PLACE_GLIDE_MS * 1e-3 * 48_000.0) as usize;
    let mut seen = Vec::new();
    let mut forces = Vec::new();
    for _ in 0..frames.div_ceil(chunk) {
        fill(&mut m, &host);
        forces.extend_from_slice(&m.inputs[..chunk]);
        seen.extend_from_slice(&m.inputs[chunk..2 * chunk]);
    }
    let at = seen[frames - 1];
    println!("a step of 1 on the coordinate: {at:.4} after {frames} samples");
    assert!((at - (1.0 - (-1.0f64).exp())).abs() < 0.01, "{at}");
    assert!(seen.windows(2).all(|w| w[1] > w[0]), "the glide rises");
    let force = forces[0];
    assert!(
        force != 0.0 && forces.iter().all(|&f| f == force),
        "{forces:?}"
    );
    // Silence: the coordinate glides back down.
    host[3] = [0.0; instrument::CHUNK];
    fill(&mut m, &host);
    assert!(m.inputs[chunk..2 * chunk].iter().all(|&v| v < at));
}

/// A coordinate gliding back to rest lands on it: after the host falls silent it reads 0
/// exactly, never a subnormal on its way.
#[test]
fn a_coordinate_glides_back_to_its_rest_exactly() {
    let mut m = glide_model();
    let chunk = instrument::CHUNK;
    let mut host = vec![[0.0f64; instrument::CHUNK]; MAX_HOST_INPUTS];
    host[3] = [0.7; instrument::CHUNK];
    for _ in 0..100 {
        fill(&mut m, &host);
    }
    host[3] = [0.0; instrument::CHUNK];
    let mut last = f64::NAN;
    for _ in 0..96_000 / chunk {
        fill(&mut m, &host);
        for &v in &m.inputs[chunk..2 * chunk] {
            assert!(v == 0.0 || v.is_normal(), "a subnormal glide value {v:e}");
        }
        last = m.inputs[2 * chunk - 1];
    }
    assert_eq!(
        last.to_bits(),
        0.0f64.to_bits(),
        "the glide ends at {last:e}"
    );
}
