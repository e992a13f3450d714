//! The stability envelope: how far the host's Stiffness and Damping gains may go before the
//! model's coupled (Gershgorin) loads reach the limit of spec §5.2.

use crate::analysis::modes::ExactStability;
use crate::{Engine, ScaleClass};

/// Stability budget kept free by the Stiffness/Damping clamp: the loads of every mass and
/// uniform structure stay below this fraction of the limit.
pub const STABILITY_HEADROOM: f64 = 0.95;

/// One line of the stability envelope: a mass or structure whose load is
/// `k·gK + z·gZ` for Stiffness gain gK and Damping gain gZ (stable below 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadLine {
    pub k: f64,
    pub z: f64,
}

/// The loads that can limit the host gains, reduced to the ones that can be the worst for
/// some gain pair (a mass whose K and Z loads are both below another's never limits).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StabilityEnvelope {
    pub lines: Vec<LoadLine>,
    /// The factor applied to the analysed loads (below 1 when the bound rejected the model
    /// as written; see [`envelope`]).
    pub scale: f64,
}

impl StabilityEnvelope {
    /// The largest Stiffness gain that keeps every load below [`STABILITY_HEADROOM`] at
    /// Damping gain `gz` (infinite when no load depends on K).
    pub fn max_stiffness(&self, gz: f64) -> f64 {
        let mut g = f64::INFINITY;
        for l in &self.lines {
            if l.k > 0.0 {
                g = g.min(((STABILITY_HEADROOM - gz * l.z) / l.k).max(0.0));
            }
        }
        g
    }

    /// The largest Damping gain that keeps every load below the headroom at Stiffness gain
    /// `gk`.
    pub fn max_damping(&self, gk: f64) -> f64 {
        let mut g = f64::INFINITY;
        for l in &self.lines {
            if l.z > 0.0 {
                g = g.min(((STABILITY_HEADROOM - gk * l.k) / l.z).max(0.0));
            }
        }
        g
    }

    /// Clamps a requested (Stiffness, Damping) gain pair into the stable region. Damping may
    /// use only the budget left by `min(gk, k_floor)` (so turning Damping up never takes the
    /// model's own stiffness away), then Stiffness takes what remains. Returns the gains and
    /// whether anything was clamped.
    pub fn clamp(&self, gk: f64, gz: f64, k_floor: f64) -> (f64, f64, bool) {
        self.clamp_moved(gk, gz, k_floor, self, &[])
    }

    pub(crate) fn from_loads(mut loads: Vec<LoadLine>) -> StabilityEnvelope {
        // Sort by K load, largest first; keep a line only if its Z load beats every line with a
        // larger K load.
        loads.sort_by(|a, b| b.k.total_cmp(&a.k).then(b.z.total_cmp(&a.z)));
        let mut lines: Vec<LoadLine> = Vec::new();
        let mut best_z = f64::NEG_INFINITY;
        for l in loads {
            if !(l.k.is_finite() && l.z.is_finite()) {
                continue;
            }
            if l.z > best_z {
                best_z = l.z;
                lines.push(l);
            }
        }
        StabilityEnvelope { lines, scale: 1.0 }
    }

    pub(crate) fn scaled(mut self, scale: f64) -> StabilityEnvelope {
        for l in &mut self.lines {
            l.k *= scale;
            l.z *= scale;
        }
        self.scale = scale;
        self
    }

    /// Clamps like [`StabilityEnvelope::clamp`] while macro slots move parameters: `moved`
    /// holds, per moved slot, the envelope at the end of its range it moved towards and how
    /// far (0 … 1, linear in the parameter value); `reference` is the envelope of the same
    /// kind (Gershgorin, scaled alike) at the declared values, which this one may be an
    /// exact refinement of. Each slot's limit is interpolated harmonically between this
    /// envelope's and the moved one's, which bounds the true limit from below when loads
    /// depend linearly on the parameter; the tightest slot sets the limit. The other slots
    /// that tighten compound on it, each by its own ratio to `reference` (loads go as K/M, so
    /// a slot lowering a mass and one raising a stiffness on it multiply). A slot that
    /// loosens changes nothing, as it may act on other masses than a tightening one loads.
    /// With one slot moved this is that slot's limit.
    pub fn clamp_moved(
        &self,
        gk: f64,
        gz: f64,
        k_floor: f64,
        reference: &StabilityEnvelope,
        moved: &[(&StabilityEnvelope, f64)],
    ) -> (f64, f64, bool) {
        const TOLERANCE: f64 = 1.0 + 1e-9;
        let blend = |a: f64, b: f64, f: f64| -> f64 {
            if !(a.is_finite() && b.is_finite()) {
                return a.min(b);
            }
            let inv = (1.0 - f) / a.max(1e-300) + f / b.max(1e-300);
            1.0 / inv
        };
        let limit = |of: &dyn Fn(&StabilityEnvelope) -> f64| -> f64 {
            let base = of(self);
            let mut tightest = (base, None);
            for (i, (e, f)) in moved.iter().enumerate() {
                let l = blend(base, of(e), *f);
                if l < tightest.0 {
                    tightest = (l, Some(i));
                }
            }
            let reference = of(reference);
            let mut acc = tightest.0;
            if reference.is_finite() && reference > 0.0 {
                for (i, (e, f)) in moved.iter().enumerate() {
                    let ratio = blend(reference, of(e), *f) / reference;
                    if Some(i) != tightest.1 && ratio < 1.0 {
                        acc *= ratio;
                    }
                }
            }
            acc
        };
        // The stiffness Damping leaves room for; a model that cannot keep its own (unstable
        // as written at this rate, or with these macros) leaves Damping a tenth of what it
        // can keep.
        let stiffest = limit(&|e| e.max_stiffness(0.0));
        let k_at = if stiffest < gk.min(k_floor) {
            0.9 * stiffest
        } else {
            gk.min(k_floor)
        };
        let z_limit = limit(&|e| e.max_damping(k_at));
        let z = gz.min(z_limit * TOLERANCE);
        let k_limit = limit(&|e| e.max_stiffness(z));
        let k = gk.min(k_limit * TOLERANCE);
        (k, z, k < gk || z < gz)
    }
}

/// The highest coupled load of the model and the mass that has it.
pub fn worst_load(report: &crate::StabilityReport) -> (f64, String) {
    report
        .masses
        .iter()
        .max_by(|a, b| a.coupled_load().total_cmp(&b.coupled_load()))
        .map(|m| (m.coupled_load(), m.label.clone()))
        .unwrap_or((0.0, String::new()))
}

/// Splits the coupled (Gershgorin) load of every mass, (K_eq + K_coupled + 2(Z_eq +
/// Z_coupled))/4M, into its Stiffness and Damping parts by analysing the model with one class
/// switched off at a time (a nonlinear law can put K-class arguments into its damping bound).
/// Below 1 for every mass, no mode of the linearised network exceeds the time step's limit;
/// the per-mass rule of spec §5.2 alone lets coupled chains explode at half the stiffness it
/// allows.
///
/// The Gershgorin bound can be pessimistic (a small triangular lattice passes at unit gains
/// although its bound says 1.5), and the model as written is the author's decision: when the
/// bound rejects unit gains, the whole envelope is scaled so that unit gains sit exactly at
/// the headroom. The clamp then never takes away what the script asks for.
pub fn envelope(engine: &mut Engine) -> StabilityEnvelope {
    let raw = raw_envelope(engine);
    let unit = raw.lines.iter().map(|l| l.k + l.z).fold(0.0, f64::max);
    let scale = if unit > STABILITY_HEADROOM {
        STABILITY_HEADROOM / unit
    } else {
        1.0
    };
    raw.scaled(scale)
}

/// Damping gains, as fractions of the largest stable one, at which the exact envelope takes a
/// point of the stability boundary.
const EXACT_SAMPLES: [f64; 2] = [0.0, 0.5];

/// The exact stability limit of the linear network (4M − K − 2Z positive definite, see
/// [`crate::analysis::modes`]) as an envelope: lines through points of its boundary in the
/// (Stiffness, Damping) gain plane, at Damping gains 0 and ½ of the largest stable one and on the
/// Damping axis. The stable region is convex (the criterion is linear in the gains), so these
/// chords lie inside it and the clamp stays safe. None where the criterion does not apply (a
/// negative stiffness or damping in the network): the Gershgorin envelope remains there.
///
/// A model the criterion rejects as written gets its exact limits too, below unit gains: it
/// would explode (a script written at the edge for 44.1 kHz and played at 22.05 kHz, where
/// every per-sample stiffness is four times larger), and the Gershgorin envelope's trust in
/// the script ([`envelope`]) is meant for the bound's pessimism, not for that.
pub fn exact_envelope(ex: &ExactStability) -> Option<StabilityEnvelope> {
    ex.is_stable(1.0, 1.0)?;
    // Each limit is a bisection of some fifty sparse factorisations (a second for the largest
    // plates): the two axes at once.
    let (z_max, k_max) = super::concurrent::join(|| ex.max_damping(0.0), || ex.max_stiffness(0.0));
    let (z_max, k_max) = (z_max?, k_max?);
    let mut lines = Vec::new();
    if !z_max.is_finite() {
        // Nothing scales with Damping: the Stiffness limit alone.
        lines.push(LoadLine {
            k: 1.0 / k_max,
            z: 0.0,
        });
    } else if !k_max.is_finite() {
        lines.push(LoadLine {
            k: 0.0,
            z: 1.0 / z_max,
        });
    } else {
        let mut points: Vec<(f64, f64)> = Vec::with_capacity(EXACT_SAMPLES.len() + 1);
        for f in EXACT_SAMPLES {
            let z = f * z_max;
            let k = if z == 0.0 {
                k_max
            } else {
                ex.max_stiffness(z)?
            };
            points.push((k, z));
        }
        points.push((0.0, z_max));
        for w in points.windows(2) {
            let ((k1, z1), (k2, z2)) = (w[0], w[1]);
            let det = k1 * z2 - k2 * z1;
            if det > 0.0 {
                lines.push(LoadLine {
                    k: ((z2 - z1) / det).max(0.0),
                    z: ((k1 - k2) / det).max(0.0),
                });
            }
        }
    }
    (!lines.is_empty()).then(|| StabilityEnvelope::from_loads(lines).scaled(1.0))
}

/// The envelope of the model's current parameter values, unscaled.
pub fn raw_envelope(engine: &mut Engine) -> StabilityEnvelope {
    let coupled = |r: &crate::StabilityReport| -> Vec<f64> {
        r.masses.iter().map(|m| m.coupled_load()).collect()
    };
    engine.set_class_gain(ScaleClass::Damping, 0.0);
    let k = coupled(&engine.stability_numbers());
    engine.set_class_gain(ScaleClass::Damping, 1.0);
    engine.set_class_gain(ScaleClass::Stiffness, 0.0);
    let z = coupled(&engine.stability_numbers());
    engine.set_class_gain(ScaleClass::Stiffness, 1.0);
    engine.apply_pending_changes();
    let loads = k
        .into_iter()
        .zip(z)
        .map(|(k, z)| LoadLine { k, z })
        .collect();
    StabilityEnvelope::from_loads(loads)
}
