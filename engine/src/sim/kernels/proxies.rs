//! Stages 3 and 5 of spec §1.5: connection points (spec §2.8), placed by interpolation and
//! spreading their force back to the macro nodes.

use super::Points;

/// Connection points (spec §2.8), points `base..base+len`: massless points interpolated from up
/// to four macro nodes, whose force is spread back with the same weights.
#[derive(Clone, Debug, Default)]
pub(crate) struct Proxies {
    pub base: usize,
    pub nodes: Vec<[u32; 4]>,
    pub weights: Vec<[f64; 4]>,
    /// The macro each proxy addresses: first node, length and width (width 0 for 1-D).
    pub geometry: Vec<(u32, u32, u32)>,
    /// Argument slots of the coordinates (α, or u and w).
    pub coord_slots: Vec<[usize; 2]>,
}

impl Proxies {
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Recomputes the nodes and weights of proxy `i` from its coordinates (spec §2.8).
    pub fn derive(&mut self, i: usize, args: &[f64]) {
        self.derive_with(i, |slot| args[slot]);
    }

    /// [`Proxies::derive`] with the argument of each slot given by `arg`.
    pub fn derive_with(&mut self, i: usize, arg: impl Fn(usize) -> f64) {
        /// Clamped position along `n` nodes: (lower node, upper node, fraction).
        fn along(c: f64, n: u32) -> (u32, u32, f64) {
            let last = n.saturating_sub(1);
            // NaN coordinates count as 0.
            let c = if c >= 0.0 { c.min(1.0) } else { 0.0 };
            let p = c * last as f64;
            let lo = (p.floor() as u32).min(last);
            let hi = (lo + 1).min(last);
            (lo, hi, p - lo as f64)
        }
        let (base, length, width) = self.geometry[i];
        let [s0, s1] = self.coord_slots[i];
        if width == 0 {
            let (m1, m2, a) = along(arg(s0), length);
            self.nodes[i] = [base + m1, base + m2, base + m1, base + m1];
            self.weights[i] = [1.0 - a, a, 0.0, 0.0];
        } else {
            let (i1, i2, ai) = along(arg(s0), length);
            let (j1, j2, aj) = along(arg(s1), width);
            let node = |i: u32, j: u32| base + i * width + j;
            self.nodes[i] = [node(i1, j1), node(i2, j1), node(i1, j2), node(i2, j2)];
            self.weights[i] = [
                (1.0 - ai) * (1.0 - aj),
                ai * (1.0 - aj),
                (1.0 - ai) * aj,
                ai * aj,
            ];
        }
    }

    /// The interpolated position of proxy `i`: Σ w·x_node (spec §2.8).
    #[inline(always)]
    pub(crate) fn interpolate(&self, i: usize, x: &[f64]) -> f64 {
        let [n0, n1, n2, n3] = self.nodes[i];
        let [w0, w1, w2, w3] = self.weights[i];
        w0 * x[n0 as usize] + w1 * x[n1 as usize] + w2 * x[n2 as usize] + w3 * x[n3 as usize]
    }

    /// Stage 3: x̃_P ← x_P, x_P ← Σ w·x_node. The force slot is cleared here, after stage 6 of
    /// the previous step read it (it holds F_P for `frcOutput`, spec §3.12 e).
    #[inline(always)]
    pub(crate) fn update_positions(&self, p: &mut Points) {
        for i in 0..self.len() {
            let pos = self.interpolate(i, &p.x);
            let k = self.base + i;
            p.xp[k] = p.x[k];
            p.x[k] = pos;
            p.f[k] = 0.0;
        }
    }

    /// Stage 5: spread F_P onto the macro nodes, in creation order.
    #[inline(always)]
    pub(crate) fn spread_forces(&self, p: &mut Points) {
        for i in 0..self.len() {
            let fp = p.f[self.base + i];
            let nodes = self.nodes[i];
            let weights = self.weights[i];
            for (n, w) in nodes.iter().zip(weights) {
                p.f[*n as usize] += w * fp;
            }
        }
    }
}
