//! The linearised system of spec §5.5 in matrix form: per-step masses M (diagonal), the
//! stiffness matrix K and the damping matrix Z over the moving points (the network's weighted
//! Laplacian, fixed points eliminated), and the input and output vectors of every channel.
//!
//! With these, the scheme of spec §1.5 is M·x[n+1] = (2M − K − Z)·x[n] + (Z − M)·x[n−1] + f[n]:
//! the update law of every moving point (spec §2.1.2, §2.7) with the forces of stage 4 computed
//! from the positions after the mass phase (spec §1.6).

use crate::analysis::network::{endpoint_nodes, Network};
use crate::Engine;

/// A symmetric sparse matrix as a sorted list of lower-triangle entries (row ≥ column).
#[derive(Clone, Debug, Default)]
pub(crate) struct SymSparse {
    pub n: usize,
    /// (row, column, value), row ≥ column, sorted by (column, row), no duplicates.
    pub entries: Vec<(u32, u32, f64)>,
}

impl SymSparse {
    /// Sums duplicate entries of an unsorted list of (i, j, v) with either order of i, j.
    pub fn from_entries(n: usize, mut raw: Vec<(u32, u32, f64)>) -> SymSparse {
        for e in &mut raw {
            if e.0 < e.1 {
                std::mem::swap(&mut e.0, &mut e.1);
            }
        }
        raw.sort_by_key(|e| (e.1, e.0));
        let mut entries: Vec<(u32, u32, f64)> = Vec::with_capacity(raw.len());
        for (i, j, v) in raw {
            match entries.last_mut() {
                Some(last) if last.0 == i && last.1 == j => last.2 += v,
                _ => entries.push((i, j, v)),
            }
        }
        SymSparse { n, entries }
    }

    /// y = A·x.
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        for &(i, j, v) in &self.entries {
            let (i, j) = (i as usize, j as usize);
            y[i] += v * x[j];
            if i != j {
                y[j] += v * x[i];
            }
        }
    }

    /// The matrix D·A·D for a diagonal D.
    pub fn scaled(&self, d: &[f64]) -> SymSparse {
        SymSparse {
            n: self.n,
            entries: self
                .entries
                .iter()
                .map(|&(i, j, v)| (i, j, v * d[i as usize] * d[j as usize]))
                .collect(),
        }
    }

    /// a·A + b·B + diag(c), on the union of the patterns.
    pub fn combine(a: f64, x: &SymSparse, b: f64, y: &SymSparse, c: &[f64]) -> SymSparse {
        let mut raw: Vec<(u32, u32, f64)> = Vec::with_capacity(x.entries.len() + y.entries.len());
        raw.extend(x.entries.iter().map(|&(i, j, v)| (i, j, a * v)));
        raw.extend(y.entries.iter().map(|&(i, j, v)| (i, j, b * v)));
        raw.extend(c.iter().enumerate().map(|(i, &v)| (i as u32, i as u32, v)));
        SymSparse::from_entries(x.n, raw)
    }

    /// The dense matrix (both triangles).
    pub fn dense(&self) -> faer::Mat<f64> {
        let mut m = faer::Mat::<f64>::zeros(self.n, self.n);
        for &(i, j, v) in &self.entries {
            m[(i as usize, j as usize)] += v;
            if i != j {
                m[(j as usize, i as usize)] += v;
            }
        }
        m
    }

    /// The lower triangle as a faer sparse matrix.
    pub fn lower(&self) -> Option<faer::sparse::SparseColMat<u32, f64>> {
        let triplets: Vec<faer::sparse::Triplet<u32, u32, f64>> = self
            .entries
            .iter()
            .map(|&(row, col, val)| faer::sparse::Triplet::new(row, col, val))
            .collect();
        faer::sparse::SparseColMat::try_new_from_triplets(self.n, self.n, &triplets).ok()
    }

    /// True when every value is finite and at most `limit` in magnitude.
    pub fn is_within(&self, limit: f64) -> bool {
        self.entries.iter().all(|e| e.2.abs() <= limit)
    }

    /// [`SymSparse::is_within`] for D·A·D, without forming it.
    pub fn scaled_is_within(&self, d: &[f64], limit: f64) -> bool {
        self.entries
            .iter()
            .all(|&(i, j, v)| (v * d[i as usize] * d[j as usize]).abs() <= limit)
    }
}

/// A signal vector over the moving points whose value at a mode with eigenvalue r is
/// `p + q·(1 − 1/r)`: `p` multiplies positions, `q` velocities x[n] − x[n−1].
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Port {
    pub p: Vec<f64>,
    pub q: Vec<f64>,
    /// False when the channel has no linear path to the moving points (an audio-rate
    /// parameter, an output of a fixed point).
    pub linear: bool,
}

/// The linear system of a model at one operating point.
#[derive(Clone, Debug, Default)]
pub(crate) struct System {
    /// Per-step masses of the moving points (the degrees of freedom).
    pub mass: Vec<f64>,
    /// The material point of each degree of freedom.
    pub point: Vec<u32>,
    pub k: SymSparse,
    pub z: SymSparse,
    /// One per input channel: the force vector b with f[n] = b(u[n]).
    pub inputs: Vec<Port>,
    /// One per output channel: y[n] = c·x (positions and velocities).
    pub outputs: Vec<Port>,
}

/// The moving degrees of freedom of an endpoint with their weights (spec §2.8).
fn dofs<'a>(
    e: &'a Engine,
    dof: &'a [Option<u32>],
    p: u32,
) -> impl Iterator<Item = (u32, f64)> + 'a {
    endpoint_nodes(e, p)
        .filter_map(move |(node, w)| dof.get(node).copied().flatten().map(|d| (d, w)))
}

impl System {
    /// Assembles K, Z and the ports from a network (spec §5.5 step 1). With `strike`, a
    /// force input also drives the far endpoint of every contact of its target that is open
    /// at rest, with weight 1: a hammer's blow reaches what it hits through the contact,
    /// which the rest state leaves open.
    pub fn assemble(e: &Engine, net: &Network, strike: bool) -> System {
        let n_points = e.model.info.num_points;
        let mut dof = vec![None; n_points];
        let mut mass = Vec::new();
        let mut point = Vec::new();
        for p in 0..n_points {
            if net.is_moving(p) {
                dof[p] = Some(mass.len() as u32);
                mass.push(net.mass[p]);
                point.push(p as u32);
            }
        }
        let n = mass.len();
        let mut kr = Vec::new();
        let mut zr = Vec::new();
        for p in 0..n_points {
            if let Some(d) = dof[p] {
                kr.push((d, d, net.k_ground[p]));
                zr.push((d, d, net.z_ground[p]));
            }
        }
        // A link adds k·d·dᵀ and z·d·dᵀ, with d = u_a − u_b over the moving points.
        let link_vector = |a: u32, b: u32| -> Vec<(u32, f64)> {
            let mut d: Vec<(u32, f64)> = dofs(e, &dof, a).collect();
            d.extend(dofs(e, &dof, b).map(|(i, w)| (i, -w)));
            d
        };
        for l in &net.links {
            let d = link_vector(l.a, l.b);
            for &(i, wi) in &d {
                for &(j, wj) in &d {
                    if i >= j {
                        let f = wi * wj;
                        if l.k != 0.0 {
                            kr.push((i, j, l.k * f));
                        }
                        if l.z != 0.0 {
                            zr.push((i, j, l.z * f));
                        }
                    }
                }
            }
        }
        // Of the ordered pairs (i, j) and (j, i) of d·dᵀ only the one with i ≥ j is kept: the
        // lower triangle, each off-diagonal product once.
        let k = SymSparse::from_entries(n, kr);
        let z = SymSparse::from_entries(n, zr);

        // Inputs (spec §2.2): a force input adds its signal to its target; a position input
        // moves an avatar, whose links push the moving points with −s·(k·u + z·Δu)·d.
        let num_in = e.model.info.num_inputs();
        let mut inputs = vec![
            Port {
                p: vec![0.0; n],
                q: vec![0.0; n],
                linear: false,
            };
            num_in
        ];
        for r in &e.model.force_inputs {
            let port = &mut inputs[r.channel as usize];
            for (i, w) in dofs(e, &dof, r.index) {
                port.p[i as usize] += w;
                port.linear = true;
            }
            if strike {
                for &(a, b) in &net.open_contacts {
                    let far = if a == r.index {
                        b
                    } else if b == r.index {
                        a
                    } else {
                        continue;
                    };
                    for (i, w) in dofs(e, &dof, far) {
                        port.p[i as usize] += w;
                        port.linear = true;
                    }
                }
            }
        }
        for r in &e.model.avatars {
            let port = &mut inputs[r.channel as usize];
            port.linear = true;
            for l in &net.links {
                let s = (l.a == r.index) as u32 as f64 - (l.b == r.index) as u32 as f64;
                if s == 0.0 {
                    continue;
                }
                for (i, w) in link_vector(l.a, l.b) {
                    port.p[i as usize] -= s * l.k * w;
                    port.q[i as usize] -= s * l.z * w;
                }
            }
        }

        // Outputs: a position output reads x (spec §2.2.3); a force output reads the link
        // forces on its points, −f on an endpoint a and +f on an endpoint b (spec §1.3).
        let num_out = e.model.info.num_outputs();
        let mut outputs = vec![
            Port {
                p: vec![0.0; n],
                q: vec![0.0; n],
                linear: false,
            };
            num_out
        ];
        for r in &e.model.pos_outputs {
            let port = &mut outputs[r.channel as usize];
            for (i, w) in dofs(e, &dof, r.index) {
                port.p[i as usize] += w;
                port.linear = true;
            }
        }
        for &(channel, start, len) in &e.model.frc_outputs {
            let port = &mut outputs[channel as usize];
            let sources = &e.model.frc_sources[start as usize..(start + len) as usize];
            for l in &net.links {
                let s = sources.iter().filter(|&&p| p == l.b).count() as f64
                    - sources.iter().filter(|&&p| p == l.a).count() as f64;
                if s == 0.0 {
                    continue;
                }
                for (i, w) in link_vector(l.a, l.b) {
                    port.p[i as usize] += s * l.k * w;
                    port.q[i as usize] += s * l.z * w;
                    port.linear = true;
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

    /// The number of degrees of freedom.
    pub fn len(&self) -> usize {
        self.mass.len()
    }
}
