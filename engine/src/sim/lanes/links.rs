//! Stage 4 of spec §1.5 in lanes: the interactions of a link group ([`Group`]), each lane with
//! its own arguments, in the plain engine's order (`Group::apply`), so that each lane equals
//! a plain engine bit for bit (engine test `lanes`).

use super::arith::TableLaw;
use super::vector::{self, Ops};
use super::Lanes;
use crate::laws::{Law, LawKind, LawVisitor};
use crate::sim::engine::Group;
use crate::sim::engine::Interactions;
use std::marker::PhantomData;

/// A link law in every lane: the force of a group's link `i` from the deltas of every lane.
/// A trait with inlined methods rather than a closure: a closure is compiled without the
/// instruction set of the loop that calls it, and its vector operations would not inline.
/// The arguments are read apart from the force, so that a uniform band reads them once.
pub(super) trait LaneLaw {
    /// A link's arguments, as the law reads them.
    type Args: Copy;
    /// Link `i`'s arguments.
    fn args(&self, i: usize) -> Self::Args;
    /// The force for `args` and the deltas of every lane.
    fn force<S: pulp::Simd>(&self, o: Ops<S>, args: Self::Args, dx: Lanes, dv: Lanes) -> Lanes;
}

/// `law` on every pair of a group and every lane, with the convention of spec §1.3: F₁ −= f,
/// F₂ += f, link by link; a band as `Group::apply` runs it (its forces, then every point's
/// sum: the same arithmetic).
#[inline(always)]
pub(super) fn apply<S: pulp::Simd>(
    o: Ops<S>,
    g: &Group,
    x: &[Lanes],
    xp: &[Lanes],
    f: &mut [Lanes],
    law: &impl LaneLaw,
) {
    let n = g.len();
    let (a, b) = (&g.a[..n], &g.b[..n]);
    let mut i = 0;
    let mut c = 0;
    loop {
        if g.reversed.get(c).copied().unwrap_or(false) {
            // Reversed chains scatter here, with the links before the next chain.
            c += 1;
            continue;
        }
        let (next, m, d) = match g.chains.get(c) {
            Some(&(start, len, d)) => (start as usize, len as usize, d as usize),
            None => (n, 0, 0),
        };
        for k in i..next {
            let (ia, ib) = (a[k] as usize, b[k] as usize);
            let (dx, dv) = vector::deltas(o, x[ia], x[ib], xp[ia], xp[ib]);
            let force = law.force(o, law.args(k), dx, dv);
            f[ia] = o.sub(f[ia], force);
            f[ib] = o.add(f[ib], force);
        }
        if m == 0 {
            break;
        }
        // A band in order, link by link: f[q+j] −= s_j, then f[q+j+d] += s_j. Point t gets
        // (F + s[t−d]) − s[t], as `Group::apply` sums it; lanes need no scratch.
        let q = a[next] as usize;
        let points = q..q + m + d;
        let (x, xp, f) = (&x[points.clone()], &xp[points.clone()], &mut f[points]);
        // A uniform band's links have the same arguments in every lane: the first link's.
        let uniform = g.uniform.get(c).copied().unwrap_or(false);
        match (d, uniform) {
            (1, true) => chain::<S, true>(o, x, xp, f, law, next),
            (1, false) => chain::<S, false>(o, x, xp, f, law, next),
            (_, true) => {
                let args = law.args(next);
                band(o, x, xp, f, d, |_| args, law)
            }
            (_, false) => band(o, x, xp, f, d, |j| law.args(next + j), law),
        }
        i = next + m;
        c += 1;
    }
}

/// A band of offset 1 (a chain of `x.len() − 1` links over consecutive points, the group's
/// links from `first` on), with the arithmetic of `apply`'s band loop: each point's position,
/// velocity and pending force are read once and carried to the next link in registers. A
/// `UNIFORM` chain reads the first link's arguments for every link.
#[inline(always)]
fn chain<S: pulp::Simd, const UNIFORM: bool>(
    o: Ops<S>,
    x: &[Lanes],
    xp: &[Lanes],
    f: &mut [Lanes],
    law: &impl LaneLaw,
    first: usize,
) {
    let m = x.len() - 1;
    let (xp, f) = (&xp[..=m], &mut f[..=m]);
    let (mut xa, mut va, mut fa) = (x[0], o.sub(x[0], xp[0]), f[0]);
    let uniform = law.args(first);
    for j in 0..m {
        let xb = x[j + 1];
        let vb = o.sub(xb, xp[j + 1]);
        // Δx and Δv as `vector::deltas` forms them.
        let args = if UNIFORM {
            uniform
        } else {
            law.args(first + j)
        };
        let force = law.force(o, args, o.sub(xa, xb), o.sub(va, vb));
        f[j] = o.sub(fa, force);
        fa = o.add(f[j + 1], force);
        (xa, va) = (xb, vb);
    }
    f[m] = fa;
}

/// A band of offset `d` over `x.len() − d` links, link j with the arguments `args(j)`, in
/// `apply`'s order.
#[inline(always)]
fn band<S: pulp::Simd, L: LaneLaw>(
    o: Ops<S>,
    x: &[Lanes],
    xp: &[Lanes],
    f: &mut [Lanes],
    d: usize,
    args: impl Fn(usize) -> L::Args,
    law: &L,
) {
    let m = x.len() - d;
    let (xp, f) = (&xp[..m + d], &mut f[..m + d]);
    for j in 0..m {
        let (dx, dv) = vector::deltas(o, x[j], x[j + d], xp[j], xp[j + d]);
        let force = law.force(o, args(j), dx, dv);
        f[j] = o.sub(f[j], force);
        f[j + d] = o.add(f[j + d], force);
    }
}

/// Stage 4 in lanes, law by law as `Interactions::step` runs it ([`LawKind::visit_all`]):
/// each group with its argument columns (`args`, one [`Lanes`] per slot).
pub(super) struct Stage4<'a, S> {
    pub o: Ops<S>,
    pub interactions: &'a Interactions,
    pub args: &'a [Lanes],
    pub x: &'a [Lanes],
    pub xp: &'a [Lanes],
    pub f: &'a mut [Lanes],
}

impl<S: pulp::Simd> LawVisitor for Stage4<'_, S> {
    #[inline(always)]
    fn visit<L: Law>(&mut self, kind: LawKind) {
        let g = self.interactions.group(kind);
        if g.len() == 0 {
            return;
        }
        let arity = L::ROW.columns.len();
        let args = self.args;
        let cols = std::array::from_fn(|c| {
            if c < arity {
                &args[g.cols[c]..g.cols[c] + g.len()]
            } else {
                &[][..]
            }
        });
        let law = TableLaw::<L> {
            cols,
            law: PhantomData,
        };
        apply(self.o, g, self.x, self.xp, self.f, &law);
    }
}
