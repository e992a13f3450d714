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
    // One sweep, row by row, while the rows are in cache: the node law on row r with its
    // velocities (a ring of two rows), its pinned nodes, its links along the width, then its
    // forces: row r's own links' (−s_j after +s_{j−1}, as the pass-by-pass kernel assigns
    // them) plus the link from row r − 1, whose node receives −s after +s from above. Each
    // force is the same sum in the same order as in the script, so the result is bit-identical
    // to `mesh_step_passes`; fusing the velocity into the node law (x' − x is the x − x̃ taken
    // after it) and the two force passes into one saves two passes over the row.
    for row in 0..len {
        let r = row * w;
        let (v_even, v_odd) = v[..2 * w].split_at_mut(w);
        let (vc, vp) = if row % 2 == 0 {
            (v_even, &*v_odd)
        } else {
            (v_odd, &*v_even)
        };
        {
            let (xr, xpr, fr) = (&mut x[r..r + w], &mut xp[r..r + w], &f[r..r + w]);
            let nodes = xr.iter_mut().zip(xpr.iter_mut());
            for ((xj, xpj), (fj, vj)) in nodes.zip(fr.iter().zip(vc.iter_mut())) {
                let old = *xj;
                let next = a * old + b * *xpj + fj * inv_m;
                *xpj = old;
                *xj = next;
                *vj = next - old;
            }
        }
        while let Some(&p) = mac.pinned.get(pin).filter(|&&p| (p as usize) < r + w) {
            x[p as usize] = x_edge;
            xp[p as usize] = x_edge;
            // The velocity as `mesh_step_passes` takes it, after the pin.
            vc[p as usize - r] = x[p as usize] - xp[p as usize];
            pin += 1;
        }
        let xr = &x[r..r + w];
        let sr = &mut s[..w - 1];
        for j in 0..w - 1 {
            sr[j] = laws::spring_damper(xr[j] - xr[j + 1], vc[j] - vc[j + 1], k, z);
        }
        let sr = &*sr;
        // Row r's own forces, as `mesh_step_passes` assigns them before the links from the row
        // above add to them (macros have both sizes ≥ 2): −s_0, s_{j−1} − s_j, s_{W−2}.
        if row == 0 {
            let fr = &mut f[..w];
            fr[0] = -sr[0];
            for j in 1..w - 1 {
                fr[j] = sr[j - 1] - sr[j];
            }
            fr[w - 1] = sr[w - 2];
        } else {
            let (above, here) = f[r - w..r + w].split_at_mut(w);
            let xu = &x[r - w..r];
            let link = |j: usize| laws::spring_damper(xu[j] - xr[j], vp[j] - vc[j], k, z);
            let sv = link(0);
            above[0] -= sv;
            here[0] = -sr[0] + sv;
            for j in 1..w - 1 {
                let sv = link(j);
                above[j] -= sv;
                here[j] = (sr[j - 1] - sr[j]) + sv;
            }
            let sv = link(w - 1);
            above[w - 1] -= sv;
            here[w - 1] = sr[w - 2] + sv;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::MacroSlots;

    /// Both schedules, from the same irregular state, agree bit for bit for 50 samples, on a
    /// free mesh, a corner-pinned one and a closed one, of several shapes (macros have both
    /// sizes ≥ 2).
    #[test]
    fn rows_and_passes_are_bit_identical() {
        for (len, w) in [(7, 5), (2, 2), (5, 3), (3, 9), (9, 2)] {
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
        for pinned in [vec![], corners, closed] {
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
