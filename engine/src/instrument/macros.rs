//! Macro slots: the model's `param`s and `audioParam`s bound to the generic host parameters,
//! with ranges the stability analysis accepts.

use super::host::HostSettings;
use super::NUM_MACROS;
use crate::analysis::envelope::{worst_load, STABILITY_HEADROOM};
use crate::{Engine, ParamId};

/// A macro slot bound to one of the model's `param`s or `audioParam`s. For an `audioParam`
/// the slot sets its default, the centre its input modulates around.
#[derive(Clone, Debug, PartialEq)]
pub struct MacroBinding {
    pub param: ParamId,
    pub name: String,
    /// The declared value (an `audioParam`'s default): the slot's centre (normalized 0.5).
    pub default: f64,
    pub min: f64,
    pub max: f64,
}

impl MacroBinding {
    /// Maps a slot position in [0, 1] to the parameter value: min at 0, the declared value
    /// at 0.5, max at 1; geometric between positive bounds, linear otherwise.
    pub fn value_at(&self, normalized: f64) -> f64 {
        let n = normalized.clamp(0.0, 1.0);
        let (a, b, t) = if n <= 0.5 {
            (self.min, self.default, n * 2.0)
        } else {
            (self.default, self.max, (n - 0.5) * 2.0)
        };
        if a > 0.0 && b > 0.0 {
            a * (b / a).powf(t)
        } else {
            a + (b - a) * t
        }
    }

    /// The slot position of a parameter value: the inverse of [`MacroBinding::value_at`],
    /// clamped to the range.
    pub fn normalized_of(&self, value: f64) -> f64 {
        let segment = |a: f64, b: f64| -> f64 {
            let t = if a > 0.0 && b > 0.0 && value > 0.0 {
                (value / a).ln() / (b / a).ln()
            } else {
                (value - a) / (b - a)
            };
            if t.is_nan() {
                0.0
            } else {
                t.clamp(0.0, 1.0)
            }
        };
        if value < self.default && self.min < self.default {
            segment(self.min, self.default) * 0.5
        } else if value > self.default && self.max > self.default {
            0.5 + segment(self.default, self.max) * 0.5
        } else {
            0.5
        }
    }
}

/// Binds the macro slots to the model's parameters, `param`s and `audioParam`s alike, in
/// strict declaration order, with the script's ranges or a default range around the declared
/// value that the stability analysis accepts. An `audioParam` slot moves its default.
pub fn macro_bindings(engine: &mut Engine, settings: &HostSettings) -> Vec<Option<MacroBinding>> {
    let params: Vec<(usize, String, f64, bool)> = engine
        .info()
        .params
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let position = p.audio_input.is_some() && p.coordinate;
            (i, p.name.clone(), p.default, position)
        })
        .collect();
    let mut out: Vec<Option<MacroBinding>> = vec![None; NUM_MACROS];
    let base_stable = engine.stability_numbers().is_stable();
    for (slot, (index, name, default, position)) in params.into_iter().take(NUM_MACROS).enumerate()
    {
        let id = ParamId(index as u32);
        let declared = settings.macro_ranges.iter().find(|r| r.name == name);
        let (min, max) = match declared {
            Some(r) => (r.min, r.max),
            None => {
                // An audio-rate connection-point coordinate spans the macro: 0 … 1 (the
                // engine clamps coordinates there). The bisection still keeps its ends
                // stable, since moving a contact moves where its stiffness lands.
                let (lo, hi) = if position {
                    (0.0, 1.0)
                } else {
                    default_range(default)
                };
                let hi = if base_stable {
                    stable_towards(engine, id, default, hi)
                } else {
                    hi
                };
                let lo = if base_stable {
                    stable_towards(engine, id, default, lo)
                } else {
                    lo
                };
                (lo, hi)
            }
        };
        let _ = engine.set_param(id, default);
        out[slot] = Some(MacroBinding {
            param: id,
            name,
            default: default.clamp(min.min(max), max.max(min)),
            min,
            max,
        });
    }
    engine.apply_pending_changes();
    out
}

/// ×1/4 … ×4 around a non-zero value; 0 … 1 around zero.
fn default_range(v: f64) -> (f64, f64) {
    if v > 0.0 {
        (v / 4.0, v * 4.0)
    } else if v < 0.0 {
        (v * 4.0, v / 4.0)
    } else {
        (0.0, 1.0)
    }
}

/// The value closest to `target` on the segment from `from` (stable) that keeps the model
/// stable, found by bisection.
fn stable_towards(engine: &mut Engine, id: ParamId, from: f64, target: f64) -> f64 {
    let stable_at = |engine: &mut Engine, v: f64| {
        engine.set_param(id, v).is_ok() && {
            let r = engine.stability_numbers();
            worst_load(&r).0 < STABILITY_HEADROOM
        }
    };
    if stable_at(engine, target) {
        return target;
    }
    let (mut good, mut bad) = (from, target);
    for _ in 0..24 {
        let mid = 0.5 * (good + bad);
        if stable_at(engine, mid) {
            good = mid;
        } else {
            bad = mid;
        }
    }
    good
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binding(min: f64, default: f64, max: f64) -> MacroBinding {
        MacroBinding {
            param: ParamId(0),
            name: "K".into(),
            default,
            min,
            max,
        }
    }

    #[test]
    fn slot_positions_invert_values() {
        for b in [
            binding(0.025, 0.1, 0.4),
            binding(-2.0, 0.0, 1.0),
            binding(-0.4, -0.1, -0.025),
            binding(0.1, 0.1, 0.4),
        ] {
            for i in 0..=100 {
                let n = i as f64 / 100.0;
                let v = b.value_at(n);
                let back = b.normalized_of(v);
                assert!(
                    (b.value_at(back) - v).abs() <= 1e-12 * v.abs().max(1.0),
                    "{b:?} at {n}: {v} -> {back}"
                );
            }
            assert_eq!(b.normalized_of(b.default), 0.5);
            assert_eq!(b.normalized_of(f64::INFINITY), 1.0);
            // Below the range: the bottom of the slot, or its centre when the range starts at
            // the declared value.
            let bottom = if b.min < b.default { 0.0 } else { 0.5 };
            assert_eq!(b.normalized_of(b.min - 1.0), bottom);
        }
    }
}
