//! Stages 3 and 5 of a 3-D model: connection points (3-D spec §2.6), massless points
//! interpolated from a structure's nodes with the 1-D weights (1D §2.8) applied to each axis,
//! their force spread back with the same weights.
//!
//! | structure | bracket | nodes and weights |
//! |---|---|---|
//! | `string3` | `[@s α]` | 2 nodes along 0 … N−1 |
//! | `mesh3` | `[@me u w]` | 4, bilinear |
//! | `lattice3` | `[@c u v w]` | 8, trilinear |
//! | `ring3` | `[@r α]` | 2, periodic: p = frac(α)·N, the node after N−1 is 0 |

use super::super::kernels::Points;

/// The structure a connection point interpolates, from its first node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Along {
    Line { n: u32 },
    Surface { nx: u32, ny: u32 },
    Volume { nx: u32, ny: u32, nz: u32 },
    Ring { n: u32 },
}

/// A connection point: its structure, its first node and its coordinates' argument slots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ProxyDef {
    pub along: Along,
    pub base: u32,
    pub coords: [u32; 3],
}

/// Clamped position along `n` nodes (1D §2.8): (lower node, upper node, fraction); NaN
/// counts as 0.
fn along(c: f64, n: u32) -> (u32, u32, f64) {
    let last = n.saturating_sub(1);
    let c = if c >= 0.0 { c.min(1.0) } else { 0.0 };
    let p = c * last as f64;
    let lo = (p.floor() as u32).min(last);
    let hi = (lo + 1).min(last);
    (lo, hi, p - lo as f64)
}

impl ProxyDef {
    /// Its nodes and weights from its coordinates (unused entries: the first node, weight 0).
    pub fn derive(&self, args: &[f64], nodes: &mut [u32; 8], weights: &mut [f64; 8]) {
        let c = |k: usize| args[self.coords[k] as usize];
        *nodes = [self.base; 8];
        *weights = [0.0; 8];
        match self.along {
            Along::Line { n } => {
                let (m1, m2, a) = along(c(0), n);
                nodes[0] = self.base + m1;
                nodes[1] = self.base + m2;
                weights[0] = 1.0 - a;
                weights[1] = a;
            }
            Along::Ring { n } => {
                let alpha = c(0);
                let alpha = if alpha.is_finite() { alpha } else { 0.0 };
                let frac = alpha - alpha.floor();
                let p = frac * n as f64;
                let m1 = (p.floor() as u32).min(n.saturating_sub(1));
                let m2 = (m1 + 1) % n.max(1);
                let a = p - m1 as f64;
                nodes[0] = self.base + m1;
                nodes[1] = self.base + m2;
                weights[0] = 1.0 - a;
                weights[1] = a;
            }
            Along::Surface { nx, ny } => {
                let (i1, i2, ai) = along(c(0), nx);
                let (j1, j2, aj) = along(c(1), ny);
                let node = |i: u32, j: u32| self.base + i * ny + j;
                *nodes = [
                    node(i1, j1),
                    node(i2, j1),
                    node(i1, j2),
                    node(i2, j2),
                    self.base,
                    self.base,
                    self.base,
                    self.base,
                ];
                weights[..4].copy_from_slice(&[
                    (1.0 - ai) * (1.0 - aj),
                    ai * (1.0 - aj),
                    (1.0 - ai) * aj,
                    ai * aj,
                ]);
            }
            Along::Volume { nx, ny, nz } => {
                let (i1, i2, ai) = along(c(0), nx);
                let (j1, j2, aj) = along(c(1), ny);
                let (k1, k2, ak) = along(c(2), nz);
                let node = |i: u32, j: u32, k: u32| self.base + (i * ny + j) * nz + k;
                let mut n = 0;
                for (k, wk) in [(k1, 1.0 - ak), (k2, ak)] {
                    for (j, wj) in [(j1, 1.0 - aj), (j2, aj)] {
                        for (i, wi) in [(i1, 1.0 - ai), (i2, ai)] {
                            nodes[n] = node(i, j, k);
                            weights[n] = (wi * wj) * wk;
                            n += 1;
                        }
                    }
                }
            }
        }
    }

    /// How many of the eight entries it uses.
    pub fn width(&self) -> usize {
        match self.along {
            Along::Line { .. } | Along::Ring { .. } => 2,
            Along::Surface { .. } => 4,
            Along::Volume { .. } => 8,
        }
    }
}

/// Stage 3: x̃_P ← x_P, x_P ← Σ w·x_node on each axis; F_P cleared (it held the previous
/// sample's force for `frcOutput`).
#[inline(always)]
pub(crate) fn update_positions(
    defs: &[ProxyDef],
    base: usize,
    nodes: &[[u32; 8]],
    weights: &[[f64; 8]],
    axes: [&mut Points; 3],
) {
    for axis in axes {
        for (i, d) in defs.iter().enumerate() {
            let (n, w) = (&nodes[i], &weights[i]);
            let mut pos = w[0] * axis.x[n[0] as usize];
            for k in 1..d.width() {
                pos += w[k] * axis.x[n[k] as usize];
            }
            let p = base + i;
            axis.xp[p] = axis.x[p];
            axis.x[p] = pos;
            axis.f[p] = 0.0;
        }
    }
}

/// Stage 5: F_node += w·F_P, connection point by connection point.
#[inline(always)]
pub(crate) fn spread_forces(
    defs: &[ProxyDef],
    base: usize,
    nodes: &[[u32; 8]],
    weights: &[[f64; 8]],
    axes: [&mut Points; 3],
) {
    for axis in axes {
        for (i, d) in defs.iter().enumerate() {
            let fp = axis.f[base + i];
            for k in 0..d.width() {
                axis.f[nodes[i][k] as usize] += weights[i][k] * fp;
            }
        }
    }
}

/// The interpolated position of connection point `i` on one axis.
pub(crate) fn interpolate(d: &ProxyDef, n: &[u32; 8], w: &[f64; 8], x: &[f64]) -> f64 {
    let mut pos = w[0] * x[n[0] as usize];
    for k in 1..d.width() {
        pos += w[k] * x[n[k] as usize];
    }
    pos
}
