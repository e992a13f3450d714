//! Replacing the model while the instrument plays: a sounding model crossfades to the new one
//! over 20 ms with both running; a silent one is dropped at once and the new model fades in
//! alone, as the crossfade would have faded it in against silence.

use ressort_engine::instrument::{
    self, Controls, Event, Instrument, Timed, MAX_HOST_INPUTS, SWAP_FADE_MS,
};

const SR: f64 = 48_000.0;
const BLOCK: usize = 64;

/// An oscillator resting at 0 and struck by notes.
const A: &str = "\
@o osc 1. 0.02 0.002 0. 0.
@in1 frcInput @o
@out1 posOutput @o
";

/// An oscillator resting at 0.1: its output starts on a step that a swap must fade in.
const B: &str = "\
@g ground 0.1
@o osc 1. 0.05 0.001 0.1 0.
@l springDamper @g @o 0.01 0.
@in1 frcInput @o
@out1 posOutput @o
";

/// Linear output stage: no DC filter, well below the soft ceiling.
fn linear() -> Controls {
    Controls {
        output_db: -12.0,
        dc_filter: false,
        ..Controls::DEFAULT
    }
}

/// Prepared as a legacy project: today's conventions take each output's rest value off (B
/// would start at 0), and these tests need B's step to see the fade.
fn model(text: &str) -> Box<instrument::Prepared> {
    Box::new(instrument::prepare_with("swap", text, SR, instrument::Conventions::Legacy).unwrap())
}

/// Runs `blocks` blocks; a note-on at the start of the first when `strike`. Returns the left
/// channel and whether each block reported a running fade.
fn run(inst: &mut Instrument, blocks: usize, strike: bool) -> (Vec<f32>, Vec<bool>) {
    let controls = linear();
    let mut left = vec![0.0f32; blocks * BLOCK];
    let mut right = vec![0.0f32; BLOCK];
    let mut fading = Vec::new();
    for b in 0..blocks {
        let note = Event::NoteOn {
            note: 60,
            velocity: 0.9,
            channel: 0,
            voice_id: None,
        };
        let events = if strike && b == 0 {
            vec![Timed::new(0, note)]
        } else {
            vec![]
        };
        let host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
        let mut out: [&mut [f32]; 2] = [&mut left[b * BLOCK..(b + 1) * BLOCK], &mut right];
        let report = inst.process(
            BLOCK,
            &host,
            false,
            &mut events.into_iter(),
            &controls,
            &mut out,
        );
        fading.push(report.fading);
    }
    (left, fading)
}

#[test]
fn a_silent_model_is_replaced_at_once_and_the_new_one_fades_in() {
    let fade = (SWAP_FADE_MS * 1e-3 * SR) as usize;
    let blocks = fade.div_ceil(BLOCK) + 4;
    // The new model alone from the start, for reference (it starts where the swap starts).
    let mut fresh = Instrument::new(SR, linear());
    fresh.set_model(model(B));
    let (reference, _) = run(&mut fresh, blocks, false);
    assert!(reference[0].abs() > 1e-3, "B's output starts on a step");

    let mut inst = Instrument::new(SR, linear());
    assert!(inst.set_model(model(A)).is_none());
    let (before, _) = run(&mut inst, 8, false);
    assert!(before.iter().all(|&y| y == 0.0), "A at rest is silent");
    let replaced = inst.set_model(model(B));
    assert!(
        replaced.is_some(),
        "the silent model comes back at once, to be freed"
    );
    let (after, fading) = run(&mut inst, blocks, false);
    // The fade-in: B's own output times the crossfade's ramp (1 − t), t from 1 to 0.
    for (i, (&y, &r)) in after.iter().zip(&reference).enumerate() {
        let t = if i < fade {
            (fade - i) as f64 / fade as f64
        } else {
            0.0
        };
        let expected = r as f64 * (1.0 - t);
        assert!(
            (y as f64 - expected).abs() <= 1e-6 * r.abs().max(1e-3) as f64,
            "sample {i}: {y} against {expected}"
        );
    }
    assert!(after[0].abs() < reference[0].abs() / 100.0, "no step");
    assert!(fading[0] && !fading[blocks - 1], "{fading:?}");
}

#[test]
fn a_sounding_model_crossfades_with_both_running() {
    let mut inst = Instrument::new(SR, linear());
    inst.set_model(model(A));
    let (struck, _) = run(&mut inst, 8, true);
    assert!(struck.iter().any(|y| y.abs() > 1e-4), "the note sounds");
    assert!(
        inst.set_model(model(B)).is_none(),
        "the sounding model fades out: nothing to free yet"
    );
    let (_, fading) = run(&mut inst, 4, false);
    assert!(fading[0], "{fading:?}");
    let fade_blocks = ((SWAP_FADE_MS * 1e-3 * SR) as usize).div_ceil(BLOCK);
    let (_, fading) = run(&mut inst, fade_blocks, false);
    assert!(!fading[fade_blocks - 1], "{fading:?}");
    assert!(
        inst.take_retired().is_some(),
        "the faded model waits to be freed"
    );
}
