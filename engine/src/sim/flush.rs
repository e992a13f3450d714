//! The periodic flush of tiny values, so that a decaying model never reaches the subnormal
//! range and its outputs never are subnormal, whatever the host's FTZ/DAZ setting.

use crate::sim::kernels::Points;

/// Positions, delayed positions and pending forces smaller than this (model units) are set to
/// exactly 0 every
/// [`FLUSH_INTERVAL`] samples: a decaying model never reaches the subnormal range (below
/// 2.2·10⁻³⁰⁸), where every operation is slow on CPUs without flush-to-zero, and the outputs it
/// reads never are subnormal, whatever the host's FTZ/DAZ setting. 10⁻¹⁵⁰ is 3000 dB below
/// anything audible, and leaves 150 orders of magnitude for the products of the kernels and a
/// fast decay between two flushes.
pub const FLUSH_BELOW: f64 = 1.0e-150;

/// How often (in samples counted from the reset, so independent of the block size) the state
/// is flushed.
pub const FLUSH_INTERVAL: u64 = 64;

/// Sets every position, delayed position and pending force below [`FLUSH_BELOW`] to exactly
/// 0 (a mask, not a branch, so that it vectorises). The forces count: stage 4 leaves them
/// for the next sample's mass update, and a tail flushed without them comes back from them.
#[inline(always)]
pub(crate) fn flush_tiny(p: &mut Points) {
    // One loop per array: a chain of the three does not vectorise.
    for a in [&mut p.x, &mut p.xp, &mut p.f] {
        for v in a.iter_mut() {
            // Every value is written back: v·1 + 0 is v for any v that is not tiny
            // (NaN stays for the guard), v·0 + 0 is +0 for a tiny one (−0 included).
            // Written as a select (or as a bit mask, which the compiler turns back into
            // one), this compiled into AVX masked stores, which Zen CPUs run microcoded:
            // the flush cost 3 % of the Chladni plate's time.
            let keep = if v.abs() < FLUSH_BELOW { 0.0 } else { 1.0 };
            *v = *v * keep + 0.0;
        }
    }
}
