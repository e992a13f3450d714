//! The exact stability limit of the linear network (issue 14, point 2), for the host's
//! Stiffness and Damping gains.
//!
//! The scheme M·x[n+1] = (2M − K − Z)·x[n] + (Z − M)·x[n−1] with symmetric K ⪰ 0 and Z ⪰ 0
//! keeps the energy
//!
//! ```text
//! E = ½·vᵀ(M − K/4 − Z/2)·v + ½·x̄ᵀK·x̄,   v = x[n+1] − x[n],  x̄ = (x[n+1] + x[n])/2,
//! ```
//!
//! which never grows: E[n+½] − E[n−½] = −¼·(v₊ + v₋)ᵀZ(v₊ + v₋) (derived from spec §1.5 by
//! multiplying the step by (x[n+1] − x[n−1])/2). So every eigenvalue has |r| ≤ 1 exactly when
//! **4M − K − 2Z is positive definite**: for one oscillator K + 2Z < 4M (spec §5.1), for
//! proportional damping λ + 2γ < 4 per mode (spec §5.5), and in general the quadratic form that
//! the per-mass rule and the Gershgorin bound of spec §5.2 bound row by row.
//!
//! The network is the one of the stability rule ([`crate::analysis::network::Valuation::Bound`]:
//! contacts engaged, nonlinear laws at their bounded tangent), so it covers what playing can
//! reach. With the Stiffness gain g and the Damping gain h, K = g·K₁ and Z = h·Z₁ + g·Z_K
//! (Z_K is the K-class part of `nlSpringDamper`'s bounded damping 0.3·k), and the limit is the
//! largest g (or h) that keeps 4M − g·(K₁ + 2Z_K) − 2h·Z₁ positive definite, found by
//! bisection on the success of a sparse Cholesky factorisation. The energy argument needs
//! K₁ + 2Z_K ⪰ 0 and Z₁ ⪰ 0 as matrices, not each link: a network with a negative spring (a
//! stiff wire's bending written as negative second-neighbour springs) qualifies when the
//! assembled matrices are positive semi-definite. Where they are not, the Gershgorin bound of
//! [`crate::instrument`]'s envelope remains.

use super::system::{SymSparse, System};
use super::ANALYSIS_LIMIT;
use crate::analysis::network::{Network, Valuation};
use crate::{Engine, ScaleClass};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, SymbolicCholesky};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Par, Side};
use std::sync::Arc;

/// The inverse of the tolerance of the positive semi-definite test of a network with negative
/// links: A ⪰ −10⁻⁹·4M.
const SEMIDEFINITE_SCALE: f64 = 1e9;

/// Bisection steps: the limit to 2⁻⁴⁰ of its bracket.
const BISECTION_STEPS: usize = 40;

/// The largest Stiffness gain that keeps the model stable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StiffnessLimit {
    /// From the exact criterion (4M − K − 2Z positive definite).
    Exact(f64),
    /// From the Gershgorin bound of spec §5.2 (the analysis does not apply: a negative
    /// stiffness or damping in the network).
    Bound(f64),
}

impl StiffnessLimit {
    /// The limit, whichever way it was found.
    pub fn value(self) -> f64 {
        match self {
            StiffnessLimit::Exact(g) | StiffnessLimit::Bound(g) => g,
        }
    }
}

/// The model's linear network split by host gain, ready for stability queries. Built by
/// [`Engine::exact_stability`] off the audio thread.
#[derive(Clone, Debug)]
pub struct ExactStability {
    /// The lower triangle's pattern of 4M − g·(K₁ + 2Z_K) − 2h·Z₁, in compressed columns.
    pattern: SymbolicSparseColMat<u32>,
    /// Per stored entry of `pattern`, its terms: K₁ + 2Z_K (scaled by the Stiffness gain),
    /// 2Z₁ (by the Damping gain) and 4M, each where that matrix has the entry.
    terms: Vec<Terms>,
    applies: bool,
    /// True when some spring or damper of the network is negative (a stiff wire's or plate's
    /// bending written as negative second-neighbour springs).
    signed: bool,
    /// The symbolic factorisation of `pattern` (None where faer could not make one: every
    /// test then factorises from scratch).
    symbolic: Option<Arc<SymbolicCholesky<u32>>>,
}

/// What one search reuses from factorisation to factorisation: the matrix's values, the
/// factor's and faer's scratch (allocating and zeroing the factor each time was a sixth of
/// a search on the Chladni plate).
struct Workspace {
    values: Vec<f64>,
    factor: Vec<f64>,
    scratch: Option<MemBuffer>,
}

/// One entry's terms in [`ExactStability`].
#[derive(Clone, Copy, Debug)]
struct Terms {
    k: Option<f64>,
    z: Option<f64>,
    m: Option<f64>,
}

impl Terms {
    /// The entry at gains g and h: (−g)·k + (−h)·z + m over the terms present, summed in
    /// that order (as [`SymSparse::combine`] sums them, so the factorisations see the same
    /// values bit for bit).
    fn at(self, g: f64, h: f64) -> f64 {
        let k = self.k.map(|k| (-g) * k);
        let z = self.z.map(|z| (-h) * z);
        let kz = match (k, z) {
            (Some(k), Some(z)) => Some(k + z),
            (k, z) => k.or(z),
        };
        match (kz, self.m) {
            (Some(v), Some(m)) => v + m,
            (v, m) => v.or(m).unwrap_or(0.0),
        }
    }
}

impl ExactStability {
    /// False when the network's stiffness or damping matrix is not positive semi-definite (a
    /// negative script value that the rest of the network does not outweigh): the criterion
    /// then does not apply.
    pub fn applies(&self) -> bool {
        self.applies
    }

    /// True when some spring or damper of the network is negative. The per-mass (Gershgorin)
    /// rule sums signed stiffnesses, so there a negative spring lowers a mass's load and the
    /// rule's limit is no bound from below on the exact one.
    pub fn has_negative_links(&self) -> bool {
        self.signed
    }

    /// True when 4M − g·(K₁ + 2Z_K) − 2h·Z₁ is positive definite; None when the criterion
    /// does not apply.
    pub fn is_stable(&self, stiffness_gain: f64, damping_gain: f64) -> Option<bool> {
        self.applies
            .then(|| self.positive_definite(&mut self.workspace(), stiffness_gain, damping_gain))
    }

    /// The largest Stiffness gain that keeps the model stable at Damping gain `damping_gain`
    /// (infinite when no stiffness scales with it, 0 when the damping alone is unstable).
    pub fn max_stiffness(&self, damping_gain: f64) -> Option<f64> {
        self.applies.then(|| {
            let mut ws = self.workspace();
            self.largest(|g| self.positive_definite(&mut ws, g, damping_gain))
        })
    }

    /// The largest Damping gain that keeps the model stable at Stiffness gain
    /// `stiffness_gain`.
    pub fn max_damping(&self, stiffness_gain: f64) -> Option<f64> {
        self.applies.then(|| {
            let mut ws = self.workspace();
            self.largest(|h| self.positive_definite(&mut ws, stiffness_gain, h))
        })
    }

    /// The largest t ≥ 0 with `stable(t)`, assuming stability is lost once and for all as t
    /// grows (the quadratic form decreases in t).
    fn largest(&self, mut stable: impl FnMut(f64) -> bool) -> f64 {
        if !stable(0.0) {
            return 0.0;
        }
        let (mut lo, mut hi) = (0.0, 1.0);
        while stable(hi) {
            lo = hi;
            hi *= 2.0;
            if hi > 1e30 {
                return f64::INFINITY;
            }
        }
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (lo + hi);
            if stable(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    fn workspace(&self) -> Workspace {
        Workspace {
            values: vec![0.0; self.terms.len()],
            factor: vec![0.0; self.symbolic.as_ref().map_or(0, |s| s.len_val())],
            scratch: self.symbolic.as_ref().and_then(|s| {
                MemBuffer::try_new(
                    s.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
                )
                .ok()
            }),
        }
    }

    fn positive_definite(&self, ws: &mut Workspace, g: f64, h: f64) -> bool {
        if self.terms.is_empty() {
            return true;
        }
        // The values only: the pattern and its symbolic factorisation are made once.
        for (v, t) in ws.values.iter_mut().zip(&self.terms) {
            *v = t.at(g, h);
        }
        let mat = SparseColMatRef::new(self.pattern.as_ref(), &ws.values);
        match (&self.symbolic, &mut ws.scratch) {
            (Some(sym), Some(scratch)) => sym
                .factorize_numeric_llt(
                    &mut ws.factor,
                    mat,
                    Side::Lower,
                    Default::default(),
                    Par::Seq,
                    MemStack::new(scratch),
                    Default::default(),
                )
                .is_ok(),
            _ => mat.sp_cholesky(Side::Lower).is_ok(),
        }
    }
}

impl Engine {
    /// Prepares the exact stability analysis of the current parameter values (module
    /// [`crate::analysis::modes`], issue 14 point 2). The host gains are restored afterwards.
    pub fn exact_stability(&mut self) -> ExactStability {
        let (gk, gz) = (
            self.class_gain(ScaleClass::Stiffness),
            self.class_gain(ScaleClass::Damping),
        );
        let at = |e: &mut Engine, k: f64, z: f64| -> System {
            e.set_class_gain(ScaleClass::Stiffness, k);
            e.set_class_gain(ScaleClass::Damping, z);
            e.apply_pending_changes();
            let net = Network::walk(e, Valuation::Bound);
            System::assemble(e, &net, false)
        };
        let k_side = at(self, 1.0, 0.0);
        let z_side = at(self, 0.0, 1.0);
        self.set_class_gain(ScaleClass::Stiffness, gk);
        self.set_class_gain(ScaleClass::Damping, gz);
        self.apply_pending_changes();
        // K₁ + 2Z_K and 2Z₁.
        let a_k = SymSparse::combine(1.0, &k_side.k, 2.0, &k_side.z, &vec![0.0; k_side.len()]);
        let a_z = SymSparse::combine(2.0, &z_side.z, 0.0, &z_side.k, &vec![0.0; z_side.len()]);
        let four_m: Vec<f64> = k_side.mass.iter().map(|m| 4.0 * m).collect();
        let net = Network::walk(self, Valuation::Bound);
        // Finite, and within what a factorisation takes once normalised by the masses (as
        // the modal analysis requires, [`ANALYSIS_LIMIT`]): otherwise the Gershgorin bound.
        let masses = four_m.iter().all(|m| m.is_finite() && *m > 0.0);
        let finite = masses && {
            let inv_sqrt: Vec<f64> = four_m.iter().map(|m| 2.0 / m.sqrt()).collect();
            a_k.scaled_is_within(&inv_sqrt, ANALYSIS_LIMIT)
                && a_z.scaled_is_within(&inv_sqrt, ANALYSIS_LIMIT)
        };
        let nonnegative = net.links.iter().all(|l| l.k >= 0.0 && l.z >= 0.0)
            && net.k_ground.iter().chain(&net.z_ground).all(|v| *v >= 0.0);
        let (pattern, terms) = entry_terms(&a_k, &a_z, &four_m);
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            Default::default(),
            Default::default(),
        )
        .ok()
        .map(Arc::new);
        let mut stability = ExactStability {
            pattern,
            terms,
            applies: finite,
            signed: !nonnegative,
            symbolic,
        };
        if finite && !nonnegative {
            // A negative spring or damper: the energy argument needs only the assembled
            // K₁ + 2Z_K and Z₁ to be positive semi-definite, as they are for a wire whose
            // bending stiffness is written as negative second-neighbour springs. Tested as
            // A + 10⁻⁹·4M ≻ 0, that is 4M + 10⁹·A ≻ 0 (gains of −10⁹).
            let mut ws = stability.workspace();
            stability.applies = stability.positive_definite(&mut ws, -SEMIDEFINITE_SCALE, 0.0)
                && stability.positive_definite(&mut ws, 0.0, -SEMIDEFINITE_SCALE);
        }
        stability
    }

    /// The largest Stiffness gain that keeps the model stable at Damping gain `damping_gain`:
    /// exact where the analysis applies, else the Gershgorin bound of spec §5.2 (the load of
    /// [`crate::instrument`]'s envelope at 1, without its headroom).
    pub fn stiffness_limit(&mut self, damping_gain: f64) -> StiffnessLimit {
        if let Some(g) = self.exact_stability().max_stiffness(damping_gain) {
            return StiffnessLimit::Exact(g);
        }
        StiffnessLimit::Bound(self.gershgorin_stiffness_limit(damping_gain))
    }

    /// The Gershgorin bound's largest Stiffness gain at Damping gain `damping_gain`: the
    /// smallest (1 − h·z)/k over the coupled loads k·g + z·h of the masses (spec §5.2).
    pub fn gershgorin_stiffness_limit(&mut self, damping_gain: f64) -> f64 {
        let raw = crate::analysis::envelope::raw_envelope(self);
        raw.lines
            .iter()
            .filter(|l| l.k > 0.0)
            .map(|l| ((1.0 - damping_gain * l.z) / l.k).max(0.0))
            .fold(f64::INFINITY, f64::min)
    }
}

/// The union pattern of `a_k`, `a_z` and the diagonal `four_m` in compressed columns (rows
/// ascending), with each stored entry's terms.
fn entry_terms(
    a_k: &SymSparse,
    a_z: &SymSparse,
    four_m: &[f64],
) -> (SymbolicSparseColMat<u32>, Vec<Terms>) {
    let n = four_m.len();
    // Every entry of the three, by (column, row); the sort is stable, so an entry's terms
    // come in the order k, z, m.
    let mut all: Vec<(u32, u32, u8, f64)> =
        Vec::with_capacity(a_k.entries.len() + a_z.entries.len() + n);
    all.extend(a_k.entries.iter().map(|&(i, j, v)| (j, i, 0, v)));
    all.extend(a_z.entries.iter().map(|&(i, j, v)| (j, i, 1, v)));
    all.extend((0..n as u32).map(|i| (i, i, 2, four_m[i as usize])));
    all.sort_by_key(|e| (e.0, e.1));
    let mut col_ptr = vec![0u32; n + 1];
    let mut row_idx = Vec::with_capacity(all.len());
    let mut terms: Vec<Terms> = Vec::with_capacity(all.len());
    let mut last = None;
    for (col, row, which, v) in all {
        if last != Some((col, row)) {
            last = Some((col, row));
            row_idx.push(row);
            col_ptr[col as usize + 1] += 1;
            terms.push(Terms {
                k: None,
                z: None,
                m: None,
            });
        }
        let t = terms.last_mut().expect("an entry was pushed");
        let slot = match which {
            0 => &mut t.k,
            1 => &mut t.z,
            _ => &mut t.m,
        };
        // A matrix has each entry once (SymSparse sums its duplicates).
        *slot = Some(slot.map_or(v, |s| s + v));
    }
    for j in 0..n {
        col_ptr[j + 1] += col_ptr[j];
    }
    let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    (pattern, terms)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_terms_give_the_combined_matrix_bit_for_bit() {
        // The precomputed pattern and terms against the matrix the bisection used to build
        // for every factorisation: same pattern, same values (random sparse K, Z and M).
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for n in 1..12u32 {
            let mut random_entries = |count: u64| -> Vec<(u32, u32, f64)> {
                (0..count)
                    .map(|_| {
                        let (i, j) = ((next() % n as u64) as u32, (next() % n as u64) as u32);
                        (i, j, (next() % 1000) as f64 / 7.0 - 40.0)
                    })
                    .collect()
            };
            let k = SymSparse::from_entries(n as usize, random_entries(2 * n as u64));
            let z = SymSparse::from_entries(n as usize, random_entries(n as u64));
            let zeros = vec![0.0; n as usize];
            let a_k = SymSparse::combine(1.0, &k, 2.0, &z, &zeros);
            let a_z = SymSparse::combine(2.0, &z, 0.0, &k, &zeros);
            let four_m: Vec<f64> = (0..n).map(|i| 4.0 + i as f64 / 3.0).collect();
            let (pattern, terms) = entry_terms(&a_k, &a_z, &four_m);
            for (g, h) in [(0.0, 0.0), (1.0, 1.0), (0.37, 2.5), (13.1, 0.0), (0.0, 7.9)] {
                let old = SymSparse::combine(-g, &a_k, -h, &a_z, &four_m)
                    .lower()
                    .expect("a valid matrix");
                let values: Vec<f64> = terms.iter().map(|t| t.at(g, h)).collect();
                assert_eq!(old.symbolic().col_ptr(), pattern.col_ptr(), "n = {n}");
                assert_eq!(old.symbolic().row_idx(), pattern.row_idx(), "n = {n}");
                let bits = |v: &[f64]| v.iter().map(|x| (x + 0.0).to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(old.val()), bits(&values), "n = {n}, g = {g}, h = {h}");
            }
        }
    }
}
