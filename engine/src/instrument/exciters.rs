//! Exciters: what a key does to a model input beyond the strike (docs/LANGUAGE.md §12.4).
//!
//! A script names, with `~exciter inK KIND [AMOUNT [TIME_MS]]`, the gesture a key makes on
//! an input; the instrument plays it on every voice (or on the one model), sample by sample,
//! from the note's own sample:
//!
//! * **bow** (a position input): while the key is held the input moves at a steady speed,
//!   `AMOUNT × (0.4 + 0.6·v)` units per second with v the velocity response (or the key's
//!   pressure, whichever is larger). The speed rises from 0 over `TIME_MS` at note-on and falls
//!   back over the same time at note-off, where the bow stops. Without an amount, the speed of
//!   a full-velocity note is 0.95 × the `nlBow`'s Vscale on that avatar, so every velocity
//!   bows inside the law's slip range Vscale/3 … Vscale (spec §2.6.2).
//! * **pluck** (a position input): the plectrum rests `AMOUNT/2` to one side of the input's
//!   declared position; key-down sweeps it to the other side in `TIME_MS` (a half cosine), so
//!   it crosses the string once. The next key sweeps it back (alternate strokes, as a
//!   guitarist picks); a voice of a bank starts every note from the first side. In one
//!   dimension a plectrum cannot pass around the string, so a return stroke always plucks:
//!   "across and back" is two notes. Without an amount the travel is 4 × the `nlPluck`'s
//!   Pscale on that avatar (spec §2.6.1: the tent is Pscale wide on each side). The tent's
//!   peak force is fixed, so the string is dragged furthest, and sounds loudest, when the
//!   plectrum moves slowly enough for it to follow: a full-velocity note sweeps in `TIME_MS`,
//!   softer ones faster, down to 0.4 × `TIME_MS`. A press on the plectrum's stiffness (below)
//!   makes velocity louder still.
//! * **press** (any input): a held key pushes the input by `AMOUNT × v` (v as for the bow),
//!   reached over `TIME_MS`, and lets it back over the same time at note-off. On a force
//!   input it is a force (× Force Gain), on a position input an offset, on an `audioParam`
//!   a value added to its default, kept inside its `~macro` range when it has one.
//!
//! A bow whose friction is an `audioParam` pressed by a second exciter lands and leaves the
//! string with the key: `~exciter in1 bow` and `~exciter in5 press 0.08` on
//! `@nlZ audioParam @in5`. Nothing here allocates: a voice keeps one [`Gesture`] per exciter
//! in place.

use super::host::{InputRole, Rejected};
use crate::laws::LawKind;
use crate::{ElementKind, Engine, ParamKind};
use crate::{Endpoint, ExciterKind, ModelSpec, SampleRateMode, REFERENCE_SAMPLE_RATE_HZ};
use std::f64::consts::PI;

pub use crate::lang::MAX_EXCITERS;

/// The ramp of a bow or a press when the script gives none.
pub const DEFAULT_RAMP_MS: f64 = 5.0;
/// The pluck's sweep when the script gives none.
pub const DEFAULT_SWEEP_MS: f64 = 6.0;
/// How long a strike without a key (the editor's Strike and Audition, a sidechain trigger)
/// holds a bow or a press before it lets go.
pub const STRIKE_HOLD_MS: f64 = 300.0;

/// The share of a bow's full speed that the softest note keeps.
const BOW_FLOOR: f64 = 0.4;
/// The share of a pluck's sweep time that the softest note takes.
const PLUCK_FLOOR: f64 = 0.4;

/// One exciter of a prepared model, in the running rate's units.
#[derive(Clone, Debug, PartialEq)]
pub struct Exciter {
    /// The model input (0-based).
    pub input: usize,
    pub kind: ExciterKind,
    /// Bow: the speed of a full-velocity note in units per step; pluck: half the travel;
    /// press: the depth of a full-velocity note.
    pub amount: f64,
    /// Samples of the ramp (bow, press) or of the sweep (pluck), at least 1.
    pub samples: f64,
    pub role: InputRole,
    /// The press's value stays inside these (an `audioParam`'s `~macro` range, as an
    /// offset from its default).
    pub low: f64,
    pub high: f64,
    /// The point the exciter's avatar acts on (the other end of its `nlBow` or `nlPluck`),
    /// where the modal analysis finds the reference pitch of a model without a strike.
    pub contact: Option<Endpoint>,
}

/// What one exciter is doing on one voice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gesture {
    /// The velocity response of the note that started it.
    level: f64,
    /// Bow and press: the ramp, 0 … 1.
    env: f64,
    /// Bow: the distance the bow has travelled.
    travel: f64,
    /// Pluck: the side the sweep started from (±1) and how far it got (0 … 1; 1 at rest).
    from: f64,
    t: f64,
    /// Pluck: the sweep's step per sample.
    rate: f64,
}

impl Gesture {
    /// At rest, the plectrum on its first side.
    pub const REST: Gesture = Gesture {
        level: 0.0,
        env: 0.0,
        travel: 0.0,
        from: -1.0,
        t: 1.0,
        rate: 0.0,
    };

    /// The input's offset from its rest at this sample, then one step on.
    #[inline]
    fn step(&mut self, x: &Exciter, held: bool, pressure: f64) -> f64 {
        let drive = self.level.max(pressure);
        match x.kind {
            ExciterKind::Bow => {
                self.env = ramp(self.env, held, x.samples);
                self.travel += x.amount * (BOW_FLOOR + (1.0 - BOW_FLOOR) * drive) * self.env;
                self.travel
            }
            ExciterKind::Pluck => {
                if self.t < 1.0 {
                    self.t = (self.t + self.rate).min(1.0);
                }
                x.amount * self.from * (PI * self.t).cos()
            }
            ExciterKind::Press => {
                self.env = ramp(self.env, held, x.samples);
                (x.amount * drive * self.env).clamp(x.low, x.high)
            }
            ExciterKind::Strike => 0.0,
        }
    }

    /// A key went down with velocity response `level`.
    fn start(&mut self, x: &Exciter, level: f64) {
        self.level = level;
        if x.kind == ExciterKind::Pluck && self.t >= 1.0 {
            // From where the plectrum rests (the far side of the last sweep) to the other.
            self.from = -self.from;
            self.t = 0.0;
            let time = PLUCK_FLOOR + (1.0 - PLUCK_FLOOR) * level.clamp(0.0, 1.0);
            self.rate = (time * x.samples).recip();
        }
    }

    /// Whether the gesture still moves its input, or holds it away from rest.
    fn busy(&self, x: &Exciter, held: bool) -> bool {
        match x.kind {
            ExciterKind::Bow | ExciterKind::Press => held || self.env > 0.0,
            ExciterKind::Pluck => self.t < 1.0,
            ExciterKind::Strike => false,
        }
    }
}

/// One ramp step towards 1 (held) or 0 over `samples`.
#[inline]
fn ramp(env: f64, held: bool, samples: f64) -> f64 {
    if held {
        (env + samples.recip()).min(1.0)
    } else {
        (env - samples.recip()).max(0.0)
    }
}

/// The gestures of one voice (or of the one model), one per exciter.
pub type Gestures = [Gesture; MAX_EXCITERS];

/// Every gesture at rest.
pub const AT_REST: Gestures = [Gesture::REST; MAX_EXCITERS];

/// A key went down: every exciter starts its gesture.
pub fn start(gestures: &mut Gestures, exciters: &[Exciter], level: f64) {
    for (g, x) in gestures.iter_mut().zip(exciters) {
        g.start(x, level);
    }
}

/// Whether any gesture still moves or holds its input.
pub fn busy(gestures: &Gestures, exciters: &[Exciter], held: bool) -> bool {
    gestures.iter().zip(exciters).any(|(g, x)| g.busy(x, held))
}

/// Adds `len` samples of every gesture to lane `lane` of `width` of the planar inputs `vin`
/// (`n_in` channels of `len × width`). `force` is what a force input's value is multiplied by
/// (the Force Gain and the rate scale of force signals).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn play(
    gestures: &mut Gestures,
    exciters: &[Exciter],
    held: bool,
    pressure: f64,
    force: f64,
    vin: &mut [f64],
    len: usize,
    width: usize,
    lane: usize,
) {
    for (g, x) in gestures.iter_mut().zip(exciters) {
        let gain = if x.role == InputRole::Force {
            force
        } else {
            1.0
        };
        let base = x.input * len * width + lane;
        let Some(row) = vin.get_mut(base..base + (len - 1) * width + 1) else {
            continue;
        };
        for n in 0..len {
            row[n * width] += g.step(x, held, pressure) * gain;
        }
    }
}

/// The exciters of a script, resolved against its compiled model at `sample_rate`: each on an
/// input that can take it, with its amount and time in the running rate's units. Strikes are
/// not among them (they are the note input). Errors name the directive's line and column.
pub fn resolve(
    spec: &ModelSpec,
    engine: &Engine,
    roles: &[InputRole],
    sample_rate: f64,
) -> Result<Vec<Exciter>, Rejected> {
    let mut out = Vec::new();
    let mut errors = Vec::new();
    let per_second = match spec.sample_rate_mode {
        SampleRateMode::Scaled => REFERENCE_SAMPLE_RATE_HZ,
        SampleRateMode::Raw => sample_rate,
    };
    let lookup = |name: &str| engine.param_id(name).and_then(|id| engine.param(id));
    for d in spec.host.exciters.iter() {
        let k = d.input as usize - 1;
        let at = format!(
            "{}:{}: error: `~exciter in{} {}`",
            d.span.line,
            d.span.col,
            d.input,
            d.kind.name()
        );
        let Some(&role) = roles.get(k).filter(|r| **r != InputRole::Unused) else {
            errors.push(format!("{at}: the model has no input in{}", d.input));
            continue;
        };
        let needs_position = matches!(d.kind, ExciterKind::Bow | ExciterKind::Pluck);
        if d.kind == ExciterKind::Strike {
            if role != InputRole::Force {
                errors.push(format!(
                    "{at}: in{} is not a force input (frcInput); a strike is a force",
                    d.input
                ));
            }
            continue;
        }
        if needs_position && role != InputRole::Position {
            errors.push(format!(
                "{at}: in{} is not a position input (posInput); a {} moves an avatar",
                d.input,
                d.kind.name()
            ));
            continue;
        }
        // The law the avatar acts through, for the defaults and the reference pitch.
        let avatar = format!("in{}", d.input);
        let law = match &spec.space {
            Some(space) => space_law(space, &avatar, d.kind, &lookup),
            None => spec.elements.iter().find_map(|e| match &e.kind {
                ElementKind::Interaction { law, a, b } => {
                    let (me, other) = if matches!(a, Endpoint::Label(l) if **l == avatar) {
                        (a, b)
                    } else if matches!(b, Endpoint::Label(l) if **l == avatar) {
                        (b, a)
                    } else {
                        return None;
                    };
                    let _ = me;
                    let scale = match (d.kind, law.kind()) {
                        (ExciterKind::Bow, LawKind::Bow) => law.arg("Vscale"),
                        (ExciterKind::Pluck, LawKind::Pluck) => law.arg("Pscale"),
                        _ => None,
                    }?;
                    Some((scale.eval(&lookup), other.clone()))
                }
                _ => None,
            }),
        };
        let ms = d.time_ms.unwrap_or(if d.kind == ExciterKind::Pluck {
            DEFAULT_SWEEP_MS
        } else {
            DEFAULT_RAMP_MS
        });
        let samples = (ms * 1e-3 * sample_rate).max(1.0);
        let (amount, contact) = match d.kind {
            ExciterKind::Bow => {
                let speed = match (d.amount, &law) {
                    (Some(v), _) => v,
                    (None, Some((scale, _))) if scale.is_finite() && *scale > 0.0 => {
                        0.95 * scale * per_second
                    }
                    _ => {
                        errors.push(format!(
                            "{at}: in{} bows nothing (no nlBow on @{avatar}): give the bow's \
                             speed in units per second",
                            d.input
                        ));
                        continue;
                    }
                };
                (speed / sample_rate, law.map(|l| l.1))
            }
            ExciterKind::Pluck => {
                let travel = match (d.amount, &law) {
                    (Some(v), _) => v,
                    (None, Some((scale, _))) if scale.is_finite() && *scale > 0.0 => 4.0 * scale,
                    _ => {
                        errors.push(format!(
                            "{at}: in{} plucks nothing (no nlPluck on @{avatar}): give the \
                             plectrum's travel",
                            d.input
                        ));
                        continue;
                    }
                };
                (0.5 * travel, law.map(|l| l.1))
            }
            ExciterKind::Press | ExciterKind::Strike => {
                let Some(depth) = d.amount else {
                    errors.push(format!("{at}: a press needs its depth"));
                    continue;
                };
                (depth, None)
            }
        };
        // An audioParam keeps to its `~macro` range.
        let (mut low, mut high) = (f64::NEG_INFINITY, f64::INFINITY);
        if role == InputRole::AudioParam {
            for p in &spec.params {
                if let ParamKind::Audio { input, default } = p.kind {
                    if input == d.input {
                        if let Some(r) = spec.host.macro_ranges.iter().find(|r| r.name == p.name) {
                            low = low.max(r.min - default);
                            high = high.min(r.max - default);
                        }
                    }
                }
            }
        }
        out.push(Exciter {
            input: k,
            kind: d.kind,
            amount,
            samples,
            role,
            low: low.min(high),
            high,
            contact,
        });
    }
    if errors.is_empty() {
        Ok(out)
    } else {
        Err(Rejected(errors))
    }
}

/// The law a 3-D avatar `avatar` acts through for an exciter of `kind` (3-D spec §2.5): the
/// bow's Vscale or the plectrum's Pscale, and the endpoint it acts on.
fn space_law(
    space: &crate::spec::space::SpaceSpec,
    avatar: &str,
    kind: ExciterKind,
    lookup: &impl Fn(&str) -> Option<f64>,
) -> Option<(f64, Endpoint)> {
    use crate::laws::space::SpaceLawKind as K;
    space.elements.iter().find_map(|e| match &e.kind {
        crate::spec::space::SpaceKind::Interaction {
            law,
            args,
            a,
            b: Some(b),
        } => {
            let other = if matches!(a, Endpoint::Label(l) if **l == *avatar) {
                b
            } else if matches!(b, Endpoint::Label(l) if **l == *avatar) {
                a
            } else {
                return None;
            };
            let column = match (kind, law) {
                (ExciterKind::Bow, K::Bow | K::BowDir) => "Vscale",
                (ExciterKind::Pluck, K::Pluck | K::PluckDir) => "Pscale",
                _ => return None,
            };
            let slot = law.row().slot_of(column)?;
            Some((args.get(slot)?.eval(lookup), other.clone()))
        }
        _ => None,
    })
}
