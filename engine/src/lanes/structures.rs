//! The lane versions of stages 2 b, 3 and 5 of spec §1.5: macro structures (spec §2.7) and
//! connection points (spec §2.8), each lane with its own arguments. Every lane runs the
//! operations of the plain kernels (`kernels::macros`, `kernels::mesh`'s pass-by-pass
//! schedule, `kernels::proxies`) in their order, so each lane equals a plain engine bit for bit
//! (engine test `lanes`).

use super::Lanes;
use crate::engine::{node_law, LineMacro, MeshMacro, Proxies};
use crate::laws;

/// Per-lane node law coefficients (a, b, 1/M) of a macro from its M and Zo slots.
#[inline(always)]
fn lane_node_law(args: &[Lanes], m: usize, zo: usize) -> (Lanes, Lanes, Lanes) {
    let mut out = (
        [0.0; super::LANES],
        [0.0; super::LANES],
        [0.0; super::LANES],
    );
    for l in 0..super::LANES {
        let (a, b, inv_m) = node_law(args[m][l], args[zo][l]);
        out.0[l] = a;
        out.1[l] = b;
        out.2[l] = inv_m;
    }
    out
}

/// Node law of a macro's moving nodes `nodes` (`kernels::macros::node_law`): X[n+1] =
/// a·X + b·X̃ + F·(1/M), per lane.
#[inline(always)]
fn update_nodes(
    (a, b, inv_m): (Lanes, Lanes, Lanes),
    x: &mut [Lanes],
    xp: &mut [Lanes],
    f: &[Lanes],
    nodes: std::ops::Range<usize>,
) {
    for i in nodes {
        for l in 0..super::LANES {
            let next = a[l] * x[i][l] + b[l] * xp[i][l] + f[i][l] * inv_m[l];
            xp[i][l] = x[i][l];
            x[i][l] = next;
        }
    }
}

/// A string, chain or stiff string (`kernels::macros`: `update_line_nodes`, `chain_links`,
/// then for a stiff string `stiffness_links`).
#[inline(always)]
pub(super) fn line_step(
    mac: &LineMacro,
    stiff: bool,
    x: &mut [Lanes],
    xp: &mut [Lanes],
    f: &mut [Lanes],
    s: &mut [Lanes],
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
    update_nodes(law, x, xp, f, lo..hi);
    if n < 2 {
        f.fill([0.0; super::LANES]);
    } else {
        let (k, z) = (args[mac.slots.k], args[mac.slots.z]);
        let s = &mut s[..n - 1];
        for i in 0..n - 1 {
            for l in 0..super::LANES {
                let dv = (x[i][l] - xp[i][l]) - (x[i + 1][l] - xp[i + 1][l]);
                s[i][l] = laws::spring_damper(x[i][l] - x[i + 1][l], dv, k[l], z[l]);
            }
        }
        for l in 0..super::LANES {
            f[0][l] = -s[0][l];
        }
        for i in 1..n - 1 {
            for l in 0..super::LANES {
                f[i][l] = s[i - 1][l] - s[i][l];
            }
        }
        for l in 0..super::LANES {
            f[n - 1][l] = s[n - 2][l];
        }
    }
    if stiff {
        let k2 = args[mac.slots.k2];
        let n = n as isize;
        for i in -1..n {
            let p = i.clamp(0, n - 1) as usize;
            let q = (i + 2).clamp(0, n - 1) as usize;
            for l in 0..super::LANES {
                let t = k2[l] * (x[p][l] - x[q][l]);
                f[p][l] -= t;
                f[q][l] += t;
            }
        }
    }
}

/// A mesh, pass by pass (`kernels::mesh::mesh_step_passes`).
#[inline(always)]
pub(super) fn mesh_step(
    mac: &MeshMacro,
    x: &mut [Lanes],
    xp: &mut [Lanes],
    f: &mut [Lanes],
    v: &mut [Lanes],
    s: &mut [Lanes],
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
    update_nodes(law, x, xp, f, 0..n);
    for &p in &mac.pinned {
        x[p as usize] = x_edge;
        xp[p as usize] = x_edge;
    }
    let v = &mut v[..n];
    for i in 0..n {
        for l in 0..super::LANES {
            v[i][l] = x[i][l] - xp[i][l];
        }
    }
    let sd = |p: usize, q: usize, l: usize| {
        laws::spring_damper(x[p][l] - x[q][l], v[p][l] - v[q][l], k[l], z[l])
    };
    // Links along the width, row by row: each row's forces assigned (F is consumed).
    let sr = &mut s[..w - 1];
    for row in 0..len {
        let r = row * w;
        for j in 0..w - 1 {
            for l in 0..super::LANES {
                sr[j][l] = sd(r + j, r + j + 1, l);
            }
        }
        for l in 0..super::LANES {
            f[r][l] = -sr[0][l];
            f[r + w - 1][l] = sr[w - 2][l];
        }
        for j in 1..w - 1 {
            for l in 0..super::LANES {
                f[r + j][l] = sr[j - 1][l] - sr[j][l];
            }
        }
    }
    // Links along the length, (i, i + W): node i receives +s[i − W] before −s[i].
    let m = (len - 1) * w;
    let s = &mut s[..m];
    for i in 0..m {
        for l in 0..super::LANES {
            s[i][l] = sd(i, i + w, l);
        }
    }
    for i in 0..w.min(m) {
        for l in 0..super::LANES {
            f[i][l] -= s[i][l];
        }
    }
    for i in w..m {
        for l in 0..super::LANES {
            f[i][l] = f[i][l] + s[i - w][l] - s[i][l];
        }
    }
    for i in m.max(w)..n {
        for l in 0..super::LANES {
            f[i][l] += s[i - w][l];
        }
    }
}

/// Stage 3 (`Proxies::update_positions`): x̃_P ← x_P, x_P ← Σ w·x_node, F_P ← 0.
#[inline(always)]
pub(super) fn place_connection_points(
    proxies: &Proxies,
    x: &mut [Lanes],
    xp: &mut [Lanes],
    f: &mut [Lanes],
) {
    for i in 0..proxies.len() {
        let [n0, n1, n2, n3] = proxies.nodes[i].map(|n| n as usize);
        let [w0, w1, w2, w3] = proxies.weights[i];
        let k = proxies.base + i;
        for l in 0..super::LANES {
            let pos = w0 * x[n0][l] + w1 * x[n1][l] + w2 * x[n2][l] + w3 * x[n3][l];
            xp[k][l] = x[k][l];
            x[k][l] = pos;
            f[k][l] = 0.0;
        }
    }
}

/// Stage 5 (`Proxies::spread_forces`): F_P onto the macro nodes, in creation order.
#[inline(always)]
pub(super) fn spread_connection_forces(proxies: &Proxies, f: &mut [Lanes]) {
    for i in 0..proxies.len() {
        let fp = f[proxies.base + i];
        for (n, w) in proxies.nodes[i].iter().zip(proxies.weights[i]) {
            for l in 0..super::LANES {
                f[*n as usize][l] += w * fp[l];
            }
        }
    }
}
