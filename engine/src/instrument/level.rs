//! Automatic levels: every model sounds at one loudness without touching a knob, and a drum
//! on the sidechain strikes it as hard as a medium note.
//!
//! When a model is prepared (today's conventions; legacy projects keep their own levels) the
//! instrument plays it offline, off the audio thread, through its own signal path (tuning,
//! exciters, stability clamp, DC filter):
//!
//! 1. **Rest.** What every output reads at rest ([`Prepared::rest_out`]): a hammer's height,
//!    an avatar's position. It is taken off each copy of the model before the output stage, so
//!    that a voice's note-on is no step of the hammer's height into the output.
//! 2. **A note**: C4 at velocity 0.8 ([`MEASURE_KEY`], [`MEASURE_VELOCITY`]), held for the
//!    render, the peak of every output measured (the main pair and the auxiliary ones). The
//!    output trim puts that peak at [`TARGET_DBFS`]; Output Gain (0 dB by default) adds to it.
//!    Velocity still scales the strike, so softer notes stay softer.
//! 3. **A drum**: a reference kick on the sidechain channels that feed the model, peaking at
//!    [`REFERENCE_DRUM_DBFS`] (a sine gliding 150 → 45 Hz under an 80 ms decay). The input
//!    trim of the host signals that push the model (on its force and position inputs) makes its
//!    answer peak as high as the note did, so a normal drum strikes like a medium note and a
//!    hot one stays below the ceiling. Force and Position Gain (0 dB) add to it. Models the
//!    sidechain does not push keep 0 dB. A hammer between the input and the model makes the
//!    answer far from proportional (a weak push presses the hammer onto a plate, or does not
//!    reach the string at all), so the trim is checked by playing the kick through it and
//!    corrected until the two peaks agree within 2 dB (at most four more renders).
//!
//! A render is at most [`SECONDS`] long, shortened for large models to [`WORK_BUDGET`]
//! element-steps but a note's never below [`NOTE_MIN_SECONDS`] (the 150 × 150 plate gets 3,000
//! samples at 48 kHz, its peak comes after about 1,400, and 11,520 at 192 kHz). A
//! model silent from the note takes its level from the drum; a model silent from both keeps
//! 0 dB.

use super::controls::Controls;
use super::events::{Event, Timed};
use super::prepare::Prepared;
use super::{Instrument, MAX_HOST_INPUTS, MAX_HOST_OUTPUTS};

/// Where the automatic trim puts a C4 note at velocity 0.8.
pub const TARGET_DBFS: f64 = -12.0;
/// The note the level is measured with: the home key of a pitched model.
pub const MEASURE_KEY: u8 = super::prepare::HOME_KEY;
pub const MEASURE_VELOCITY: f32 = 0.8;
/// The peak of the reference drum hits.
pub const REFERENCE_DRUM_DBFS: f64 = -6.0;
/// The longest level render, in seconds: a bow builds up over a second, and a bouncing ball
/// can pass its energy on for as long.
pub const SECONDS: f64 = 1.5;
/// How long [`note_level`] plays: the two seconds of the level band's check, so that a sound
/// that keeps growing after the calibration's render (a squeal, a bow that speaks late) is
/// measured where the band is held.
pub const NOTE_LEVEL_SECONDS: f64 = 2.0;
/// The longest drum render.
const DRUM_SECONDS: f64 = 0.3;
/// Element-steps (points + interactions, times samples) a render may take.
pub const WORK_BUDGET: f64 = 2e8;
/// The shortest note render, whatever [`WORK_BUDGET`] says: a struck model's peak comes a
/// time after the note, not a number of samples (the 150 × 150 plate's hammer meets the
/// plate some 29 ms after it; the budget alone gave it 15 ms at 192 kHz, which measured
/// silence and took the trim from the drum, 74 dB too quiet).
pub const NOTE_MIN_SECONDS: f64 = 0.06;
/// The output gain the renders are measured at, far below the soft ceiling's knee.
const MEASURE_GAIN_DB: f64 = -60.0;
/// The trims stay within these (linear).
const OUTPUT_TRIM_RANGE: (f64, f64) = (1e-3, 1e5);
const INPUT_TRIM_RANGE: (f64, f64) = (1e-5, 1e3);
/// Below this the model counts as silent.
const SILENT: f64 = 1e-12;

/// Element-steps the renders of a provisional model's levels ([`calibrate_quick`]) may take:
/// some 20 ms of simulation on this machine's slowest path.
pub const QUICK_WORK_BUDGET: f64 = 1e7;
/// How much quieter than its shortened note render asks a provisional model plays when the
/// render was cut short: the peak may come later and higher (a bow builds up over a second),
/// and a level that rises when the exact analyses arrive is better than one that hits the
/// ceiling before.
pub const QUICK_SHORT_MARGIN_DB: f64 = 12.0;

/// Measures the model's rest outputs, note level and drum level, and sets its trims.
pub fn calibrate(p: Prepared) -> Prepared {
    calibrate_within(p, WORK_BUDGET, true)
}

/// [`calibrate`] within [`QUICK_WORK_BUDGET`], without the drum's correcting renders and
/// without the note's floor of [`NOTE_MIN_SECONDS`]: the levels a provisional model plays
/// at until its exact analyses are done ([`super::load::prepare_provisional`]). A render cut
/// short errs on the quiet side by [`QUICK_SHORT_MARGIN_DB`]; a model too large for even a
/// few samples measures silent and keeps 0 dB.
pub fn calibrate_quick(p: Prepared) -> Prepared {
    calibrate_within(p, QUICK_WORK_BUDGET, false)
}

fn calibrate_within(p: Prepared, work_budget: f64, full: bool) -> Prepared {
    let mut p = p;
    p.facts_mut().rest_out = rest_outputs(&mut p);
    let size = (p.engine.info().num_points + p.engine.info().num_interactions).max(1) as f64;
    let budget = (work_budget / size).max(1.0);
    let sr = p.facts.sample_rate;
    let (note_floor, drum_floor) = if full {
        (NOTE_MIN_SECONDS * sr, 0.25 * sr)
    } else {
        (0.0, 0.0)
    };
    let note_frames = (SECONDS * sr).min(budget.max(note_floor)) as usize;
    // Shorter than the full calibration's render (only a quick one can be).
    let full_frames =
        (SECONDS * sr).min((WORK_BUDGET / size).max(1.0).max(NOTE_MIN_SECONDS * sr)) as usize;
    let short = note_frames < full_frames;
    // A kick lasts about 0.3 s: its window is not shortened below a quarter second.
    let drum_frames = ((DRUM_SECONDS * sr).min(budget.max(drum_floor)) as usize).max(1);
    let (p1, note) = peak(p, note_frames, true, None);
    // The drum, when the sidechain pushes a force input.
    // Played on every channel that feeds the model (a drum on a stereo sidechain moves its
    // audio-rate parameters too), when some of them push it.
    let order = super::host::default_order(false);
    let mask = super::fed_channels(&p1, order);
    let (mut p3, drum) = if super::pushing_channels(&p1, order) != 0 {
        let kick = kick(drum_frames, sr);
        peak(p1, drum_frames, false, Some((&kick, mask)))
    } else {
        (p1, 0.0)
    };
    let target = if short {
        10f64.powf((TARGET_DBFS - QUICK_SHORT_MARGIN_DB) / 20.0)
    } else {
        10f64.powf(TARGET_DBFS / 20.0)
    };
    let (output, input) = if note > SILENT {
        (target / note, if drum > SILENT { note / drum } else { 1.0 })
    } else if drum > SILENT {
        (target / drum, 1.0)
    } else {
        (1.0, 1.0)
    };
    p3.facts_mut().output_trim = output.clamp(OUTPUT_TRIM_RANGE.0, OUTPUT_TRIM_RANGE.1);
    p3.facts_mut().input_trim = input.clamp(INPUT_TRIM_RANGE.0, INPUT_TRIM_RANGE.1);
    if full && note > SILENT && drum > SILENT {
        p3 = refine_input_trim(p3, note, drum_frames, mask);
    }
    p3
}

/// The kick's answer is not proportional to its force where a hammer or a contact stands in
/// between (a weaker push may press the hammer onto the plate, or not reach the string at
/// all): the input trim is checked by playing the kick through it, and searched for (a
/// bisection of its logarithm between a trim found too quiet and one too loud, widened by
/// [`MAX_STEP`] while one side is missing) until the kick peaks within [`REFINE_DB`] of the
/// note (aiming [`AIM_DB`] above it), for at most [`REFINE_PASSES`] renders. The trim kept
/// is the closest one measured that does not sound louder than that aim by more than
/// [`HOT_DB`], the loudest quieter one otherwise.
fn refine_input_trim(p: Prepared, note: f64, frames: usize, mask: u16) -> Prepared {
    let mut p = p;
    let output = p.facts.output_trim;
    p.facts_mut().output_trim = 1.0;
    let kick = kick(frames, p.facts.sample_rate);
    let (mut lo, mut hi): (Option<f64>, Option<f64>) = (None, None);
    // (trim, dB off the note) of every render.
    let mut tried: Vec<(f64, f64)> = Vec::new();
    let mut t = p.facts.input_trim;
    for _ in 0..REFINE_PASSES {
        p.facts_mut().input_trim = t;
        let (back, drum) = peak(p, frames, false, Some((&kick, mask)));
        p = back;
        // Aimed a little above the note: where a hammer stands in between, a kick a little
        // weaker than the reference still reaches it.
        let off = if drum > SILENT {
            20.0 * (drum / note).log10() - AIM_DB
        } else {
            -240.0
        };
        tried.push((t, off));
        if off.abs() <= REFINE_DB {
            break;
        }
        if off < 0.0 {
            lo = Some(lo.map_or(t, |l: f64| l.max(t)));
        } else {
            hi = Some(hi.map_or(t, |h: f64| h.min(t)));
        }
        t = match (lo, hi) {
            (Some(l), Some(h)) => (l * h).sqrt(),
            (Some(l), None) if off > -200.0 => l * 10f64.powf(-off / 20.0).min(MAX_STEP),
            (Some(l), None) => l * MAX_STEP,
            (None, Some(h)) => h * 10f64.powf(-off / 20.0).max(1.0 / MAX_STEP),
            (None, None) => t,
        }
        .clamp(INPUT_TRIM_RANGE.0, INPUT_TRIM_RANGE.1);
    }
    let keep = tried
        .iter()
        .filter(|(_, off)| *off <= HOT_DB && *off > -200.0)
        .min_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .or_else(|| {
            tried
                .iter()
                .filter(|(_, off)| *off <= 0.0)
                .max_by(|a, b| a.1.total_cmp(&b.1))
        })
        .map_or(p.facts.input_trim, |(t, _)| *t);
    p.facts_mut().input_trim = keep;
    p.facts_mut().output_trim = output;
    p
}

/// How many renders the input trim's search may take, how close it must land, the largest
/// step of a correction, and how much louder than the note a kick may be kept.
const REFINE_PASSES: usize = 6;
const REFINE_DB: f64 = 2.0;
const MAX_STEP: f64 = 100.0;
const HOT_DB: f64 = 4.0;
/// Where the search aims, dB above the note.
const AIM_DB: f64 = 2.0;

/// Each output's value after one step from rest with every input at rest.
fn rest_outputs(p: &mut Prepared) -> Vec<f64> {
    let n_in = p.facts.roles.len();
    let n_out = p.facts.num_outputs;
    let mut inputs = vec![0.0; n_in];
    inputs.copy_from_slice(&p.facts.rest[..n_in]);
    let mut outputs = vec![0.0; n_out.max(1)];
    p.engine.process(1, &inputs, &mut outputs[..n_out]);
    let tripped = p.engine.is_tripped();
    p.engine.reset();
    if tripped || outputs.iter().any(|v| !v.is_finite()) {
        return vec![0.0; n_out.max(1)];
    }
    outputs
}

/// Plays the model for `frames` samples from rest, with the measuring note at the first
/// sample (`note`) and `drum` on the host channels of its mask (those that push force
/// inputs), and returns it at rest with the peak of its outputs (the main pair and the
/// auxiliary ones) at unit gain.
fn peak(p: Prepared, frames: usize, note: bool, drum: Option<(&[f32], u16)>) -> (Prepared, f64) {
    let (p, loudest, _) = peak_at(p, frames, note, drum, &Controls::DEFAULT);
    (p, loudest)
}

/// The measuring note (C4 at velocity 0.8, from rest: the model is reset first) played with
/// `controls` for [`NOTE_LEVEL_SECONDS`] (shortened for large models to [`WORK_BUDGET`]):
/// the model back at rest, the peak a host would hear at the controls' Output Gain before the soft
/// ceiling (dBFS; −240 for silence), and the guard's trips. Vary measures its variations by it
/// ([`super::vary::vary_playable`]).
pub fn note_level(p: Prepared, controls: &Controls) -> (Prepared, f64, u32) {
    // From rest, whatever the model played before.
    let mut p = p;
    p.engine.reset();
    p.rest_gestures();
    if let Some(b) = p.bank.as_mut() {
        b.clear();
    }
    let size = (p.engine.info().num_points + p.engine.info().num_interactions).max(1) as f64;
    let frames =
        (NOTE_LEVEL_SECONDS * p.facts.sample_rate).min((WORK_BUDGET / size).max(1.0)) as usize;
    let (p, loudest, trips) = peak_at(p, frames, true, None, controls);
    let db = if loudest > SILENT && loudest.is_finite() {
        20.0 * loudest.log10() + controls.output_db
    } else {
        -240.0
    };
    (p, db, trips)
}

/// [`peak`] with `controls` (their Output Gain replaced by the measuring gain) and the guard's
/// trips.
fn peak_at(
    p: Prepared,
    frames: usize,
    note: bool,
    drum: Option<(&[f32], u16)>,
    controls: &Controls,
) -> (Prepared, f64, u32) {
    let sr = p.facts.sample_rate;
    let controls = Controls {
        output_db: MEASURE_GAIN_DB,
        ..*controls
    };
    let mut trips = 0;
    let mut inst = Instrument::new(sr, controls);
    inst.set_model(Box::new(p));
    const BLOCK: usize = 256;
    // Every output the host can hear: the main pair and the auxiliary ones.
    let channels = match inst.model().map_or(1, |m| m.facts.num_outputs) {
        0..=2 => 2,
        n => n.min(MAX_HOST_OUTPUTS).div_ceil(2) * 2,
    };
    let mut buffers = [[0.0f32; BLOCK]; MAX_HOST_OUTPUTS];
    let mut loudest = 0.0f32;
    let mut done = 0;
    while done < frames {
        let len = BLOCK.min(frames - done);
        let first = done == 0 && note;
        let mut events =
            std::iter::once(Timed::new(0, Event::note_on(MEASURE_KEY, MEASURE_VELOCITY)))
                .filter(|_| first);
        let mut host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
        if let Some((d, mask)) = drum {
            for (c, h) in host.iter_mut().enumerate() {
                if mask & (1 << c) != 0 {
                    *h = d.get(done..);
                }
            }
        }
        let mut out: [&mut [f32]; MAX_HOST_OUTPUTS] = buffers.each_mut().map(|b| &mut b[..len]);
        let report = inst.process(
            len,
            &host,
            false,
            &mut events,
            &controls,
            &mut out[..channels],
        );
        trips += report.trips;
        for b in &buffers[..channels] {
            for s in &b[..len] {
                loudest = loudest.max(s.abs());
            }
        }
        done += len;
    }
    let [current, _, _] = inst.take_models();
    let mut p = *current.expect("the instrument keeps the model it plays");
    // The gains the note was tuned with go; one step with every input at rest puts the
    // audio-rate parameters a key pressed back at their defaults; the reset then puts the
    // points back.
    p.engine.set_class_gain(crate::ScaleClass::Stiffness, 1.0);
    p.engine.set_class_gain(crate::ScaleClass::Damping, 1.0);
    let n_in = p.facts.roles.len();
    let mut rest = vec![0.0; n_in];
    rest.copy_from_slice(&p.facts.rest[..n_in]);
    let mut outputs = vec![0.0; p.facts.num_outputs];
    p.engine.process(1, &rest, &mut outputs);
    p.engine.reset();
    p.rest_gestures();
    let gain = 10f64.powf(MEASURE_GAIN_DB / 20.0);
    (p, loudest as f64 / gain, trips)
}

/// The reference kick: a sine gliding from 150 to 45 Hz (30 ms) under an 80 ms decay,
/// peaking at [`REFERENCE_DRUM_DBFS`].
pub fn kick(frames: usize, sample_rate: f64) -> Vec<f32> {
    let mut phase = 0.0f64;
    let raw: Vec<f64> = (0..frames)
        .map(|n| {
            let t = n as f64 / sample_rate;
            let f = 45.0 + 105.0 * (-t / 0.03).exp();
            phase += std::f64::consts::TAU * f / sample_rate;
            (-t / 0.08).exp() * phase.sin()
        })
        .collect();
    normalized(&raw)
}

fn normalized(raw: &[f64]) -> Vec<f32> {
    let peak = raw.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scale = if peak > 0.0 {
        10f64.powf(REFERENCE_DRUM_DBFS / 20.0) / peak
    } else {
        0.0
    };
    raw.iter().map(|v| (v * scale) as f32).collect()
}
