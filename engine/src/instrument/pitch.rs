//! The reference pitch a model is tuned by (issue 14, concert pitch of issue 36): the mode a key
//! excites, found by the modal analysis, or where the analysis cannot read the model, the
//! strongest peak of its response to an impulse or of its free run.

use super::exciters::Exciter;
use super::host::InputRole;
use super::prepare::input_rests;
use super::CHUNK;
use crate::analysis::modes::ModalAnalysis;
use crate::{compile, CompileOptions, Element, ElementKind, Engine, ModelSpec, Span};

/// The MIDI key (fractional) whose equal-tempered pitch is `f` Hz, A4 = 440 Hz at key 69.
pub fn concert_key(f: f64) -> f64 {
    69.0 + 12.0 * (f / 440.0).log2()
}

/// Bits of its mantissa an analysed reference pitch keeps after the leading one
/// ([`settle_pitch`]).
pub const PITCH_BITS: u32 = 20;

/// An analysed reference pitch rounded to [`PITCH_BITS`] bits of mantissa: a step of at most
/// 2⁻²⁰ of the pitch (1.65 thousandths of a cent), so the rounding moves a pitch by at most
/// 0.83 thousandths of a cent.
///
/// The eigensolvers' sums follow the processor's SIMD width (faer dispatches AVX2 or AVX-512 at
/// run time), so the same script analysed on two machines gives pitches a few parts in 10¹³
/// apart (at most 5·10⁻¹¹ over the shipped table). Every note is tuned by this pitch, so those
/// last bits would make a project bounce differently on another computer. Rounded, the two
/// agree unless a pitch lies within that noise of a rounding boundary (a chance below 10⁻⁴
/// per model). Exact in binary: no library function is involved, only the mantissa.
pub fn settle_pitch(f: f64) -> f64 {
    if !f.is_finite() || f == 0.0 {
        return f;
    }
    let drop = 52 - PITCH_BITS;
    let bits = f.to_bits();
    let half = 1u64 << (drop - 1);
    // Round half up on the magnitude; a carry into the exponent is the next power of two.
    f64::from_bits((bits + half) & !((1u64 << drop) - 1))
}

/// The reference pitch under today's conventions: the mode the modal analysis finds from
/// where a key excites the model (the strike's input, else the point an exciter's avatar
/// acts on: the bowed or plucked mass), taken down to its fundamental when it is a harmonic
/// of a lower mode ([`reference_mode`]). Models the analysis cannot read fall back to the
/// impulse response, as [`reference_pitch`] does.
pub(crate) fn musical_reference_pitch(
    spec: &ModelSpec,
    engine: &mut Engine,
    note_input: Option<usize>,
    exciters: &[Exciter],
    roles: &[InputRole],
    sample_rate: f64,
) -> Option<f64> {
    if engine.info().num_outputs() == 0 {
        return None;
    }
    if let Some(k) = note_input {
        let a = engine.modes(None);
        return reference_mode(&a, k + 1).or_else(|| estimate_pitch(engine, note_input, roles));
    }
    if exciters.is_empty() {
        // Nothing for a key to play: a model that plays by itself from rest (a dropped ball)
        // is heard by how it sounds then.
        return free_run_pitch(engine, roles);
    }
    // A force where the first bow or plectrum acts, on a copy of the model.
    let contact = exciters.iter().find_map(|x| x.contact.clone());
    if let Some(target) = contact {
        let channel = roles.len() as u32 + 1;
        let mut probe = spec.clone();
        let label = crate::spec::Label::new(format!("in{channel}"));
        match &mut probe.space {
            // A 3-D probe pushes along the line the exciter's avatar moves on.
            Some(space) => {
                let avatar = exciters
                    .iter()
                    .find(|x| x.contact.is_some())
                    .map(|x| format!("in{}", x.input + 1));
                let dir = space.elements.iter().find_map(|e| match &e.kind {
                    crate::spec::space::SpaceKind::PosInput { dir, .. }
                        if Some(e.label.as_str()) == avatar.as_deref() =>
                    {
                        dir.clone()
                    }
                    _ => None,
                });
                space.elements.push(crate::spec::space::SpaceElement {
                    label,
                    kind: crate::spec::space::SpaceKind::FrcInput {
                        channel,
                        target,
                        dir,
                    },
                    buffers: Vec::new(),
                    span: Span::default(),
                });
            }
            None => probe.elements.push(Element {
                label,
                kind: ElementKind::FrcInput { channel, target },
                buffers: Vec::new(),
                tag_xy: None,
                span: Span::default(),
            }),
        }
        let mut options = CompileOptions::at(sample_rate);
        options.jit = false;
        if let Ok(mut e) = compile(&probe, &options) {
            let a = e.modes(None);
            return reference_mode(&a, channel as usize);
        }
        return None;
    }
    // A press on a position or force input: the analysis from that input.
    let k = exciters
        .iter()
        .find(|x| matches!(x.role, InputRole::Force | InputRole::Position))?
        .input;
    let a = engine.modes(None);
    reference_mode(&a, k + 1)
}

/// The reference mode from `input` (1-based) to `@out1`: the strongest mode above 20 Hz, or
/// the fundamental of the harmonic series it belongs to. A string's strongest mode at the
/// listening point is often a higher harmonic; its pitch is its fundamental. The fundamental
/// is the lowest mode f at most 40 dB weaker than the strongest, such that the strongest lies
/// within 1 % of a whole multiple n·f (n ≥ 2) and a mode lies within 1 % of 2·f: a series, not
/// two modes of a membrane that happen to fall near a ratio.
pub fn reference_mode(a: &ModalAnalysis, input: usize) -> Option<f64> {
    let strongest = a.strongest(input, 1, 20.0)?;
    let (fs, gs) = (
        strongest.frequency_hz,
        strongest
            .gains
            .get((input - 1) * a.num_outputs)
            .copied()
            .unwrap_or(0.0),
    );
    let near = |f: f64, target: f64| (f - target).abs() <= 0.01 * target;
    let has_mode = |target: f64| a.modes.iter().any(|m| near(m.frequency_hz, target));
    for (i, m) in a.modes.iter().enumerate() {
        let f = m.frequency_hz;
        if f < 20.0 || f >= fs * 0.99 {
            continue;
        }
        let n = (fs / f).round();
        if n >= 2.0 && near(fs, n * f) && a.gain(i, input, 1) >= 0.01 * gs && has_mode(2.0 * f) {
            return Some(f);
        }
    }
    Some(fs)
}

/// The model's reference pitch (issue 14): the strongest mode that `@out1` hears from the note
/// input, by the modal analysis ([`crate::analysis::modes`]), for models of any size: dense and
/// exact up to [`crate::analysis::modes::DENSE_LIMIT`] moving points, the strongest of the lowest
/// [`crate::analysis::modes::DEFAULT_SPARSE_COUNT`] above (about 2 s for the 150 × 150 plate).
/// Models the analysis cannot read (a note input with no linear path) fall back to the impulse
/// response's strongest peak ([`estimate_pitch`]), within its work budget.
pub(crate) fn reference_pitch(
    engine: &mut Engine,
    note_input: Option<usize>,
    roles: &[InputRole],
) -> Option<f64> {
    let k = note_input?;
    if engine.info().num_outputs() == 0 {
        return None;
    }
    if let Some(f) = engine.reference_pitch(k + 1, 1).filter(|f| *f > 0.0) {
        return Some(f);
    }
    estimate_pitch(engine, note_input, roles)
}

/// Work budget of the pitch estimate, in element-steps: small models get a long window,
/// models too large for it get none (the tuning law then uses its low-frequency limit).
const PITCH_BUDGET: f64 = 4e7;
/// The budget of [`quick_pitch`]: some 10 ms of simulation on this machine's slowest path.
const QUICK_PITCH_BUDGET: f64 = 4e6;
/// Length of the pitch estimate's impulse response.
const PITCH_WINDOW: usize = 8192;

/// The model's reference pitch: the strongest spectral peak of `@out1` after a force impulse
/// on the note input, found by rendering [`PITCH_WINDOW`] samples off the audio thread. The
/// engine is reset afterwards. None when the model has no force input or output, is too large
/// for the budget, or does not ring.
fn estimate_pitch(
    engine: &mut Engine,
    note_input: Option<usize>,
    roles: &[InputRole],
) -> Option<f64> {
    impulse_pitch(engine, note_input, roles, PITCH_BUDGET)
}

/// The provisional reference pitch a model plays with while its exact analyses run
/// ([`super::prepare::Source::Provisional`]): the impulse response's peak within
/// [`QUICK_PITCH_BUDGET`], so for models of up to about 500 elements; None above, where the
/// key plays the model's own pitch at its `~key` until the analysed pitch arrives.
pub(crate) fn quick_pitch(
    engine: &mut Engine,
    note_input: Option<usize>,
    roles: &[InputRole],
) -> Option<f64> {
    impulse_pitch(engine, note_input, roles, QUICK_PITCH_BUDGET)
}

/// [`estimate_pitch`] within `budget` element-steps.
fn impulse_pitch(
    engine: &mut Engine,
    note_input: Option<usize>,
    roles: &[InputRole],
    budget: f64,
) -> Option<f64> {
    let k = note_input?;
    let info = engine.info();
    if info.num_outputs() == 0 {
        return None;
    }
    let size = (info.num_points + info.num_interactions).max(1) as f64;
    if size * PITCH_WINDOW as f64 > budget {
        return None;
    }
    let sr = engine.sample_rate_hz();
    let n_in = roles.len();
    let n_out = info.num_outputs();
    let mut inputs = vec![0.0; n_in * CHUNK];
    let mut outputs = vec![0.0; n_out * CHUNK];
    let mut signal = Vec::with_capacity(PITCH_WINDOW);
    inputs[k * CHUNK] = -1e-3;
    while signal.len() < PITCH_WINDOW {
        engine.process(CHUNK, &inputs, &mut outputs);
        inputs.fill(0.0);
        signal.extend_from_slice(&outputs[..CHUNK]);
    }
    let tripped = engine.is_tripped();
    engine.reset();
    if tripped {
        return None;
    }
    peak_frequency(&signal, sr)
}

/// Work budget of the free-run pitch, in element-steps, and its longest window.
const FREE_RUN_BUDGET: f64 = 1e8;
const FREE_RUN_SECONDS: f64 = 1.0;

/// The pitch of a model that moves by itself from rest (a ball dropped at every reset, as a
/// voice of Drunk Triangles): the strongest peak of `@out1` over up to a second of it, its
/// inputs at rest, within [`FREE_RUN_BUDGET`]. The engine is reset afterwards.
fn free_run_pitch(engine: &mut Engine, roles: &[InputRole]) -> Option<f64> {
    let info = engine.info();
    let n_out = info.num_outputs();
    if n_out == 0 {
        return None;
    }
    let size = (info.num_points + info.num_interactions).max(1) as f64;
    let sr = engine.sample_rate_hz();
    let frames = (FREE_RUN_SECONDS * sr).min(FREE_RUN_BUDGET / size) as usize / CHUNK * CHUNK;
    if frames < 1024 {
        return None;
    }
    let rest = input_rests(engine);
    let n_in = roles.len();
    let mut inputs = vec![0.0; n_in * CHUNK];
    for (k, r) in rest.iter().enumerate().take(n_in) {
        inputs[k * CHUNK..(k + 1) * CHUNK].fill(*r);
    }
    let mut outputs = vec![0.0; n_out * CHUNK];
    let mut signal = Vec::with_capacity(frames);
    while signal.len() < frames {
        engine.process(CHUNK, &inputs, &mut outputs);
        signal.extend_from_slice(&outputs[..CHUNK]);
    }
    let tripped = engine.is_tripped();
    engine.reset();
    let first = signal[0];
    if tripped || signal.iter().all(|v| *v == first) {
        return None;
    }
    peak_frequency(&signal, sr)
}

/// The frequency of the strongest peak above 20 Hz (Hann window, parabolic interpolation of
/// the log magnitude).
pub fn peak_frequency(signal: &[f64], sample_rate: f64) -> Option<f64> {
    let n = signal.len();
    let mean = signal.iter().sum::<f64>() / n as f64;
    let mut frame: Vec<f64> = signal
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
            (x - mean) * w
        })
        .collect();
    let fft = realfft::RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut spectrum = fft.make_output_vec();
    fft.process(&mut frame, &mut spectrum).ok()?;
    let mags: Vec<f64> = spectrum.iter().map(|c| c.norm()).collect();
    let lo = ((20.0 * n as f64 / sample_rate).ceil() as usize).max(1);
    let (mut best, mut best_mag) = (0, 0.0);
    for (i, &m) in mags.iter().enumerate().take(mags.len() - 1).skip(lo) {
        if m > best_mag {
            best = i;
            best_mag = m;
        }
    }
    if !(best_mag > 0.0 && best_mag.is_finite()) {
        return None;
    }
    let (a, b, c) = (
        mags[best - 1].max(1e-300).ln(),
        best_mag.ln(),
        mags[best + 1].max(1e-300).ln(),
    );
    let denom = a - 2.0 * b + c;
    let delta = if denom != 0.0 {
        0.5 * (a - c) / denom
    } else {
        0.0
    };
    Some((best as f64 + delta.clamp(-0.5, 0.5)) * sample_rate / n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rounding is to the nearest point of the 20-bit grid, within half a step, exact on
    /// the grid, and carries into the next octave.
    #[test]
    fn a_settled_pitch_is_the_nearest_point_of_the_grid() {
        let step = |f: f64| 2f64.powi(f.log2().floor() as i32 - PITCH_BITS as i32);
        for f in [27.5, 261.625_565_300_598_6, 301.33, 1234.567_89, 19_999.9] {
            let s = settle_pitch(f);
            assert!((s - f).abs() <= 0.5 * step(f), "{f} → {s}");
            assert_eq!(settle_pitch(s), s, "{f}: the grid is fixed");
            assert_eq!(s.to_bits() & ((1 << (52 - PITCH_BITS)) - 1), 0);
            let cents = 1200.0 * (s / f).log2().abs();
            assert!(cents < 0.00083, "{f}: {cents} cents");
        }
        assert_eq!(settle_pitch(512.0 - 1e-9), 512.0);
        assert_eq!(settle_pitch(440.0), 440.0);
        for f in [0.0, f64::INFINITY, f64::NAN] {
            assert_eq!(settle_pitch(f).to_bits(), f.to_bits());
        }
    }

    /// Two analyses of one pitch that differ in their last bits, as two processors' give
    /// (5·10⁻¹¹ at most over the shipped table), settle to one pitch away from a boundary.
    #[test]
    fn last_bit_noise_settles_to_one_pitch() {
        for f in [110.0 * 1.000_000_1, 261.625_565_300_598_6, 301.33, 4321.0] {
            let s = settle_pitch(f);
            for r in [1e-13, -1e-13, 5e-11, -5e-11] {
                assert_eq!(settle_pitch(f * (1.0 + r)), s, "{f} moved by {r}");
            }
        }
    }

    /// The pitch a script's analysis gives is settled before the model plays by it.
    #[test]
    fn an_analysed_model_plays_by_a_settled_pitch() {
        let text = include_str!("../../tests/legacy/harmonic-oscillator.mdl");
        let m = crate::instrument::prepare("harmonic-oscillator", text, 48_000.0).unwrap();
        let f = m
            .facts()
            .settings
            .reference_pitch_hz
            .expect("it has a pitch");
        assert_eq!(settle_pitch(f), f);
        assert_eq!(m.facts().settings.reference_key, concert_key(f));
    }
}
