//! The output stage: DC filter, soft ceiling, smoothing and the tuning law.

use std::f64::consts::PI;

/// The high-pass of the mi-gen example patches (spec §7.0): y = x − onepole₄₀(x).
#[derive(Clone, Copy, Debug, Default)]
pub struct DcBlocker {
    state: f64,
    coefficient: f64,
}

impl DcBlocker {
    pub const CUTOFF_HZ: f64 = 40.0;

    pub fn new(sample_rate: f64) -> DcBlocker {
        DcBlocker {
            state: 0.0,
            coefficient: 1.0 - (-2.0 * PI * Self::CUTOFF_HZ / sample_rate).exp(),
        }
    }

    #[inline]
    pub fn process(&mut self, x: f64) -> f64 {
        self.state += self.coefficient * (x - self.state);
        // After a DC offset goes away the state decays geometrically and would reach the
        // subnormal range (seconds later), where every operation on it is slow. Far below
        // anything audible it is zero.
        if self.state.abs() < FLUSH_LEVEL {
            self.state = 0.0;
        }
        x - self.state
    }

    pub fn reset(&mut self) {
        self.state = 0.0;
    }
}

/// Levels below this are flushed to zero in the output stage's state: 10⁻³⁰ is 600 dB below
/// full scale, and far above the subnormal range of f32 (10⁻³⁸) and f64.
pub const FLUSH_LEVEL: f64 = 1e-30;

/// An output sample as the host receives it: f32, with anything below [`FLUSH_LEVEL`] (which
/// would be subnormal or close to it in f32) written as exactly 0. Hosts and validators
/// reject subnormal output, and the next plugin in the chain would pay for it.
#[inline]
pub fn output_sample(x: f64) -> f32 {
    if x.abs() < FLUSH_LEVEL {
        0.0
    } else {
        x as f32
    }
}

/// A host input sample as the model reads it: NaN, ±∞ and subnormal samples (below
/// 1.2·10⁻³⁸, 750 dB under full scale) read 0. The test looks at the exponent bits, so a
/// subnormal never enters an arithmetic operation: without DAZ, x86 CPUs take a slow assist for
/// subnormal operands (FTZ flushes only results), and clap-validator feeds whole blocks of them.
#[inline]
pub fn input_sample(s: f32) -> f64 {
    const EXPONENT: u32 = 0x7f80_0000;
    match s.to_bits() & EXPONENT {
        0 | EXPONENT => 0.0,
        _ => s as f64,
    }
}

/// Knee of the soft ceiling: below it the output is untouched.
pub const CEILING_KNEE: f64 = 0.5;

/// The soft ceiling: identity up to the knee, then a tanh curve that approaches ±1 and never
/// exceeds it. Continuous with a continuous slope. Non-finite input gives 0.
#[inline]
pub fn soft_ceiling(x: f64) -> f64 {
    if !x.is_finite() {
        return 0.0;
    }
    let a = x.abs();
    if a <= CEILING_KNEE {
        x
    } else {
        let room = 1.0 - CEILING_KNEE;
        (CEILING_KNEE + room * ((a - CEILING_KNEE) / room).tanh()).copysign(x)
    }
}

/// Decibels to a linear gain.
#[inline]
pub fn db_to_gain(db: f64) -> f64 {
    10f64.powf(db / 20.0)
}

/// A one-pole smoother advanced once per chunk: by a full chunk of `chunk` samples on the
/// chunk grid, or by the shorter span to the next grid point when automation starts a chunk
/// between grid points.
#[derive(Clone, Copy, Debug, Default)]
pub struct ChunkSmoother {
    pub value: f64,
    /// Time constant in samples.
    tau: f64,
    chunk: usize,
    /// Coefficient of a full chunk.
    coefficient: f64,
}

impl ChunkSmoother {
    /// `time_ms` is the time constant.
    pub fn new(sample_rate: f64, chunk: usize, time_ms: f64, value: f64) -> ChunkSmoother {
        let tau = (time_ms * 1e-3 * sample_rate).max(1.0);
        ChunkSmoother {
            value,
            tau,
            chunk,
            coefficient: 1.0 - (-(chunk as f64) / tau).exp(),
        }
    }

    /// Moves towards `target` by a full chunk.
    #[inline]
    pub fn next(&mut self, target: f64) -> f64 {
        self.advance(self.chunk, target)
    }

    /// Moves towards `target` by `samples`; snaps when within a relative 1e-9 so the value
    /// settles.
    #[inline]
    pub fn advance(&mut self, samples: usize, target: f64) -> f64 {
        let d = target - self.value;
        if d.abs() <= 1e-9 * target.abs().max(1e-12) {
            self.value = target;
        } else if samples == self.chunk {
            self.value += self.coefficient * d;
        } else {
            self.value += (1.0 - (-(samples as f64) / self.tau).exp()) * d;
        }
        self.value
    }
}

/// The Stiffness gain that moves a mode from `f_hz` by `semitones` under the exact discrete
/// law sin²(πf/SR) = K/4M (spec §5.3): (sin(πf'/SR) / sin(πf/SR))², f' = f·2^(st/12).
/// Without a reference pitch the low-frequency limit 2^(st/6) applies. f' is kept below
/// 0.49·SR, where the law stops being monotonic.
pub fn tuning_gain(semitones: f64, f_hz: Option<f64>, sample_rate: f64) -> f64 {
    let ratio = 2f64.powf(semitones / 12.0);
    match f_hz {
        Some(f) if f > 0.0 && f < 0.49 * sample_rate => {
            let target = (f * ratio).min(0.49 * sample_rate);
            let s0 = (PI * f / sample_rate).sin();
            let s1 = (PI * target / sample_rate).sin();
            (s1 / s0).powi(2)
        }
        _ => ratio * ratio,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ceiling_is_continuous_bounded_and_monotonic() {
        let mut last = -2.0;
        for i in -4000..=4000 {
            let x = i as f64 * 0.005;
            let y = soft_ceiling(x);
            assert!(y.abs() <= 1.0, "{x} -> {y}");
            assert!(y >= last, "not monotonic at {x}");
            last = y;
        }
        assert_eq!(soft_ceiling(0.3), 0.3);
        assert!((soft_ceiling(CEILING_KNEE + 1e-9) - CEILING_KNEE).abs() < 1e-8);
        assert_eq!(soft_ceiling(f64::NAN), 0.0);
        assert_eq!(soft_ceiling(f64::INFINITY), 0.0);
        assert!(soft_ceiling(1e300) <= 1.0);
    }

    #[test]
    fn output_is_never_subnormal() {
        for x in [
            1e-40,
            -1.27e-40,
            1e-35,
            -1e-31,
            1e-300,
            f64::MIN_POSITIVE / 2.0,
            0.0,
            -0.0,
        ] {
            let y = output_sample(x);
            assert!(!y.is_subnormal(), "{x} -> {y:e}");
            assert_eq!(y, 0.0, "{x}");
        }
        assert_eq!(output_sample(0.25), 0.25);
        assert_eq!(output_sample(-1e-20), -1e-20f32);
        // The smallest normal f32 itself passes; nothing between it and zero is written.
        for i in 0..2000 {
            let x = 1e-45 * 1.05f64.powi(i);
            let y = output_sample(x);
            assert!(!y.is_subnormal(), "{x:e} -> {y:e}");
        }
    }

    #[test]
    fn inputs_read_non_finite_and_subnormal_samples_as_zero() {
        for s in [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MIN_POSITIVE / 2.0,
            -1e-40,
            f32::from_bits(1),
            0.0,
            -0.0,
        ] {
            assert_eq!(input_sample(s).to_bits(), 0.0f64.to_bits(), "{s:e}");
        }
        for s in [f32::MIN_POSITIVE, -0.5, 1.0, 3e38, -1e-20] {
            assert_eq!(input_sample(s), s as f64);
        }
    }

    #[test]
    fn dc_blocker_tail_reaches_zero_not_subnormals() {
        // A DC step that goes away: the filter's state decays to exactly 0 instead of
        // through the subnormal range.
        let mut dc = DcBlocker::new(48_000.0);
        for _ in 0..48_000 {
            dc.process(1.0);
        }
        let mut last = 1.0;
        for _ in 0..48_000 * 10 {
            last = dc.process(0.0);
            assert!(!last.is_subnormal() && !dc.state.is_subnormal());
        }
        assert_eq!(last, 0.0);
        assert_eq!(dc.state, 0.0);
    }

    #[test]
    fn dc_blocker_removes_a_constant_and_passes_audio() {
        let sr = 48_000.0;
        let mut dc = DcBlocker::new(sr);
        let mut y = 0.0;
        for _ in 0..48_000 {
            y = dc.process(1.0);
        }
        assert!(y.abs() < 1e-6, "{y}");
        let mut dc = DcBlocker::new(sr);
        let mut peak: f64 = 0.0;
        for n in 0..48_000 {
            let x = (2.0 * PI * 1000.0 * n as f64 / sr).sin();
            let y = dc.process(x);
            if n > 24_000 {
                peak = peak.max(y.abs());
            }
        }
        assert!((peak - 1.0).abs() < 0.01, "1 kHz passes at {peak}");
    }

    #[test]
    fn smoother_steps_compose_whatever_their_length() {
        // Two half chunks land where one full chunk does: a chunk cut by automation keeps
        // the smoothing time.
        let mut full = ChunkSmoother::new(48_000.0, 16, 15.0, 0.0);
        let mut halves = full;
        full.next(1.0);
        halves.advance(8, 1.0);
        halves.advance(8, 1.0);
        assert!(
            (full.value - halves.value).abs() < 1e-15,
            "{} {}",
            full.value,
            halves.value
        );
        // 15 ms is 720 samples at 48 kHz: after 720 samples, 1 − 1/e of the way.
        let mut s = ChunkSmoother::new(48_000.0, 16, 15.0, 0.0);
        for _ in 0..45 {
            s.next(1.0);
        }
        assert!(
            (s.value - (1.0 - (-1f64).exp())).abs() < 1e-12,
            "{}",
            s.value
        );
    }

    #[test]
    fn tuning_follows_the_exact_discrete_law() {
        let sr = 48_000.0;
        for &f in &[100.0, 1000.0, 5000.0] {
            for &st in &[-12.0, 7.0, 12.0] {
                let g = tuning_gain(st, Some(f), sr);
                // A mass-spring oscillator: sin²(πf/SR) = K/4M, so f ∝ asin(√(gK/4M)).
                let k_over_4m = (PI * f / sr).sin().powi(2);
                let f_new = (g * k_over_4m).sqrt().asin() * sr / PI;
                let expected = f * 2f64.powf(st / 12.0);
                assert!((f_new / expected - 1.0).abs() < 1e-9, "{f} {st}: {f_new}");
            }
        }
        assert!((tuning_gain(12.0, None, sr) - 4.0).abs() < 1e-12);
    }
}
