//! Each law's slope for the analyses: the linear spring-damper (k, z) that stands for it in
//! the stability rule (spec §5.2, at its bounded tangent) and in the modal analysis (spec
//! §5.5, at rest: the rest elongation Δx, Δv = 0).
//!
//! | law | bounded (stability, §5.2) | at rest (modes, Δv = 0) |
//! |---|---|---|
//! | `springDamper` | (K, Z) | (K, Z) |
//! | `contact` | engaged: (K, Z) | (K, Z) if Δx > −θ (closed at rest), else open |
//! | `nlContact` | bounded tangent k, or 3k − 2s below the tipping point | if d = Δx + θ > 0, the slope of the bounded cubic at d, else open |
//! | `nlSpring2`/`nlSpring3` | linear K | tangent K + 2Q·\|Δx\| / K + 3Q·Δx² (K at Δx = 0) |
//! | `nlSpringDamper` | bounded tangent, damping Z + 0.3k | the slope at Δx, damping Z (Z + 0.3k in the bounded region) |
//! | `nlPluck` | 0.9·\|K\|, Z | −0.9K (no damping) for \|Δx\| < scale/10, K/10 with Z in the outer band, nothing beyond `scale` |
//! | `nlBow` | stick slope in Z: ⅔·Z, or 0.63·e^½·Z (smooth) | the same stick slope (the bow rests on the string: Δv = 0) |

use super::table::LawKind;
use super::PLUCK_SHARPNESS;

/// A law as the linear network sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Linear {
    /// f = k·Δx + z·Δv.
    Link { k: f64, z: f64 },
    /// A contact open at rest: no force, but a path the modal analysis notes.
    Open,
    /// No force at all.
    Free,
}

/// What the bounded valuation notes of a law's arguments (spec §5.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BoundNote {
    /// A negative cubic coefficient: the law softens without bound.
    NegativeCubic,
    /// A nonlinear term with no bound: the linear K is all the rule can use.
    Unbounded,
    /// `nlSpringDamper` bounded below its own small-signal stiffness.
    WeakBound,
}

/// The tangent of the bounded cubic of `nlContact`/`nlSpringDamper` at d (spec §2.4.2,
/// §2.5.3): s for c = 0, k on the bounded branch, s + 3c·d² in the cubic region. Returns the
/// slope and whether d is in the bounded region.
fn bounded_cubic_slope(d: f64, s: f64, c: f64, k: f64) -> (f64, bool) {
    if c == 0.0 {
        (s, false)
    } else if s >= k || c < 0.0 {
        (k, true)
    } else if c * d * d <= k - s {
        (s + 3.0 * c * d * d, false)
    } else {
        (k, true)
    }
}

/// The bounded tangent of the bounded cubic: s for c = 0, k when the bound is all there is,
/// else 3k − 2s (the slope at the tipping point, the steepest the cubic gets).
fn bounded_cubic_bound(s: f64, c: f64, k: f64) -> f64 {
    if c == 0.0 {
        s
    } else if s >= k || c < 0.0 {
        k
    } else {
        3.0 * k - 2.0 * s
    }
}

impl LawKind {
    /// The law's linear stand-in for the arguments `a` (its columns, per-step values): at its
    /// bounded tangent when `rest_dx` is `None`, else at rest with elongation `rest_dx`.
    pub(crate) fn linearise(self, a: &[f64], rest_dx: Option<f64>) -> Linear {
        let link = |k: f64, z: f64| Linear::Link { k, z };
        match self {
            LawKind::SpringDamper => link(a[0], a[1]),
            LawKind::Contact => {
                let (k, z, t) = (a[0], a[1], a[2]);
                // Engaged iff Δx > −θ (spec §2.4.1); counted engaged by the bound.
                if rest_dx.is_none_or(|dx| dx > -t) {
                    link(k, z)
                } else {
                    Linear::Open
                }
            }
            LawKind::NlContact => {
                let (s, c, k, z, t) = (a[0], a[1], a[2], a[3], a[4]);
                let (k, c) = if k < s { (s, 0.0) } else { (k, c) };
                match rest_dx {
                    None => link(bounded_cubic_bound(s, c, k), z),
                    Some(dx) if dx + t > 0.0 => link(bounded_cubic_slope(dx + t, s, c, k).0, z),
                    Some(_) => Linear::Open,
                }
            }
            LawKind::NlSpring2 | LawKind::NlSpring3 => {
                let (k, q, z) = (a[0], a[1], a[2]);
                match rest_dx {
                    None => link(k, z),
                    // d/dΔx of K·Δx + Q·sgn(Δx)·Δx² or K·Δx + Q·Δx³ (spec §2.5.1–2).
                    Some(dx) if self == LawKind::NlSpring2 => link(k + 2.0 * q * dx.abs(), z),
                    Some(dx) => link(k + 3.0 * q * dx * dx, z),
                }
            }
            LawKind::NlSpringDamper => {
                let (s, c, k, z) = (a[0], a[1], a[2], a[3]);
                match rest_dx {
                    None if c == 0.0 => link(s, z),
                    None => link(bounded_cubic_bound(s, c, k), z + 0.3 * k),
                    Some(dx) => match bounded_cubic_slope(dx, s, c, k) {
                        (slope, true) => link(slope, z + 0.3 * k),
                        (slope, false) => link(slope, z),
                    },
                }
            }
            LawKind::Pluck => {
                let (k, scale, z) = (a[0], a[1], a[2]);
                match rest_dx {
                    None => link(0.9 * k.abs(), z),
                    // The tent of spec §2.6.1: slope −(K − K/σ) inside d_t, K/σ with Z
                    // outside.
                    Some(dx) if dx.abs() < scale / PLUCK_SHARPNESS => {
                        link(-(k - k / PLUCK_SHARPNESS), 0.0)
                    }
                    Some(dx) if dx.abs() < scale => link(k / PLUCK_SHARPNESS, z),
                    Some(_) => Linear::Free,
                }
            }
            LawKind::Bow => {
                let (z, scale, smooth) = (a[0], a[1], a[2]);
                // The slope of the friction law at Δv = 0 (spec §2.6.2); no force for
                // scale ≤ 0.
                let stick = if !(scale > 0.0) {
                    0.0
                } else if smooth >= 1.0 {
                    0.63 * 0.5f64.exp() * z
                } else {
                    2.0 / 3.0 * z
                };
                link(0.0, stick)
            }
        }
    }

    /// What the stability rule notes of the arguments `a`, if anything.
    pub(crate) fn bound_note(self, a: &[f64]) -> Option<BoundNote> {
        match self {
            // `k < s` turns the cubic off (spec §2.4.2).
            LawKind::NlContact if a[1] < 0.0 && !(a[2] < a[0]) => Some(BoundNote::NegativeCubic),
            LawKind::NlSpring2 | LawKind::NlSpring3 if a[1] != 0.0 => Some(BoundNote::Unbounded),
            LawKind::NlSpringDamper if a[1] < 0.0 => Some(BoundNote::NegativeCubic),
            LawKind::NlSpringDamper if a[1] != 0.0 && a[2] < a[0] => Some(BoundNote::WeakBound),
            LawKind::SpringDamper
            | LawKind::Contact
            | LawKind::NlContact
            | LawKind::NlSpring2
            | LawKind::NlSpring3
            | LawKind::NlSpringDamper
            | LawKind::Pluck
            | LawKind::Bow => None,
        }
    }
}
