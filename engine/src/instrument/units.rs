//! Macro slots in musical units. A slot bound to a stiffness reads as the frequency it gives
//! the model's reference mode, a damping as that mode's T60, a connection-point coordinate as
//! 0 … 1 and a mass as a ratio of the declared mass; anything else as its per-step value. The
//! per-step value stays readable (`K = 0.12` is still understood, and the editor shows it).
//!
//! What a parameter is comes from the stability analysis (spec §5.2): moving it changes the
//! masses' M, or their attached stiffness K_eq, or damping Z_eq. The frequencies and decays
//! come from the modal analysis ([`crate::analysis::modes`]) at the slot's ends and its centre, and
//! are interpolated between them: the slot is geometric in the value on each side of its centre,
//! and a mode's frequency a power of its stiffness in the low-frequency limit, so piecewise
//! log-linear.

use super::macros::MacroBinding;
use crate::{Engine, StabilityReport};

/// How a macro slot's value reads.
#[derive(Clone, Debug, PartialEq)]
pub enum MacroUnit {
    /// The per-step value: `NAME = 0.1200`.
    Value,
    /// A connection-point coordinate: `NAME = 0.300` along the structure.
    Position,
    /// A mass: `NAME ×2.00` of the declared value.
    MassRatio,
    /// A stiffness: the reference mode's frequency, `NAME: 312 Hz`.
    Frequency(UnitTable),
    /// A damping: the reference mode's decay, `NAME: T60 2.35 s`.
    Decay(UnitTable),
}

/// A quantity at slot positions, increasing in position; positive values.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitTable {
    /// (slot position 0 … 1, value), by position.
    pub points: Vec<(f64, f64)>,
}

impl UnitTable {
    /// The value at slot position `n`: log-linear between the table's positions.
    pub fn at(&self, n: f64) -> f64 {
        let p = &self.points;
        let n = n.clamp(0.0, 1.0);
        let i = p
            .windows(2)
            .position(|w| n <= w[1].0)
            .unwrap_or(p.len().saturating_sub(2));
        let (a, b) = (p[i], p[(i + 1).min(p.len() - 1)]);
        if b.0 <= a.0 {
            return a.1;
        }
        let t = (n - a.0) / (b.0 - a.0);
        if t <= 0.0 {
            a.1
        } else if t >= 1.0 {
            b.1
        } else {
            (a.1.ln() + t * (b.1.ln() - a.1.ln())).exp()
        }
    }

    /// The slot position whose value is `v` (bisection; the table is monotone), clamped to
    /// the ends.
    pub fn position_of(&self, v: f64) -> f64 {
        let (lo_v, hi_v) = (self.at(0.0), self.at(1.0));
        let rising = hi_v >= lo_v;
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if (self.at(mid) < v) == rising {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// True when the reference mode follows the slot: monotone, and moving by more than
    /// [`FLAT`] of itself over the range. A flatter table is a slot that does not move that
    /// mode (a stiffness elsewhere in the model), whose "trend" is the eigensolver's rounding
    /// and would flip with the processor's SIMD width; its unit is the plain value.
    fn follows_the_slot(&self) -> bool {
        let p = &self.points;
        if !p.iter().all(|x| x.1 > 0.0 && x.1.is_finite()) {
            return false;
        }
        let (lo, hi) = p.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), x| {
            (lo.min(x.1), hi.max(x.1))
        });
        let noise = FLAT * hi;
        if hi - lo <= noise {
            return false;
        }
        let up = p.windows(2).all(|w| w[1].1 >= w[0].1 - noise);
        let down = p.windows(2).all(|w| w[1].1 <= w[0].1 + noise);
        up || down
    }
}

/// A unit table whose values span less than this fraction of themselves does not follow its
/// slot ([`UnitTable::follows_the_slot`]).
const FLAT: f64 = 1e-6;

/// What moving a parameter changes, by the stability analysis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    Mass,
    Stiffness,
    Damping,
    Other,
}

fn sums(r: &StabilityReport) -> (f64, f64, f64) {
    r.masses.iter().fold((0.0, 0.0, 0.0), |(m, k, z), s| {
        (m + s.m, k + s.k_eq, z + s.z_eq)
    })
}

/// What the parameter of `b` is: the masses, stiffness or damping its value moves (the
/// largest relative change wins). The engine is left at the declared value.
pub fn role(engine: &mut Engine, b: &MacroBinding) -> Role {
    let base = sums(&engine.stability_numbers());
    let other = if b.max != b.default { b.max } else { b.min };
    if other == b.default || engine.set_param(b.param, other).is_err() {
        return Role::Other;
    }
    let moved = sums(&engine.stability_numbers());
    let _ = engine.set_param(b.param, b.default);
    engine.apply_pending_changes();
    let rel = |a: f64, b: f64| (b - a).abs() / a.abs().max(1e-300);
    let changes = [
        (rel(base.0, moved.0), Role::Mass),
        (rel(base.1, moved.1), Role::Stiffness),
        (rel(base.2, moved.2), Role::Damping),
    ];
    changes
        .iter()
        .filter(|c| c.0 > 1e-12)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map_or(Role::Other, |c| c.1)
}

/// Slot positions at which the reference mode is measured: the ends and the declared value.
/// Between them the slot is geometric in the value, and a mode's frequency (or decay) a power
/// of it in the low-frequency limit, so log-linear interpolation is close.
const TABLE_POSITIONS: [f64; 3] = [0.0, 0.5, 1.0];

/// The largest model whose table positions are analysed at once. A dense analysis holds
/// about three N × N matrices (24 MB for the 1000-mass string): three at once took a
/// never-seen string's load to a 130 MB peak, one at a time keeps it near 48 MB.
const CONCURRENT_POINTS: usize = 300;

/// The unit of slot `b`. `reference(engine)` measures the reference mode of the engine as it
/// stands: (frequency in Hz, T60 in s), or None where the analysis does not apply; it is
/// called at the [`TABLE_POSITIONS`] for a stiffness or damping, all at once up to
/// [`CONCURRENT_POINTS`] points: each is a modal analysis of up to a few hundred
/// milliseconds, so each but the first runs on its own thread with its own copy of the engine
/// (a table whose low end fails then costs the other two in CPU time, not in wall time).
/// Larger models measure one position after the other, for their memory. The engine is left
/// at the declared value.
pub fn unit_of(
    engine: &mut Engine,
    b: &MacroBinding,
    coordinate: bool,
    reference: &(dyn Fn(&mut Engine) -> Option<(f64, f64)> + Sync),
) -> MacroUnit {
    if coordinate {
        return MacroUnit::Position;
    }
    let role = role(engine, b);
    let table = |engine: &mut Engine, pick: fn((f64, f64)) -> f64| -> Option<UnitTable> {
        let measure = |e: &mut Engine, n: f64| -> Option<f64> {
            e.set_param(b.param, b.value_at(n)).ok()?;
            e.apply_pending_changes();
            reference(e).map(pick)
        };
        let values = if engine.info().num_points <= CONCURRENT_POINTS {
            // The positions at once: each but the first on its own thread, with its own copy
            // of the engine.
            let (mut middle, mut high) = (engine.clone(), engine.clone());
            let ((v_high, v_middle), v_low) = crate::analysis::concurrent::join(
                || {
                    crate::analysis::concurrent::join(
                        || measure(&mut high, TABLE_POSITIONS[2]),
                        || measure(&mut middle, TABLE_POSITIONS[1]),
                    )
                },
                || measure(engine, TABLE_POSITIONS[0]),
            );
            [v_low, v_middle, v_high]
        } else {
            TABLE_POSITIONS.map(|n| measure(engine, n))
        };
        let _ = engine.set_param(b.param, b.default);
        engine.apply_pending_changes();
        let points = TABLE_POSITIONS
            .iter()
            .zip(values)
            .map(|(&n, v)| match v {
                Some(v) if v.is_finite() && v > 0.0 => Some((n, v)),
                _ => None,
            })
            .collect::<Option<Vec<_>>>()?;
        let t = UnitTable { points };
        t.follows_the_slot().then_some(t)
    };
    match role {
        Role::Mass if b.default > 0.0 => MacroUnit::MassRatio,
        Role::Stiffness => table(engine, |r| r.0).map_or(MacroUnit::Value, MacroUnit::Frequency),
        Role::Damping => table(engine, |r| r.1).map_or(MacroUnit::Value, MacroUnit::Decay),
        _ => MacroUnit::Value,
    }
}

/// Four significant digits, without exponent for ordinary magnitudes.
pub fn format_value(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.3e}")
    } else {
        let digits = if a >= 1.0 {
            3 - a.log10().floor() as i32
        } else {
            4
        };
        format!("{v:.*}", digits.clamp(0, 6) as usize)
    }
}

/// A frequency with three or four significant digits: `312 Hz`, `1.25 kHz`.
fn format_hz(f: f64) -> String {
    if f >= 1000.0 {
        format!("{:.3} kHz", f / 1000.0)
    } else if f >= 100.0 {
        format!("{f:.1} Hz")
    } else {
        format!("{f:.2} Hz")
    }
}

fn format_seconds(t: f64) -> String {
    if t >= 100.0 {
        format!("{t:.0} s")
    } else if t >= 10.0 {
        format!("{t:.1} s")
    } else if t >= 0.01 {
        format!("{t:.3} s")
    } else {
        format!("{:.2} ms", t * 1000.0)
    }
}

impl MacroUnit {
    /// The slot's text at position `n`.
    pub fn text(&self, b: &MacroBinding, n: f64) -> String {
        let v = b.value_at(n);
        match self {
            MacroUnit::Value => format!("{} = {}", b.name, format_value(v)),
            MacroUnit::Position => format!("{} = {:.3}", b.name, v),
            MacroUnit::MassRatio => format!("{} ×{:.3}", b.name, v / b.default),
            MacroUnit::Frequency(t) => format!("{}: {}", b.name, format_hz(t.at(n))),
            MacroUnit::Decay(t) => format!("{}: T60 {}", b.name, format_seconds(t.at(n))),
        }
    }

    /// The slot position a typed text asks for: the unit's own form (`312 Hz`, `1.2 kHz`,
    /// `T60 2.5 s`, `450 ms`, `×2`) or the per-step value (`K = 0.12`, `0.12`).
    pub fn position_of(&self, b: &MacroBinding, text: &str) -> Option<f64> {
        let t = text.trim().replace(['\u{2212}'], "-");
        let body = t
            .strip_prefix(b.name.as_str())
            .map(|r| r.trim_start_matches([':', ' ']))
            .unwrap_or(&t)
            .trim();
        let lower = body.to_ascii_lowercase();
        let num = |s: &str| s.trim().parse::<f64>().ok().filter(|v| v.is_finite());
        match self {
            MacroUnit::Frequency(table) => {
                if let Some(k) = lower.strip_suffix("khz").and_then(num) {
                    return Some(table.position_of(k * 1000.0));
                }
                if let Some(h) = lower.strip_suffix("hz").and_then(num) {
                    return Some(table.position_of(h));
                }
            }
            MacroUnit::Decay(table) => {
                let l = lower.trim_start_matches("t60").trim();
                if let Some(ms) = l.strip_suffix("ms").and_then(num) {
                    return Some(table.position_of(ms / 1000.0));
                }
                if let Some(s) = l.strip_suffix('s').and_then(num) {
                    return Some(table.position_of(s));
                }
            }
            MacroUnit::MassRatio => {
                let r = lower.trim_start_matches(['×', 'x', '*']);
                if r.len() != lower.len() {
                    return num(r).map(|r| b.normalized_of(r * b.default));
                }
            }
            MacroUnit::Value | MacroUnit::Position => {}
        }
        // The per-step value: `K = 0.12`, `= 0.12`, `0.12`.
        let value = body.trim_start_matches('=').trim();
        num(value).map(|v| b.normalized_of(v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ParamId;

    fn binding() -> MacroBinding {
        MacroBinding {
            param: ParamId(0),
            name: "K".into(),
            default: 0.1,
            min: 0.025,
            max: 0.4,
        }
    }

    #[test]
    fn tables_interpolate_and_invert() {
        let t = UnitTable {
            points: vec![(0.0, 100.0), (0.5, 200.0), (1.0, 400.0)],
        };
        assert!((t.at(0.25) - 141.421356).abs() < 1e-4, "log-linear");
        assert_eq!(t.at(2.0), 400.0);
        for n in [0.0, 0.1, 0.5, 0.77, 1.0] {
            assert!((t.position_of(t.at(n)) - n).abs() < 1e-9);
        }
        let falling = UnitTable {
            points: vec![(0.0, 4.0), (0.5, 2.0), (1.0, 1.0)],
        };
        assert!((falling.position_of(2.0) - 0.5).abs() < 1e-9);
    }

    #[test]
    fn texts_read_back() {
        let b = binding();
        let f = MacroUnit::Frequency(UnitTable {
            points: vec![(0.0, 110.0), (0.5, 220.0), (1.0, 440.0)],
        });
        assert_eq!(f.text(&b, 0.5), "K: 220.0 Hz");
        assert_eq!(f.text(&b, 1.0), "K: 440.0 Hz");
        for typed in ["K: 220.0 Hz", "220 hz", "0.22 kHz", "K = 0.1", "0.1"] {
            let n = f.position_of(&b, typed).unwrap();
            assert!((n - 0.5).abs() < 1e-6, "{typed}: {n}");
        }
        let d = MacroUnit::Decay(UnitTable {
            points: vec![(0.0, 8.0), (0.5, 2.0), (1.0, 0.5)],
        });
        assert_eq!(d.text(&b, 0.5), "K: T60 2.000 s");
        for typed in ["K: T60 2.000 s", "2 s", "2000 ms", "T60 2s"] {
            assert!(
                (d.position_of(&b, typed).unwrap() - 0.5).abs() < 1e-6,
                "{typed}"
            );
        }
        let m = MacroUnit::MassRatio;
        assert_eq!(m.text(&b, 1.0), "K ×4.000");
        assert!((m.position_of(&b, "×4").unwrap() - 1.0).abs() < 1e-9);
        assert!((m.position_of(&b, "x1").unwrap() - 0.5).abs() < 1e-9);
        let v = MacroUnit::Value;
        assert_eq!(v.text(&b, 0.5), "K = 0.1000");
        assert_eq!(v.position_of(&b, "K = 0.1000"), Some(0.5));
        assert_eq!(v.position_of(&b, "nonsense"), None);
        // Exponent forms read too (formerly the plugin's own macro text parser).
        assert_eq!(
            v.position_of(&b, "K = 2.500e-2"),
            Some(b.normalized_of(0.025))
        );
        // Text → position → text is stable.
        for u in [&f, &d, &m, &v] {
            for i in 0..=20 {
                let n = i as f64 / 20.0;
                let text = u.text(&b, n);
                let back = u.position_of(&b, &text).unwrap();
                assert_eq!(u.text(&b, back), text, "{u:?} at {n}");
            }
        }
    }
}
