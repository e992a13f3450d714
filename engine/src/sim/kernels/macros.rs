//! Stage 2 b of spec §1.5: the macro structures (strings, chains, stiff strings, meshes,
//! spec §2.7), each updating its nodes and then adding its internal forces.

use super::proxies::Proxies;
use super::Points;
use crate::laws;
use crate::laws::nodes::{node_coefficients, node_step, stiffness_spring};
use crate::laws::Scalar;
use crate::sim::kernels::mesh::{mesh_step_passes, mesh_step_rows, ROW_SWEEP_NODES};

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
    /// Local indices of pinned nodes (corners or border), ascending.
    pub pinned: Vec<u32>,
    /// Whether every row's first and last nodes are pinned (a closed mesh): the row sweep
    /// then leaves them to the pinning instead of moving them first.
    pub sides_pinned: bool,
    /// Whether every node of the first and last rows is pinned (a closed mesh): the row sweep
    /// then only computes their drives.
    pub ends_pinned: bool,
    pub slots: MacroSlots,
    /// K and Z of the previous sample, (0, 0) before the first: the row sweep computes the
    /// previous sample's link forces with them ([`mesh_step_rows`]).
    pub last_kz: (f64, f64),
}

impl MeshMacro {
    /// A mesh of `length` rows of `width` nodes from `base`, with the nodes `pinned` (local
    /// indices, in any order).
    pub(crate) fn new(
        base: usize,
        length: usize,
        width: usize,
        mut pinned: Vec<u32>,
        slots: MacroSlots,
    ) -> MeshMacro {
        pinned.sort_unstable();
        pinned.dedup();
        let is_pinned = |i: usize| pinned.binary_search(&(i as u32)).is_ok();
        let sides_pinned = width > 0
            && (0..length).all(|r| is_pinned(r * width) && is_pinned(r * width + width - 1));
        let last = length.saturating_sub(1) * width;
        let ends_pinned = length > 0 && (0..width).all(|j| is_pinned(j) && is_pinned(last + j));
        MeshMacro {
            base,
            length,
            width,
            pinned,
            sides_pinned,
            ends_pinned,
            slots,
            last_kz: (0.0, 0.0),
        }
    }
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
    /// The forces the connection points spread onto a large mesh's nodes (local node, force),
    /// ascending; four entries per connection point.
    pub scratch_ext: Vec<(u32, f64)>,
}

impl Macros {
    /// Clears the state the macros keep between samples (spec §1.5 stage 0: no force yet).
    pub(crate) fn reset(&mut self) {
        for mac in &mut self.meshes {
            mac.last_kz = (0.0, 0.0);
        }
    }

    #[inline(always)]
    /// `avx2`: the sample loop runs with AVX2 (pulp's V3), so the large plates may use the
    /// row sweep's AVX2 loop ([`crate::sim::kernels::mesh`]).
    pub(crate) fn step(&mut self, p: &mut Points, args: &[f64], proxies: &Proxies, avx2: bool) {
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
        for mac in &mut self.meshes {
            let n = mac.length * mac.width;
            let range = mac.base..mac.base + n;
            let x = &mut p.x[range.clone()];
            let xp = &mut p.xp[range.clone()];
            let f = &mut p.f[range];
            if n >= ROW_SWEEP_NODES {
                let ext = take_spread_forces(mac, proxies, f, &mut self.scratch_ext);
                mesh_step_rows(mac, x, xp, s, ext, args, avx2);
            } else {
                mesh_step_passes(mac, x, xp, f, v, s, args);
            }
        }
    }
}

/// The forces stage 5 spread onto mesh `mac`'s nodes, as (local node, force) in ascending
/// order, each node once; their slots in F are cleared. Connection points are the only
/// elements that write onto a macro's nodes (spec §2.8). `ext` has room for four nodes per
/// connection point (a length, not a capacity: a cloned engine keeps it).
#[inline(always)]
fn take_spread_forces<'a>(
    mac: &MeshMacro,
    proxies: &Proxies,
    f: &mut [f64],
    ext: &'a mut [(u32, f64)],
) -> &'a [(u32, f64)] {
    let base = mac.base as u32;
    let mut len = 0;
    for (nodes, &(first, _, _)) in proxies.nodes.iter().zip(&proxies.geometry) {
        if first == base {
            for &n in nodes {
                ext[len] = (n - base, 0.0);
                len += 1;
            }
        }
    }
    let ext = &mut ext[..len];
    ext.sort_unstable_by_key(|e| e.0);
    let mut unique = 0;
    for i in 0..len {
        if i == 0 || ext[i].0 != ext[unique - 1].0 {
            ext[unique] = ext[i];
            unique += 1;
        }
    }
    let ext = &mut ext[..unique];
    for e in ext.iter_mut() {
        e.1 = std::mem::take(&mut f[e.0 as usize]);
    }
    ext
}

/// Moves the nodes of a line macro with the node law; fixed ends keep x = x̃ = X₀. The node
/// forces are left for `chain_links`, which assigns every one of them (a macro of one node
/// has them reset here).
#[inline(always)]
fn update_line_nodes(mac: &LineMacro, x: &mut [f64], xp: &mut [f64], f: &mut [f64], args: &[f64]) {
    let (a, b, inv_m) = node_coefficients(args[mac.slots.m], args[mac.slots.zo]);
    let n = x.len();
    let (lo, hi) = if mac.fixed_ends {
        (1, n.saturating_sub(1))
    } else {
        (0, n)
    };
    for i in lo..hi {
        let next = node_step(&Scalar, (a, b, inv_m), x[i], xp[i], f[i]);
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
        let t = stiffness_spring(&Scalar, k2, x[a], x[b]);
        f[a] -= t;
        f[b] += t;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The spread forces of a large mesh come out sorted, each node once with its whole force,
    /// their slots cleared; a connection point on another macro is left alone.
    #[test]
    fn spread_forces_are_taken_once_per_node() {
        let mac = MeshMacro::new(10, 3, 4, vec![], MacroSlots::default());
        let proxies = Proxies {
            nodes: vec![[16, 17, 20, 21], [0, 1, 0, 0], [15, 16, 19, 20]],
            geometry: vec![(10, 3, 4), (0, 5, 0), (10, 3, 4)],
            ..Default::default()
        };
        let mut f: Vec<f64> = (0..12).map(|i| i as f64 + 0.5).collect();
        let mut ext = vec![(0, 0.0); 12];
        let taken = take_spread_forces(&mac, &proxies, &mut f, &mut ext).to_vec();
        assert_eq!(
            taken,
            [
                (5, 5.5),
                (6, 6.5),
                (7, 7.5),
                (9, 9.5),
                (10, 10.5),
                (11, 11.5)
            ]
        );
        let cleared: Vec<usize> = (0..12).filter(|&i| f[i] == 0.0).collect();
        assert_eq!(cleared, [5, 6, 7, 9, 10, 11]);
    }
}
