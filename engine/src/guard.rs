//! The runtime guard (spec §3.12 f): what it reports, and the end-of-block position check.
//! The per-sample check of every output is stage 6 (`Engine::write_outputs`).

use crate::engine::Engine;

/// What the runtime guard saw (spec §3.12 f; issue: stability guard).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardEvent {
    /// The sample, counted from the last reset, at which the problem was seen.
    pub sample: u64,
    pub kind: GuardKind,
    /// The point (index in [`crate::info::ModelInfo::points`], or a connection point beyond them) whose
    /// position went bad, when known.
    pub point: Option<u32>,
    /// The output channel (0-based) that went bad, when it was an output.
    pub output: Option<u32>,
}

/// Why the guard tripped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GuardKind {
    /// A position or output became NaN or infinite.
    NonFinite,
    /// A position or output exceeded [`Engine::position_limit`].
    Runaway,
}

impl Engine {
    /// Checks every position at the end of a block.
    pub(crate) fn scan_positions(&mut self) {
        let limit = self.position_limit;
        let found = self.points.x.iter().position(|v| !(v.abs() <= limit));
        if let Some(i) = found {
            let kind = if self.points.x[i].is_finite() {
                GuardKind::Runaway
            } else {
                GuardKind::NonFinite
            };
            self.trip(kind, Some(i as u32), None);
        }
    }

    pub(crate) fn trip(&mut self, kind: GuardKind, point: Option<u32>, output: Option<u32>) {
        self.guard = Some(GuardEvent {
            sample: self.samples_since_reset,
            kind,
            point,
            output,
        });
    }
}
