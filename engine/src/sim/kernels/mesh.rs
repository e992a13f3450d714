//! The mesh macro's kernel (spec §2.7.4): the node law on every node, then spring-dampers
//! along the width and along the length, in the script's order.
//!
//! Two schedules of the same physics: pass by pass over the whole mesh, link by link in the
//! script's order (six contiguous loops, bit-identical to the mesh written element by
//! element and to the voice banks), and, for the large plates, one sweep row by row that
//! sums the same forces as a stencil, in another order, and keeps no force array.
//! [`Macros::step`](super::macros::Macros::step) picks by size; a test runs both from the
//! same state and compares the positions within rounding.

use super::macros::MeshMacro;
use crate::laws;
use crate::laws::nodes::{node_coefficients, node_step};
use crate::laws::Scalar;

/// Meshes with at least this many nodes run row by row ([`mesh_step_rows`]): from there the
/// six passes stream more than the caches hold. Smaller ones keep the script's summation
/// order, which the small presets' samples and the voice banks share.
pub(crate) const ROW_SWEEP_NODES: usize = 4096;

/// Rows of scratch [`mesh_step_rows`] needs: a ring of three rows of drives and a row of
/// connection-point forces.
pub(crate) const SCRATCH_ROWS: usize = 4;

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
    let (a, b, inv_m) = node_coefficients(args[mac.slots.m], args[mac.slots.zo]);
    let (k, z) = (args[mac.slots.k], args[mac.slots.z]);
    let (len, w) = (mac.length, mac.width);
    let n = len * w;
    let x_edge = x[0];
    for i in 0..n {
        let next = node_step(&Scalar, (a, b, inv_m), x[i], xp[i], f[i]);
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

/// Row by row, for the large plates, as a stencil. The forces the links of sample n would
/// have left in F (spec §1.5 stage 4, with K and Z as they were at sample n, kept in
/// [`MeshMacro::last_kz`]) are, on each node a, Σ K·(x_b − x_a) + Z·(v_b − v_a) over its
/// neighbours b, from x and x̃ as sample n left them (v = x − x̃). Divided by M, that sum is the
/// discrete Laplacian of one field, the node's *drive* y = (K/M)·x + (Z/M)·v:
///
///   y = K′·x + Z′·(x − x̃)                    K′ = K/M, Z′ = Z/M
///   F_a/M = ((y_l + y_r) + (y_u + y_d)) − 4·y_a   (a node inside the mesh)
///   X[n+1] = (a·X + b·X̃) + (F_a/M + F_ext/M)     a = 2 − Zo/M, b = Zo/M − 1
///
/// A node on a free side sums the neighbours it has, in the same order, less d·y_a for its d
/// neighbours. The sweep computes each row's drives once, one row ahead, into a ring of
/// three rows, and moves each row from its own drives and those of the rows above and below:
/// no force array, and no node reads another's position. The sum is
/// [`mesh_step_passes`]' in another order, so the two agree within rounding (spec §1.5: the
/// summation order matters only for bit identity with a reference implementation), for 8
/// additions and 5 multiplications a node instead of 12 and 7. A mesh at rest stays at rest
/// bit for bit: equal drives give a Laplacian of exactly 0, as equal positions give the
/// links a force of exactly 0. On the Chladni plate the two schedules' outputs differ by at
/// most 4.4e−16 over 3 s after a strike (1.4e−13 of the peak).
///
/// The cost is the memory operations, not the arithmetic: per four nodes 8 loads and 3
/// stores (x, x̃ and the row below's, the drives), which this CPU (Zen 3) streams at about
/// 1.5 a cycle, against 13 adds and multiplies on four pipes.
///
/// Only the connection points (spec §2.8) write forces onto a mesh's nodes, and the sweep
/// reads and clears those (`ext`: local node and force, ascending); F therefore holds no
/// internal force of the mesh between samples.
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
    let (a, b, inv_m) = node_coefficients(args[mac.slots.m], args[mac.slots.zo]);
    let (k, z) = mac.last_kz;
    mac.last_kz = (args[mac.slots.k], args[mac.slots.z]);
    let law = Stencil {
        a,
        b,
        k: k * inv_m,
        z: z * inv_m,
    };
    let (len, w) = (mac.length, mac.width);
    let (ring, rest) = scratch.split_at_mut(3 * w);
    // The connection points' forces over M on the row being moved, −0 where there is none
    // (L + −0 is L).
    let e = &mut rest[..w];
    e.fill(-0.0);
    drives(&law, &x[..w], &xp[..w], &mut ring[..w]);
    let sides = mac.sides_pinned;
    let x_edge = x[0];
    let mut next_ext = 0;
    for row in 0..len {
        let r = row * w;
        let (y_up, y_row, y_below) = ring_rows(ring, w, row);
        let first_ext = next_ext;
        while next_ext < ext.len() && (ext[next_ext].0 as usize) < r + w {
            next_ext += 1;
        }
        let row_ext = &ext[first_ext..next_ext];
        for &(node, fe) in row_ext {
            e[node as usize - r] = fe * inv_m;
        }
        let (x_to, x_below) = x.split_at_mut(r + w);
        let (xp_to, xp_below) = xp.split_at_mut(r + w);
        let (xr, xpr) = (&mut x_to[r..], &mut xp_to[r..]);
        let below = (row + 1 < len).then(|| (&x_below[..w], &xp_below[..w]));
        match below {
            Some((xb, xpb)) if row > 0 && w >= 3 => {
                let ys = (y_up, y_row);
                if row_ext.is_empty() {
                    inner_row::<false>(&law, xr, xpr, xb, xpb, ys, y_below, e, sides, avx2);
                } else {
                    inner_row::<true>(&law, xr, xpr, xb, xpb, ys, y_below, e, sides, avx2);
                }
            }
            _ => {
                if let Some((xb, xpb)) = below {
                    drives(&law, xb, xpb, y_below);
                }
                let y_up = (row > 0).then_some(y_up);
                let y_below = below.is_some().then_some(&*y_below);
                any_row(&law, xr, xpr, y_up, y_row, y_below, e, mac.ends_pinned);
            }
        }
        for &(node, _) in row_ext {
            e[node as usize - r] = -0.0;
        }
    }
    // The pinning, once the sweep is done: no row reads another's positions, so a pinned node
    // moved by its row and reset only here is never seen moved.
    for &p in &mac.pinned {
        x[p as usize] = x_edge;
        xp[p as usize] = x_edge;
    }
}

/// The coefficients of one sample of the stencil: the node law's a and b, and K′ = K/M and
/// Z′ = Z/M of the drives.
#[derive(Clone, Copy)]
pub(super) struct Stencil {
    pub a: f64,
    pub b: f64,
    pub k: f64,
    pub z: f64,
}

/// y = K′·x + Z′·(x − x̃).
#[inline(always)]
fn drive(law: &Stencil, x: f64, xp: f64) -> f64 {
    law.k * x + law.z * (x - xp)
}

/// The drives of one row.
#[inline(always)]
fn drives(law: &Stencil, x: &[f64], xp: &[f64], y: &mut [f64]) {
    let w = y.len();
    let (x, xp) = (&x[..w], &xp[..w]);
    for j in 0..w {
        y[j] = drive(law, x[j], xp[j]);
    }
}

/// The ring's rows for moving row `row` (row i's drives are in slot i mod 3): the drives of
/// the row above, of the row itself, and the slot for the row below's (which held the drives
/// of the row two above).
#[inline(always)]
fn ring_rows(ring: &mut [f64], w: usize, row: usize) -> (&[f64], &[f64], &mut [f64]) {
    let (r0, rest) = ring[..3 * w].split_at_mut(w);
    let (r1, r2) = rest.split_at_mut(w);
    match row % 3 {
        0 => (r2, r0, r1),
        1 => (r0, r1, r2),
        _ => (r1, r2, r0),
    }
}

/// A node's neighbours' drives, `None` where it has none on that side.
struct Neighbours {
    left: Option<f64>,
    right: Option<f64>,
    up: Option<f64>,
    down: Option<f64>,
}

/// Any node, from its neighbours' drives: ((y_l + y_r) + (y_u + y_d)) − d·y over the d
/// neighbours it has, in that order; then the node law with `e`, its connection points'
/// force over M (−0 for none).
#[inline(always)]
fn any_node(law: &Stencil, x: &mut f64, xp: &mut f64, y: f64, ys: Neighbours, e: f64) {
    let sum = |p: Option<f64>, q: Option<f64>| match (p, q) {
        (Some(p), Some(q)) => Some(p + q),
        (p, None) => p,
        (None, q) => q,
    };
    let degree = [ys.left, ys.right, ys.up, ys.down]
        .iter()
        .filter(|y| y.is_some())
        .count() as f64;
    let neighbours = sum(sum(ys.left, ys.right), sum(ys.up, ys.down)).unwrap_or(0.0);
    let laplacian = neighbours - degree * y;
    let xj = *x;
    *x = (law.a * xj + law.b * *xp) + (laplacian + e);
    *xp = xj;
}

/// The first or last row of a mesh at least two nodes wide and two rows long: each node has
/// one row next to it (`y_other`), so ((y_l + y_r) + y_v) − 3·y, and (y_r + y_v) − 2·y at
/// the ends, which is [`any_node`]'s sum, in a loop the compiler vectorises.
#[inline(always)]
fn end_row(
    law: &Stencil,
    xr: &mut [f64],
    xpr: &mut [f64],
    y_row: &[f64],
    y_other: &[f64],
    e: &[f64],
) {
    let w = xr.len();
    let (xpr, y_row, y_other, e) = (&mut xpr[..w], &y_row[..w], &y_other[..w], &e[..w]);
    let Stencil { a, b, .. } = *law;
    let mut node = |j: usize, laplacian: f64| {
        let xj = xr[j];
        xr[j] = (a * xj + b * xpr[j]) + (laplacian + e[j]);
        xpr[j] = xj;
    };
    node(0, (y_row[1] + y_other[0]) - 2.0 * y_row[0]);
    node(w - 1, (y_row[w - 2] + y_other[w - 1]) - 2.0 * y_row[w - 1]);
    for j in 1..w - 1 {
        node(
            j,
            ((y_row[j - 1] + y_row[j + 1]) + y_other[j]) - 3.0 * y_row[j],
        );
    }
}

/// The first and last rows, and the rows of meshes less than three nodes wide. `y_up` and
/// `y_below` are the drives of the rows next to it, where there are. With `ends_pinned`, the
/// first and last rows are left to the pinning.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn any_row(
    law: &Stencil,
    xr: &mut [f64],
    xpr: &mut [f64],
    y_up: Option<&[f64]>,
    y_row: &[f64],
    y_below: Option<&[f64]>,
    e: &[f64],
    ends_pinned: bool,
) {
    let w = xr.len();
    let (xpr, y_row, e) = (&mut xpr[..w], &y_row[..w], &e[..w]);
    let end = y_up.is_none() || y_below.is_none();
    match (y_up, y_below) {
        _ if end && ends_pinned => {}
        (Some(y_other), None) | (None, Some(y_other)) if w >= 2 => {
            end_row(law, xr, xpr, y_row, y_other, e)
        }
        _ => {
            for j in 0..w {
                let ys = Neighbours {
                    left: j.checked_sub(1).map(|l| y_row[l]),
                    right: y_row.get(j + 1).copied(),
                    up: y_up.map(|y| y[j]),
                    down: y_below.map(|y| y[j]),
                };
                any_node(law, &mut xr[j], &mut xpr[j], y_row[j], ys, e[j]);
            }
        }
    }
}

/// A row with rows above and below it: the row below's drives, then every node of the row.
/// The loop over the inner columns has no dependency from one column to the next (each node
/// reads only drives), so the compiler vectorises it whatever the instruction set. With
/// `EXT`, each node's law adds `e`, the connection points' force over M (−0 for none). With
/// `sides_pinned`, the first and last columns are left to the pinning. Each row comes in as
/// its own argument so that the compiler knows they do not overlap (in a struct they lose
/// that, and the loop no longer vectorises).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn inner_row<const EXT: bool>(
    law: &Stencil,
    xr: &mut [f64],
    xpr: &mut [f64],
    xb: &[f64],
    xpb: &[f64],
    (y_up, y_row): (&[f64], &[f64]),
    y_below: &mut [f64],
    e: &[f64],
    sides_pinned: bool,
    avx2: bool,
) {
    let w = xr.len();
    let (xpr, xb, xpb) = (&mut xpr[..w], &xb[..w], &xpb[..w]);
    let (y_up, y_row, y_below, e) = (&y_up[..w], &y_row[..w], &mut y_below[..w], &e[..w]);
    for j in [0, w - 1] {
        y_below[j] = drive(law, xb[j], xpb[j]);
        if !sides_pinned {
            let ys = Neighbours {
                left: (j > 0).then(|| y_row[j - 1]),
                right: (j == 0).then(|| y_row[1]),
                up: Some(y_up[j]),
                down: Some(y_below[j]),
            };
            any_node(law, &mut xr[j], &mut xpr[j], y_row[j], ys, e[j]);
        }
    }
    let mut first = 1;
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: `avx2` is set only when the sample loop runs with AVX2; the rows are W ≥ 3
        // long.
        first = unsafe {
            super::mesh_avx2::inner_columns::<EXT>(law, xr, xpr, xb, xpb, y_up, y_row, y_below, e)
        };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = avx2;
    for j in first..w - 1 {
        inner_column::<EXT>(law, j, xr, xpr, xb, xpb, y_up, y_row, y_below, e);
    }
}

/// Column j of [`inner_row`]'s loop: the row below's drive, then the node.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn inner_column<const EXT: bool>(
    law: &Stencil,
    j: usize,
    xr: &mut [f64],
    xpr: &mut [f64],
    xb: &[f64],
    xpb: &[f64],
    y_up: &[f64],
    y_row: &[f64],
    y_below: &mut [f64],
    e: &[f64],
) {
    let yb = drive(law, xb[j], xpb[j]);
    y_below[j] = yb;
    let laplacian = ((y_row[j - 1] + y_row[j + 1]) + (y_up[j] + yb)) - 4.0 * y_row[j];
    let laplacian = if EXT { laplacian + e[j] } else { laplacian };
    let xj = xr[j];
    xr[j] = (law.a * xj + law.b * xpr[j]) + laplacian;
    xpr[j] = xj;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::kernels::macros::MacroSlots;

    /// The argument slots of the tests' meshes: `args` is [M, K, K2, Z, Zo].
    const SLOTS: MacroSlots = MacroSlots {
        m: 0,
        k: 1,
        k2: 2,
        z: 3,
        zo: 4,
    };

    /// Both schedules, from the same irregular state, agree within rounding for 200 samples,
    /// on a free mesh, a corner-pinned one and a closed one, of several shapes (macros have
    /// both sizes ≥ 2), with forces spread onto some nodes between samples (stage 5) and K
    /// and Z changing. The stencil sums the links' forces in another order; its error is a
    /// few units in the last place of the largest term, far below 1e−12 of the motion (a
    /// force of the wrong sign, a missed neighbour or a one-sample slip is above 1e−4).
    #[test]
    fn rows_and_passes_agree() {
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
            (12, 19),
            (11, 22),
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
            let mut mac = MeshMacro::new(0, len, w, pinned, SLOTS);
            assert_eq!(mac.sides_pinned, sides, "{len}×{w}");
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
            // The AVX2 loop, where the CPU has it, from the same start: the same bits as the
            // plain loop.
            let mut with_avx2 = crate::sim::kernels::avx2()
                .is_some()
                .then(|| (mac.clone(), x2.clone(), xp2.clone(), scratch.clone()));
            let mut moved = 0.0f64;
            for step in 0..200 {
                let args = [1.3, 0.21 + 0.01 * (step % 3) as f64, 0.0, 0.013, 0.002];
                // Forces on a node in the first row, one inside, one in the last row.
                let ext: Vec<(u32, f64)> = [1.min(n - 1), n / 2, n - 1]
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
                if let Some((mac, x, xp, scratch)) = &mut with_avx2 {
                    mesh_step_rows(mac, x, xp, scratch, &ext, &args, true);
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(x), bits(&x2), "AVX2, {len}×{w}, sample {step}");
                    assert_eq!(bits(xp), bits(&xp2), "AVX2, {len}×{w}, sample {step}");
                }
                for (i, (p, q)) in x1.iter().zip(&x2).enumerate() {
                    assert!(
                        (p - q).abs() <= 1e-12 * 0.1,
                        "{len}×{w}, sample {step}, node {i}: {p} against {q}"
                    );
                }
                assert_eq!(xp1, xp2, "{len}×{w}: x̃ is the previous x");
                xp2.clone_from(&xp1);
                x2.clone_from(&x1);
                if let Some((_, x, xp, _)) = &mut with_avx2 {
                    x.clone_from(&x1);
                    xp.clone_from(&xp1);
                }
                moved = moved.max((x1[n / 2] - start(0.7)[n / 2]).abs());
            }
            assert!(moved > 1e-3, "{len}×{w}: moved {moved}");
        }
    }

    /// A mesh at rest away from 0 stays there bit for bit: equal drives have a Laplacian of
    /// exactly 0 (the engine holds a model at rest without stepping it, `rest.rs`).
    #[test]
    fn a_mesh_at_rest_stays_at_rest() {
        let (len, w) = (9, 13);
        let mut mac = MeshMacro::new(0, len, w, vec![], SLOTS);
        let (mut x, mut xp) = (vec![0.3711; len * w], vec![0.3711; len * w]);
        let mut scratch = vec![0.0; SCRATCH_ROWS * w];
        for _ in 0..10 {
            mesh_step_rows(
                &mut mac,
                &mut x,
                &mut xp,
                &mut scratch,
                &[],
                &[1.7, 0.23, 0.0, 0.011, 0.0],
                false,
            );
        }
        assert!(x
            .iter()
            .chain(&xp)
            .all(|v| v.to_bits() == 0.3711f64.to_bits()));
    }
}
