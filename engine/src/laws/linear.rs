//! Each law's slope for the analyses: the linear spring-damper (k, z) that stands for it in
//! the stability rule (spec §5.2, at its bounded tangent) and in the modal analysis (spec
//! §5.5, at rest: the rest elongation Δx, Δv = 0). Each law gives its own
//! ([`super::Law::linearise`], described in the law's file).

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
