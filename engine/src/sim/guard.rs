//! The runtime guard (spec §3.12 f): what it reports, and the end-of-block position check.
//! The per-sample check of every output is stage 6 (`Engine::write_outputs`).

/// What the runtime guard saw (spec §3.12 f; issue: stability guard).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardEvent {
    /// The sample, counted from the last reset, at which the problem was seen.
    pub sample: u64,
    pub kind: GuardKind,
    /// The point (index in [`crate::sim::info::ModelInfo::points`], or a connection point beyond
    /// them) whose position went bad, when known.
    pub point: Option<u32>,
    /// The output channel (0-based) that went bad, when it was an output.
    pub output: Option<u32>,
}

/// Why the guard tripped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GuardKind {
    /// A position or output became NaN or infinite.
    NonFinite,
    /// An output exceeded [`Engine::position_limit`](crate::Engine::position_limit), or a
    /// point [`Engine::point_limit`](crate::Engine::point_limit).
    Runaway,
}

/// The end-of-block check: the first position that is not finite or beyond `limit`, with
/// what is wrong with it.
pub(crate) fn scan_positions(x: &[f64], limit: f64) -> Option<(GuardKind, u32)> {
    let i = x.iter().position(|v| !(v.abs() <= limit))?;
    let kind = if x[i].is_finite() {
        GuardKind::Runaway
    } else {
        GuardKind::NonFinite
    };
    Some((kind, i as u32))
}
