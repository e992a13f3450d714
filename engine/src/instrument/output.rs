//! The output stage: model outputs → host channels. Per sample: the crossfade from a
//! replaced model, the output gain ramp, the DC filter, the guard's fade-in, the soft ceiling
//! and the flush of tiny values to zero. Nothing non-finite, subnormal or above full scale
//! leaves it.

use super::dsp::{output_sample, soft_ceiling, DcBlocker};
use super::prepare::Prepared;
use super::MAX_HOST_OUTPUTS;

/// Time for the output to fade back in after the guard reset an exploding model.
pub const GUARD_FADE_MS: f64 = 50.0;

/// The state the output stage keeps between samples.
#[derive(Clone, Copy, Debug)]
pub(super) struct OutputStage {
    dc: [DcBlocker; MAX_HOST_OUTPUTS],
    /// Fade-in after a guard reset: current gain and step per sample.
    guard_gain: f64,
    guard_step: f64,
}

/// Host channel `c` of a model's outputs at sample `i` of a chunk of `len`: channel 0 is
/// `@out1`, channel 1 `@out2` (or `@out1` again for a mono model), channel c `@out(c+1)`;
/// taken off the model's rest output and trimmed ([`super::level`]).
#[inline]
pub(super) fn model_channel(m: &Prepared, c: usize, i: usize, len: usize) -> f64 {
    let k = if c == 1 && m.facts.num_outputs == 1 {
        0
    } else {
        c
    };
    if k < m.facts.num_outputs {
        // Off its rest value, through the automatic trim (0 and 1 in legacy projects).
        (m.outputs[k * len + i] - m.facts.rest_out[k]) * m.facts.output_trim
    } else {
        0.0
    }
}

/// One span of the output stage: where its gain ramp and the crossfade stand.
#[derive(Clone, Copy, Debug)]
pub(super) struct Span {
    /// Samples in the span.
    pub len: usize,
    /// Output gain at the start of the chunk's ramp and at its end.
    pub g0: f64,
    pub g1: f64,
    /// Samples of the chunk rendered before this span, and the chunk's length.
    pub done: usize,
    pub chunk_len: usize,
    pub dc_on: bool,
    /// The model's guard tripped in this span: everything after its first sample is muted.
    pub tripped: bool,
}

impl OutputStage {
    pub fn new(sample_rate: f64) -> OutputStage {
        OutputStage {
            dc: [DcBlocker::new(sample_rate); MAX_HOST_OUTPUTS],
            guard_gain: 1.0,
            guard_step: 0.0,
        }
    }

    /// Clears the DC filters and starts the guard's fade-in from silence.
    pub fn restart(&mut self, sample_rate: f64) {
        self.dc.iter_mut().for_each(DcBlocker::reset);
        self.guard_gain = 0.0;
        self.guard_step = 1.0 / (GUARD_FADE_MS * 1e-3 * sample_rate).max(1.0);
    }

    /// Writes one span to `out[c][offset..offset + span.len]` for every host channel. While
    /// `fade_left` of `fade_len` samples count down, the current model fades in and the
    /// outgoing one, if any, fades out. Returns (tripped, loudest |sample| written): tripped when
    /// the model's guard tripped ([`Span::tripped`]) or an output was not finite.
    pub fn render(
        &mut self,
        span: Span,
        current: Option<&Prepared>,
        outgoing: Option<&Prepared>,
        fade: (&mut usize, usize),
        out: &mut [&mut [f32]],
        offset: usize,
    ) -> (bool, f64) {
        let (fade_left, fade_len) = fade;
        let channels = out.len().min(MAX_HOST_OUTPUTS);
        let len = span.len;
        let mut tripped = span.tripped;
        let mut loudest: f64 = 0.0;
        let mut frame = [0.0f64; MAX_HOST_OUTPUTS];
        for i in 0..len {
            // Without an outgoing model (it was silent) the new one fades in from 0.
            let t = if *fade_left > 0 {
                *fade_left as f64 / fade_len as f64
            } else {
                0.0
            };
            let g =
                span.g0 + (span.g1 - span.g0) * (span.done + i + 1) as f64 / span.chunk_len as f64;
            let mut finite = true;
            for (c, y) in frame[..channels].iter_mut().enumerate() {
                let mut x = current.map_or(0.0, |m| model_channel(m, c, i, len));
                if t > 0.0 {
                    let old = outgoing.map_or(0.0, |old| model_channel(old, c, i, len));
                    x = x * (1.0 - t) + old * t;
                }
                x *= g;
                if span.dc_on {
                    x = self.dc[c].process(x);
                }
                finite &= x.is_finite();
                *y = x;
            }
            if *fade_left > 0 {
                *fade_left -= 1;
            }
            if !finite {
                tripped = true;
                frame[..channels].fill(0.0);
            }
            let gain = self.guard_gain;
            if gain < 1.0 {
                self.guard_gain = (gain + self.guard_step).min(1.0);
            }
            for (c, &y) in frame[..channels].iter().enumerate() {
                let y = soft_ceiling(if gain < 1.0 { y * gain } else { y });
                loudest = loudest.max(y.abs());
                if let Some(s) = out[c].get_mut(offset + i) {
                    *s = output_sample(y);
                }
            }
            if tripped {
                // Silence the rest of this span; the guard fade starts after it.
                self.guard_gain = 0.0;
            }
        }
        (tripped, loudest)
    }
}
