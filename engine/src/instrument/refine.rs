//! A provisional model takes its exact analyses while it plays.
//!
//! A script whose analyses are not kept plays at once on quick stand-ins
//! ([`super::prepare_provisional`]: the Gershgorin envelope, a short impulse response's pitch,
//! levels from shortened renders) while [`super::prepare_with`] runs the exact analyses on
//! another thread. Their facts replace the stand-ins in the running model at a chunk boundary,
//! without restarting it: the notes sounding go on. What the swap would otherwise change in a
//! step is carried over:
//!
//! * **Output and input trims.** A factor of their own ([`Settle`]) takes old trim / new trim
//!   at the swap, so the product the audio hears is continuous, and glides to 1 with the time
//!   constant [`SETTLE_MS`]: the two trims may be some 20 dB apart (a large model's quick level
//!   is measured at its own pitch, and cut short), which the gains' 5 ms would make a swell.
//! * **Pitch.** Keys are tuned from the reference key (`note_st = key − reference_key`). A voice
//!   keeps the distance it was given at its note-on, so a held voice keeps its pitch and the
//!   next notes play in tune. The one model of a script without voices is retuned by its key
//!   at every chunk: it keeps the keys' move as an offset (`kept_st`) until its next note, so
//!   that the note sounding keeps its pitch too, and the next one plays in tune. Nothing
//!   glides under a held note: the provisional estimate may be far off (a large model's is
//!   its own pitch at its `~key`), and a glide of that size would be heard as a bend.
//! * **Stability limits.** The exact envelope admits at least what the Gershgorin one does
//!   (it is exact where the other is a bound), so a clamped Stiffness or Damping can only rise,
//!   through the gains' chunk-wise steps.

use super::dsp::ChunkSmoother;
use super::prepare::Facts;
use super::{Instrument, CHUNK};
use std::sync::Arc;

/// Time constant of the glide from a provisional model's levels to its exact ones.
pub const SETTLE_MS: f64 = 250.0;

/// The factors that carry a refined model from its provisional trims to its exact ones: the
/// output's and the sidechain inputs'. Exactly 1 (and so no change to a single bit) until a
/// refinement, and again once the glide has settled.
#[derive(Clone, Copy, Debug)]
pub(super) struct Settle {
    pub output: ChunkSmoother,
    pub input: ChunkSmoother,
}

impl Settle {
    pub fn new(sample_rate: f64) -> Settle {
        let unit = ChunkSmoother::new(sample_rate, CHUNK, SETTLE_MS, 1.0);
        Settle {
            output: unit,
            input: unit,
        }
    }

    /// Moves both towards 1 by `samples`.
    pub fn advance(&mut self, samples: usize) {
        self.output.advance(samples, 1.0);
        self.input.advance(samples, 1.0);
    }
}

impl Instrument {
    /// Whether the running model is the one prepared with `facts` ([`Prepared::shared_facts`]).
    /// Realtime-safe.
    ///
    /// [`Prepared::shared_facts`]: super::Prepared::shared_facts
    pub fn plays(&self, facts: &Arc<Facts>) -> bool {
        self.current
            .as_deref()
            .is_some_and(|m| Arc::ptr_eq(&m.facts, facts))
    }

    /// Hands the running model the facts of its exact analyses: `exact` replaces the facts of
    /// the model that plays with `provisional` (the same `Arc`), ramping what changes (see the
    /// module documentation). Returns the facts to free off the audio thread: the replaced
    /// ones, or `exact` itself when the running model is another one by now (a newer model, a
    /// deactivation) or the facts do not fit it. Realtime-safe: nothing is allocated or freed.
    pub fn refine(&mut self, provisional: &Arc<Facts>, exact: Arc<Facts>) -> Arc<Facts> {
        let Some(m) = self.current.as_deref_mut() else {
            return exact;
        };
        let fits = Arc::ptr_eq(&m.facts, provisional)
            && exact.sample_rate == m.facts.sample_rate
            && exact.roles.len() == m.facts.roles.len()
            && exact.num_outputs == m.facts.num_outputs
            && exact.rest_out.len() == m.facts.rest_out.len()
            && exact.macros.len() == m.facts.macros.len();
        if !fits {
            return exact;
        }
        let ratio = |old: f64, new: f64| {
            let r = old / new;
            if r.is_finite() && r > 0.0 {
                r
            } else {
                1.0
            }
        };
        let output = ratio(m.facts.output_trim, exact.output_trim);
        let input = ratio(m.facts.input_trim, exact.input_trim);
        self.settle.output.value *= output;
        self.last_output_gain *= output;
        self.settle.input.value *= input;
        if m.bank.is_none() {
            let moved = exact.settings.reference_key - m.facts.settings.reference_key;
            if moved.is_finite() {
                self.kept_st += moved;
            }
        }
        let old = std::mem::replace(&mut m.facts, exact);
        // The new limits and tuning apply from the next chunk.
        self.apply();
        old
    }
}

#[cfg(test)]
mod tests {
    use super::super::{
        prepare_provisional, prepare_with, Controls, Conventions, Event, Instrument, Timed,
        MAX_HOST_INPUTS,
    };
    use std::sync::Arc;

    const SR: f64 = 48_000.0;
    /// A script no table knows, monophonic (no `~voices`): a key retunes the one model. Too
    /// large for the provisional pitch estimate (600 elements), so the exact analyses move its
    /// reference key by some 40 semitones (it rings near 25 Hz).
    const SCRIPT: &str =
        "@s string 300 1. 0.1 0.001 0. 0.\n@in1 frcInput [@s 0.3]\n@out1 posOutput [@s 0.7]\n";

    /// `frames` of output (left), a C4 at the first sample when `note`.
    fn play(inst: &mut Instrument, frames: usize, note: bool) -> Vec<f32> {
        let mut left = vec![0.0f32; frames];
        let mut right = vec![0.0f32; frames];
        let on = note.then(|| Timed::new(0, Event::note_on(60, 0.8)));
        let mut events = on.into_iter();
        let host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
        let mut out: [&mut [f32]; 2] = [&mut left, &mut right];
        inst.process(
            frames,
            &host,
            false,
            &mut events,
            &Controls::DEFAULT,
            &mut out,
        );
        left
    }

    #[test]
    fn a_provisional_model_takes_its_exact_facts_while_it_plays() {
        let quick = prepare_provisional("t", SCRIPT, SR, Conventions::Musical).expect("plays");
        assert!(quick.facts().provisional);
        let provisional = quick.shared_facts();
        let exact = prepare_with("t", SCRIPT, SR, Conventions::Musical).expect("loads");
        assert!(!exact.facts().provisional);
        let exact = exact.shared_facts();

        let mut inst = Instrument::new(SR, Controls::DEFAULT);
        inst.set_model(Box::new(quick));
        let before = play(&mut inst, 4800, true);
        // The same, never refined.
        let mut unrefined = Instrument::new(SR, Controls::DEFAULT);
        unrefined.set_model(Box::new(
            prepare_provisional("t", SCRIPT, SR, Conventions::Musical).expect("plays"),
        ));
        assert_eq!(play(&mut unrefined, 4800, true), before);
        let gains = inst.gains();
        // Facts of another model are handed back unused.
        let other = prepare_with("t", SCRIPT, SR, Conventions::Musical).expect("loads");
        let unused = inst.refine(&other.shared_facts(), Arc::clone(&exact));
        assert!(Arc::ptr_eq(&unused, &exact));
        assert!(inst.plays(&provisional));

        let moved = exact.settings.reference_key - provisional.settings.reference_key;
        assert!(moved.abs() > 12.0, "the keys move by {moved} semitones");
        let back = inst.refine(&provisional, Arc::clone(&exact));
        assert!(
            Arc::ptr_eq(&back, &provisional),
            "the provisional facts come back"
        );
        assert!(inst.plays(&exact));
        // The note sounding keeps its pitch at the swap (to the discrete law's change of
        // reference, far below a cent), where the keys' move would take its stiffness by a
        // factor 2^(moved/6).
        let at_swap = inst.gains();
        assert!(
            (at_swap.requested_stiffness / gains.requested_stiffness - 1.0).abs() < 1e-3,
            "the stiffness asked jumps at the swap: {} → {}",
            gains.requested_stiffness,
            at_swap.requested_stiffness
        );
        let after = play(&mut inst, 4800, false);
        assert!(after.iter().all(|s| s.is_finite()));
        // No click: the output leaves the unrefined one's gradually (the trims glide), not
        // by a step at the swap.
        let went_on = play(&mut unrefined, 4800, false);
        let peak = before.iter().fold(0.0f32, |m, s| m.max(s.abs()));
        assert!(peak > 1e-4, "the note sounds before the swap ({peak})");
        let apart = |n: usize| {
            after[..n]
                .iter()
                .zip(&went_on)
                .fold(0.0f32, |m, (a, b)| m.max((a - b).abs()))
        };
        assert!(
            apart(8) <= 0.01 * peak,
            "the output steps by {} at the swap (peak {peak})",
            apart(8)
        );

        // The next note plays in tune: as on a model prepared exactly from the start.
        let mut reference = Instrument::new(SR, Controls::DEFAULT);
        reference.set_model(Box::new(
            prepare_with("t", SCRIPT, SR, Conventions::Musical).expect("loads"),
        ));
        play(&mut reference, 480, true);
        play(&mut inst, 480, true);
        let (g, r) = (inst.gains(), reference.gains());
        assert_eq!(
            g.requested_stiffness, r.requested_stiffness,
            "the next note is tuned as on the exact model"
        );
    }
}
