//! The analyses kept for the presets (`models/analyses.txt`, engine/src/instrument/analyses.rs):
//! the shipped table covers every preset as written today at every shipped rate, it equals a
//! fresh analysis, and a model prepared from kept analyses plays the samples the analysed one
//! plays.

mod common;

use common::presets;
use ressort_engine::instrument::analyses::{self, Analyses, AGREEMENT, SHIPPED_RATES};
use ressort_engine::instrument::pitch::PITCH_BITS;
use ressort_engine::instrument::{
    prepare_analysed, prepare_analysed_at_pitch, prepare_with, Controls, Conventions, Event,
    Instrument, Prepared, Timed, MAX_HOST_INPUTS, MAX_HOST_OUTPUTS,
};

const REGENERATE: &str =
    "cargo run --release -p ressort-engine --example analyses_table -- --write";

#[test]
fn the_shipped_table_covers_every_preset_as_written_today() {
    let table = analyses::shipped();
    let presets = presets();
    let mut missing = Vec::new();
    for (name, text) in &presets {
        for rate in SHIPPED_RATES {
            if table.find(text, rate).is_none() {
                missing.push(format!("{name} at {rate} Hz"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "models/analyses.txt has no analyses for {} (a preset changed or was added): run `{REGENERATE}`",
        missing.join(", ")
    );
    assert_eq!(
        table.entries.len(),
        presets.len() * SHIPPED_RATES.len(),
        "models/analyses.txt holds entries of scripts no longer in models/: run `{REGENERATE}`"
    );
    println!(
        "{} presets × {} rates: {} entries",
        presets.len(),
        SHIPPED_RATES.len(),
        table.entries.len()
    );
}

/// A phrase through the instrument, without resetting the model first: notes, a chord, a
/// moved macro, and the model's own state carried from one block to the next.
fn play(model: Prepared, sr: f64) -> Vec<u32> {
    let controls = Controls::DEFAULT;
    let mut inst = Instrument::new(sr, controls);
    inst.set_model(Box::new(model));
    let frames = (0.6 * sr) as usize;
    let events = [
        (0, Event::note_on(60, 0.8)),
        (4000, Event::note_on(67, 0.5)),
        (9000, Event::note_off(60)),
        (12000, Event::note_on(48, 1.0)),
        (20000, Event::note_off(67)),
    ];
    let mut moved = controls;
    moved.macros[0] = 0.8;
    moved.macros[1] = 0.2;
    let mut out = vec![vec![0.0f32; frames]; 2];
    let mut done = 0;
    while done < frames {
        let len = 333.min(frames - done);
        let mut evs = events
            .iter()
            .filter(|(t, _)| *t >= done && *t < done + len)
            .map(|&(t, e)| Timed::new((t - done) as u32, e));
        let host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
        let c = if done > frames / 2 { &moved } else { &controls };
        let mut slices: Vec<&mut [f32]> =
            out.iter_mut().map(|c| &mut c[done..done + len]).collect();
        inst.process(
            len,
            &host,
            false,
            &mut evs,
            c,
            &mut slices[..2.min(MAX_HOST_OUTPUTS)],
        );
        done += len;
    }
    out.concat().iter().map(|s| s.to_bits()).collect()
}

/// At 48 kHz (the other rates take a minute and a half more; the example's check mode
/// compares them all), on two threads: each preset analysed afresh (the macro units without
/// a budget, as the table holds them) agrees with the shipped entry, to the last bits the
/// processor's SIMD width moves ([`AGREEMENT`]), and the model loaded from kept analyses plays
/// the analysed model's samples. The entries written before fresh pitches were rounded
/// (`settle_pitch`) keep their unrounded pitch, and the level calibration's renders carry a
/// pitch's last bits far (a bouncing ball's trim moved 4e-5, a trim search took another
/// branch): the rest of the analysis runs at the entry's own pitch, and the fresh pitch is
/// compared apart, within half a step of the rounding grid.
#[test]
fn the_shipped_table_equals_a_fresh_analysis_and_plays_its_samples() {
    let sr = 48000.0;
    let presets = presets();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let outcomes = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some((name, text)) = presets.get(i) else {
                    break;
                };
                let shipped = analyses::shipped().find(text, sr);
                let at = shipped.as_ref().and_then(|s| s.reference_pitch_hz);
                let analysed = prepare_analysed_at_pitch(
                    name,
                    text,
                    sr,
                    Conventions::Musical,
                    f64::INFINITY,
                    at,
                )
                .expect("a preset prepares");
                let fresh = Analyses::of(analysed.facts());
                let pitch = prepare_analysed(name, text, sr, Conventions::Musical, 0.0)
                    .expect("a preset prepares")
                    .facts()
                    .settings
                    .reference_pitch_hz;
                let grid = 0.5f64.powi(PITCH_BITS as i32 + 1) * (1.0 + 1e-9) + AGREEMENT;
                let distance = shipped
                    .ok_or_else(|| "no entry".to_string())
                    .and_then(|s| s.distance(&fresh))
                    .and_then(|d| match (at, pitch) {
                        (None, None) => Ok(d),
                        (Some(a), Some(b)) if ((a - b) / a).abs() <= grid => Ok(d),
                        _ => Err(format!("pitch {at:?} against a fresh {pitch:?}")),
                    });
                // The loading path (kept analyses applied to a new preparation) with this
                // machine's analyses: the samples must not depend on where they came from.
                analyses::remember(text, sr, Conventions::Musical, fresh.clone());
                let kept = prepare_with(name, text, sr, Conventions::Musical).expect("it loads");
                let same_facts = Analyses::of(kept.facts()) == fresh;
                let (a, b) = (play(analysed, sr), play(kept, sr));
                let first = a.iter().zip(&b).position(|(x, y)| x != y);
                let sounds = a.iter().any(|&s| f32::from_bits(s) != 0.0);
                outcomes
                    .lock()
                    .unwrap()
                    .push((name.clone(), distance, same_facts, first, sounds));
            });
        }
    });
    let outcomes = outcomes.into_inner().unwrap();
    let stale: Vec<String> = outcomes
        .iter()
        .filter_map(|o| match &o.1 {
            Ok(d) if *d <= AGREEMENT => None,
            Ok(d) => Some(format!("{} (relative difference {d:.1e})", o.0)),
            Err(e) => Some(format!("{} ({e})", o.0)),
        })
        .collect();
    assert!(
        stale.is_empty(),
        "the analyses of {stale:?} changed (a law or an analysis changed): run `{REGENERATE}`, \
         and say in the commit why they changed"
    );
    let (exact, worst) = outcomes.iter().fold((0, 0.0f64), |(n, w), o| {
        let d = *o.1.as_ref().unwrap();
        (n + usize::from(d == 0.0), w.max(d))
    });
    for (name, _, same_facts, first, sounds) in &outcomes {
        assert!(same_facts, "{name}: the facts of the kept analyses");
        assert_eq!(*first, None, "{name}: the kept analyses play other samples");
        assert!(sounds, "{name} sounds");
    }
    println!(
        "{} presets: the table agrees with a fresh analysis ({exact} bit for bit, the largest \
         relative difference {worst:.1e}), and kept analyses play the same samples",
        outcomes.len()
    );
}

#[test]
fn a_script_analysed_once_is_kept_for_the_process() {
    // Not a preset: the shipped table does not know it.
    let text = "@m1 mass 1. 0. 0.\n@m2 mass 1. 0. 0.\n@g1 ground 0.\n@g2 ground 0.\n\
                @s1 springDamper @g1 @m1 0.01 0.001\n@s2 springDamper @m1 @m2 0.02 0.0001\n\
                @s3 springDamper @m2 @g2 0.01 0.001\n@in1 frcInput @m1\n@out1 posOutput @m2\n";
    let sr = 47000.0;
    for conventions in [Conventions::Musical, Conventions::Legacy] {
        assert!(analyses::recall(text, sr, conventions).is_none());
        let first = prepare_with("kept", text, sr, conventions).expect("it prepares");
        let kept = analyses::recall(text, sr, conventions).expect("its analyses are kept");
        assert_eq!(*kept, Analyses::of(first.facts()));
        let again = prepare_with("kept", text, sr, conventions).expect("it loads again");
        assert_eq!(Analyses::of(again.facts()), Analyses::of(first.facts()));
        assert_eq!(play(first, sr), play(again, sr), "{conventions:?}");
    }
    // Another rate is another model.
    assert!(analyses::recall(text, 44100.0, Conventions::Musical).is_none());
}
