//! Holding a model at rest: what [`Rest`] means and when a state is a fixed point
//! ([`stationary`]); `Engine::hold` writes a held model's outputs without stepping it.

use crate::sim::flush::FLUSH_BELOW;
use crate::sim::kernels::Points;

/// What [`Engine::process`](crate::Engine::process) knows of the state between blocks.
///
/// A model at rest with silent inputs stays at rest, and stepping it costs as much as a
/// ringing one: a polyphonic instrument's own model, which the host's audio plays, idles like
/// that whenever nothing feeds it. One sample of the loop maps the state (x, x̃, F) to the
/// next; F is recomputed from x and x̃ (and the inputs) at every sample. So if a silent sample
/// leaves x = x̃ on every point, bit for bit ([`Rest::Still`]), and the next silent sample
/// does so again, the state after it equals the state before it: a fixed point, which every
/// later silent sample keeps ([`Rest::Fixed`]) as long as no parameter or gain changes
/// (`params_dirty` clears it) and the periodic flush has nothing to flush (no value below
/// [`FLUSH_BELOW`] but 0). A fixed state's outputs repeat its last ones, so `process` writes
/// them without stepping: the same samples, bit for bit (test `a_model_at_rest_is_held`).
///
/// What reaches such a point: any model before its first excitation (its initial state, when
/// that is at rest), and a damped model whose motion the flush has set to exactly 0. A model
/// under a static load (gravity, a contact holding a mass) usually ends its decay in a cycle
/// of the last bit of a position instead, and keeps being stepped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Rest {
    #[default]
    Moving,
    /// The last sample was silent and left x = x̃ everywhere.
    Still,
    /// A fixed point: held while the inputs stay silent and nothing changes.
    Fixed,
}

/// Whether every point stands still (x = x̃, bit for bit) and the periodic flush has nothing
/// to flush (see [`Rest`]).
pub(crate) fn stationary(p: &Points) -> bool {
    let tiny = |v: &f64| v.abs() < FLUSH_BELOW && *v != 0.0;
    p.x.iter()
        .zip(&p.xp)
        .all(|(a, b)| a.to_bits() == b.to_bits())
        && !p.x.iter().chain(&p.f).any(tiny)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compile::{compile, CompileOptions};
    use crate::lang::parse;
    use crate::sim::engine::DEFAULT_POSITION_LIMIT;

    /// Models that come back to rest: a damped string macro struck through a connection
    /// point, a mass on a spring to a ground at 0.1 (it rests away from 0), an oscillator
    /// moved by a position input, a mass whose gravity is a parameter (0, then 0.001).
    const MODELS: [&str; 4] = [
        "@s string 12 1. 0.1 0.05 0.01 0. 0.\n@in1 frcInput [@s 0.3]\n\
         @out1 posOutput [@s 0.6]\n@out2 frcOutput [@s 0.3]\n",
        "@g ground 0.1\n@m mass 1. 0.1 0.\n@l springDamper @g @m 0.05 0.02\n\
         @in1 frcInput @m\n@out1 posOutput @m\n",
        "@in1 posInput 0.\n@m mass 1. 0. 0.\n@l springDamper @in1 @m 0.05 0.08\n\
         @out1 posOutput @m\n",
        "@G param 0.\n@g ground 0.\n@m mass 1. G 0. 0.\n@l springDamper @g @m 0.05 0.02\n\
         @out1 posOutput @m\n",
    ];

    /// Each model runs a script of blocks (odd sizes, silence, strikes, a NaN input, a gain
    /// change, a position limit that trips the guard while the model is held, a reset) twice:
    /// as `process` runs it, and with the rest state cleared before every block, so that every
    /// sample is stepped. Outputs, positions, guard events and sample counts are equal bit for
    /// bit, and the first run did hold a fixed point.
    /// `engine::silent` reads a block as silent exactly when every sample is +0 or not
    /// finite, wherever the loud sample lies in its 64-sample chunks.
    #[test]
    fn silence_is_plus_zero_or_not_finite() {
        let quiet = [0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -f64::NAN];
        let loud = [-0.0, 1e-310, -1e-310, 1.0, f64::MAX, -f64::MIN_POSITIVE];
        for len in [1, 63, 64, 65, 130] {
            for at in [0, len / 2, len - 1] {
                let mut v: Vec<f64> = (0..len).map(|i| quiet[i % quiet.len()]).collect();
                assert!(crate::sim::engine::silent(&v));
                for &l in &loud {
                    v[at] = l;
                    assert!(!crate::sim::engine::silent(&v), "{l:e} at {at} of {len}");
                }
            }
        }
        assert!(crate::sim::engine::silent(&[]));
    }

    /// A change applied before the block (`apply_pending_changes`, as the instrument does)
    /// ends the hold as a change applied by `process` does: a mass resting on a spring is
    /// pulled down by a gravity parameter either way.
    #[test]
    fn a_change_applied_before_the_block_ends_the_hold() {
        let spec = parse(MODELS[3]).spec.expect("parses");
        let mut e = compile(&spec, &CompileOptions::at(48_000.0)).expect("compiles");
        let mut out = vec![0.0; 64];
        e.process(64, &[], &mut out);
        e.process(64, &[], &mut out);
        assert_eq!(e.rest, Rest::Fixed);
        let g = e.param_id("G").unwrap();
        e.set_param(g, 0.001).expect("a finite value");
        e.apply_pending_changes();
        e.process(64, &[], &mut out);
        assert!(out[63] < 0.0, "the mass falls: {}", out[63]);
    }

    #[test]
    fn a_model_at_rest_is_held() {
        for text in MODELS {
            let spec = parse(text).spec.expect("parses");
            let engine = compile(&spec, &CompileOptions::at(48_000.0)).expect("compiles");
            let (mut held, mut stepped) = (engine.clone(), engine);
            let ins = held.model.info.inputs.len().max(1);
            let outs = held.model.info.outputs.len();
            let (mut held_blocks, mut trips) = (0, 0);
            let mut lcg = 7u64;
            for block in 0..900 {
                lcg = lcg
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let frames = 1 + (lcg >> 33) as usize % 700;
                let mut input = vec![0.0; ins * frames];
                match block {
                    100 | 450 => input[frames / 2] = 0.5,
                    300 => input[0] = f64::NAN,
                    _ => {}
                }
                for e in [&mut held, &mut stepped] {
                    match block {
                        // Positions at rest are 0 or 0.1: this limit trips the offset model.
                        50 => e.set_position_limit(0.05),
                        60 => {
                            e.set_position_limit(DEFAULT_POSITION_LIMIT);
                            e.reset();
                        }
                        600 => {
                            e.set_class_gain(crate::spec::ScaleClass::Stiffness, 1.5);
                            if let Some(g) = e.param_id("G") {
                                e.set_param(g, 0.001).expect("a finite value");
                            }
                        }
                        _ => {}
                    }
                }
                stepped.rest = Rest::Moving;
                if held.rest == Rest::Fixed {
                    held_blocks += 1;
                }
                let (mut a, mut b) = (vec![0.0; outs * frames], vec![0.0; outs * frames]);
                let ra = held.process(frames, &input, &mut a);
                let rb = stepped.process(frames, &input, &mut b);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&a), bits(&b), "{text} block {block}");
                assert_eq!((ra.simulated, ra.tripped), (rb.simulated, rb.tripped));
                assert_eq!(bits(held.positions()), bits(stepped.positions()));
                assert_eq!(held.guard, stepped.guard);
                assert_eq!(held.samples_since_reset, stepped.samples_since_reset);
                trips += ra.tripped as u32;
            }
            assert!(held_blocks > 50, "{text}: held {held_blocks} blocks");
            if text.contains("ground 0.1") {
                assert_eq!(trips, 1, "the limit trips the held offset model");
            }
        }
    }
}
