//! Stability analysis (spec §5.2), on the effective per-step values of a compiled model (after
//! sample-rate scaling, host gains and current parameter values).
//!
//! **Per-mass rule** (SMC'19 paper): every moving mass must satisfy 4M > K_eq + 2·Z_eq, where
//! K_eq and Z_eq sum the stiffness and damping of everything attached to it:
//!
//! * linear links and contacts (counted as engaged) with their K and Z;
//! * `osc` elements and macro nodes with their own K and Z, or Z_o;
//! * bounded nonlinear links at their bounded tangent stiffness: k for the bounded branch, and
//!   3k − 2s, the peak of the cubic region just below the tipping point (derived, §2.5.3), when
//!   the cubic region exists; `nlSpringDamper` also counts its bounded-region damping Z + 0.3k;
//! * `nlSpring2`/`nlSpring3` at their linear K (their tangent stiffness is unbounded, which is
//!   reported as a warning when Q ≠ 0);
//! * `nlPluck` at 0.9·K, the steepest slope of its tent, and its Z;
//! * `nlBow` by its stick slope in Z_eq: 2/3·Z for the piecewise profile, 0.63·e^½·Z ≈ 1.04·Z
//!   for the smooth one (the slope of its law at Δv = 0).
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

use crate::engine::Engine;
use crate::info::PointKind;
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
    /// A nonlinear spring without a bound (`nlSpring2`/`nlSpring3` with Q ≠ 0).
    Unbounded {
        label: String,
        keyword: &'static str,
    },
    /// A negative cubic coefficient in a bounded law: the bounded branch applies everywhere.
    NegativeCubic {
        label: String,
        keyword: &'static str,
    },
    /// `nlSpringDamper` with k < s and c ≠ 0: bounded by the weaker k (compat).
    WeakBound { label: String },
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
            StabilityWarning::Unbounded { label, keyword } => write!(
                f,
                "@{label}: {keyword} has no stiffness bound and may become unstable for high \
                 elongation"
            ),
            StabilityWarning::NegativeCubic { label, keyword } => write!(
                f,
                "@{label}: negative cubic coefficient in {keyword}; the bounded branch applies"
            ),
            StabilityWarning::WeakBound { label } => write!(
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
        analyze(self)
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

fn analyze(e: &Engine) -> StabilityReport {
    let info = &e.info;
    let n = info.num_points;
    let args = &e.args;
    let mut k_eq = vec![0.0; n];
    let mut z_eq = vec![0.0; n];
    let mut k_cp = vec![0.0; n];
    let mut z_cp = vec![0.0; n];
    let mut warnings = Vec::new();

    let is_moving = |p: usize| -> bool {
        match info.points[p].kind {
            PointKind::Mass | PointKind::Osc | PointKind::MassG => true,
            PointKind::MacroNode { fixed } => !fixed,
            PointKind::Ground | PointKind::Avatar => false,
        }
    };
    // The share of an endpoint that moves: 1 or 0 for a point, the weights of its moving
    // nodes for a connection point.
    let moving_weight = |p: u32| -> f64 {
        let p = p as usize;
        if p < n {
            is_moving(p) as u32 as f64
        } else if let Some(i) = p
            .checked_sub(e.proxies.base)
            .filter(|&i| i < e.proxies.len())
        {
            e.proxies.nodes[i]
                .iter()
                .zip(e.proxies.weights[i])
                .filter(|(node, _)| is_moving(**node as usize))
                .map(|(_, w)| w)
                .sum()
        } else {
            0.0
        }
    };
    // Off-diagonal row sums of a link a–b on a's side: towards b, and, for a connection
    // point, among a's own nodes.
    let couple = |a: u32, b: u32, k: f64, z: f64, k_cp: &mut [f64], z_cp: &mut [f64]| {
        let other = moving_weight(b);
        let p = a as usize;
        if p < n {
            k_cp[p] += k * other;
            z_cp[p] += z * other;
        } else if let Some(i) = p
            .checked_sub(e.proxies.base)
            .filter(|&i| i < e.proxies.len())
        {
            let own = moving_weight(a);
            for (node, w) in e.proxies.nodes[i].iter().zip(e.proxies.weights[i]) {
                let f = w * (other + own - w).max(0.0);
                k_cp[*node as usize] += f * k;
                z_cp[*node as usize] += f * z;
            }
        }
    };

    // Adds (k, z) to a point, spreading over macro nodes for connection points.
    let add = |p: u32, k: f64, z: f64, k_eq: &mut [f64], z_eq: &mut [f64]| {
        let p = p as usize;
        if p < n {
            k_eq[p] += k;
            z_eq[p] += z;
        } else if let Some(i) = p.checked_sub(e.proxies.base) {
            if i < e.proxies.len() {
                for (node, w) in e.proxies.nodes[i].iter().zip(e.proxies.weights[i]) {
                    k_eq[*node as usize] += w * k;
                    z_eq[*node as usize] += w * z;
                }
            }
        }
    };

    // Interaction labels are not kept on the hot structures: warnings name the endpoints.
    let ix = &e.interactions;
    let endpoints = |g: &crate::engine::Group, i: usize| -> String {
        format!(
            "{}–{}",
            info.point_label(g.a[i] as usize),
            info.point_label(g.b[i] as usize)
        )
    };
    let col = |g: &crate::engine::Group, c: usize, i: usize| args[g.cols[c] + i];

    // Linear links, and contacts counted as engaged.
    for g in [&ix.linear, &ix.contact] {
        for i in 0..g.len() {
            let (k, z) = (col(g, 0, i), col(g, 1, i));
            add(g.a[i], k, z, &mut k_eq, &mut z_eq);
            add(g.b[i], k, z, &mut k_eq, &mut z_eq);
            couple(g.a[i], g.b[i], k, z, &mut k_cp, &mut z_cp);
            couple(g.b[i], g.a[i], k, z, &mut k_cp, &mut z_cp);
        }
    }
    let g = &ix.nl_contact;
    for i in 0..g.len() {
        let (s, c, k, z) = (col(g, 0, i), col(g, 1, i), col(g, 2, i), col(g, 3, i));
        if c < 0.0 {
            warnings.push(StabilityWarning::NegativeCubic {
                label: endpoints(g, i),
                keyword: "nlContact",
            });
        }
        let (k, c) = if k < s { (s, 0.0) } else { (k, c) };
        let kb = if c == 0.0 {
            s
        } else if s >= k || c < 0.0 {
            k
        } else {
            3.0 * k - 2.0 * s
        };
        add(g.a[i], kb, z, &mut k_eq, &mut z_eq);
        add(g.b[i], kb, z, &mut k_eq, &mut z_eq);
        couple(g.a[i], g.b[i], kb, z, &mut k_cp, &mut z_cp);
        couple(g.b[i], g.a[i], kb, z, &mut k_cp, &mut z_cp);
    }
    for (g, keyword) in [(&ix.nl_spring2, "nlSpring2"), (&ix.nl_spring3, "nlSpring3")] {
        for i in 0..g.len() {
            let (k, q, z) = (col(g, 0, i), col(g, 1, i), col(g, 2, i));
            if q != 0.0 {
                warnings.push(StabilityWarning::Unbounded {
                    label: endpoints(g, i),
                    keyword,
                });
            }
            add(g.a[i], k, z, &mut k_eq, &mut z_eq);
            add(g.b[i], k, z, &mut k_eq, &mut z_eq);
            couple(g.a[i], g.b[i], k, z, &mut k_cp, &mut z_cp);
            couple(g.b[i], g.a[i], k, z, &mut k_cp, &mut z_cp);
        }
    }
    let g = &ix.nl_spring_damper;
    for i in 0..g.len() {
        let (s, c, k, z) = (col(g, 0, i), col(g, 1, i), col(g, 2, i), col(g, 3, i));
        if c < 0.0 {
            warnings.push(StabilityWarning::NegativeCubic {
                label: endpoints(g, i),
                keyword: "nlSpringDamper",
            });
        } else if c != 0.0 && k < s {
            warnings.push(StabilityWarning::WeakBound {
                label: endpoints(g, i),
            });
        }
        let (kb, zb) = if c == 0.0 {
            (s, z)
        } else if s >= k || c < 0.0 {
            (k, z + 0.3 * k)
        } else {
            (3.0 * k - 2.0 * s, z + 0.3 * k)
        };
        add(g.a[i], kb, zb, &mut k_eq, &mut z_eq);
        add(g.b[i], kb, zb, &mut k_eq, &mut z_eq);
        couple(g.a[i], g.b[i], kb, zb, &mut k_cp, &mut z_cp);
        couple(g.b[i], g.a[i], kb, zb, &mut k_cp, &mut z_cp);
    }
    let g = &ix.pluck;
    for i in 0..g.len() {
        let (k, z) = (0.9 * col(g, 0, i).abs(), col(g, 2, i));
        add(g.a[i], k, z, &mut k_eq, &mut z_eq);
        add(g.b[i], k, z, &mut k_eq, &mut z_eq);
        couple(g.a[i], g.b[i], k, z, &mut k_cp, &mut z_cp);
        couple(g.b[i], g.a[i], k, z, &mut k_cp, &mut z_cp);
    }
    let g = &ix.bow;
    for i in 0..g.len() {
        let (z, smooth) = (col(g, 0, i), col(g, 2, i));
        let stick = if smooth >= 1.0 {
            0.63 * 0.5f64.exp() * z
        } else {
            2.0 / 3.0 * z
        };
        add(g.a[i], 0.0, stick, &mut k_eq, &mut z_eq);
        add(g.b[i], 0.0, stick, &mut k_eq, &mut z_eq);
        couple(g.a[i], g.b[i], 0.0, stick, &mut k_cp, &mut z_cp);
        couple(g.b[i], g.a[i], 0.0, stick, &mut k_cp, &mut z_cp);
    }

    // Single masses: osc terms.
    let s = &e.singles;
    let mut mass = vec![f64::INFINITY; n];
    for i in 0..s.len() {
        if s.fixed[i] {
            continue;
        }
        mass[i] = args[s.cols[0] + i];
        k_eq[i] += args[s.cols[1] + i];
        z_eq[i] += args[s.cols[2] + i];
    }

    // Macros: internal links, ground friction, structure limits.
    let m = &e.macros;
    for mac in m.lines.iter().chain(&m.stiff) {
        let (mm, k, k2, z, zo) = (
            args[mac.slots.m],
            args[mac.slots.k],
            args[mac.slots.k2],
            args[mac.slots.z],
            args[mac.slots.zo],
        );
        let stiff = m.stiff.iter().any(|s| s.base == mac.base);
        let nn = mac.len;
        for j in 0..nn {
            let p = mac.base + j;
            mass[p] = mm;
            let links = (j > 0) as u32 + (j + 1 < nn) as u32;
            k_eq[p] += links as f64 * k;
            z_eq[p] += links as f64 * z + zo;
            let moving = (j > 0 && is_moving(p - 1)) as u32 as f64
                + (j + 1 < nn && is_moving(p + 1)) as u32 as f64;
            k_cp[p] += moving * k;
            z_cp[p] += moving * z;
        }
        if stiff {
            let last = nn as isize - 1;
            for i in -1..=last {
                let (a, b) = (i.clamp(0, last) as usize, (i + 2).clamp(0, last) as usize);
                if a != b {
                    let (pa, pb) = (mac.base + a, mac.base + b);
                    k_eq[pa] += k2;
                    k_eq[pb] += k2;
                    k_cp[pa] += k2 * is_moving(pb) as u32 as f64;
                    k_cp[pb] += k2 * is_moving(pa) as u32 as f64;
                }
            }
        }
        let lambda_k = if stiff {
            stiff_string_lambda(k, k2)
        } else {
            4.0 * k
        };
        let load = (lambda_k + 2.0 * (4.0 * z + zo)) / (4.0 * mm);
        if !(load < 1.0) {
            let owner = &info.owners[info.points[mac.base].owner as usize];
            warnings.push(StabilityWarning::StructureLimit {
                label: owner.label.clone(),
                keyword: owner.keyword,
                load,
            });
        }
    }
    for mac in &m.meshes {
        let (mm, k, z, zo) = (
            args[mac.slots.m],
            args[mac.slots.k],
            args[mac.slots.z],
            args[mac.slots.zo],
        );
        let (l, w) = (mac.length, mac.width);
        for i in 0..l {
            for j in 0..w {
                let p = mac.base + i * w + j;
                mass[p] = mm;
                let links =
                    (i > 0) as u32 + (i + 1 < l) as u32 + (j > 0) as u32 + (j + 1 < w) as u32;
                k_eq[p] += links as f64 * k;
                z_eq[p] += links as f64 * z + zo;
                let moving = [
                    (i > 0).then(|| p - w),
                    (i + 1 < l).then(|| p + w),
                    (j > 0).then(|| p - 1),
                    (j + 1 < w).then(|| p + 1),
                ]
                .into_iter()
                .flatten()
                .filter(|&q| is_moving(q))
                .count() as f64;
                k_cp[p] += moving * k;
                z_cp[p] += moving * z;
            }
        }
        let load = (8.0 * k + 2.0 * (8.0 * z + zo)) / (4.0 * mm);
        if !(load < 1.0) {
            let owner = &info.owners[info.points[mac.base].owner as usize];
            warnings.push(StabilityWarning::StructureLimit {
                label: owner.label.clone(),
                keyword: owner.keyword,
                load,
            });
        }
    }

    let mut masses = Vec::new();
    for p in 0..info.points.len() {
        if !is_moving(p) {
            continue;
        }
        let entry = MassStability {
            point: p as u32,
            label: info.point_label(p),
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
