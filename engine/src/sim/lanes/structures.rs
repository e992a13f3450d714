//! The lane versions of stages 2 b, 3 and 5 of spec §1.5: macro structures (spec §2.7) and
//! connection points (spec §2.8), each lane with its own arguments. Every lane runs the
//! operations of the plain kernels (`kernels::macros`, `kernels::mesh`'s pass-by-pass
//! schedule, `kernels::proxies`) in their order, so each lane equals a plain engine bit for bit
//! (engine test `lanes`).

use super::arith::Native;
use super::vector::{self, Ops};
use super::{Lanes, LANES};
use crate::laws::nodes::node_coefficients;
use crate::laws::nodes::{node_step, stiffness_spring};
use crate::sim::engine::{LineMacro, MeshMacro, Proxies};

/// Per-lane node law coefficients (a, b, 1/M) of a macro from its M and Zo slots.
#[inline(always)]
fn lane_node_law(args: &[Lanes], m: usize, zo: usize) -> (Lanes, Lanes, Lanes) {
    let mut out = (Lanes::ZERO, Lanes::ZERO, Lanes::ZERO);
    for l in 0..LANES {
        let (a, b, inv_m) = node_coefficients(args[m][l], args[zo][l]);
        out.0[l] = a;
        out.1[l] = b;
        out.2[l] = inv_m;
    }
    out
}

/// Node law of a macro's moving nodes `nodes` ([`node_step`]): X[n+1] = a·X + b·X̃ + F·(1/M),
/// per lane, native vector by native vector.
#[inline(always)]
fn update_nodes<S: pulp::Simd>(
    o: Ops<S>,
    (a, b, inv_m): (Lanes, Lanes, Lanes),
    x: &mut [Lanes],
    xp: &mut [Lanes],
    f: &[Lanes],
    nodes: std::ops::Range<usize>,
) {
    let ar = Native(o.0);
    let (a, b, inv_m) = (vectors::<S>(&a), vectors::<S>(&b), vectors::<S>(&inv_m));
    let (x, xp, f) = (&mut x[nodes.clone()], &mut xp[nodes.clone()], &f[nodes]);
    for ((x, xp), f) in x.iter_mut().zip(xp.iter_mut()).zip(f) {
        let mut next = Lanes::ZERO;
        let (xv, xpv, fv) = (vectors::<S>(x), vectors::<S>(xp), vectors::<S>(f));
        let (out, _) = S::as_mut_simd_f64s(&mut next.0);
        for v in 0..out.len() {
            out[v] = node_step(&ar, (a[v], b[v], inv_m[v]), xv[v], xpv[v], fv[v]);
        }
        *xp = *x;
        *x = next;
    }
}

/// The native vectors of a [`Lanes`] (every lane: [`LANES`] is a whole number of vectors).
#[inline(always)]
fn vectors<S: pulp::Simd>(v: &Lanes) -> &[S::f64s] {
    S::as_simd_f64s(&v.0).0
}

/// A string, chain or stiff string (`kernels::macros`: `update_line_nodes`, `chain_links`,
/// then for a stiff string `stiffness_links`). The chain's forces are assigned, F₀ = −s₀,
/// Fᵢ = sᵢ₋₁ − sᵢ, F_{n−1} = s_{n−2}, each node's position and velocity read once.
#[inline(always)]
pub(super) fn line_step<S: pulp::Simd>(
    o: Ops<S>,
    mac: &LineMacro,
    stiff: bool,
    x: &mut [Lanes],
    xp: &mut [Lanes],
    f: &mut [Lanes],
    args: &[Lanes],
) {
    let law = lane_node_law(args, mac.slots.m, mac.slots.zo);
    let n = mac.len;
    let (x, xp, f) = (
        &mut x[mac.base..mac.base + n],
        &mut xp[mac.base..mac.base + n],
        &mut f[mac.base..mac.base + n],
    );
    let (lo, hi) = if mac.fixed_ends {
        (1, n.saturating_sub(1))
    } else {
        (0, n)
    };
    update_nodes(o, law, x, xp, f, lo..hi);
    if n < 2 {
        f.fill(Lanes::ZERO);
    } else {
        let (k, z) = (args[mac.slots.k], args[mac.slots.z]);
        let (mut xa, mut va) = (x[0], o.sub(x[0], xp[0]));
        let mut before = Lanes::ZERO;
        for i in 0..n - 1 {
            let xb = x[i + 1];
            let vb = o.sub(xb, xp[i + 1]);
            let s = vector::spring_damper(o, o.sub(xa, xb), o.sub(va, vb), k, z);
            f[i] = if i == 0 { o.neg(s) } else { o.sub(before, s) };
            (xa, va, before) = (xb, vb, s);
        }
        f[n - 1] = before;
    }
    if stiff {
        let k2 = args[mac.slots.k2];
        let n = n as isize;
        for i in -1..n {
            let p = i.clamp(0, n - 1) as usize;
            let q = (i + 2).clamp(0, n - 1) as usize;
            let mut t = Lanes::ZERO;
            let (k2v, xa, xb) = (vectors::<S>(&k2), vectors::<S>(&x[p]), vectors::<S>(&x[q]));
            let (out, _) = S::as_mut_simd_f64s(&mut t.0);
            for v in 0..out.len() {
                out[v] = stiffness_spring(&Native(o.0), k2v[v], xa[v], xb[v]);
            }
            f[p] = o.sub(f[p], t);
            f[q] = o.add(f[q], t);
        }
    }
}

/// A mesh, pass by pass (`kernels::mesh::mesh_step_passes`).
#[inline(always)]
pub(super) fn mesh_step<S: pulp::Simd>(
    o: Ops<S>,
    mac: &MeshMacro,
    x: &mut [Lanes],
    xp: &mut [Lanes],
    f: &mut [Lanes],
    v: &mut [Lanes],
    args: &[Lanes],
) {
    let law = lane_node_law(args, mac.slots.m, mac.slots.zo);
    let (k, z) = (args[mac.slots.k], args[mac.slots.z]);
    let (len, w) = (mac.length, mac.width);
    let n = len * w;
    let (x, xp, f) = (
        &mut x[mac.base..mac.base + n],
        &mut xp[mac.base..mac.base + n],
        &mut f[mac.base..mac.base + n],
    );
    let x_edge = x[0];
    update_nodes(o, law, x, xp, f, 0..n);
    for &p in &mac.pinned {
        x[p as usize] = x_edge;
        xp[p as usize] = x_edge;
    }
    let v = &mut v[..n];
    for ((v, x), xp) in v.iter_mut().zip(&*x).zip(&*xp) {
        *v = o.sub(*x, *xp);
    }
    // A function, not a closure: a closure does not inherit the instruction set, so its
    // vector operations would not inline.
    #[inline(always)]
    fn link<S: pulp::Simd>(
        o: Ops<S>,
        x: &[Lanes],
        v: &[Lanes],
        p: usize,
        q: usize,
        (k, z): (Lanes, Lanes),
    ) -> Lanes {
        vector::spring_damper(o, o.sub(x[p], x[q]), o.sub(v[p], v[q]), k, z)
    }
    // Links along the width, row by row: each row's forces assigned (F is consumed), F_r =
    // −s₀, then s_{j−1} − s_j, the row's last node s_{w−2}.
    for row in 0..len {
        let r = row * w;
        let mut before = Lanes::ZERO;
        for j in 0..w - 1 {
            let s = link(o, x, v, r + j, r + j + 1, (k, z));
            f[r + j] = if j == 0 { o.neg(s) } else { o.sub(before, s) };
            before = s;
        }
        f[r + w - 1] = before;
    }
    // Links along the length, (i, i + W), in order: node i receives +s[i − W] before −s[i].
    for i in 0..(len - 1) * w {
        let s = link(o, x, v, i, i + w, (k, z));
        f[i] = o.sub(f[i], s);
        f[i + w] = o.add(f[i + w], s);
    }
}

/// Stage 3 (`Proxies::update_positions`): x̃_P ← x_P, x_P ← Σ w·x_node, F_P ← 0.
#[inline(always)]
pub(super) fn place_connection_points<S: pulp::Simd>(
    o: Ops<S>,
    proxies: &Proxies,
    x: &mut [Lanes],
    xp: &mut [Lanes],
    f: &mut [Lanes],
) {
    for i in 0..proxies.len() {
        let [n0, n1, n2, n3] = proxies.nodes[i].map(|n| n as usize);
        let [w0, w1, w2, w3] = proxies.weights[i].map(Lanes::splat);
        let k = proxies.base + i;
        let pos = o.add(
            o.add(o.add(o.mul(w0, x[n0]), o.mul(w1, x[n1])), o.mul(w2, x[n2])),
            o.mul(w3, x[n3]),
        );
        xp[k] = x[k];
        x[k] = pos;
        f[k] = Lanes::ZERO;
    }
}

/// Stage 5 (`Proxies::spread_forces`): F_P onto the macro nodes, in creation order.
#[inline(always)]
pub(super) fn spread_connection_forces<S: pulp::Simd>(
    o: Ops<S>,
    proxies: &Proxies,
    f: &mut [Lanes],
) {
    for i in 0..proxies.len() {
        let fp = f[proxies.base + i];
        for (n, w) in proxies.nodes[i].iter().zip(proxies.weights[i]) {
            let n = *n as usize;
            f[n] = o.add(f[n], o.mul(Lanes::splat(w), fp));
        }
    }
}
