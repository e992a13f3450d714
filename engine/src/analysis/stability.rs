//! Stability analysis (spec §5.2), on the effective per-step values of a compiled model (after
//! sample-rate scaling, host gains and current parameter values).
//!
//! **Per-mass rule** (SMC'19 paper): every moving mass must satisfy 4M > K_eq + 2·Z_eq, where
//! K_eq and Z_eq sum the stiffness and damping of everything attached to it:
//!
//! * `osc` elements and macro nodes with their own K and Z, or Z_o;
//! * every link by its law's linear stand-in at its bound (`LawKind::linearise`, described in
//!   each law's file under `laws/`): linear links and contacts (counted as engaged) with their
//!   K and Z; bounded nonlinear links at their bounded tangent, k for the bounded branch and
//!   3k − 2s, the peak of the cubic region just below the tipping point (derived, §2.5.3);
//!   unbounded ones at their linear part, with a warning; `nlPluck` at the steepest slope of
//!   its tent; `nlBow` by its stick slope in Z_eq.
//!
//! A link attached to a connection point acts on the macro nodes through the interpolation
//! weights w; each node counts w·K and w·Z (the row sum of the spread stiffness).
//!
//! **Stricter limits for uniform structures** (derived, §5.2), reported as warnings: with the
//! largest eigenvalues λ_K of the stiffness operator and λ_Z of the damping operator, a macro
//! is stable when λ_K + 2λ_Z < 4M. This gives K + 2Z + Z_o/2 < M for strings and chains and
//! 2K + 4Z + Z_o/2 < M for 4-neighbour meshes. For the stiff string
//! λ_K = max over θ of 2K(1 − cos θ) + 2K_s(1 − cos 2θ), which is 2K + 4K_s + K²/(4K_s) when
//! K < 4K_s and 4K otherwise.

use crate::analysis::network::{endpoint_nodes, kind_moves, Network, Valuation};
use crate::laws::linear::BoundNote;
use crate::sim::engine::Engine;
use std::fmt;

/// The per-mass rule for one moving point.
#[derive(Clone, Debug, PartialEq)]
pub struct MassStability {
    /// Index in [`crate::ModelInfo::points`].
    pub point: u32,
    /// `m1`, `s[12]`, `mesh[3,4]`.
    pub label: String,
    /// Per-step mass M.
    pub m: f64,
    /// Sum of attached stiffnesses (per step).
    pub k_eq: f64,
    /// Sum of attached dampings (per step).
    pub z_eq: f64,
    /// Stiffness of the links to other moving points: the off-diagonal row sum of the
    /// stiffness matrix (per step).
    pub k_coupled: f64,
    /// Damping of the links to other moving points (per step).
    pub z_coupled: f64,
}

impl MassStability {
    /// 4M − (K_eq + 2·Z_eq): positive when the rule holds.
    pub fn margin(&self) -> f64 {
        4.0 * self.m - (self.k_eq + 2.0 * self.z_eq)
    }

    /// (K_eq + 2·Z_eq) / 4M: below 1 when the rule holds.
    pub fn load(&self) -> f64 {
        (self.k_eq + 2.0 * self.z_eq) / (4.0 * self.m)
    }

    /// True when 4M > K_eq + 2·Z_eq.
    pub fn is_stable(&self) -> bool {
        self.margin() > 0.0
    }

    /// The Gershgorin bound of this mass's row: (K_eq + K_coupled + 2·(Z_eq + Z_coupled)) / 4M.
    /// Below 1 for every mass, no mode of the linearised network exceeds the step's limit,
    /// which the per-mass rule alone does not guarantee for coupled masses (a uniform chain
    /// passes the per-mass rule up to K = 2M but is stable only up to K = M). For uniform
    /// strings and meshes it equals the structure load.
    pub fn coupled_load(&self) -> f64 {
        (self.k_eq + self.k_coupled + 2.0 * (self.z_eq + self.z_coupled)) / (4.0 * self.m)
    }
}

/// Something the analysis wants the user to know.
#[derive(Clone, Debug, PartialEq)]
pub enum StabilityWarning {
    /// A mass breaks the per-mass rule.
    MassRule(MassStability),
    /// A uniform structure exceeds its stricter eigenvalue limit: `load` = (λ_K + 2λ_Z)/4M ≥ 1.
    StructureLimit {
        label: String,
        keyword: &'static str,
        load: f64,
    },
    /// A nonlinear law without a bound (`nlSpring2`/`nlSpring3` with Q ≠ 0, for example). For the
    /// link warnings, `label` names the link's endpoints (`g–m`) and `element` is the index of the
    /// interaction in the spec's elements (its label and line).
    Unbounded {
        label: String,
        keyword: &'static str,
        element: u32,
    },
    /// A negative cubic coefficient in a bounded law: the bounded branch applies everywhere.
    NegativeCubic {
        label: String,
        keyword: &'static str,
        element: u32,
    },
    /// `nlSpringDamper` with k < s and c ≠ 0: bounded by the weaker k (compat).
    WeakBound { label: String, element: u32 },
}

impl StabilityWarning {
    /// The spec element an interaction warning is about (an index into
    /// `ModelSpec::elements`); `None` for the warnings about masses and structures.
    pub fn element(&self) -> Option<usize> {
        match self {
            StabilityWarning::Unbounded { element, .. }
            | StabilityWarning::NegativeCubic { element, .. }
            | StabilityWarning::WeakBound { element, .. } => Some(*element as usize),
            StabilityWarning::MassRule(_) | StabilityWarning::StructureLimit { .. } => None,
        }
    }
}

impl fmt::Display for StabilityWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StabilityWarning::MassRule(m) => write!(
                f,
                "@{}: 4M > K_eq + 2·Z_eq is violated (M = {:.6}, K_eq = {:.6}, Z_eq = {:.6}, \
                 load {:.3})",
                m.label,
                m.m,
                m.k_eq,
                m.z_eq,
                m.load()
            ),
            StabilityWarning::StructureLimit {
                label,
                keyword,
                load,
            } => write!(
                f,
                "@{label}: this {keyword} exceeds the stricter limit for uniform structures \
                 (λ_K + 2λ_Z = {load:.3} × 4M); it may blow up although every mass passes the \
                 per-mass rule"
            ),
            StabilityWarning::Unbounded { label, keyword, .. } => write!(
                f,
                "@{label}: {keyword} has no stiffness bound and may become unstable for high \
                 elongation"
            ),
            StabilityWarning::NegativeCubic { label, keyword, .. } => write!(
                f,
                "@{label}: negative cubic coefficient in {keyword}; the bounded branch applies"
            ),
            StabilityWarning::WeakBound { label, .. } => write!(
                f,
                "@{label}: nlSpringDamper with Klim < K and KnlQ ≠ 0 is bounded by the weaker \
                 Klim"
            ),
        }
    }
}

/// The analysis of a whole model.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StabilityReport {
    /// Every moving mass (single masses and moving macro nodes), in point order.
    pub masses: Vec<MassStability>,
    pub warnings: Vec<StabilityWarning>,
}

impl StabilityReport {
    /// True when every mass satisfies the per-mass rule.
    pub fn is_stable(&self) -> bool {
        self.masses.iter().all(MassStability::is_stable)
    }

    /// The masses that break the per-mass rule.
    pub fn violations(&self) -> impl Iterator<Item = &MassStability> {
        self.masses.iter().filter(|m| !m.is_stable())
    }

    /// The mass closest to (or furthest past) the limit.
    pub fn worst(&self) -> Option<&MassStability> {
        self.masses
            .iter()
            .max_by(|a, b| a.load().total_cmp(&b.load()))
    }
}

impl Engine {
    /// Analyses the model with its current parameter values and host gains (spec §5.2). A
    /// parameter change still pending for the next block is applied first.
    pub fn stability(&mut self) -> StabilityReport {
        self.apply_pending_changes();
        analyze(self, true)
    }

    /// [`Engine::stability`] with every mass's label left empty
    /// ([`crate::ModelInfo::point_label`] names the one a reader shows): for the instrument's
    /// envelopes, macro ranges and units, which read only the numbers and analyse a model
    /// dozens of times as it is prepared, and for the plugin's model summary (a label is
    /// formatted per moving point: on the 150 × 150 plate, 8 ms of a 15 ms report).
    pub fn stability_numbers(&mut self) -> StabilityReport {
        self.apply_pending_changes();
        analyze(self, false)
    }
}

/// The largest stiffness eigenvalue of a stiff string with link stiffness `k` and
/// second-neighbour stiffness `ks` (per unit mass).
fn stiff_string_lambda(k: f64, ks: f64) -> f64 {
    if ks > 0.0 && k < 4.0 * ks {
        2.0 * k + 4.0 * ks + k * k / (4.0 * ks)
    } else {
        4.0 * k
    }
}

fn analyze(e: &Engine, labelled: bool) -> StabilityReport {
    let info = &e.model.info;
    let n = info.num_points;
    let args = &e.args;
    // The network with every nonlinear law at its bounded tangent (crate::analysis::network).
    let net = Network::walk(e, Valuation::Bound);
    let mut k_eq = net.k_ground.clone();
    let mut z_eq = net.z_ground.clone();
    let mut k_cp = vec![0.0; n];
    let mut z_cp = vec![0.0; n];
    let mut warnings: Vec<StabilityWarning> = net
        .notes
        .iter()
        .map(|n| {
            let (label, keyword, element) = (n.label.clone(), n.keyword, n.element);
            match n.note {
                BoundNote::NegativeCubic => StabilityWarning::NegativeCubic {
                    label,
                    keyword,
                    element,
                },
                BoundNote::Unbounded => StabilityWarning::Unbounded {
                    label,
                    keyword,
                    element,
                },
                BoundNote::WeakBound => StabilityWarning::WeakBound { label, element },
            }
        })
        .collect();

    let is_moving = |p: usize| -> bool { kind_moves(info.points[p].kind) };
    // The share of an endpoint that moves: 1 or 0 for a point, the weights of its moving
    // nodes for a connection point.
    let moving_weight = |p: u32| -> f64 {
        endpoint_nodes(e, p)
            .filter(|&(node, _)| is_moving(node))
            .map(|(_, w)| w)
            .sum()
    };
    // Off-diagonal row sums of a link a–b on a's side: towards b, and, for a connection
    // point, among a's own nodes.
    let couple = |a: u32, b: u32, k: f64, z: f64, k_cp: &mut [f64], z_cp: &mut [f64]| {
        let other = moving_weight(b);
        if (a as usize) < n {
            k_cp[a as usize] += k * other;
            z_cp[a as usize] += z * other;
        } else {
            let own = moving_weight(a);
            for (node, w) in endpoint_nodes(e, a) {
                let f = w * (other + own - w).max(0.0);
                k_cp[node] += f * k;
                z_cp[node] += f * z;
            }
        }
    };
    // Adds (k, z) to a point, spreading over macro nodes for connection points.
    let add = |p: u32, k: f64, z: f64, k_eq: &mut [f64], z_eq: &mut [f64]| {
        for (node, w) in endpoint_nodes(e, p) {
            k_eq[node] += w * k;
            z_eq[node] += w * z;
        }
    };
    // A link between two material points of a 1-D model (no connection point) takes the
    // arithmetic of `add` and `couple` with weight 1 directly: the same operations in the same
    // order, so the same bits, without the endpoints' generality, which costs most of the time
    // on a large mesh (a provisional model's envelopes, instrument::prepare).
    let plain = e.space.is_none();
    let weight = |p: usize| -> f64 { is_moving(p).then_some(1.0).into_iter().sum() };
    for l in &net.links {
        let (a, b) = (l.a as usize, l.b as usize);
        if plain && a < n && b < n {
            k_eq[a] += 1.0 * l.k;
            z_eq[a] += 1.0 * l.z;
            k_eq[b] += 1.0 * l.k;
            z_eq[b] += 1.0 * l.z;
            let (towards_b, towards_a) = (weight(b), weight(a));
            k_cp[a] += l.k * towards_b;
            z_cp[a] += l.z * towards_b;
            k_cp[b] += l.k * towards_a;
            z_cp[b] += l.z * towards_a;
            continue;
        }
        add(l.a, l.k, l.z, &mut k_eq, &mut z_eq);
        add(l.b, l.k, l.z, &mut k_eq, &mut z_eq);
        couple(l.a, l.b, l.k, l.z, &mut k_cp, &mut z_cp);
        couple(l.b, l.a, l.k, l.z, &mut k_cp, &mut z_cp);
    }
    let mass = &net.mass;

    // Structure limits of uniform macros (derived, spec §5.2); their links and Z_o are in
    // the network.
    let m = &e.macros;
    let mut structure = |base: usize, load: f64| {
        if !(load < 1.0) {
            let owner = &info.owners[info.points[base].owner as usize];
            warnings.push(StabilityWarning::StructureLimit {
                label: owner.label.to_string(),
                keyword: owner.keyword,
                load,
            });
        }
    };
    for (mac, stiff) in m
        .lines
        .iter()
        .map(|l| (l, false))
        .chain(m.stiff.iter().map(|l| (l, true)))
    {
        let (mm, k, k2, z, zo) = (
            args[mac.slots.m],
            args[mac.slots.k],
            args[mac.slots.k2],
            args[mac.slots.z],
            args[mac.slots.zo],
        );
        let lambda_k = if stiff {
            stiff_string_lambda(k, k2)
        } else {
            4.0 * k
        };
        structure(mac.base, (lambda_k + 2.0 * (4.0 * z + zo)) / (4.0 * mm));
    }
    for mac in &m.meshes {
        let (mm, k, z, zo) = (
            args[mac.slots.m],
            args[mac.slots.k],
            args[mac.slots.z],
            args[mac.slots.zo],
        );
        structure(mac.base, (8.0 * k + 2.0 * (8.0 * z + zo)) / (4.0 * mm));
    }

    let mut masses = Vec::new();
    for p in 0..info.points.len() {
        if !is_moving(p) {
            continue;
        }
        let entry = MassStability {
            point: p as u32,
            label: if labelled {
                info.point_label(p)
            } else {
                String::new()
            },
            m: mass[p],
            k_eq: k_eq[p],
            z_eq: z_eq[p],
            k_coupled: k_cp[p],
            z_coupled: z_cp[p],
        };
        if !entry.is_stable() {
            warnings.push(StabilityWarning::MassRule(entry.clone()));
        }
        masses.push(entry);
    }
    StabilityReport { masses, warnings }
}
