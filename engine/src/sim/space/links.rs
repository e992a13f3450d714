//! Stage 4 of a 3-D model, the interactions (3-D spec §1.5, §2.2–§2.5): one group per law of
//! the 3-D table, applied in table order, each link as its law's file writes it
//! ([`crate::laws::space`]), F₁ −= g and F₂ += g in link order (a one-endpoint law, F₁ −= g).
//!
//! A group's links are in segments: the links of one structure, one adder, or a run of
//! explicit lines. Within a segment, argument slot `c` of link `i` is
//! `base[c] + step[c]·i`: a structure's shared K and Z have step 0, its rest lengths (each
//! link's own `auto`) step 1, an explicit line's every slot step 1.

use super::super::kernels::Points;
use crate::laws::space::{map3, Ends, SpaceLaw, SpaceLawKind, SpaceLawVisitor};
use crate::laws::Scalar;
use crate::sim::lanes::Native;
use pulp::Simd;

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

/// Link `l` of segment `seg` (its index `i` in the segment): its force by the law on the
/// scalar path, applied F₁ −= g, F₂ += g.
#[inline(always)]
fn one<L: SpaceLaw>(
    g: &Group3,
    seg: &Segment,
    i: u32,
    x: &mut Points,
    y: &mut Points,
    z: &mut Points,
    args: &[f64],
) {
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
    spread::<L>(L::force(&Scalar, &e, p), a, b, x, y, z);
}

/// F₁ −= g and, for a two-endpoint law, F₂ += g.
#[inline(always)]
fn spread<L: SpaceLaw>(
    f: [f64; 3],
    a: usize,
    b: usize,
    x: &mut Points,
    y: &mut Points,
    z: &mut Points,
) {
    x.f[a] -= f[0];
    y.f[a] -= f[1];
    z.f[a] -= f[2];
    if L::ROW.endpoints != 1 {
        x.f[b] += f[0];
        y.f[b] += f[1];
        z.f[b] += f[2];
    }
}

/// One group's links on the three axes, one at a time (the reference path, and the
/// remainder of [`apply_vector`]).
#[inline(always)]
fn apply<L: SpaceLaw>(g: &Group3, x: &mut Points, y: &mut Points, z: &mut Points, args: &[f64]) {
    for seg in &g.segments {
        for i in 0..seg.len {
            one::<L>(g, seg, i, x, y, z, args);
        }
    }
}

/// The most links [`apply_vector`] evaluates at once (AVX-512's eight `f64`s).
const MAX_WIDTH: usize = 8;

/// The three axes as slices of one length `n`, so that one comparison of an endpoint index
/// with `n` stands for the bounds checks of all nine arrays.
struct View<'a> {
    n: usize,
    x: [&'a [f64]; 3],
    xp: [&'a [f64]; 3],
    f: [&'a mut [f64]; 3],
}

impl<'a> View<'a> {
    #[inline(always)]
    fn new(x: &'a mut Points, y: &'a mut Points, z: &'a mut Points) -> View<'a> {
        let n = x.x.len();
        View {
            n,
            x: [&x.x[..n], &y.x[..n], &z.x[..n]],
            xp: [&x.xp[..n], &y.xp[..n], &z.xp[..n]],
            f: [&mut x.f[..n], &mut y.f[..n], &mut z.f[..n]],
        }
    }
}

/// One group's links on the three axes, `S::F64_LANES` links at a time: their endpoints and
/// arguments gathered into one native vector per coordinate, the law evaluated once on
/// [`Native`] (each lane the scalar law's IEEE operations in the same order, so each link's
/// g has the scalar path's bits), then g applied link by link in link order as [`apply`]
/// does, so every force sums in the same order. A chunk whose links are a chain (endpoints
/// at consecutive points, a string or a mesh row) loads its coordinates as vectors; an
/// argument with its own slot per link (step 1) is one vector load. The segment's remainder
/// runs [`one`].
#[inline(always)]
fn apply_vector<L: SpaceLaw, S: Simd>(
    simd: S,
    g: &Group3,
    x: &mut Points,
    y: &mut Points,
    z: &mut Points,
    args: &[f64],
) {
    let w = S::F64_LANES;
    let slots = L::ROW.slots();
    let two = L::ROW.endpoints != 1;
    let arith = Native(simd);
    let load = |v: &[f64]| S::as_simd_f64s(&v[..w]).0[0];
    for seg in &g.segments {
        let len = seg.len as usize;
        let full = len - len % w;
        // Arguments shared by the whole segment (step 0) are splatted once.
        let mut shared = [simd.splat_f64s(0.0); MAX_SLOTS];
        for c in 0..slots {
            if seg.step[c] == 0 {
                shared[c] = simd.splat_f64s(args[seg.base[c] as usize]);
            }
        }
        let mut v = View::new(x, y, z);
        let mut i = 0;
        while i < full {
            let start = seg.start as usize + i;
            let (la, lb) = (&g.a[start..start + w], &g.b[start..start + w]);
            let (a0, b0) = (la[0] as usize, lb[0] as usize);
            let chain = (0..w).all(|k| la[k] as usize == a0 + k && lb[k] as usize == b0 + k)
                && a0 + w <= v.n
                && b0 + w <= v.n;
            let e = if chain {
                Ends {
                    x1: map3(|c| load(&v.x[c][a0..])),
                    xp1: map3(|c| load(&v.xp[c][a0..])),
                    x2: map3(|c| load(&v.x[c][b0..])),
                    xp2: map3(|c| load(&v.xp[c][b0..])),
                }
            } else {
                // Endpoint coordinates: x₁, x̃₁, x₂, x̃₂ on each axis, lane k the link i + k.
                let mut ends = [[0.0; MAX_WIDTH]; 12];
                for k in 0..w {
                    let (a, b) = (la[k] as usize, lb[k] as usize);
                    assert!(a < v.n && b < v.n);
                    for c in 0..3 {
                        ends[c][k] = v.x[c][a];
                        ends[3 + c][k] = v.xp[c][a];
                        ends[6 + c][k] = v.x[c][b];
                        ends[9 + c][k] = v.xp[c][b];
                    }
                }
                Ends {
                    x1: map3(|c| load(&ends[c])),
                    xp1: map3(|c| load(&ends[3 + c])),
                    x2: map3(|c| load(&ends[6 + c])),
                    xp2: map3(|c| load(&ends[9 + c])),
                }
            };
            let mut p = shared;
            for c in 0..slots {
                match seg.step[c] {
                    0 => {}
                    1 => {
                        let at = (seg.base[c] as usize) + i;
                        p[c] = load(&args[at..at + w]);
                    }
                    step => {
                        let mut a = [0.0; MAX_WIDTH];
                        for (k, a) in a[..w].iter_mut().enumerate() {
                            *a = args[(seg.base[c] + step * (i + k) as u32) as usize];
                        }
                        p[c] = load(&a);
                    }
                }
            }
            let f = L::force(&arith, &e, |c| p[c]);
            let mut out = [[0.0; MAX_WIDTH]; 3];
            for (o, f) in out.iter_mut().zip(f) {
                S::as_mut_simd_f64s(&mut o[..]).0[0] = f;
            }
            // F₁ −= g, F₂ += g, link by link. On a chain whose second endpoints follow its
            // first ones (b = a + 1), point a + k gets + g(k − 1) from link k − 1, then
            // − g(k) from link k, and nothing in between: each force is one read, those two
            // operations in that order and one write, point by point, instead of a chain of
            // read-modify-writes through memory.
            if chain && two && b0 == a0 + 1 {
                for (c, f) in v.f.iter_mut().enumerate() {
                    let o = &out[c];
                    let f = &mut f[a0..a0 + w + 1];
                    f[0] -= o[0];
                    for k in 1..w {
                        f[k] = (f[k] + o[k - 1]) - o[k];
                    }
                    f[w] += o[w - 1];
                }
                i += w;
                continue;
            }
            for k in 0..w {
                let (a, b) = (la[k] as usize, lb[k] as usize);
                assert!(a < v.n && b < v.n);
                for c in 0..3 {
                    v.f[c][a] -= out[c][k];
                }
                if two {
                    for c in 0..3 {
                        v.f[c][b] += out[c][k];
                    }
                }
            }
            i += w;
        }
        for i in full..len {
            one::<L>(g, seg, i as u32, x, y, z, args);
        }
    }
}

/// Stage 4's interactions: every group in table order, on the instruction set `arch` (the
/// engine's; every choice gives the same bits).
#[inline(always)]
pub(crate) fn step(
    groups: &[Group3],
    x: &mut Points,
    y: &mut Points,
    z: &mut Points,
    args: &[f64],
    arch: pulp::Arch,
) {
    struct Visit<'a, S> {
        simd: S,
        groups: &'a [Group3],
        x: &'a mut Points,
        y: &'a mut Points,
        z: &'a mut Points,
        args: &'a [f64],
    }
    impl<S: Simd> SpaceLawVisitor for Visit<'_, S> {
        #[inline(always)]
        fn visit<L: SpaceLaw>(&mut self, kind: SpaceLawKind) {
            let g = &self.groups[kind.index()];
            if g.segments.is_empty() {
                return;
            }
            // One vector or less: the scalar path.
            if S::F64_LANES > 1 && S::F64_LANES <= MAX_WIDTH && g.len() >= S::F64_LANES {
                apply_vector::<L, S>(self.simd, g, self.x, self.y, self.z, self.args);
            } else {
                apply::<L>(g, self.x, self.y, self.z, self.args);
            }
        }
    }
    struct Stage4<'a> {
        groups: &'a [Group3],
        x: &'a mut Points,
        y: &'a mut Points,
        z: &'a mut Points,
        args: &'a [f64],
    }
    impl pulp::WithSimd for Stage4<'_> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: Simd>(self, simd: S) {
            SpaceLawKind::visit_all(&mut Visit {
                simd,
                groups: self.groups,
                x: self.x,
                y: self.y,
                z: self.z,
                args: self.args,
            });
        }
    }
    arch.dispatch(Stage4 {
        groups,
        x,
        y,
        z,
        args,
    });
}
