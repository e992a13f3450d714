//! The vector arithmetic of the 3-D laws, on any [`Arith`], and the common evaluation of a
//! central law (3-D spec §2.2), written once for every central law and every path.

use crate::laws::Arith;

/// A 3-vector (x, y, z).
pub(crate) type V3<F> = [F; 3];

/// `[f(0), f(1), f(2)]`, always inlined. The laws' vector steps are written with it rather
/// than `array::map`, which goes through `try_map`: where the compiler left that outlined,
/// it was compiled without the caller's instruction set, and every SIMD operation in its
/// closure became a call (a vector damper's Δv cost some 3× a whole spring on AVX2).
#[inline(always)]
pub(crate) fn map3<T>(mut f: impl FnMut(usize) -> T) -> V3<T> {
    [f(0), f(1), f(2)]
}

/// The two endpoints of an interaction at one step: positions and delayed positions (3-D
/// spec §1.2, §1.3). A one-endpoint law reads endpoint 1 only.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ends<F> {
    pub x1: V3<F>,
    pub xp1: V3<F>,
    pub x2: V3<F>,
    pub xp2: V3<F>,
}

impl<F: Copy> Ends<F> {
    /// d = x₁ − x₂ (3-D spec §2.2 step 1).
    #[inline(always)]
    pub fn d<A: Arith<F = F>>(&self, a: &A) -> V3<F> {
        map3(|c| a.sub(self.x1[c], self.x2[c]))
    }

    /// d̃ = x̃₁ − x̃₂.
    #[inline(always)]
    pub fn dp<A: Arith<F = F>>(&self, a: &A) -> V3<F> {
        map3(|c| a.sub(self.xp1[c], self.xp2[c]))
    }

    /// Δv = (x₁ − x̃₁) − (x₂ − x̃₂) (3-D spec §1.3).
    #[inline(always)]
    pub fn dv<A: Arith<F = F>>(&self, a: &A) -> V3<F> {
        map3(|c| {
            a.sub(
                a.sub(self.x1[c], self.xp1[c]),
                a.sub(self.x2[c], self.xp2[c]),
            )
        })
    }

    /// Endpoint 1's own velocity x₁ − x̃₁ (the one-endpoint laws).
    #[inline(always)]
    pub fn v1<A: Arith<F = F>>(&self, a: &A) -> V3<F> {
        map3(|c| a.sub(self.x1[c], self.xp1[c]))
    }
}

/// u·v = (u_x v_x + u_y v_y) + u_z v_z, left to right (3-D spec §2.2 step 2).
#[inline(always)]
pub(crate) fn dot<A: Arith>(a: &A, u: V3<A::F>, v: V3<A::F>) -> A::F {
    a.add(
        a.add(a.mul(u[0], v[0]), a.mul(u[1], v[1])),
        a.mul(u[2], v[2]),
    )
}

/// s·v.
#[inline(always)]
pub(crate) fn scale<A: Arith>(a: &A, s: A::F, v: V3<A::F>) -> V3<A::F> {
    map3(|c| a.mul(s, v[c]))
}

/// v / |v|, or 0 for a zero (or non-finite) vector: a direction argument (3-D spec §1.7),
/// normalised where it is used, so that a direction moved by a parameter stays a unit vector;
/// a zero direction applies no force.
#[inline(always)]
pub(crate) fn unit<A: Arith>(a: &A, v: V3<A::F>) -> V3<A::F> {
    let n = a.sqrt(dot(a, v, v));
    let ok = a.gt(n, a.num(0.0));
    map3(|c| a.select(ok, a.div(v[c], n), a.num(0.0)))
}

/// The common evaluation of an unconditional central law (3-D spec §2.2): d, q, ℓ = √q,
/// with `RATE` also ℓ̃ from the delayed positions and ė = ℓ − ℓ̃ (0 without), then
/// f = `law(q, ℓ, ė)`, and g = (f/ℓ)·d, or no force when q = 0 (§1.4, steps 8–10).
#[inline(always)]
pub(crate) fn central<A: Arith, const RATE: bool>(
    a: &A,
    e: &Ends<A::F>,
    law: impl FnOnce(&A, A::F, A::F, A::F) -> A::F,
) -> V3<A::F> {
    let d = e.d(a);
    let q = dot(a, d, d);
    let s = along(a, e, q, law, RATE);
    scale(a, s, d)
}

/// [`central`] for a conditional law, engaged where `engaged(q)` holds (3-D spec §2.2 step 3:
/// the test on q, before any square root). Not engaged, it applies no force, and the square
/// roots are skipped where the arithmetic can skip them ([`Arith::branch`]).
#[inline(always)]
pub(crate) fn central_if<A: Arith, const RATE: bool>(
    a: &A,
    e: &Ends<A::F>,
    engaged: impl FnOnce(&A, A::F) -> A::M,
    law: impl FnOnce(&A, A::F, A::F, A::F) -> A::F,
) -> V3<A::F> {
    let d = e.d(a);
    let q = dot(a, d, d);
    let on = engaged(a, q);
    let s = a.branch(on, |a| along(a, e, q, law, RATE), |a| a.num(0.0));
    scale(a, s, d)
}

/// s = f/ℓ (3-D spec §2.2 steps 4–9), 0 when q = 0.
#[inline(always)]
fn along<A: Arith>(
    a: &A,
    e: &Ends<A::F>,
    q: A::F,
    law: impl FnOnce(&A, A::F, A::F, A::F) -> A::F,
    rate: bool,
) -> A::F {
    let zero = a.num(0.0);
    let l = a.sqrt(q);
    let edot = if rate {
        let dp = e.dp(a);
        a.sub(l, a.sqrt(dot(a, dp, dp)))
    } else {
        zero
    };
    let f = law(a, q, l, edot);
    a.select(a.gt(q, zero), a.div(f, l), zero)
}

/// The regularised Coulomb friction of a contact (3-D spec §2.3.4): with the relative velocity
/// `w` and the contact normal `n` (a unit vector, or 0), the tangential velocity
/// v_t = w − (w·n)n, τ = |v_t|, φ = Zt·τ, capped at μ·|f_normal| when μ > 0, and the force
/// h = (φ/τ)·v_t; 0 when Zt ≤ 0 or τ = 0.
#[inline(always)]
pub(crate) fn friction<A: Arith>(
    a: &A,
    w: V3<A::F>,
    n: V3<A::F>,
    f_normal: A::F,
    zt: A::F,
    mu: A::F,
) -> V3<A::F> {
    let zero = a.num(0.0);
    let wn = dot(a, w, n);
    let vt = map3(|c| a.sub(w[c], a.mul(wn, n[c])));
    let tau = a.sqrt(dot(a, vt, vt));
    let phi = a.mul(zt, tau);
    let cap = a.mul(mu, a.abs(f_normal));
    let phi = a.select(a.and(a.gt(mu, zero), a.lt(cap, phi)), cap, phi);
    let on = a.and(a.gt(zt, zero), a.gt(tau, zero));
    let r = a.select(on, a.div(phi, tau), zero);
    scale(a, r, vt)
}

/// The blocks of a central law at rest (3-D spec §5.1): with the separation `d0`, the tangent
/// stiffness `k_t`, the force `t` (positive attractive) and the damping slope `z` of its
/// scalar law, B = k_t·uuᵀ + (t/ℓ)(I − uuᵀ) and C = z·uuᵀ. At coincident points, where u
/// is undefined, the law's zero-length limit k_t·I (exact for L = 0, §1.8).
pub(crate) fn central_block(d0: [f64; 3], k_t: f64, t: f64, z: f64) -> super::Block {
    let l = (d0[0] * d0[0] + d0[1] * d0[1] + d0[2] * d0[2]).sqrt();
    let mut b = super::Block::ZERO;
    if !(l > 0.0) {
        for i in 0..3 {
            b.k[i][i] = k_t;
        }
        return b;
    }
    let u = d0.map(|c| c / l);
    let across = t / l;
    for i in 0..3 {
        for j in 0..3 {
            let uu = u[i] * u[j];
            let eye = if i == j { 1.0 } else { 0.0 };
            b.k[i][j] = k_t * uu + across * (eye - uu);
            b.z[i][j] = z * uu;
        }
    }
    b
}

/// The length |v|.
pub(crate) fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// x₁ − x₂.
pub(crate) fn sub(x1: [f64; 3], x2: [f64; 3]) -> [f64; 3] {
    [x1[0] - x2[0], x1[1] - x2[1], x1[2] - x2[2]]
}
