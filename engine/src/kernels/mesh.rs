//! The mesh macro's kernel (spec §2.7.4): the node law on every node, then spring-dampers
//! along the width and along the length, in the script's order.
//!
//! Two schedules of the same arithmetic, bit for bit: pass by pass over the whole mesh (six
//! contiguous loops, best while the mesh fits in cache), and one sweep row by row (each row
//! touched once while it is in cache, best for the large plates). [`mesh_step`] picks by size;
//! a test runs both on the same state and compares every bit.

use crate::engine::{node_law, MeshMacro};
use crate::laws;

/// Meshes with at least this many nodes run row by row: from there the six passes stream
/// more than the caches hold (measured: the 150 × 150 plate 6 % faster by rows, the 25 × 20
/// mesh 7 % slower).
pub(crate) const ROW_SWEEP_NODES: usize = 4096;

/// One sample of a mesh: X[n+1] for every node, then the forces of its links (assigned, not
/// accumulated: F is consumed by the node law first).
#[inline(always)]
pub(crate) fn mesh_step(
    mac: &MeshMacro,
    x: &mut [f64],
    xp: &mut [f64],
    f: &mut [f64],
    v: &mut [f64],
    s: &mut [f64],
    args: &[f64],
) {
    if mac.length * mac.width >= ROW_SWEEP_NODES {
        mesh_step_rows(mac, x, xp, f, v, s, args);
    } else {
        mesh_step_passes(mac, x, xp, f, v, s, args);
    }
}

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

/// Row by row (see the module documentation).
#[inline(always)]
pub(crate) fn mesh_step_rows(
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
    let x_edge = x[0];
    let mut pin = 0;
    // One sweep, row by row, while the rows are in cache: the node law on row r, its pinned
    // nodes, its velocities (a ring of two rows), its links along the width (which assign its
    // forces), then the links between rows r − 1 and r. Row r − 1 thereby receives −s after
    // +s from above, and row r +s after its own row's links: the order of the script (and
    // of the pass-by-pass kernel this replaces), so the sums are bit-identical.
    for row in 0..len {
        let r = row * w;
        {
            let (xr, xpr, fr) = (&mut x[r..r + w], &mut xp[r..r + w], &f[r..r + w]);
            for j in 0..w {
                let next = a * xr[j] + b * xpr[j] + fr[j] * inv_m;
                xpr[j] = xr[j];
                xr[j] = next;
            }
        }
        while let Some(&p) = mac.pinned.get(pin).filter(|&&p| (p as usize) < r + w) {
            x[p as usize] = x_edge;
            xp[p as usize] = x_edge;
            pin += 1;
        }
        let (v_even, v_odd) = v[..2 * w].split_at_mut(w);
        let (vc, vp) = if row % 2 == 0 {
            (v_even, &*v_odd)
        } else {
            (v_odd, &*v_even)
        };
        let (xr, xpr) = (&x[r..r + w], &xp[r..r + w]);
        for j in 0..w {
            vc[j] = xr[j] - xpr[j];
        }
        let fr = &mut f[r..r + w];
        if w >= 2 {
            let sr = &mut s[..w - 1];
            for j in 0..w - 1 {
                sr[j] = laws::spring_damper(xr[j] - xr[j + 1], vc[j] - vc[j + 1], k, z);
            }
            fr[0] = -sr[0];
            for j in 1..w - 1 {
                fr[j] = sr[j - 1] - sr[j];
            }
            fr[w - 1] = sr[w - 2];
        } else {
            fr.fill(0.0);
        }
        if row > 0 {
            let (above, here) = f[r - w..r + w].split_at_mut(w);
            let (xu, xr) = x[r - w..r + w].split_at(w);
            for j in 0..w {
                let sv = laws::spring_damper(xu[j] - xr[j], vp[j] - vc[j], k, z);
                above[j] -= sv;
                here[j] += sv;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::MacroSlots;

    /// Both schedules, from the same irregular state, agree bit for bit for 50 samples, on a
    /// free mesh, a corner-pinned one and a closed one.
    #[test]
    fn rows_and_passes_are_bit_identical() {
        let (len, w) = (7, 5);
        let n = len * w;
        let closed: Vec<u32> = (0..n as u32)
            .filter(|&i| {
                let (r, c) = (i as usize / w, i as usize % w);
                r == 0 || r == len - 1 || c == 0 || c == w - 1
            })
            .collect();
        for pinned in [vec![], vec![0, 4, 30, 34], closed] {
            let mac = MeshMacro {
                base: 0,
                length: len,
                width: w,
                pinned,
                slots: MacroSlots {
                    m: 0,
                    k: 1,
                    k2: 2,
                    z: 3,
                    zo: 4,
                },
            };
            let args = [1.3, 0.21, 0.0, 0.013, 0.002];
            let start = |seed: f64| -> Vec<f64> {
                (0..n)
                    .map(|i| ((i as f64 + 1.0) * seed).sin() * 0.1)
                    .collect()
            };
            let (mut x1, mut xp1, mut f1) = (start(0.7), start(1.3), start(2.1));
            let (mut x2, mut xp2, mut f2) = (x1.clone(), xp1.clone(), f1.clone());
            let (mut v1, mut s1) = (vec![0.0; n], vec![0.0; n]);
            let (mut v2, mut s2) = (vec![0.0; n], vec![0.0; n]);
            for _ in 0..50 {
                mesh_step_passes(&mac, &mut x1, &mut xp1, &mut f1, &mut v1, &mut s1, &args);
                mesh_step_rows(&mac, &mut x2, &mut xp2, &mut f2, &mut v2, &mut s2, &args);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&x1), bits(&x2));
                assert_eq!(bits(&xp1), bits(&xp2));
                assert_eq!(bits(&f1), bits(&f2));
            }
        }
    }
}
