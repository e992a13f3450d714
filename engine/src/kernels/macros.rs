//! Stage 2 b of spec §1.5: the macro structures (strings, chains, stiff strings, meshes,
//! spec §2.7), each updating its nodes and then adding its internal forces.

use crate::engine::Points;
use crate::laws;

/// The argument slots of one macro in `Engine::args`: M, K, K2 (stiff strings), Z, Zo.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct MacroSlots {
    pub m: usize,
    pub k: usize,
    pub k2: usize,
    pub z: usize,
    pub zo: usize,
}

/// A string, chain or stiff string occupying points `base..base+len`.
#[derive(Clone, Debug)]
pub(crate) struct LineMacro {
    pub base: usize,
    pub len: usize,
    /// Strings and stiff strings: nodes 0 and N−1 never move.
    pub fixed_ends: bool,
    pub slots: MacroSlots,
}

/// A mesh of `length × width` nodes at `base..`, node index i·W + j (spec §2.7.4).
#[derive(Clone, Debug)]
pub(crate) struct MeshMacro {
    pub base: usize,
    pub length: usize,
    pub width: usize,
    /// Local indices of pinned nodes (corners or border).
    pub pinned: Vec<u32>,
    pub slots: MacroSlots,
}

/// The per-step coefficients of the ground-friction node law of spec §2.7:
/// X[n+1] = (2 − Zo/M)·X + (Zo/M − 1)·X̃ + F/M.
#[inline(always)]
pub(crate) fn node_law(m: f64, zo: f64) -> (f64, f64, f64) {
    let zm = zo / m;
    (2.0 - zm, zm - 1.0, 1.0 / m)
}

/// Stage 2 b: all macro structures. Each updates its nodes, then adds its internal forces.
#[derive(Clone, Debug, Default)]
pub(crate) struct Macros {
    pub lines: Vec<LineMacro>,
    pub stiff: Vec<LineMacro>,
    pub meshes: Vec<MeshMacro>,
    /// Node velocities x − x̃ of the macro being computed (sized for the largest macro).
    pub scratch_v: Vec<f64>,
    /// Link forces of the macro being computed.
    pub scratch_s: Vec<f64>,
}

impl Macros {
    #[inline(always)]
    pub(crate) fn step(&mut self, p: &mut Points, args: &[f64]) {
        let (v, s) = (&mut self.scratch_v, &mut self.scratch_s);
        for mac in &self.lines {
            let range = mac.base..mac.base + mac.len;
            let x = &mut p.x[range.clone()];
            let xp = &mut p.xp[range.clone()];
            let f = &mut p.f[range];
            update_line_nodes(mac, x, xp, f, args);
            chain_links(x, xp, f, s, args[mac.slots.k], args[mac.slots.z]);
        }
        for mac in &self.stiff {
            let range = mac.base..mac.base + mac.len;
            let x = &mut p.x[range.clone()];
            let xp = &mut p.xp[range.clone()];
            let f = &mut p.f[range];
            update_line_nodes(mac, x, xp, f, args);
            chain_links(x, xp, f, s, args[mac.slots.k], args[mac.slots.z]);
            stiffness_links(x, f, args[mac.slots.k2]);
        }
        for mac in &self.meshes {
            let n = mac.length * mac.width;
            let range = mac.base..mac.base + n;
            let x = &mut p.x[range.clone()];
            let xp = &mut p.xp[range.clone()];
            let f = &mut p.f[range];
            crate::kernels::mesh::mesh_step(mac, x, xp, f, v, s, args);
        }
    }
}

/// Moves the nodes of a line macro with the node law; fixed ends keep x = x̃ = X₀. The node
/// forces are left for `chain_links`, which assigns every one of them (a macro of one node
/// has them reset here).
#[inline(always)]
fn update_line_nodes(mac: &LineMacro, x: &mut [f64], xp: &mut [f64], f: &mut [f64], args: &[f64]) {
    let (a, b, inv_m) = node_law(args[mac.slots.m], args[mac.slots.zo]);
    let n = x.len();
    let (lo, hi) = if mac.fixed_ends {
        (1, n.saturating_sub(1))
    } else {
        (0, n)
    };
    for i in lo..hi {
        let next = a * x[i] + b * xp[i] + f[i] * inv_m;
        xp[i] = x[i];
        x[i] = next;
    }
    if n < 2 {
        f.fill(0.0);
    }
}

/// The N−1 spring-dampers (i, i+1) of a line macro (spec §2.7.1–§2.7.3). Every node force is
/// assigned: F_i = s_{i−1} − s_i, which is (0 + s_{i−1}) − s_i, the same sum in the same order
/// as applying the links one by one in script order to forces reset to 0. Velocities are
/// taken where they are used, (x_i − x̃_i) − (x_{i+1} − x̃_{i+1}), the same operations as
/// through a velocity array.
#[inline(always)]
fn chain_links(x: &[f64], xp: &[f64], f: &mut [f64], s: &mut [f64], k: f64, z: f64) {
    let n = x.len();
    if n < 2 {
        return;
    }
    let s = &mut s[..n - 1];
    let (xa, xb) = (&x[..n - 1], &x[1..n]);
    let (xpa, xpb) = (&xp[..n - 1], &xp[1..n]);
    for i in 0..n - 1 {
        s[i] = laws::spring_damper(xa[i] - xb[i], (xa[i] - xpa[i]) - (xb[i] - xpb[i]), k, z);
    }
    f[0] = -s[0];
    for i in 1..n - 1 {
        f[i] = s[i - 1] - s[i];
    }
    f[n - 1] = s[n - 2];
}

/// The stiff string's undamped K₂ springs (spec §2.7.3): f = K₂(x_a − x_b) for
/// a = clip(i, 0, N−1), b = clip(i+2, 0, N−1), i = −1..N−1, applied in that order.
#[inline(always)]
fn stiffness_links(x: &[f64], f: &mut [f64], k2: f64) {
    let n = x.len() as isize;
    for i in -1..n {
        let a = i.clamp(0, n - 1) as usize;
        let b = (i + 2).clamp(0, n - 1) as usize;
        let t = k2 * (x[a] - x[b]);
        f[a] -= t;
        f[b] += t;
    }
}
