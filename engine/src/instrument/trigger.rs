//! Sidechain trigger mode: onsets in the host's force signals become strikes, as a drummer's
//! hits on a pad do. With the switch on (a control, saved with the project), the channels
//! that would push the model's force inputs feed this detector instead; each onset plays a
//! strike ([`super::Event::Strike`]: on the one model, or a voice at the reference key) at the
//! sample its peak window ends, with a velocity from the hit's peak.
//!
//! Per sample, on the loudest of those channels (|x|):
//!
//! * a peak follower `fast` (instant attack, [`FAST_RELEASE_MS`] release) and a slow average
//!   `slow` ([`SLOW_ATTACK_MS`] attack, [`SLOW_RELEASE_MS`] release) of |x|;
//! * an onset when `fast` is above the threshold and twice (6 dB over) what `slow` was, at
//!   least [`REFRACTORY_MS`] after the last one: a sustained sound raises `slow` and does not
//!   retrigger, a new hit does;
//! * its velocity is read from the peak over the next [`PEAK_WINDOW_MS`], in dB:
//!   v = (peak dBFS + sensitivity + 40) / 42.5, clamped to 0 … 1. At 0 dB of sensitivity a hit
//!   peaking at −6 dBFS plays velocity 0.8 (a medium note), −20 dBFS 0.47; anything below
//!   about −38 dBFS (velocity 0.05) does not trigger.
//!
//! The detector keeps its state between blocks, so the strikes do not depend on how the host
//! cuts them; it never allocates.

use super::events::{Event, Timed};

/// The peak follower's release.
pub const FAST_RELEASE_MS: f64 = 10.0;
/// The slow average's attack and release.
pub const SLOW_ATTACK_MS: f64 = 30.0;
pub const SLOW_RELEASE_MS: f64 = 150.0;
/// The shortest time between two onsets.
pub const REFRACTORY_MS: f64 = 40.0;
/// How long after an onset its peak is looked for (a quarter period of 62 Hz: the first
/// swing of a kick); the strike lands at its end.
pub const PEAK_WINDOW_MS: f64 = 4.0;
/// dB below full scale where velocity reaches 0 (at 0 dB of sensitivity), and the dB span to
/// velocity 1.
const FLOOR_DB: f64 = -40.0;
const SPAN_DB: f64 = 42.5;
/// The lowest velocity that triggers.
const MIN_VELOCITY: f64 = 0.05;
/// The most onsets one block may hold (one per 40 ms: 8 in a block of 16,384 at 48 kHz).
pub const MAX_ONSETS: usize = 64;

/// The level in dBFS at which a hit plays velocity `v` with `sensitivity_db`.
pub fn level_for_velocity(v: f64, sensitivity_db: f64) -> f64 {
    FLOOR_DB + SPAN_DB * v - sensitivity_db
}

/// The detector's state.
#[derive(Clone, Copy, Debug)]
pub struct Trigger {
    fast: f64,
    slow: f64,
    fast_release: f64,
    slow_attack: f64,
    slow_release: f64,
    window: u32,
    refractory: u64,
    since: u64,
    /// An onset looking for its peak: samples left, peak so far.
    pending: Option<(u32, f64)>,
    /// The onsets of the block being scanned.
    onsets: [Timed; MAX_ONSETS],
    count: usize,
}

fn coefficient(ms: f64, sample_rate: f64) -> f64 {
    1.0 - (-1.0 / (ms * 1e-3 * sample_rate).max(1.0)).exp()
}

impl Trigger {
    pub fn new(sample_rate: f64) -> Trigger {
        Trigger {
            fast: 0.0,
            slow: 0.0,
            fast_release: 1.0 - coefficient(FAST_RELEASE_MS, sample_rate),
            slow_attack: coefficient(SLOW_ATTACK_MS, sample_rate),
            slow_release: coefficient(SLOW_RELEASE_MS, sample_rate),
            window: (PEAK_WINDOW_MS * 1e-3 * sample_rate).round().max(1.0) as u32,
            refractory: (REFRACTORY_MS * 1e-3 * sample_rate) as u64,
            since: u64::MAX / 2,
            pending: None,
            onsets: [Timed::new(0, Event::Strike { velocity: 0.0 }); MAX_ONSETS],
            count: 0,
        }
    }

    /// Forgets every hit heard so far.
    pub fn reset(&mut self) {
        self.fast = 0.0;
        self.slow = 0.0;
        self.since = u64::MAX / 2;
        self.pending = None;
        self.count = 0;
    }

    /// Scans one block: `level(n)` is the detection signal (|x|, the loudest channel) at
    /// sample n of `frames`. Returns the strikes, in time order.
    pub fn scan(
        &mut self,
        frames: usize,
        sensitivity_db: f64,
        level: impl Fn(usize) -> f64,
    ) -> &[Timed] {
        self.count = 0;
        let threshold_db = level_for_velocity(MIN_VELOCITY, sensitivity_db);
        let threshold = 10f64.powf(threshold_db / 20.0);
        for n in 0..frames {
            let a = level(n);
            let a = if a.is_finite() { a.abs() } else { 0.0 };
            let slow_before = self.slow;
            self.fast = a.max(self.fast * self.fast_release);
            let k = if a > self.slow {
                self.slow_attack
            } else {
                self.slow_release
            };
            self.slow += k * (a - self.slow);
            if self.slow < 1e-30 {
                self.slow = 0.0;
            }
            if self.fast < 1e-30 {
                self.fast = 0.0;
            }
            self.since = self.since.saturating_add(1);
            match self.pending {
                Some((left, peak)) => {
                    let peak = peak.max(a);
                    if left <= 1 {
                        self.pending = None;
                        let db = 20.0 * peak.max(1e-12).log10() + sensitivity_db;
                        let v = ((db - FLOOR_DB) / SPAN_DB).clamp(0.0, 1.0);
                        if self.count < MAX_ONSETS {
                            self.onsets[self.count] =
                                Timed::new(n as u32, Event::Strike { velocity: v as f32 });
                            self.count += 1;
                        }
                    } else {
                        self.pending = Some((left - 1, peak));
                    }
                }
                None => {
                    if self.since >= self.refractory
                        && self.fast > threshold
                        && self.fast > 2.0 * slow_before
                    {
                        self.since = 0;
                        self.pending = Some((self.window, a));
                    }
                }
            }
        }
        &self.onsets[..self.count]
    }
}

/// Two time-ordered event streams as one: the host's and the trigger's.
pub struct Merge<'a, I: Iterator<Item = Timed>> {
    host: &'a mut I,
    host_next: Option<Timed>,
    own: &'a [Timed],
}

impl<I: Iterator<Item = Timed>> std::fmt::Debug for Merge<'_, I> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Merge")
            .field("host_next", &self.host_next)
            .field("own", &self.own)
            .finish()
    }
}

impl<'a, I: Iterator<Item = Timed>> Merge<'a, I> {
    pub fn new(host: &'a mut I, own: &'a [Timed]) -> Self {
        let host_next = host.next();
        Merge {
            host,
            host_next,
            own,
        }
    }
}

impl<I: Iterator<Item = Timed>> Iterator for Merge<'_, I> {
    type Item = Timed;

    fn next(&mut self) -> Option<Timed> {
        match (self.host_next, self.own.first()) {
            (Some(h), Some(o)) if o.timing < h.timing => {
                self.own = &self.own[1..];
                Some(*o)
            }
            (Some(h), _) => {
                self.host_next = self.host.next();
                Some(h)
            }
            (None, Some(o)) => {
                self.own = &self.own[1..];
                Some(*o)
            }
            (None, None) => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SR: f64 = 48_000.0;

    fn hits(times_s: &[f64], peak: f64, frames: usize) -> Vec<f64> {
        let mut x = vec![0.0; frames];
        for &t in times_s {
            let start = (t * SR) as usize;
            for n in 0..(0.15 * SR) as usize {
                if let Some(s) = x.get_mut(start + n) {
                    let tt = n as f64 / SR;
                    *s += peak * (-tt / 0.05).exp() * (std::f64::consts::TAU * 80.0 * tt).sin();
                }
            }
        }
        x
    }

    fn strikes(x: &[f64], block: usize, sensitivity: f64) -> Vec<(usize, f32)> {
        let mut t = Trigger::new(SR);
        let mut out = Vec::new();
        for (b, chunk) in x.chunks(block).enumerate() {
            for e in t.scan(chunk.len(), sensitivity, |n| chunk[n]) {
                if let Event::Strike { velocity } = e.event {
                    out.push((b * block + e.timing as usize, velocity));
                }
            }
        }
        out
    }

    #[test]
    fn four_hits_are_four_strikes_whatever_the_blocks() {
        let x = hits(&[0.1, 0.6, 1.1, 1.6], 0.5, (2.0 * SR) as usize);
        let a = strikes(&x, 512, 0.0);
        assert_eq!(a.len(), 4, "{a:?}");
        assert_eq!(a, strikes(&x, 37, 0.0));
        for (i, &(n, v)) in a.iter().enumerate() {
            let onset = ((0.1 + 0.5 * i as f64) * SR) as usize;
            assert!(
                n >= onset && n <= onset + (0.005 * SR) as usize,
                "{n} vs {onset}"
            );
            // −6 dBFS at 0 dB sensitivity: a medium note.
            assert!((v - 0.8).abs() < 0.03, "velocity {v}");
        }
    }

    #[test]
    fn quieter_hits_are_softer_and_sensitivity_raises_them() {
        let x = hits(&[0.1], 0.1, (0.5 * SR) as usize);
        let soft = strikes(&x, 256, 0.0)[0].1;
        let raised = strikes(&x, 256, 12.0)[0].1;
        assert!(soft < 0.6 && raised > soft + 0.2, "{soft} {raised}");
        // Below the floor nothing triggers.
        let faint = hits(&[0.1], 0.005, (0.5 * SR) as usize);
        assert!(strikes(&faint, 256, 0.0).is_empty());
    }

    #[test]
    fn a_sustained_tone_does_not_retrigger() {
        let x: Vec<f64> = (0..SR as usize)
            .map(|n| 0.5 * (std::f64::consts::TAU * 100.0 * n as f64 / SR).sin())
            .collect();
        assert_eq!(strikes(&x, 512, 0.0).len(), 1);
    }
}
