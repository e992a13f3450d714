//! Stage 4 of a 3-D model, the interactions (3-D spec §1.5, §2.2–§2.5): one group per law of
//! the 3-D table, applied in table order, each link as its law's file writes it
//! ([`crate::laws::space`]), F₁ −= g and F₂ += g in link order (a one-endpoint law, F₁ −= g).
//!
//! A group's links are in segments: the links of one structure, one adder, or a run of
//! explicit lines. Within a segment, argument slot `c` of link `i` is
//! `base[c] + step[c]·i`: a structure's shared K and Z have step 0, its rest lengths (each
//! link's own `auto`) step 1, an explicit line's every slot step 1.

use super::super::kernels::Points;
use crate::laws::space::{Ends, SpaceLaw, SpaceLawKind, SpaceLawVisitor};
use crate::laws::Scalar;

/// The most argument slots of a 3-D law.
pub(crate) const MAX_SLOTS: usize = SpaceLawKind::MAX_SLOTS;

/// A range of a group's links with one slot addressing.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Segment {
    pub start: u32,
    pub len: u32,
    pub base: [u32; MAX_SLOTS],
    pub step: [u32; MAX_SLOTS],
}

/// The links of one 3-D law.
#[derive(Clone, Debug, Default)]
pub(crate) struct Group3 {
    /// Endpoint point indices (`b` equals `a` for a one-endpoint law).
    pub a: Vec<u32>,
    pub b: Vec<u32>,
    /// Each link's element (an index into the spec's 3-D elements), for the analyses' notes.
    pub elements: Vec<u32>,
    pub segments: Vec<Segment>,
}

impl Group3 {
    pub fn len(&self) -> usize {
        self.a.len()
    }
}

/// One group's links on the three axes.
#[inline(always)]
fn apply<L: SpaceLaw>(g: &Group3, x: &mut Points, y: &mut Points, z: &mut Points, args: &[f64]) {
    let one = L::ROW.endpoints == 1;
    for seg in &g.segments {
        for i in 0..seg.len {
            let l = (seg.start + i) as usize;
            let a = g.a[l] as usize;
            let b = g.b[l] as usize;
            let p = |c: usize| args[(seg.base[c] + seg.step[c] * i) as usize];
            let e = Ends {
                x1: [x.x[a], y.x[a], z.x[a]],
                xp1: [x.xp[a], y.xp[a], z.xp[a]],
                x2: [x.x[b], y.x[b], z.x[b]],
                xp2: [x.xp[b], y.xp[b], z.xp[b]],
            };
            let f = L::force(&Scalar, &e, p);
            x.f[a] -= f[0];
            y.f[a] -= f[1];
            z.f[a] -= f[2];
            if !one {
                x.f[b] += f[0];
                y.f[b] += f[1];
                z.f[b] += f[2];
            }
        }
    }
}

/// Stage 4's interactions: every group in table order.
#[inline(always)]
pub(crate) fn step(
    groups: &[Group3],
    x: &mut Points,
    y: &mut Points,
    z: &mut Points,
    args: &[f64],
) {
    struct Visit<'a> {
        groups: &'a [Group3],
        x: &'a mut Points,
        y: &'a mut Points,
        z: &'a mut Points,
        args: &'a [f64],
    }
    impl SpaceLawVisitor for Visit<'_> {
        #[inline(always)]
        fn visit<L: SpaceLaw>(&mut self, kind: SpaceLawKind) {
            let g = &self.groups[kind.index()];
            if !g.segments.is_empty() {
                apply::<L>(g, self.x, self.y, self.z, self.args);
            }
        }
    }
    SpaceLawKind::visit_all(&mut Visit {
        groups,
        x,
        y,
        z,
        args,
    });
}
