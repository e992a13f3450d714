//! The analyses of a 3-D model (3-D spec §5, §6).
//!
//! * **Stability** (§5.4, §5.5): each link counted by its law's bounds k̂ and ẑ, the largest
//!   eigenvalues of its stiffness and damping blocks over every configuration it can be in
//!   ([`crate::laws::space::SpaceLawKind::bound`]). Bounding every block by k̂·I and ẑ·I makes
//!   the 3-D network three copies, one per axis, of a scalar network with links (k̂, ẑ): its
//!   per-point rule is §5.4's rule (b), and its matrices are ⪰ the true ones, so the energy
//!   criterion 4M − K − 2Z ≻ 0 on it (`modes::limit`) is a sufficient, amplitude-independent
//!   test (§5.3, §5.5). [`bound_network`] builds that scalar network, which the 1-D rule, the
//!   Gershgorin envelope and the exact limit then read as they read a 1-D model's.
//! * **Modes** (§6): the static equilibrium under gravity and pre-tension (`equilibrium`),
//!   then the linearised 3N-degree-of-freedom system there, with each law's 3 × 3 blocks
//!   (`system`), which the 1-D solvers take as they take a 1-D system.

use crate::analysis::network::{Link, LinkNote, Network};
use crate::laws::linear::BoundNote;
use crate::laws::space::SpaceLawKind;
use crate::sim::space::links::MAX_SLOTS;
use crate::sim::space::Space;
use crate::Engine;

pub mod equilibrium;
pub(crate) mod system;

/// One link of a 3-D model: its law, endpoints, element and argument values.
pub(crate) struct LinkValues {
    pub kind: SpaceLawKind,
    pub a: u32,
    pub b: u32,
    pub element: u32,
    pub p: [f64; MAX_SLOTS],
}

/// Every link of a 3-D model with its current argument values, group by group.
pub(crate) fn links<'a>(
    space: &'a Space,
    args: &'a [f64],
) -> impl Iterator<Item = LinkValues> + 'a {
    SpaceLawKind::ALL.into_iter().flat_map(move |kind| {
        let g = &space.model.groups[kind.index()];
        g.segments.iter().flat_map(move |seg| {
            (0..seg.len).map(move |i| {
                let l = (seg.start + i) as usize;
                let mut p = [0.0; MAX_SLOTS];
                for (c, v) in p.iter_mut().enumerate().take(kind.row().slots()) {
                    *v = args[(seg.base[c] + seg.step[c] * i) as usize];
                }
                LinkValues {
                    kind,
                    a: g.a[l],
                    b: g.b[l],
                    element: g.elements[l],
                    p,
                }
            })
        })
    })
}

/// The material points an endpoint of a 3-D model stands for, with weights (a connection
/// point's nodes, §2.6).
pub(crate) fn endpoint_nodes(space: &Space, num_points: usize, p: u32) -> Vec<(usize, f64)> {
    let p = p as usize;
    if p < num_points {
        return vec![(p, 1.0)];
    }
    let i = p - num_points;
    let Some(def) = space.model.proxies.get(i) else {
        return Vec::new();
    };
    (0..def.width())
        .map(|k| (space.proxy_nodes[i][k] as usize, space.proxy_weights[i][k]))
        .filter(|(_, w)| *w != 0.0)
        .collect()
}

/// Each moving point's mass, the stiffness and damping its own law carries towards a fixed
/// reference (an `osc`'s K and Z, a node's Zo, the medium's Za), and its free axes.
pub(crate) struct PointTerms {
    pub mass: Vec<f64>,
    pub k_ground: Vec<f64>,
    pub z_ground: Vec<f64>,
    pub axes: Vec<[bool; 3]>,
}

pub(crate) fn point_terms(e: &Engine) -> PointTerms {
    let n = e.model.info.num_points;
    let mut t = PointTerms {
        mass: vec![f64::INFINITY; n],
        k_ground: vec![0.0; n],
        z_ground: vec![0.0; n],
        axes: vec![[false; 3]; n],
    };
    let Some(space) = &e.space else {
        return t;
    };
    let args = &e.args;
    for run in &space.model.runs {
        let m = args[run.m as usize];
        let k = run.k.map_or(0.0, |s| args[s as usize]);
        let z = run.z.map_or(0.0, |s| args[s as usize]) + space.za;
        for p in run.first..run.first + run.count {
            let p = p as usize;
            t.mass[p] = m;
            t.k_ground[p] = k;
            t.z_ground[p] = z;
            t.axes[p] = run.axes;
        }
    }
    t
}

/// The scalar network of the stability rule for a 3-D model (see the module's doc): every
/// link at its bounds (k̂, ẑ), a one-endpoint law (`planeContact`) as a spring to a fixed
/// reference on its point.
pub(crate) fn bound_network(e: &Engine) -> Network {
    let info = &e.model.info;
    let t = point_terms(e);
    let mut net = Network {
        mass: t.mass,
        k_ground: t.k_ground,
        z_ground: t.z_ground,
        links: Vec::new(),
        notes: Vec::new(),
        open_contacts: Vec::new(),
    };
    let Some(space) = &e.space else {
        return net;
    };
    let n = info.num_points;
    for l in links(space, &e.args) {
        let (k, z, exact) = l.kind.bound(&l.p);
        let row = l.kind.row();
        if !exact {
            net.notes.push(LinkNote {
                note: BoundNote::Unbounded,
                label: format!(
                    "{}–{}",
                    info.point_label(l.a as usize),
                    info.point_label(l.b as usize)
                ),
                keyword: row.keyword,
                element: l.element,
            });
        }
        if k == 0.0 && z == 0.0 {
            continue;
        }
        if row.endpoints == 1 {
            for (node, w) in endpoint_nodes(space, n, l.a) {
                net.k_ground[node] += w * k;
                net.z_ground[node] += w * z;
            }
            continue;
        }
        net.links.push(Link {
            a: l.a,
            b: l.b,
            k,
            z,
        });
    }
    net
}
