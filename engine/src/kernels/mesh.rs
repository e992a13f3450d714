//! The mesh macro's kernel (spec §2.7.4): the node law on every node, then spring-dampers
//! along the width and along the length, in the script's order.
//!
//! Two schedules of the same arithmetic: pass by pass over the whole mesh (six contiguous
//! loops, best while the mesh fits in cache), and one sweep row by row that keeps no force
//! array (best for the large plates). [`Macros::step`](super::macros::Macros::step) picks by
//! size; a test runs both from the same state and compares the positions bit for bit.

use crate::engine::{node_law, MeshMacro};
use crate::laws;

/// Meshes with at least this many nodes run row by row ([`mesh_step_rows`]): from there the
/// six passes stream more than the caches hold.
pub(crate) const ROW_SWEEP_NODES: usize = 4096;

/// Rows of scratch [`mesh_step_rows`] needs: link forces, forces from the row above, a
/// row's forces, two velocity rows, two rows of connection-point forces.
pub(crate) const SCRATCH_ROWS: usize = 7;

/// Pass by pass: every node moves with the node law; pinned nodes are then reset to
/// x = x̃ = x_edge (node 0's position before the update); then the links (i,j)–(i,j+1) for all
/// rows, then (i,j)–(i+1,j).
#[inline(always)]
pub(crate) fn mesh_step_passes(
    mac: &MeshMacro,
    x: &mut [f64],
    xp: &mut [f64],
    f: &mut [f64],
    v: &mut [f64],
    s: &mut [f64],
    args: &[f64],
) {
    let (a, b, inv_m) = node_law(args[mac.slots.m], args[mac.slots.zo]);
    let (k, z) = (args[mac.slots.k], args[mac.slots.z]);
    let (len, w) = (mac.length, mac.width);
    let n = len * w;
    let x_edge = x[0];
    for i in 0..n {
        let next = a * x[i] + b * xp[i] + f[i] * inv_m;
        xp[i] = x[i];
        x[i] = next;
    }
    for &p in &mac.pinned {
        x[p as usize] = x_edge;
        xp[p as usize] = x_edge;
    }
    let v = &mut v[..n];
    for i in 0..n {
        v[i] = x[i] - xp[i];
    }
    // Links along the width, row by row. F is zero on entry (as in `chain_links`).
    for row in 0..len {
        let r = row * w;
        let (xr, vr, fr) = (&x[r..r + w], &v[r..r + w], &mut f[r..r + w]);
        let sr = &mut s[..w - 1];
        for j in 0..w - 1 {
            sr[j] = laws::spring_damper(xr[j] - xr[j + 1], vr[j] - vr[j + 1], k, z);
        }
        fr[0] = -sr[0];
        for j in 1..w - 1 {
            fr[j] = sr[j - 1] - sr[j];
        }
        fr[w - 1] = sr[w - 2];
    }
    // Links along the length: (n, n + W) for n < (L−1)·W. Node n receives +s[n−W] before
    // −s[n], as in script order.
    let m = (len - 1) * w;
    let s = &mut s[..m];
    for i in 0..m {
        s[i] = laws::spring_damper(x[i] - x[i + w], v[i] - v[i + w], k, z);
    }
    for i in 0..w.min(m) {
        f[i] -= s[i];
    }
    for i in w..m {
        f[i] = f[i] + s[i - w] - s[i];
    }
    for i in m.max(w)..n {
        f[i] += s[i - w];
    }
}

/// Row by row, for the large plates: one sweep that touches each row once while it is in
/// cache, and keeps no force array. The forces the links of sample n would have left in F
/// (spec §1.5 stage 4, with K and Z as they were at sample n, kept in
/// [`MeshMacro::last_kz`]) are the same sums of the same terms at the start of sample n + 1,
/// from x and x̃ as sample n left them; so the sweep computes them there, row by row, and
/// moves each row as soon as its forces are complete:
///
///   F_ij = ((s_i,j−1 − s_i,j) + s_i−1,j) − s_i,j      (row links, then the link from the row
///                                                       above, then the one to the row below)
///   s = K·(x_a − x_b) + Z·((x_a − x̃_a) − (x_b − x̃_b))
///   X_ij[n+1] = (2 − Zo/M)·X_ij + (Zo/M − 1)·X̃_ij + (F_ij + F_ext,ij)/M
///
/// so each force is the sum `mesh_step_passes` assigns, in the same order, and the positions
/// are bit-identical to it. Only the connection points (spec §2.8) write forces onto a mesh's
/// nodes, and the sweep reads and clears those (`ext`: local node and force, ascending).
/// F therefore holds no internal force of the mesh between samples. The cost: about half
/// of the pass-by-pass kernel's loads and stores, and a third less traffic to the L2 cache.
#[inline(always)]
pub(crate) fn mesh_step_rows(
    mac: &mut MeshMacro,
    x: &mut [f64],
    xp: &mut [f64],
    scratch: &mut [f64],
    ext: &[(u32, f64)],
    args: &[f64],
    avx2: bool,
) {
    let (a, b, inv_m) = node_law(args[mac.slots.m], args[mac.slots.zo]);
    let (k, z) = mac.last_kz;
    mac.last_kz = (args[mac.slots.k], args[mac.slots.z]);
    let (len, w) = (mac.length, mac.width);
    let (s, rest) = scratch.split_at_mut(w);
    let (up, rest) = rest.split_at_mut(w);
    let (fbuf, rest) = rest.split_at_mut(w);
    // Velocities x − x̃ at the start of the sample: row r's, and row r + 1's, which row r
    // computes for its links below and hands on.
    let (v_even, rest) = rest.split_at_mut(w);
    let (v_odd, rest) = rest.split_at_mut(w);
    // The connection points' forces on the rows being moved, −0 where there is none
    // (F + −0 is F): the inner loops add them last, as `any_row` does.
    let (e0, rest) = rest.split_at_mut(w);
    let e1 = &mut rest[..w];
    e0.fill(-0.0);
    e1.fill(-0.0);
    let law = NodeLaw { a, b, inv_m, k, z };
    let sides = mac.sides_pinned;
    let x_edge = x[0];
    let (mut pin, mut e) = (0, 0);
    // Which ring holds the velocities of the next row to move.
    let mut v_in_even = true;
    let mut row = 0;
    while row < len {
        let r = row * w;
        let (v_row, v_next) = if v_in_even {
            (&*v_even, &mut *v_odd)
        } else {
            (&*v_odd, &mut *v_even)
        };
        v_in_even = !v_in_even;
        let first_ext = e;
        if row > 0 && row + 2 < len {
            // Two rows, with their connection points' forces if any.
            while e < ext.len() && (ext[e].0 as usize) < r + 2 * w {
                e += 1;
            }
            let pair_ext = &ext[first_ext..e];
            if pair_ext.is_empty() {
                inner_pair::<false>(&law, w, r, x, xp, up, v_row, v_next, e0, e1, avx2, sides);
            } else {
                place(pair_ext, r, e0, e1, f64::from_bits);
                inner_pair::<true>(&law, w, r, x, xp, up, v_row, v_next, e0, e1, avx2, sides);
                place(pair_ext, r, e0, e1, |_| -0.0);
            }
            row += 2;
        } else {
            while e < ext.len() && (ext[e].0 as usize) < r + w {
                e += 1;
            }
            let ext_row = &ext[first_ext..e];
            if row > 0 && row + 1 < len {
                if ext_row.is_empty() {
                    inner_row::<false>(&law, w, r, x, xp, up, v_row, v_next, e0);
                } else {
                    place(ext_row, r, e0, e1, f64::from_bits);
                    inner_row::<true>(&law, w, r, x, xp, up, v_row, v_next, e0);
                    place(ext_row, r, e0, e1, |_| -0.0);
                }
            } else {
                any_row(&law, w, r, len, x, xp, s, up, fbuf, ext_row, v_next);
            }
            row += 1;
        }
        let done = row * w;
        while let Some(&p) = mac.pinned.get(pin).filter(|&&p| (p as usize) < done) {
            x[p as usize] = x_edge;
            xp[p as usize] = x_edge;
            pin += 1;
        }
    }
}

/// Writes `value(force bits)` of each connection-point force on rows `r` and `r + 1` into
/// their rows `e0` and `e1`.
#[inline(always)]
fn place(ext: &[(u32, f64)], r: usize, e0: &mut [f64], e1: &mut [f64], value: fn(u64) -> f64) {
    let w = e0.len();
    for &(node, fe) in ext {
        let j = node as usize - r;
        let v = value(fe.to_bits());
        if j < w {
            e0[j] = v;
        } else {
            e1[j - w] = v;
        }
    }
}

/// The coefficients of one sample of the row sweep.
pub(super) struct NodeLaw {
    pub a: f64,
    pub b: f64,
    pub inv_m: f64,
    pub k: f64,
    pub z: f64,
}

/// The links along row `r..r + w`, from the state at the start of the sample: s_j between
/// nodes j and j + 1.
#[inline(always)]
fn row_links(law: &NodeLaw, x: &[f64], xp: &[f64], s: &mut [f64]) {
    let w = x.len();
    let s = &mut s[..w - 1];
    let (k, z) = (law.k, law.z);
    for j in 0..w - 1 {
        let dv = (x[j] - xp[j]) - (x[j + 1] - xp[j + 1]);
        s[j] = laws::spring_damper(x[j] - x[j + 1], dv, k, z);
    }
}

/// A row with rows above and below it and no connection point on it: the forces and the node
/// law in one loop. Each node reads its right neighbour's old state before that neighbour
/// moves, and hands its row link to the next node (s_j−1 on the left of node j). The row's
/// velocities come from the row above; the row below's go to the next row.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn inner_row<const EXT: bool>(
    law: &NodeLaw,
    w: usize,
    r: usize,
    x: &mut [f64],
    xp: &mut [f64],
    up: &mut [f64],
    v_row: &[f64],
    v_below: &mut [f64],
    ext: &[f64],
) {
    let (x_to, x_below) = x.split_at_mut(r + w);
    let (xp_to, xp_below) = xp.split_at_mut(r + w);
    inner_nodes::<EXT>(
        law,
        &mut x_to[r..],
        &mut xp_to[r..],
        &v_row[..w],
        &x_below[..w],
        &xp_below[..w],
        &mut v_below[..w],
        &mut up[..w],
        &ext[..w],
    );
}

/// [`inner_row`]'s loop. The rows come in as separate arguments so that the compiler knows
/// they do not overlap, and vectorises it (they lose that inside a struct). The first and
/// last nodes repeat the loop's body on purpose: with the body in a helper function shared
/// by all three, the loop no longer vectorised (the plate took 66 µs instead of 23).
/// With `EXT`, each node's force ends with the connection points' force on it, `ext` (−0
/// where there is none).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn inner_nodes<const EXT: bool>(
    law: &NodeLaw,
    xr: &mut [f64],
    xpr: &mut [f64],
    vr: &[f64],
    xb: &[f64],
    xpb: &[f64],
    vb_out: &mut [f64],
    up: &mut [f64],
    ext: &[f64],
) {
    let w = xr.len();
    let (xpr, vr, xb, xpb) = (&mut xpr[..w], &vr[..w], &xb[..w], &xpb[..w]);
    let (vb_out, up, ext) = (&mut vb_out[..w], &mut up[..w], &ext[..w]);
    let with_ext = |f: f64, j: usize| if EXT { f + ext[j] } else { f };
    let NodeLaw { a, b, inv_m, k, z } = *law;
    // Node 0: −s_0, then the links above and below.
    let mut s_left = laws::spring_damper(xr[0] - xr[1], vr[0] - vr[1], k, z);
    // The last row link, for node W − 1, before the loop moves node W − 2 (see
    // `pair_nodes`).
    let s_last = laws::spring_damper(xr[w - 2] - xr[w - 1], vr[w - 2] - vr[w - 1], k, z);
    {
        let (xj, vj) = (xr[0], vr[0]);
        let vbj = xb[0] - xpb[0];
        vb_out[0] = vbj;
        let sv = laws::spring_damper(xj - xb[0], vj - vbj, k, z);
        let fj = with_ext((-s_left + up[0]) - sv, 0);
        up[0] = sv;
        xr[0] = a * xj + b * xpr[0] + fj * inv_m;
        xpr[0] = xj;
    }
    for j in 1..w - 1 {
        let (xj, vj) = (xr[j], vr[j]);
        let s_right = laws::spring_damper(xj - xr[j + 1], vj - vr[j + 1], k, z);
        let vbj = xb[j] - xpb[j];
        vb_out[j] = vbj;
        let sv = laws::spring_damper(xj - xb[j], vj - vbj, k, z);
        let fj = with_ext(((s_left - s_right) + up[j]) - sv, j);
        s_left = s_right;
        up[j] = sv;
        xr[j] = a * xj + b * xpr[j] + fj * inv_m;
        xpr[j] = xj;
    }
    // Node W − 1: s_W−2, then the links above and below.
    let j = w - 1;
    let (xj, vj) = (xr[j], vr[j]);
    let vbj = xb[j] - xpb[j];
    vb_out[j] = vbj;
    let sv = laws::spring_damper(xj - xb[j], vj - vbj, k, z);
    let fj = with_ext((s_last + up[j]) - sv, j);
    up[j] = sv;
    xr[j] = a * xj + b * xpr[j] + fj * inv_m;
    xpr[j] = xj;
}

/// Two rows with rows above and below them and no connection point on them, in one loop:
/// the link between them is computed once and used by both, and neither's velocities nor
/// that link's force go through memory. Row r's velocities come from the row above; row
/// r + 2's go to the next row. The same sums in the same order as [`inner_row`] twice.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn inner_pair<const EXT: bool>(
    law: &NodeLaw,
    w: usize,
    r: usize,
    x: &mut [f64],
    xp: &mut [f64],
    up: &mut [f64],
    v_row: &[f64],
    v_next: &mut [f64],
    e0: &[f64],
    e1: &[f64],
    avx2: bool,
    sides_pinned: bool,
) {
    let (x0, rest) = x[r..].split_at_mut(w);
    let (x1, rest) = rest.split_at_mut(w);
    let (xp0, xp_rest) = xp[r..].split_at_mut(w);
    let (xp1, xp_rest) = xp_rest.split_at_mut(w);
    pair_nodes::<EXT>(
        law,
        x0,
        xp0,
        x1,
        xp1,
        &v_row[..w],
        &rest[..w],
        &xp_rest[..w],
        &mut v_next[..w],
        &mut up[..w],
        &e0[..w],
        &e1[..w],
        avx2,
        sides_pinned,
    );
}

/// [`inner_pair`]'s loop, each row its own argument for the vectoriser (see
/// [`inner_nodes`]; in an array they lose their no-alias facts too). With `EXT`, the rows'
/// connection-point forces `e0` and `e1` end each node's force.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn pair_nodes<const EXT: bool>(
    law: &NodeLaw,
    x0: &mut [f64],
    xp0: &mut [f64],
    x1: &mut [f64],
    xp1: &mut [f64],
    v0: &[f64],
    x2: &[f64],
    xp2: &[f64],
    v2_out: &mut [f64],
    up: &mut [f64],
    e0: &[f64],
    e1: &[f64],
    avx2: bool,
    sides_pinned: bool,
) {
    let w = x0.len();
    let (xp0, x1, xp1, v0) = (&mut xp0[..w], &mut x1[..w], &mut xp1[..w], &v0[..w]);
    let (x2, xp2, v2_out, up) = (&x2[..w], &xp2[..w], &mut v2_out[..w], &mut up[..w]);
    let (e0, e1) = (&e0[..w], &e1[..w]);
    let with_ext = |f: f64, e: &[f64], j: usize| if EXT { f + e[j] } else { f };
    let NodeLaw { a, b, inv_m, k, z } = *law;
    let link = |dx: f64, dv: f64| laws::spring_damper(dx, dv, k, z);
    let mut s0_left = link(x0[0] - x0[1], v0[0] - v0[1]);
    let mut s1_left = link(x1[0] - x1[1], (x1[0] - xp1[0]) - (x1[1] - xp1[1]));
    // The last row links, for node W − 1, from the state before the loop moves node W − 2:
    // the loop's own s_left then ends unused, and the compiler vectorises every node of it
    // instead of leaving a scalar tail.
    let j = w - 2;
    let s0_last = link(x0[j] - x0[j + 1], v0[j] - v0[j + 1]);
    let s1_last = link(
        x1[j] - x1[j + 1],
        (x1[j] - xp1[j]) - (x1[j + 1] - xp1[j + 1]),
    );
    // Node 0 of both rows: −s_0, then the links above and below. Pinned sides are set by
    // the pinning after the pair, whatever is computed here, and their link below only
    // reaches the pinned node under them: only row r + 2's velocity, which the next pair's
    // links read, is needed.
    if sides_pinned {
        v2_out[0] = x2[0] - xp2[0];
    } else {
        let (x0j, v0j, x1j) = (x0[0], v0[0], x1[0]);
        let v1j = x1j - xp1[0];
        let v2j = x2[0] - xp2[0];
        v2_out[0] = v2j;
        let s01 = link(x0j - x1j, v0j - v1j);
        let s12 = link(x1j - x2[0], v1j - v2j);
        let f0 = with_ext((-s0_left + up[0]) - s01, e0, 0);
        let f1 = with_ext((-s1_left + s01) - s12, e1, 0);
        up[0] = s12;
        x0[0] = a * x0j + b * xp0[0] + f0 * inv_m;
        xp0[0] = x0j;
        x1[0] = a * x1j + b * xp1[0] + f1 * inv_m;
        xp1[0] = x1j;
    }
    let mut first = 1;
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: `avx2` is set only when the sample loop runs with AVX2 (pulp's V3); the rows
        // are W long.
        (first, s0_left, s1_left) = unsafe {
            super::mesh_avx2::pair_columns::<EXT>(
                law, x0, xp0, x1, xp1, v0, x2, xp2, v2_out, up, e0, e1, s0_left, s1_left,
            )
        };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = avx2;
    for j in first..w - 1 {
        let (x0j, v0j, x1j) = (x0[j], v0[j], x1[j]);
        let s0_right = link(x0j - x0[j + 1], v0j - v0[j + 1]);
        let v1j = x1j - xp1[j];
        let s1_right = link(x1j - x1[j + 1], v1j - (x1[j + 1] - xp1[j + 1]));
        let v2j = x2[j] - xp2[j];
        v2_out[j] = v2j;
        let s01 = link(x0j - x1j, v0j - v1j);
        let s12 = link(x1j - x2[j], v1j - v2j);
        let f0 = with_ext(((s0_left - s0_right) + up[j]) - s01, e0, j);
        let f1 = with_ext(((s1_left - s1_right) + s01) - s12, e1, j);
        s0_left = s0_right;
        s1_left = s1_right;
        up[j] = s12;
        x0[j] = a * x0j + b * xp0[j] + f0 * inv_m;
        xp0[j] = x0j;
        x1[j] = a * x1j + b * xp1[j] + f1 * inv_m;
        xp1[j] = x1j;
    }
    // Node W − 1 of both rows: s_W−2, then the links above and below; pinned as node 0.
    let j = w - 1;
    if sides_pinned {
        v2_out[j] = x2[j] - xp2[j];
        return;
    }
    let (x0j, v0j, x1j) = (x0[j], v0[j], x1[j]);
    let v1j = x1j - xp1[j];
    let v2j = x2[j] - xp2[j];
    v2_out[j] = v2j;
    let s01 = link(x0j - x1j, v0j - v1j);
    let s12 = link(x1j - x2[j], v1j - v2j);
    let f0 = with_ext((s0_last + up[j]) - s01, e0, j);
    let f1 = with_ext((s1_last + s01) - s12, e1, j);
    up[j] = s12;
    x0[j] = a * x0j + b * xp0[j] + f0 * inv_m;
    xp0[j] = x0j;
    x1[j] = a * x1j + b * xp1[j] + f1 * inv_m;
    xp1[j] = x1j;
}

/// Any row: the first and the last (no link above or below) and rows with connection points.
/// The forces go through `fbuf`, in the same order as [`inner_row`] sums them.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn any_row(
    law: &NodeLaw,
    w: usize,
    r: usize,
    len: usize,
    x: &mut [f64],
    xp: &mut [f64],
    s: &mut [f64],
    up: &mut [f64],
    fbuf: &mut [f64],
    ext_row: &[(u32, f64)],
    v_below: &mut [f64],
) {
    let NodeLaw { a, b, inv_m, k, z } = *law;
    let (xr, xpr) = (&x[r..r + w], &xp[r..r + w]);
    row_links(law, xr, xpr, s);
    fbuf[0] = -s[0];
    for j in 1..w - 1 {
        fbuf[j] = s[j - 1] - s[j];
    }
    fbuf[w - 1] = s[w - 2];
    if r > 0 {
        for j in 0..w {
            fbuf[j] += up[j];
        }
    }
    if r + w < len * w {
        let (xb, xpb) = (&x[r + w..r + 2 * w], &xp[r + w..r + 2 * w]);
        for j in 0..w {
            let vb = xb[j] - xpb[j];
            v_below[j] = vb;
            let sv = laws::spring_damper(xr[j] - xb[j], (xr[j] - xpr[j]) - vb, k, z);
            fbuf[j] -= sv;
            up[j] = sv;
        }
    }
    for &(node, fe) in ext_row {
        fbuf[node as usize - r] += fe;
    }
    let (xr, xpr) = (&mut x[r..r + w], &mut xp[r..r + w]);
    for j in 0..w {
        let xj = xr[j];
        xr[j] = a * xj + b * xpr[j] + fbuf[j] * inv_m;
        xpr[j] = xj;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::MacroSlots;

    /// Both schedules, from the same irregular state, agree bit for bit for 50 samples, on a
    /// free mesh, a corner-pinned one and a closed one, of several shapes (macros have both
    /// sizes ≥ 2), with forces spread onto some nodes between samples (stage 5) and K and Z
    /// changing.
    #[test]
    fn rows_and_passes_are_bit_identical() {
        for (len, w) in [
            (7, 5),
            (2, 2),
            (5, 3),
            (3, 9),
            (9, 2),
            (2, 7),
            (8, 11),
            (6, 14),
            (10, 6),
        ] {
            mesh_schedules_agree(len, w);
        }
    }

    fn mesh_schedules_agree(len: usize, w: usize) {
        let n = len * w;
        let closed: Vec<u32> = (0..n as u32)
            .filter(|&i| {
                let (r, c) = (i as usize / w, i as usize % w);
                r == 0 || r == len - 1 || c == 0 || c == w - 1
            })
            .collect();
        let corners = {
            let mut c = vec![0, (w - 1) as u32, (n - w) as u32, (n - 1) as u32];
            c.dedup();
            c
        };
        for (sides, pinned) in [(false, vec![]), (len == 2, corners), (true, closed)] {
            let slots = MacroSlots {
                m: 0,
                k: 1,
                k2: 2,
                z: 3,
                zo: 4,
            };
            let mut mac = MeshMacro::new(0, len, w, pinned, slots);
            assert_eq!(mac.sides_pinned, sides);
            let start = |seed: f64| -> Vec<f64> {
                (0..n)
                    .map(|i| ((i as f64 + 1.0) * seed).sin() * 0.1)
                    .collect()
            };
            // The pass-by-pass kernel keeps its forces in F; the sweep starts as stage 0
            // leaves it, with no force.
            let (mut x1, mut xp1, mut f1) = (start(0.7), start(1.3), vec![0.0; n]);
            let (mut x2, mut xp2) = (x1.clone(), xp1.clone());
            let (mut v1, mut s1) = (vec![0.0; n], vec![0.0; n]);
            let mut scratch = vec![0.0; SCRATCH_ROWS * w];
            let mut diverged = false;
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            // The AVX2 loop, where the CPU has it, from the same start.
            let mut with_avx2 = crate::kernels::avx2()
                .is_some()
                .then(|| (mac.clone(), x2.clone(), xp2.clone(), scratch.clone()));
            for step in 0..50 {
                let args = [1.3, 0.21 + 0.01 * (step % 3) as f64, 0.0, 0.013, 0.002];
                // Forces on a node in the first row, one inside, one in the last row.
                let ext: Vec<(u32, f64)> = [1, n / 2, n - 1]
                    .iter()
                    .map(|&i| (i as u32, 0.01 * (step as f64 * 0.37 + i as f64).sin()))
                    .collect::<std::collections::BTreeMap<_, _>>()
                    .into_iter()
                    .collect();
                for &(i, fe) in &ext {
                    f1[i as usize] += fe;
                }
                mesh_step_passes(&mac, &mut x1, &mut xp1, &mut f1, &mut v1, &mut s1, &args);
                mesh_step_rows(
                    &mut mac,
                    &mut x2,
                    &mut xp2,
                    &mut scratch,
                    &ext,
                    &args,
                    false,
                );
                if let Some(avx2) = &mut with_avx2 {
                    let (mac, x, xp, scratch) = avx2;
                    mesh_step_rows(mac, x, xp, scratch, &ext, &args, true);
                    assert_eq!(bits(x), bits(&x2), "AVX2, {len}×{w}, sample {step}");
                    assert_eq!(bits(xp), bits(&xp2), "AVX2, {len}×{w}, sample {step}");
                }
                assert_eq!(bits(&x1), bits(&x2), "{len}×{w}, sample {step}");
                assert_eq!(bits(&xp1), bits(&xp2), "{len}×{w}, sample {step}");
                diverged |= x1 != start(0.7);
            }
            assert!(diverged);
        }
    }
}
