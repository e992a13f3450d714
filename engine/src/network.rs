//! The linear network of a compiled model: every moving mass and every link, with effective
//! per-step values (after the sample-rate scaling of spec §1.7, the host's class gains and the
//! current parameter values). One walk serves two readers:
//!
//! * the stability analysis (spec §5.2, [`crate::stability`]) sums it per mass, with every
//!   nonlinear law at its **bounded** tangent ([`Valuation::Bound`]);
//! * the modal analysis (spec §5.5, [`crate::modes`]) and the exact stability limit assemble its
//!   matrices K and Z.
//!
//! A link joins two endpoints, each a point or a connection point (spec §2.8); its force is
//! f = k·Δx + z·Δv with F_a −= f, F_b += f (spec §1.3). Each moving point can also carry its
//! own ground terms: the `osc` K and Z (spec §2.1.2) and the macro ground friction Z_o (spec
//! §2.7), which enter the update law X[n+1] = (2 − (K+Z)/M)·X[n] + (Z/M − 1)·X[n−1] + F/M
//! exactly as a spring-damper to a fixed point.
//!
//! **How each nonlinear law enters** (Δx and Δv of spec §1.3):
//!
//! | law | [`Valuation::Bound`] (stability, §5.2) | [`Valuation::Rest`] (modes, at rest, Δv = 0) |
//! |---|---|---|
//! | `contact` | engaged: (K, Z) | (K, Z) if Δx > −θ (closed at rest), else open: nothing |
//! | `nlContact` | bounded tangent k, or 3k − 2s below the tipping point | if d = Δx + θ > 0, the slope of the bounded cubic at d, else nothing |
//! | `nlSpring2`/`nlSpring3` | linear K | tangent K + 2Q·\|Δx\| / K + 3Q·Δx² (K at Δx = 0) |
//! | `nlSpringDamper` | bounded tangent, damping Z + 0.3k | the slope at Δx, damping Z (Z + 0.3k in the bounded region) |
//! | `nlPluck` | 0.9·\|K\|, Z | small-displacement slope −0.9K (no damping) for \|Δx\| < scale/10, K/10 with Z in the outer band, nothing beyond `scale` |
//! | `nlBow` | stick slope in Z: ⅔·Z, or 0.63·e^½·Z (smooth) | the same stick slope (the bow rests on the string: Δv = 0) |

use crate::engine::{Engine, Group};
use crate::info::PointKind;
use crate::laws::PLUCK_SHARPNESS;
use crate::stability::StabilityWarning;

/// How nonlinear laws are linearised.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Valuation<'a> {
    /// At their bounded tangent, contacts engaged: the conservative linear network of the
    /// stability rule (spec §5.2).
    Bound,
    /// At the rest state: these positions (every point and connection point), zero velocity.
    Rest(&'a [f64]),
}

/// One link of the network: f = k·Δx + z·Δv between endpoints `a` and `b` (point indices,
/// connection points beyond the material points).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Link {
    pub a: u32,
    pub b: u32,
    pub k: f64,
    pub z: f64,
}

/// The linear network of a compiled model.
#[derive(Clone, Debug, Default)]
pub(crate) struct Network {
    /// Per material point: its per-step mass M, infinite for points that do not move
    /// (grounds, fixed macro nodes, avatars).
    pub mass: Vec<f64>,
    /// Per material point: the stiffness and damping towards a fixed reference that its own
    /// update law carries (`osc` K and Z; macro Z_o).
    pub k_ground: Vec<f64>,
    pub z_ground: Vec<f64>,
    /// Every link, explicit interactions first (in law order), then macro-internal links.
    pub links: Vec<Link>,
    /// What the bounded valuation wants the user to know (empty for [`Valuation::Rest`]).
    pub warnings: Vec<StabilityWarning>,
    /// The endpoints of the contacts open at rest ([`Valuation::Rest`] only): the paths a
    /// strike takes.
    pub open_contacts: Vec<(u32, u32)>,
}

impl Network {
    /// True when material point `p` moves by its own update law.
    pub fn is_moving(&self, p: usize) -> bool {
        self.mass.get(p).is_some_and(|m| m.is_finite())
    }
}

/// Whether a point moves by its own update law.
pub(crate) fn kind_moves(kind: PointKind) -> bool {
    match kind {
        PointKind::Mass | PointKind::Osc | PointKind::MassG => true,
        PointKind::MacroNode { fixed } => !fixed,
        PointKind::Ground | PointKind::Avatar => false,
    }
}

/// The material points an endpoint stands for, with weights: the point itself with weight 1,
/// or the macro nodes of a connection point with their interpolation weights (spec §2.8).
pub(crate) fn endpoint_nodes(e: &Engine, p: u32) -> impl Iterator<Item = (usize, f64)> + '_ {
    let p = p as usize;
    let n = e.info.num_points;
    let proxy = p
        .checked_sub(e.proxies.base)
        .filter(|&i| p >= n && i < e.proxies.len());
    let (nodes, weights): ([u32; 4], [f64; 4]) = match proxy {
        Some(i) => (e.proxies.nodes[i], e.proxies.weights[i]),
        None if p < n => ([p as u32, 0, 0, 0], [1.0, 0.0, 0.0, 0.0]),
        None => ([0; 4], [0.0; 4]),
    };
    nodes
        .into_iter()
        .zip(weights)
        .filter(|(_, w)| *w != 0.0)
        .map(|(node, w)| (node as usize, w))
}

/// The tangent of the bounded cubic of `nlContact`/`nlSpringDamper` at d (spec §2.4.2,
/// §2.5.3): s for c = 0, k on the bounded branch, s + 3c·d² in the cubic region. Returns the
/// slope and whether d is in the bounded region.
fn bounded_cubic_slope(d: f64, s: f64, c: f64, k: f64) -> (f64, bool) {
    if c == 0.0 {
        (s, false)
    } else if s >= k || c < 0.0 {
        (k, true)
    } else if c * d * d <= k - s {
        (s + 3.0 * c * d * d, false)
    } else {
        (k, true)
    }
}

impl Network {
    /// Walks the compiled model once (spec §5.2 and §5.5).
    pub(crate) fn walk(e: &Engine, valuation: Valuation<'_>) -> Network {
        let info = &e.info;
        let n = info.num_points;
        let args = &e.args;
        let mut net = Network {
            mass: vec![f64::INFINITY; n],
            k_ground: vec![0.0; n],
            z_ground: vec![0.0; n],
            links: Vec::new(),
            warnings: Vec::new(),
            open_contacts: Vec::new(),
        };
        let ix = &e.interactions;
        let endpoints = |g: &Group, i: usize| -> String {
            format!(
                "{}–{}",
                info.point_label(g.a[i] as usize),
                info.point_label(g.b[i] as usize)
            )
        };
        let col = |g: &Group, c: usize, i: usize| args[g.cols[c] + i];
        // The rest elongation Δx = x_a − x_b of link i, or None for the bounded valuation.
        let rest_dx = |g: &Group, i: usize| -> Option<f64> {
            match valuation {
                Valuation::Bound => None,
                Valuation::Rest(x) => Some(x[g.a[i] as usize] - x[g.b[i] as usize]),
            }
        };
        let push = |g: &Group, i: usize, k: f64, z: f64, links: &mut Vec<Link>| {
            if k != 0.0 || z != 0.0 {
                links.push(Link {
                    a: g.a[i],
                    b: g.b[i],
                    k,
                    z,
                });
            }
        };

        let g = &ix.linear;
        for i in 0..g.len() {
            push(g, i, col(g, 0, i), col(g, 1, i), &mut net.links);
        }
        let g = &ix.contact;
        for i in 0..g.len() {
            let (k, z, t) = (col(g, 0, i), col(g, 1, i), col(g, 2, i));
            // Engaged iff Δx > −θ (spec §2.4.1); counted engaged by the bound.
            if rest_dx(g, i).is_none_or(|dx| dx > -t) {
                push(g, i, k, z, &mut net.links);
            } else {
                net.open_contacts.push((g.a[i], g.b[i]));
            }
        }
        let g = &ix.nl_contact;
        for i in 0..g.len() {
            let (s, c, k, z, t) = (
                col(g, 0, i),
                col(g, 1, i),
                col(g, 2, i),
                col(g, 3, i),
                col(g, 4, i),
            );
            let (k, c) = if k < s { (s, 0.0) } else { (k, c) };
            match rest_dx(g, i) {
                None => {
                    if c < 0.0 {
                        net.warnings.push(StabilityWarning::NegativeCubic {
                            label: endpoints(g, i),
                            keyword: "nlContact",
                            element: g.elements[i],
                        });
                    }
                    let kb = if c == 0.0 {
                        s
                    } else if s >= k || c < 0.0 {
                        k
                    } else {
                        3.0 * k - 2.0 * s
                    };
                    push(g, i, kb, z, &mut net.links);
                }
                Some(dx) => {
                    let d = dx + t;
                    if d > 0.0 {
                        push(g, i, bounded_cubic_slope(d, s, c, k).0, z, &mut net.links);
                    } else {
                        net.open_contacts.push((g.a[i], g.b[i]));
                    }
                }
            }
        }
        for (g, keyword, power) in [
            (&ix.nl_spring2, "nlSpring2", 2),
            (&ix.nl_spring3, "nlSpring3", 3),
        ] {
            for i in 0..g.len() {
                let (k, q, z) = (col(g, 0, i), col(g, 1, i), col(g, 2, i));
                match rest_dx(g, i) {
                    None => {
                        if q != 0.0 {
                            net.warnings.push(StabilityWarning::Unbounded {
                                label: endpoints(g, i),
                                keyword,
                                element: g.elements[i],
                            });
                        }
                        push(g, i, k, z, &mut net.links);
                    }
                    // d/dΔx of K·Δx + Q·sgn(Δx)·Δx² or K·Δx + Q·Δx³ (spec §2.5.1–2).
                    Some(dx) => {
                        let slope = if power == 2 {
                            k + 2.0 * q * dx.abs()
                        } else {
                            k + 3.0 * q * dx * dx
                        };
                        push(g, i, slope, z, &mut net.links);
                    }
                }
            }
        }
        let g = &ix.nl_spring_damper;
        for i in 0..g.len() {
            let (s, c, k, z) = (col(g, 0, i), col(g, 1, i), col(g, 2, i), col(g, 3, i));
            let (kb, zb) = match rest_dx(g, i) {
                None => {
                    if c < 0.0 {
                        net.warnings.push(StabilityWarning::NegativeCubic {
                            label: endpoints(g, i),
                            keyword: "nlSpringDamper",
                            element: g.elements[i],
                        });
                    } else if c != 0.0 && k < s {
                        net.warnings.push(StabilityWarning::WeakBound {
                            label: endpoints(g, i),
                            element: g.elements[i],
                        });
                    }
                    if c == 0.0 {
                        (s, z)
                    } else if s >= k || c < 0.0 {
                        (k, z + 0.3 * k)
                    } else {
                        (3.0 * k - 2.0 * s, z + 0.3 * k)
                    }
                }
                Some(dx) => match bounded_cubic_slope(dx, s, c, k) {
                    (slope, true) => (slope, z + 0.3 * k),
                    (slope, false) => (slope, z),
                },
            };
            push(g, i, kb, zb, &mut net.links);
        }
        let g = &ix.pluck;
        for i in 0..g.len() {
            let (k, scale, z) = (col(g, 0, i), col(g, 1, i), col(g, 2, i));
            match rest_dx(g, i) {
                None => push(g, i, 0.9 * k.abs(), z, &mut net.links),
                // The tent of spec §2.6.1: slope −(K − K/σ) inside d_t, K/σ with Z outside.
                Some(dx) => {
                    let d_t = scale / PLUCK_SHARPNESS;
                    if dx.abs() < d_t {
                        push(g, i, -(k - k / PLUCK_SHARPNESS), 0.0, &mut net.links);
                    } else if dx.abs() < scale {
                        push(g, i, k / PLUCK_SHARPNESS, z, &mut net.links);
                    }
                }
            }
        }
        let g = &ix.bow;
        for i in 0..g.len() {
            let (z, scale, smooth) = (col(g, 0, i), col(g, 1, i), col(g, 2, i));
            // The slope of the friction law at Δv = 0 (spec §2.6.2); no force for scale ≤ 0.
            let stick = if !(scale > 0.0) {
                0.0
            } else if smooth >= 1.0 {
                0.63 * 0.5f64.exp() * z
            } else {
                2.0 / 3.0 * z
            };
            push(g, i, 0.0, stick, &mut net.links);
        }

        // Single masses: M and the osc terms (spec §2.1).
        let s = &e.singles;
        for i in 0..s.len() {
            if s.fixed[i] {
                continue;
            }
            net.mass[i] = args[s.cols[0] + i];
            net.k_ground[i] = args[s.cols[1] + i];
            net.z_ground[i] = args[s.cols[2] + i];
        }

        // Macros (spec §2.7): node masses, Z_o, internal links.
        let m = &e.macros;
        let mut internal = |a: usize, b: usize, k: f64, z: f64| {
            if k != 0.0 || z != 0.0 {
                net.links.push(Link {
                    a: a as u32,
                    b: b as u32,
                    k,
                    z,
                });
            }
        };
        let mut node_terms = Vec::new();
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
            for j in 0..mac.len {
                node_terms.push((mac.base + j, mm, zo));
            }
            for j in 0..mac.len.saturating_sub(1) {
                internal(mac.base + j, mac.base + j + 1, k, z);
            }
            if stiff {
                // f = K₂(x_a − x_b), a = clip(i, 0, N−1), b = clip(i+2, 0, N−1) (§2.7.3).
                let last = mac.len as isize - 1;
                for i in -1..=last {
                    let (a, b) = (i.clamp(0, last) as usize, (i + 2).clamp(0, last) as usize);
                    if a != b {
                        internal(mac.base + a, mac.base + b, k2, 0.0);
                    }
                }
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
            for p in 0..l * w {
                node_terms.push((mac.base + p, mm, zo));
            }
            // (i,j)–(i,j+1), then (i,j)–(i+1,j) (spec §2.7.4).
            for i in 0..l {
                for j in 0..w.saturating_sub(1) {
                    let p = mac.base + i * w + j;
                    internal(p, p + 1, k, z);
                }
            }
            for p in 0..(l.saturating_sub(1)) * w {
                internal(mac.base + p, mac.base + p + w, k, z);
            }
        }
        for (p, mm, zo) in node_terms {
            if kind_moves(info.points[p].kind) {
                net.mass[p] = mm;
                net.z_ground[p] = zo;
            }
        }
        net
    }
}
