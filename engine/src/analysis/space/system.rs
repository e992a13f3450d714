//! The linearised system of a 3-D model at rest (3-D spec §5.1, §5.2, §6.2): one degree of
//! freedom per moving point and free axis (3 for `mass` and `osc`, 1 for `massZ`, 2 for
//! `massXY`), the masses M, and K and C assembled from each law's 3 × 3 blocks at the rest
//! positions, like a graph Laplacian with 3 × 3 blocks: a link (i, j) with block B adds B to
//! ii and jj and −B to ij and ji (each endpoint spread over a connection point's nodes by its
//! weights), a one-endpoint law B to its point's block; an `osc` adds K_o·I and (Z_o + Z_a)·I.
//!
//! The ports follow 3-D spec §3: a force input's direction on its target, an avatar's motion
//! through its links, a position output's direction, a velocity output's and a microphone's
//! velocity weights, a distance's rest direction, a force output's link forces.
//!
//! A degree of freedom's "point" in [`System::point`] is 3·p + axis, so that mode shapes come
//! out with x, y and z per point.

use super::{endpoint_nodes, links, point_terms};
use crate::analysis::modes::system::{Port, SymSparse, System};
use crate::laws::space::Linear3;
use crate::sim::space::{Avatar, ForceInput, Output3, Probe3};
use crate::Engine;

/// The linear system at the positions `x` (every point's and connection point's, x y z).
/// With `strike`, a force input also drives what its target's contacts open at rest strike
/// (as the 1-D system does: a hammer's blow reaches what it hits).
pub(crate) fn assemble(e: &Engine, x: &[[f64; 3]], strike: bool) -> System {
    let Some(space) = &e.space else {
        return System::default();
    };
    let info = &e.model.info;
    let n_points = info.num_points;
    let terms = point_terms(e);
    // Degrees of freedom.
    let mut dof: Vec<[Option<u32>; 3]> = vec![[None; 3]; n_points];
    let mut mass = Vec::new();
    let mut point = Vec::new();
    for p in 0..n_points {
        if !terms.mass[p].is_finite() {
            continue;
        }
        for c in 0..3 {
            if terms.axes[p][c] {
                dof[p][c] = Some(mass.len() as u32);
                mass.push(terms.mass[p]);
                point.push((3 * p + c) as u32);
            }
        }
    }
    let n = mass.len();
    let mut kr: Vec<(u32, u32, f64)> = Vec::new();
    let mut zr: Vec<(u32, u32, f64)> = Vec::new();
    for p in 0..n_points {
        for c in 0..3 {
            if let Some(d) = dof[p][c] {
                kr.push((d, d, terms.k_ground[p]));
                zr.push((d, d, terms.z_ground[p]));
            }
        }
    }
    // An endpoint's degrees of freedom with their signed weights, per axis.
    let nodes = |p: u32, sign: f64| -> Vec<(usize, f64)> {
        endpoint_nodes(space, n_points, p)
            .into_iter()
            .map(|(node, w)| (node, sign * w))
            .collect()
    };
    let at = |p: u32| x.get(p as usize).copied().unwrap_or([0.0; 3]);
    let mut open: Vec<(u32, u32)> = Vec::new();
    // Each link's blocks, kept for the ports.
    let mut blocks: Vec<(u32, u32, bool, crate::laws::space::Block)> = Vec::new();
    for l in links(space, &e.args) {
        let row = l.kind.row();
        let one = row.endpoints == 1;
        let (xa, xb) = (at(l.a), at(l.b));
        let block = match l.kind.linearise(&l.p, xa, xb) {
            Linear3::Link(b) => b,
            Linear3::Open => {
                if !one {
                    open.push((l.a, l.b));
                }
                continue;
            }
        };
        blocks.push((l.a, l.b, one, block));
        let mut ends = nodes(l.a, 1.0);
        if !one {
            ends.extend(nodes(l.b, -1.0));
        }
        for &(i, wi) in &ends {
            for &(j, wj) in &ends {
                for ci in 0..3 {
                    for cj in 0..3 {
                        let (Some(di), Some(dj)) = (dof[i][ci], dof[j][cj]) else {
                            continue;
                        };
                        if di < dj {
                            continue;
                        }
                        let f = wi * wj;
                        let (k, z) = (block.k[ci][cj] * f, block.z[ci][cj] * f);
                        if k != 0.0 {
                            kr.push((di, dj, k));
                        }
                        if z != 0.0 {
                            zr.push((di, dj, z));
                        }
                    }
                }
            }
        }
    }
    let k = SymSparse::from_entries(n, kr);
    let z = SymSparse::from_entries(n, zr);

    let empty = || Port {
        p: vec![0.0; n],
        q: vec![0.0; n],
        linear: false,
    };
    let mut inputs = vec![empty(); info.num_inputs()];
    let mut outputs = vec![empty(); info.num_outputs()];
    let units = &space.directions.units;
    // Adds `v`·(a vector per axis) on the degrees of freedom of endpoint `p`.
    let put = |port: &mut Port, p: u32, v: [f64; 3], velocity: bool| {
        for (node, w) in endpoint_nodes(space, n_points, p) {
            for c in 0..3 {
                if let Some(d) = dof[node][c] {
                    let slot = if velocity { &mut port.q } else { &mut port.p };
                    slot[d as usize] += w * v[c];
                    port.linear = true;
                }
            }
        }
    };
    for fi in &space.model.force_inputs {
        let (p, ch, dirs): (u32, u32, Vec<[f64; 3]>) = match *fi {
            ForceInput::Line {
                point,
                channel,
                dir,
            } => (point, channel, vec![units[dir as usize]]),
            ForceInput::Xyz { point, channel } => (
                point,
                channel,
                vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            ),
        };
        for (k, d) in dirs.into_iter().enumerate() {
            let Some(port) = inputs.get_mut(ch as usize + k) else {
                continue;
            };
            put(port, p, d, false);
            if strike {
                for &(a, b) in &open {
                    let far = if a == p {
                        b
                    } else if b == p {
                        a
                    } else {
                        continue;
                    };
                    put(port, far, d, false);
                }
            }
        }
    }
    // An avatar moved by δs along â pushes every link it is an endpoint of: on the link's
    // other nodes F = −s·B·(σ·â·δs), σ its own sign in δd.
    for av in &space.model.avatars {
        let (p, ch, dirs): (u32, u32, Vec<[f64; 3]>) = match *av {
            Avatar::Line {
                point,
                channel,
                dir,
                ..
            } => (point, channel, vec![units[dir as usize]]),
            Avatar::Xyz { point, channel } => (
                point,
                channel,
                vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            ),
        };
        for (k, d) in dirs.into_iter().enumerate() {
            let Some(port) = inputs.get_mut(ch as usize + k) else {
                continue;
            };
            port.linear = true;
            for &(a, b, one, block) in &blocks {
                if one {
                    continue;
                }
                let sigma = (a == p) as u32 as f64 - (b == p) as u32 as f64;
                if sigma == 0.0 {
                    continue;
                }
                let bk = mul(block.k, d);
                let bz = mul(block.z, d);
                for (node, w) in nodes(a, 1.0).into_iter().chain(nodes(b, -1.0)) {
                    for c in 0..3 {
                        if let Some(dd) = dof[node][c] {
                            port.p[dd as usize] -= w * sigma * bk[c];
                            port.q[dd as usize] -= w * sigma * bz[c];
                        }
                    }
                }
            }
        }
    }
    for o in &space.model.outputs {
        let Some(port) = outputs.get_mut(o.channel() as usize) else {
            continue;
        };
        match *o {
            Output3::Point {
                probe: Probe3::Position,
                point,
                dir,
                ..
            } => put(port, point, units[dir as usize], false),
            Output3::Point {
                probe: Probe3::Velocity,
                point,
                dir,
                ..
            } => put(port, point, units[dir as usize], true),
            Output3::Point {
                probe: Probe3::Force,
                point,
                dir,
                ..
            } => {
                // The links' forces on the point: F_end = −s·B·δd for an endpoint of sign s.
                let a_dir = units[dir as usize];
                for &(a, b, one, block) in &blocks {
                    let s = (a == point) as u32 as f64 - (!one && b == point) as u32 as f64;
                    if s == 0.0 {
                        continue;
                    }
                    let bk = mul_t(block.k, a_dir);
                    let bz = mul_t(block.z, a_dir);
                    let mut ends = nodes(a, 1.0);
                    if !one {
                        ends.extend(nodes(b, -1.0));
                    }
                    for (node, w) in ends {
                        for c in 0..3 {
                            if let Some(dd) = dof[node][c] {
                                port.p[dd as usize] -= s * w * bk[c];
                                port.q[dd as usize] -= s * w * bz[c];
                                port.linear = true;
                            }
                        }
                    }
                }
            }
            Output3::Distance { a, b, .. } => {
                let (pa, pb) = (at(a), at(b));
                let d = [pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]];
                let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if l > 0.0 {
                    let u = d.map(|c| c / l);
                    put(port, a, u, false);
                    put(port, b, u.map(|c| -c), false);
                }
            }
            Output3::Mic { mic, .. } => {
                let m = &space.model.mics[mic as usize];
                for (j, &p) in m.members.iter().enumerate() {
                    let w = space.mic_weights[m.offset as usize + j];
                    let d = space.mic_dirs[m.offset as usize + j];
                    put(port, p, d.map(|c| w * c), true);
                }
            }
        }
    }
    System {
        mass,
        point,
        k,
        z,
        inputs,
        outputs,
    }
}

/// B·v.
fn mul(b: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| b[i][0] * v[0] + b[i][1] * v[1] + b[i][2] * v[2])
}

/// Bᵀ·v.
fn mul_t(b: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|j| b[0][j] * v[0] + b[1][j] * v[1] + b[2][j] * v[2])
}
