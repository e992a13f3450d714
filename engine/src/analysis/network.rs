//! The linear network of a compiled model: every moving mass and every link, with effective
//! per-step values (after the sample-rate scaling of spec §1.7, the host's class gains and the
//! current parameter values). One walk serves two readers:
//!
//! * the stability analysis (spec §5.2, [`crate::analysis::stability`]) sums it per mass, with
//!   every nonlinear law at its **bounded** tangent ([`Valuation::Bound`]);
//! * the modal analysis (spec §5.5, [`crate::analysis::modes`]) and the exact stability limit
//!   assemble its matrices K and Z.
//!
//! A link joins two endpoints, each a point or a connection point (spec §2.8); its force is
//! f = k·Δx + z·Δv with F_a −= f, F_b += f (spec §1.3). Each moving point can also carry its
//! own ground terms: the `osc` K and Z (spec §2.1.2) and the macro ground friction Z_o (spec
//! §2.7), which enter the update law X[n+1] = (2 − (K+Z)/M)·X[n] + (Z/M − 1)·X[n−1] + F/M
//! exactly as a spring-damper to a fixed point.
//!
//! Each law enters by its linear stand-in, [`LawKind::linearise`] (the table is in
//! [`crate::laws::linear`]).

use crate::laws::linear::{BoundNote, Linear};
use crate::laws::LawKind;
use crate::sim::engine::{Engine, Group};
use crate::sim::info::PointKind;

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

/// A law's note on one link ([`LawKind::bound_note`]).
#[derive(Clone, Debug)]
pub(crate) struct LinkNote {
    pub note: BoundNote,
    /// The link's endpoints, `g–m`.
    pub label: String,
    pub keyword: &'static str,
    /// The interaction's index in the spec's elements.
    pub element: u32,
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
    /// What the bounded valuation notes of the laws' arguments (empty for
    /// [`Valuation::Rest`]); the stability report words them.
    pub notes: Vec<LinkNote>,
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
/// or the nodes of a connection point with their interpolation weights (spec §2.8; a 3-D
/// model's, 3-D spec §2.6).
pub(crate) fn endpoint_nodes(e: &Engine, p: u32) -> impl Iterator<Item = (usize, f64)> + '_ {
    let p = p as usize;
    let n = e.model.info.num_points;
    let mut nodes = [0u32; 8];
    let mut weights = [0.0; 8];
    match &e.space {
        Some(space) => {
            for (k, (node, w)) in crate::analysis::space::endpoint_nodes(space, n, p as u32)
                .into_iter()
                .enumerate()
            {
                nodes[k] = node as u32;
                weights[k] = w;
            }
        }
        None => {
            let proxy = p
                .checked_sub(e.proxies.base)
                .filter(|&i| p >= n && i < e.proxies.len());
            match proxy {
                Some(i) => {
                    nodes[..4].copy_from_slice(&e.proxies.nodes[i]);
                    weights[..4].copy_from_slice(&e.proxies.weights[i]);
                }
                None if p < n => {
                    nodes[0] = p as u32;
                    weights[0] = 1.0;
                }
                None => {}
            }
        }
    }
    nodes
        .into_iter()
        .zip(weights)
        .filter(|(_, w)| *w != 0.0)
        .map(|(node, w)| (node as usize, w))
}

impl Network {
    /// Walks the compiled model once (spec §5.2 and §5.5).
    pub(crate) fn walk(e: &Engine, valuation: Valuation<'_>) -> Network {
        if e.space.is_some() {
            // A 3-D model's stability network (its modes come from its own system).
            return crate::analysis::space::bound_network(e);
        }
        let info = &e.model.info;
        let n = info.num_points;
        let args = &e.args;
        let mut net = Network {
            mass: vec![f64::INFINITY; n],
            k_ground: vec![0.0; n],
            z_ground: vec![0.0; n],
            links: Vec::new(),
            notes: Vec::new(),
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

        // Every law by its linear stand-in (`LawKind::linearise`).
        let mut a = [0.0; LawKind::MAX_ARITY];
        for kind in LawKind::ALL {
            let g = ix.group(kind);
            let a = &mut a[..kind.arity()];
            for i in 0..g.len() {
                for (c, v) in a.iter_mut().enumerate() {
                    *v = col(g, c, i);
                }
                let note = match valuation {
                    Valuation::Bound => kind.bound_note(a),
                    Valuation::Rest(_) => None,
                };
                if let Some(note) = note {
                    net.notes.push(LinkNote {
                        note,
                        label: endpoints(g, i),
                        keyword: kind.row().keyword,
                        element: g.elements[i],
                    });
                }
                match kind.linearise(a, rest_dx(g, i)) {
                    Linear::Link { k, z } => push(g, i, k, z, &mut net.links),
                    Linear::Open => net.open_contacts.push((g.a[i], g.b[i])),
                    Linear::Free => {}
                }
            }
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
