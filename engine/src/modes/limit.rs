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
//! The network is the one of the stability rule ([`crate::network::Valuation::Bound`]:
//! contacts engaged, nonlinear laws at their bounded tangent), so it covers what playing can
//! reach. With the Stiffness gain g and the Damping gain h, K = g·K₁ and Z = h·Z₁ + g·Z_K
//! (Z_K is the K-class part of `nlSpringDamper`'s bounded damping 0.3·k), and the limit is the
//! largest g (or h) that keeps 4M − g·(K₁ + 2Z_K) − 2h·Z₁ positive definite, found by
//! bisection on the success of a sparse Cholesky factorisation. Where the network has a
//! negative stiffness or damping, the energy argument does not hold and the Gershgorin bound
//! of [`crate::instrument`]'s envelope remains.

use super::system::{SymSparse, System};
use crate::network::{Network, Valuation};
use crate::{Engine, ScaleClass};
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::Side;

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
    /// 4M on the diagonal.
    four_m: Vec<f64>,
    /// K₁ + 2Z_K: the part scaled by the Stiffness gain.
    a_k: SymSparse,
    /// 2Z₁: the part scaled by the Damping gain.
    a_z: SymSparse,
    applies: bool,
    symbolic: Option<SymbolicLlt<u32>>,
}

impl ExactStability {
    /// False when the network has a negative stiffness or damping (an `nlPluck` resting in
    /// its tent, a negative script value): the criterion then does not apply.
    pub fn applies(&self) -> bool {
        self.applies
    }

    /// True when 4M − g·(K₁ + 2Z_K) − 2h·Z₁ is positive definite; None when the criterion
    /// does not apply.
    pub fn is_stable(&self, stiffness_gain: f64, damping_gain: f64) -> Option<bool> {
        self.applies
            .then(|| self.positive_definite(stiffness_gain, damping_gain))
    }

    /// The largest Stiffness gain that keeps the model stable at Damping gain `damping_gain`
    /// (infinite when no stiffness scales with it, 0 when the damping alone is unstable).
    pub fn max_stiffness(&self, damping_gain: f64) -> Option<f64> {
        self.applies
            .then(|| self.largest(|g| self.positive_definite(g, damping_gain)))
    }

    /// The largest Damping gain that keeps the model stable at Stiffness gain
    /// `stiffness_gain`.
    pub fn max_damping(&self, stiffness_gain: f64) -> Option<f64> {
        self.applies
            .then(|| self.largest(|h| self.positive_definite(stiffness_gain, h)))
    }

    /// The largest t ≥ 0 with `stable(t)`, assuming stability is lost once and for all as t
    /// grows (the quadratic form decreases in t).
    fn largest(&self, stable: impl Fn(f64) -> bool) -> f64 {
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

    fn positive_definite(&self, g: f64, h: f64) -> bool {
        let b = SymSparse::combine(-g, &self.a_k, -h, &self.a_z, &self.four_m);
        if b.n == 0 {
            return true;
        }
        let Some(mat) = b.lower() else {
            return false;
        };
        match &self.symbolic {
            Some(sym) => Llt::try_new_with_symbolic(sym.clone(), mat.as_ref(), Side::Lower).is_ok(),
            None => mat.sp_cholesky(Side::Lower).is_ok(),
        }
    }
}

impl Engine {
    /// Prepares the exact stability analysis of the current parameter values (module
    /// [`crate::modes`], issue 14 point 2). The host gains are restored afterwards.
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
        let applies = four_m.iter().all(|m| m.is_finite() && *m > 0.0)
            && net.links.iter().all(|l| l.k >= 0.0 && l.z >= 0.0)
            && net.k_ground.iter().chain(&net.z_ground).all(|v| *v >= 0.0)
            && a_k.is_finite()
            && a_z.is_finite();
        let pattern = SymSparse::combine(1.0, &a_k, 1.0, &a_z, &four_m);
        let symbolic = pattern
            .lower()
            .and_then(|m| SymbolicLlt::try_new(m.symbolic(), Side::Lower).ok());
        ExactStability {
            four_m,
            a_k,
            a_z,
            applies,
            symbolic,
        }
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
        let raw = crate::instrument::envelope::raw_envelope(self);
        raw.lines
            .iter()
            .filter(|l| l.k > 0.0)
            .map(|l| ((1.0 - damping_gain * l.z) / l.k).max(0.0))
            .fold(f64::INFINITY, f64::min)
    }
}
