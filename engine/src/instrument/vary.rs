//! Vary: a seeded step away from the current sound. It moves the knobs a sound designer would
//! try first (the model's bound macro slots, Damping, Release, and Stiffness on unpitched
//! models) by up to `amount` of their reach, so that every press of the editor's Vary button
//! is a new variation of the running preset that stays playable.
//!
//! What keeps a variation playable:
//! - a macro slot stays in 0 … 1, which the plugin maps into the script's `~macro` range after
//!   the stability analysis shrank it (`Facts::macro_envelopes`), so every slot position is a
//!   stable model;
//! - Stiffness and Damping pass the instrument's stability clamp as any knob does, and Vary
//!   keeps them within [`STIFFNESS_REACH`] and [`DAMPING_REACH`] octaves of unity;
//! - [`vary_playable`] plays each variation offline (the level render's note, C4 at velocity
//!   0.8): one that trips the guard or falls silent (a bow that no longer speaks) is tried
//!   again at half the amount, and the one kept gets the Output Gain that puts it at the level
//!   the sound had before (engine test `vary_keeps_every_preset_playable_and_in_the_level_band`);
//! - Tune, Force and Position Gain, the A4 reference and the playing switches are never
//!   touched, so a variation stays in tune; Stiffness is left alone on pitched models, where it
//!   would only fight the key's tuning. Output Gain moves only to hold the level.
//!
//! The same controls, amount and seed give the same variation on every machine: the random
//! numbers come from SplitMix64 (Steele, Lea and Flood, OOPSLA 2014), written out here so that
//! no crate upgrade can change a saved seed's result.

use super::controls::Controls;
use super::level::note_level;
use super::prepare::Prepared;
use super::NUM_MACROS;

/// How far Vary moves Damping at amount 1, in octaves either way, and the octaves from unity
/// it never leaves.
pub const DAMPING_STEP: f64 = 1.0;
pub const DAMPING_REACH: f64 = 1.5;
/// The same for Stiffness (unpitched models only): half an octave is a tritone of pitch.
pub const STIFFNESS_STEP: f64 = 0.5;
pub const STIFFNESS_REACH: f64 = 1.0;
/// How far a macro slot moves at amount 1 (slots run 0 … 1).
pub const MACRO_STEP: f64 = 0.5;
/// How far Release moves at amount 1 (0 … 1).
pub const RELEASE_STEP: f64 = 0.3;

/// What Vary may move on the running model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VaryScope {
    /// Which macro slots are bound to a parameter of the model (unbound slots do nothing and
    /// stay where they are).
    pub bound: [bool; NUM_MACROS],
    /// A pitched model keeps its Stiffness: keys tune it.
    pub pitched: bool,
}

/// `controls` moved by a variation of `amount` (0 … 1; 0 returns them unchanged) drawn from
/// `seed`.
pub fn vary(controls: &Controls, scope: &VaryScope, amount: f64, seed: u64) -> Controls {
    let amount = if amount.is_finite() {
        amount.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut rng = SplitMix64(seed);
    let mut out = *controls;
    // One draw per knob in a fixed order, whether it moves or not, so that a slot's variation
    // does not depend on which other slots are bound.
    for (slot, m) in out.macros.iter_mut().enumerate() {
        let step = amount * MACRO_STEP * rng.signed();
        if scope.bound[slot] {
            *m = (*m + step).clamp(0.0, 1.0);
        }
    }
    let step = amount * DAMPING_STEP * rng.signed();
    out.damping_octaves = (out.damping_octaves + step).clamp(-DAMPING_REACH, DAMPING_REACH);
    let step = amount * STIFFNESS_STEP * rng.signed();
    if !scope.pitched {
        out.stiffness_octaves =
            (out.stiffness_octaves + step).clamp(-STIFFNESS_REACH, STIFFNESS_REACH);
    }
    let step = amount * RELEASE_STEP * rng.signed();
    out.release = (out.release + step).clamp(0.0, 1.0);
    out
}

/// A variation that plays: a C4 at velocity 0.8 trips no guard and sounds no more than
/// [`MAX_DROP_DB`] below the starting sound; its Output Gain then puts it at the starting
/// level (within [`MAX_COMPENSATION_DB`]).
pub const MAX_DROP_DB: f64 = 24.0;
pub const MAX_COMPENSATION_DB: f64 = 24.0;
/// A variation that does not play is tried again at half the amount, then from the next
/// seeds (each at the amount and half of it): this many seeds in all.
pub const SEEDS_TRIED: u64 = 4;

/// A playable variation and how it was found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variation {
    pub controls: Controls,
    /// The seed and amount that gave it: the asked ones, or a half of the amount, or a later
    /// seed.
    pub seed: u64,
    pub amount: f64,
    /// The measuring note's level before and after (dBFS, at the Output Gain of each).
    pub level_before_db: f64,
    pub level_db: f64,
}

/// A variation of `controls` on the model `p` that plays ([`MAX_DROP_DB`]), at the level the
/// starting controls play at: [`vary`] at `amount`, then at half of it while the result trips
/// the guard or falls silent (a bow that no longer speaks), then the same from the next seeds,
/// [`SEEDS_TRIED`] in all, with the Output Gain moved by the level difference the measuring
/// note shows ([`super::level::note_level`]). None when nothing played; the model comes back at
/// rest either way. Deterministic for a model, rate, controls, amount and seed.
pub fn vary_playable(
    p: Prepared,
    controls: &Controls,
    amount: f64,
    seed: u64,
) -> (Prepared, Option<Variation>) {
    let scope = p.vary_scope();
    let (mut p, before, _) = note_level(p, controls);
    let tries = (0..SEEDS_TRIED).flat_map(|k| [(k, amount), (k, 0.5 * amount)]);
    for (k, amount) in tries {
        let seed = seed.wrapping_add(k);
        let mut candidate = vary(controls, &scope, amount, seed);
        let (back, level, trips) = note_level(p, &candidate);
        p = back;
        let heard = before <= -200.0 || level >= before - MAX_DROP_DB;
        if trips == 0 && heard {
            let change = if before > -200.0 && level > -200.0 {
                (before - level).clamp(-MAX_COMPENSATION_DB, MAX_COMPENSATION_DB)
            } else {
                0.0
            };
            candidate.output_db += change;
            let variation = Variation {
                controls: candidate,
                seed,
                amount,
                level_before_db: before,
                level_db: level + change,
            };
            return (p, Some(variation));
        }
    }
    (p, None)
}

/// SplitMix64: a 64-bit counter through a bijective mixer; every seed gives a full-period
/// sequence.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [−1, 1), from the top 53 bits.
    fn signed(&mut self) -> f64 {
        let unit = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        2.0 * unit - 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scope(pitched: bool) -> VaryScope {
        let mut bound = [false; NUM_MACROS];
        bound[..3].fill(true);
        VaryScope { bound, pitched }
    }

    #[test]
    fn splitmix64_gives_the_published_sequence() {
        // The first outputs of the reference C code (splitmix64.c, Vigna) seeded with
        // 1234567, as an independent Python transcription also prints.
        let mut r = SplitMix64(1234567);
        assert_eq!(r.next(), 6457827717110365317);
        assert_eq!(r.next(), 3203168211198807973);
        assert_eq!(r.next(), 9817491932198370423);
    }

    #[test]
    fn the_same_seed_gives_the_same_variation_and_another_seed_another() {
        let c = Controls::DEFAULT;
        let a = vary(&c, &scope(false), 0.5, 7);
        assert_eq!(a, vary(&c, &scope(false), 0.5, 7));
        assert_ne!(a, vary(&c, &scope(false), 0.5, 8));
        assert_ne!(a, c);
    }

    #[test]
    fn amount_zero_changes_nothing_and_the_steps_scale_with_it() {
        let c = Controls::DEFAULT;
        assert_eq!(vary(&c, &scope(false), 0.0, 3), c);
        assert_eq!(vary(&c, &scope(false), f64::NAN, 3), c);
        let small = vary(&c, &scope(false), 0.1, 3);
        let large = vary(&c, &scope(false), 0.2, 3);
        for slot in 0..3 {
            let (s, l) = (small.macros[slot] - 0.5, large.macros[slot] - 0.5);
            assert!((l - 2.0 * s).abs() < 1e-12, "slot {slot}: {s} {l}");
        }
    }

    #[test]
    fn a_variation_stays_in_reach_moves_only_bound_slots_and_keeps_a_pitched_models_stiffness() {
        let mut c = Controls::DEFAULT;
        c.macros[5] = 0.9;
        c.tune_st = 3.0;
        c.output_db = -4.0;
        for seed in 0..2000 {
            for pitched in [false, true] {
                let v = vary(&c, &scope(pitched), 1.0, seed);
                assert!(v.macros.iter().all(|m| (0.0..=1.0).contains(m)));
                assert_eq!(&v.macros[3..], &c.macros[3..]);
                assert!(v.damping_octaves.abs() <= DAMPING_REACH);
                assert!(v.stiffness_octaves.abs() <= STIFFNESS_REACH);
                assert!((0.0..=1.0).contains(&v.release));
                if pitched {
                    assert_eq!(v.stiffness_octaves, c.stiffness_octaves);
                }
                assert_eq!(v.tune_st, c.tune_st);
                assert_eq!(v.output_db, c.output_db);
                assert_eq!(v.a4_hz, c.a4_hz);
            }
        }
        // Repeated presses wander but never leave the reach.
        let mut w = Controls::DEFAULT;
        for seed in 0..500 {
            w = vary(&w, &scope(false), 1.0, seed);
            assert!(w.damping_octaves.abs() <= DAMPING_REACH);
            assert!(w.stiffness_octaves.abs() <= STIFFNESS_REACH);
        }
    }
}
