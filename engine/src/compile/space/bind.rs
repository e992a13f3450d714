//! Pass 2 of a 3-D model: every element's arguments bound to slots, in script order (3-D spec
//! §1.5): the mass phase's runs, each law's links, the connection points, the inputs and
//! outputs, the medium.
//!
//! `auto` (§1.7) is each link's distance at stage 0: an `auto` argument is bound link by link
//! with it substituted (a constant folded), so a structure whose rest length is `[0.9*auto]`
//! has one slot per link, and one whose rest length reads no `auto` shares one.

use super::endpoints::ProxyList;
use super::{axes_of, vector_exprs, Numbering};
use crate::compile::context::Cx;
use crate::compile::Rate;
use crate::laws::space::{ColShape, SpaceLawKind};
use crate::laws::ArgClass;
use crate::sim::info::{InputUse, OutputUse};
use crate::sim::space::links::{Segment, MAX_SLOTS};
use crate::sim::space::{
    Avatar, DirectionSources, ForceInput, Group3, Init, Mic, Output3, Probe3, Run,
};
use crate::spec::expr::{BinOp, Expr};
use crate::spec::space::{Body, Lock, Probe, SpaceKind, SpaceSpec};
use crate::spec::{SampleRateMode, Vector};
use std::collections::HashMap;
use std::sync::Arc;

/// What binding produced.
#[derive(Default)]
pub(super) struct Bound {
    pub runs: Vec<Run>,
    pub still: Vec<u32>,
    pub inits: Vec<Init>,
    pub osc_points: Vec<u32>,
    pub groups: Vec<Group3>,
    pub proxies: ProxyList,
    pub avatars: Vec<Avatar>,
    pub force_inputs: Vec<ForceInput>,
    pub outputs: Vec<Output3>,
    pub mics: Vec<Mic>,
    pub directions: DirectionSources,
    pub gravity: Option<[u32; 3]>,
    pub friction: Option<u32>,
    pub audio_runs: Vec<u32>,
    pub audio_directions: bool,
    pub inputs: Vec<Vec<InputUse>>,
    pub output_uses: Vec<OutputUse>,
}

/// A link waiting for its slots: an explicit line's (its arguments, with `auto` bound), laid
/// out with the other explicit lines next to it in its group.
struct Explicit {
    a: u32,
    b: u32,
    element: usize,
    args: Vec<(Expr, ArgClass)>,
}

/// A group's links in script order: runs of explicit lines, and segments already laid out.
enum Pending {
    Explicit(Explicit),
    Laid {
        links: Vec<(u32, u32)>,
        seg: Segment,
        element: usize,
    },
}

/// `e` with `auto` replaced by `length`, folded when it is then a constant.
fn with_auto(e: &Expr, length: f64) -> Expr {
    fn sub(e: &Expr, v: f64) -> Expr {
        match e {
            Expr::Name(n) if &**n == "auto" => Expr::Num(v),
            Expr::Num(_) | Expr::Name(_) => e.clone(),
            Expr::Neg(a) => Expr::Neg(Box::new(sub(a, v))),
            Expr::Binary(op, a, b) => Expr::Binary(*op, Box::new(sub(a, v)), Box::new(sub(b, v))),
            Expr::Call(f, args) => Expr::Call(*f, args.iter().map(|a| sub(a, v)).collect()),
        }
    }
    let out = sub(e, length);
    if out.is_constant() {
        Expr::Num(out.eval(&|_| None))
    } else {
        out
    }
}

/// Whether `e` reads `auto`.
fn reads_auto(e: &Expr) -> bool {
    let mut found = false;
    e.for_each_name(&mut |n| found |= n == "auto");
    found
}

fn distance(p: [f64; 3], q: [f64; 3]) -> f64 {
    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
}

impl<'a> Cx<'a> {
    /// Binds every element of `space`.
    pub(super) fn bind_space(
        &mut self,
        space: &'a SpaceSpec,
        n: &Numbering,
        names: &HashMap<&str, f64>,
        rate: Rate,
    ) -> Bound {
        let mut b = Bound::default();
        let mut pending: Vec<Vec<Pending>> = (0..SpaceLawKind::COUNT).map(|_| Vec::new()).collect();
        self.bind_medium(space, rate, &mut b);
        let zero = Expr::Num(0.0);
        for (i, e) in space.elements.iter().enumerate() {
            match &e.kind {
                SpaceKind::Mass {
                    body,
                    m,
                    gravity,
                    pos,
                    vel,
                } => self.bind_point(
                    i,
                    n,
                    *body,
                    [m, &zero, &zero],
                    Some(gravity),
                    pos,
                    Some(vel),
                    rate,
                    false,
                    &mut b,
                ),
                SpaceKind::Osc {
                    m,
                    k,
                    z,
                    gravity,
                    pos,
                    vel,
                } => self.bind_point(
                    i,
                    n,
                    Body::Free,
                    [m, k, z],
                    Some(gravity),
                    pos,
                    Some(vel),
                    rate,
                    true,
                    &mut b,
                ),
                SpaceKind::Ground { pos } => {
                    let Some(p) = n.element_point[i] else {
                        continue;
                    };
                    b.still.push(p);
                    let x0 = self.vector3(pos, i);
                    let v = self.vector3(&Vector::Scalar(Expr::Num(0.0)), i);
                    b.inits.push(Init::Point {
                        point: p,
                        x0,
                        v,
                        factor: 0.0,
                        fixed: [true; 3],
                    });
                }
                SpaceKind::Structure(s) => {
                    self.bind_structure(i, e.label.as_str(), s, n, &mut b, &mut pending)
                }
                SpaceKind::Interaction {
                    law,
                    args,
                    a,
                    b: end2,
                } => {
                    let ea = self.endpoint3(a, i, n, &mut b.proxies, names);
                    let eb = match end2 {
                        Some(ep) => self.endpoint3(ep, i, n, &mut b.proxies, names),
                        None => ea,
                    };
                    let (Some((pa, xa)), Some((pb, xb))) = (ea, eb) else {
                        continue;
                    };
                    let l0 = distance(xa, xb);
                    let row = law.row();
                    let mut slots = Vec::with_capacity(row.slots());
                    let classes: Vec<ArgClass> = row.slot_classes().collect();
                    let mut c = 0;
                    for col in row.columns {
                        for _ in 0..col.slots() {
                            let e = args.get(c).unwrap_or(&zero);
                            let e = if col.shape == ColShape::Length {
                                with_auto(e, l0)
                            } else {
                                e.clone()
                            };
                            slots.push((e, classes[c]));
                            c += 1;
                        }
                    }
                    pending[law.index()].push(Pending::Explicit(Explicit {
                        a: pa,
                        b: pb,
                        element: i,
                        args: slots,
                    }));
                }
                SpaceKind::ContactSet { a, set, args } => {
                    let Some((pa, xa)) = self.endpoint3(a, i, n, &mut b.proxies, names) else {
                        continue;
                    };
                    let Some(placed) = n.structures.get(set.as_str()) else {
                        continue;
                    };
                    let row = SpaceLawKind::Contact.row();
                    let d_slot = row.slot_of("D").unwrap_or(2);
                    let mut base = [0u32; MAX_SLOTS];
                    let mut step = [0u32; MAX_SLOTS];
                    let classes: Vec<ArgClass> = row.slot_classes().collect();
                    for (c, cls) in classes.iter().enumerate() {
                        if c != d_slot {
                            base[c] = self.slot(args.get(c).unwrap_or(&zero), *cls, i).0 as u32;
                        }
                    }
                    let nodes = placed.geometry.nodes.len() as u32;
                    let d = args.get(d_slot).unwrap_or(&zero);
                    if reads_auto(d) {
                        base[d_slot] = self.args.len() as u32;
                        step[d_slot] = 1;
                        self.args.resize(self.args.len() + nodes as usize, 0.0);
                        for k in 0..nodes {
                            let pb = placed.first + k;
                            let e = with_auto(d, distance(xa, n.x0[pb as usize]));
                            self.bind(&e, ArgClass::None, (base[d_slot] + k) as usize, i);
                        }
                    } else {
                        base[d_slot] = self.slot(d, ArgClass::None, i).0 as u32;
                    }
                    let links = (0..nodes).map(|k| (pa, placed.first + k)).collect();
                    pending[SpaceLawKind::Contact.index()].push(Pending::Laid {
                        element: i,
                        links,
                        seg: Segment {
                            start: 0,
                            len: nodes,
                            base,
                            step,
                        },
                    });
                }
                SpaceKind::Vdampers { set, z } => {
                    let Some(placed) = n.structures.get(set.as_str()) else {
                        continue;
                    };
                    let mut base = [0u32; MAX_SLOTS];
                    base[0] = self.slot(z, ArgClass::Damping, i).0 as u32;
                    let links: Vec<(u32, u32)> = placed
                        .geometry
                        .links
                        .iter()
                        .map(|&(a, bb, _)| (placed.first + a, placed.first + bb))
                        .collect();
                    let len = links.len() as u32;
                    pending[SpaceLawKind::Vdamper.index()].push(Pending::Laid {
                        element: i,
                        links,
                        seg: Segment {
                            start: 0,
                            len,
                            base,
                            step: [0; MAX_SLOTS],
                        },
                    });
                }
                SpaceKind::PosInput { channel, pos, dir } => {
                    let Some(p) = n.element_point[i] else {
                        continue;
                    };
                    let d = self.direction(dir.as_ref(), i, &mut b);
                    let at = self.vector_slots(pos, i, &mut b);
                    let perp = b.directions.perp.len() as u32;
                    b.directions.perp.push((at, d));
                    b.avatars.push(Avatar::Line {
                        point: p,
                        channel: channel - 1,
                        dir: d,
                        perp,
                    });
                    self.avatar_init(i, p, pos, &mut b);
                    use_input(
                        &mut b.inputs,
                        *channel,
                        InputUse::Position(e.label.to_string()),
                    );
                }
                SpaceKind::PosInputXyz { channel, pos } => {
                    let Some(p) = n.element_point[i] else {
                        continue;
                    };
                    b.avatars.push(Avatar::Xyz {
                        point: p,
                        channel: channel - 1,
                    });
                    self.avatar_init(i, p, pos, &mut b);
                    for c in 0..3 {
                        use_input(
                            &mut b.inputs,
                            channel + c,
                            InputUse::Position(e.label.to_string()),
                        );
                    }
                }
                SpaceKind::FrcInput {
                    channel,
                    target,
                    dir,
                } => {
                    let Some((p, _)) = self.endpoint3(target, i, n, &mut b.proxies, names) else {
                        continue;
                    };
                    let d = self.direction(dir.as_ref(), i, &mut b);
                    b.force_inputs.push(ForceInput::Line {
                        point: p,
                        channel: channel - 1,
                        dir: d,
                    });
                    use_input(
                        &mut b.inputs,
                        *channel,
                        InputUse::Force(crate::compile::kinds::describe_endpoint(target)),
                    );
                }
                SpaceKind::FrcInputXyz { channel, target } => {
                    let Some((p, _)) = self.endpoint3(target, i, n, &mut b.proxies, names) else {
                        continue;
                    };
                    b.force_inputs.push(ForceInput::Xyz {
                        point: p,
                        channel: channel - 1,
                    });
                    for c in 0..3 {
                        use_input(
                            &mut b.inputs,
                            channel + c,
                            InputUse::Force(crate::compile::kinds::describe_endpoint(target)),
                        );
                    }
                }
                SpaceKind::Output {
                    channel,
                    probe,
                    target,
                    dir,
                } => {
                    let Some((p, _)) = self.endpoint3(target, i, n, &mut b.proxies, names) else {
                        continue;
                    };
                    let d = self.direction(dir.as_ref(), i, &mut b);
                    let probe3 = match probe {
                        Probe::Position => Probe3::Position,
                        Probe::Force => Probe3::Force,
                        Probe::Velocity => Probe3::Velocity,
                    };
                    b.outputs.push(Output3::Point {
                        channel: channel - 1,
                        probe: probe3,
                        point: p,
                        dir: d,
                    });
                    let text = crate::compile::kinds::describe_endpoint(target);
                    let use_ = match probe {
                        Probe::Force => OutputUse::Force(text),
                        _ => OutputUse::Position(text),
                    };
                    use_output(&mut b.output_uses, *channel, use_);
                }
                SpaceKind::DistOutput {
                    channel,
                    a,
                    b: end2,
                } => {
                    let ea = self.endpoint3(a, i, n, &mut b.proxies, names);
                    let eb = self.endpoint3(end2, i, n, &mut b.proxies, names);
                    let (Some((pa, _)), Some((pb, _))) = (ea, eb) else {
                        continue;
                    };
                    b.outputs.push(Output3::Distance {
                        channel: channel - 1,
                        a: pa,
                        b: pb,
                    });
                    let text = format!(
                        "{}–{}",
                        crate::compile::kinds::describe_endpoint(a),
                        crate::compile::kinds::describe_endpoint(end2)
                    );
                    use_output(&mut b.output_uses, *channel, OutputUse::Position(text));
                }
                SpaceKind::Mic {
                    channel,
                    set,
                    at,
                    dir,
                    q,
                    r0,
                } => {
                    let members = self.members(set, n, space);
                    let at = self.vector_slots(at, i, &mut b);
                    let dir = dir.as_ref().map(|d| self.direction(Some(d), i, &mut b));
                    let q = self.slot(q, ArgClass::None, i).0 as u32;
                    let r0 = self.slot(r0, ArgClass::None, i).0 as u32;
                    let offset = b.mics.iter().map(|m| m.members.len() as u32).sum();
                    b.outputs.push(Output3::Mic {
                        channel: channel - 1,
                        mic: b.mics.len() as u32,
                    });
                    b.mics.push(Mic {
                        members,
                        at,
                        dir,
                        q,
                        r0,
                        offset,
                    });
                    use_output(
                        &mut b.output_uses,
                        *channel,
                        OutputUse::Position(format!("mic on {set}")),
                    );
                }
            }
        }
        b.groups = pending.into_iter().map(|p| self.lay_out(p)).collect();
        b
    }

    /// The three expressions of a vector, compiled.
    fn vector3(&mut self, v: &Vector, i: usize) -> [crate::spec::expr::ExprRef; 3] {
        let [x, y, z] = vector_exprs(v);
        [self.expr(&x, i).0, self.expr(&y, i).0, self.expr(&z, i).0]
    }

    /// A vector bound to three slots (class none).
    fn vector_slots(&mut self, v: &Vector, i: usize, b: &mut Bound) -> [u32; 3] {
        vector_exprs(v).map(|e| {
            let (s, audio) = self.slot(&e, ArgClass::None, i);
            b.audio_directions |= audio;
            s as u32
        })
    }

    /// A direction (z by default): its slots, and its index.
    fn direction(&mut self, dir: Option<&Vector>, i: usize, b: &mut Bound) -> u32 {
        let z = Vector::Xyz(Box::new([Expr::Num(0.0), Expr::Num(0.0), Expr::Num(1.0)]));
        let slots = self.vector_slots(dir.unwrap_or(&z), i, b);
        b.directions.slots.push(slots);
        (b.directions.slots.len() - 1) as u32
    }

    /// An avatar's initial state: at its declared position, still.
    fn avatar_init(&mut self, i: usize, p: u32, pos: &Vector, b: &mut Bound) {
        let x0 = self.vector3(pos, i);
        let v = self.vector3(&Vector::Scalar(Expr::Num(0.0)), i);
        b.inits.push(Init::Point {
            point: p,
            x0,
            v,
            factor: 0.0,
            fixed: [true; 3],
        });
    }

    /// An explicit mass-type element: its run and its initial state.
    #[allow(clippy::too_many_arguments)]
    fn bind_point(
        &mut self,
        i: usize,
        n: &Numbering,
        body: Body,
        [m, k, z]: [&Expr; 3],
        gravity: Option<&Vector>,
        pos: &Vector,
        vel: Option<&Vector>,
        rate: Rate,
        osc: bool,
        b: &mut Bound,
    ) {
        let Some(p) = n.element_point[i] else {
            return;
        };
        self.check_constant(m, "mass M must be > 0", true, i);
        let (ms, a0) = self.slot(m, ArgClass::None, i);
        let (ks, a1) = self.slot(k, ArgClass::Stiffness, i);
        let (zs, a2) = self.slot(z, ArgClass::Damping, i);
        let mut audio = a0 | a1 | a2;
        // A scalar gravity g is the force (0, 0, −g); a vector the force itself (§2.1.1).
        let g = gravity.map(|g| match g {
            Vector::Scalar(s) => [
                Expr::Num(0.0),
                Expr::Num(0.0),
                Expr::Neg(Box::new(s.clone())),
            ],
            Vector::Xyz(c) => (**c).clone(),
        });
        let gravity = g.filter(|g| g.iter().any(|e| e.as_number() != Some(0.0)));
        let gravity = gravity.map(|g| {
            g.map(|e| {
                let (s, a) = self.slot(&e, ArgClass::Gravity, i);
                audio |= a;
                s as u32
            })
        });
        let axes = axes_of(body);
        let rest = osc.then(|| {
            b.osc_points.push(p);
            (b.osc_points.len() - 1) as u32
        });
        if audio {
            b.audio_runs.push(b.runs.len() as u32);
        }
        b.runs.push(Run {
            first: p,
            count: 1,
            axes,
            m: ms as u32,
            k: osc.then_some(ks as u32),
            z: osc.then_some(zs as u32),
            gravity,
            rest,
        });
        let x0 = self.vector3(pos, i);
        let v = self.vector3(vel.unwrap_or(&Vector::Scalar(Expr::Num(0.0))), i);
        b.inits.push(Init::Point {
            point: p,
            x0,
            v,
            factor: rate.velocity_factor(),
            fixed: axes.map(|free| !free),
        });
    }

    /// A structure: its runs of free nodes, its fixed nodes, its links (3-D spec §4).
    fn bind_structure(
        &mut self,
        i: usize,
        label: &str,
        s: &'a crate::spec::space::Structure,
        n: &Numbering,
        b: &mut Bound,
        pending: &mut [Vec<Pending>],
    ) {
        let Some(placed) = n.structures.get(label) else {
            return;
        };
        self.check_constant(&s.m, "mass M must be > 0", true, i);
        let (ms, a0) = self.slot(&s.m, ArgClass::None, i);
        let zo = s.zo().map(|zo| self.slot(zo, ArgClass::Damping, i));
        let audio = a0 | zo.is_some_and(|z| z.1);
        let axes = match s.lock() {
            Some(Lock::Z) => axes_of(Body::Z),
            Some(Lock::Xy) => axes_of(Body::Xy),
            None => [true; 3],
        };
        let g = &placed.geometry;
        let mut k = 0;
        while k < g.nodes.len() {
            if g.fixed[k] {
                b.still.push(placed.first + k as u32);
                k += 1;
                continue;
            }
            let start = k;
            while k < g.nodes.len() && !g.fixed[k] {
                k += 1;
            }
            if audio {
                b.audio_runs.push(b.runs.len() as u32);
            }
            b.runs.push(Run {
                first: placed.first + start as u32,
                count: (k - start) as u32,
                axes,
                m: ms as u32,
                k: None,
                z: zo.map(|z| z.0 as u32),
                gravity: None,
                rest: None,
            });
        }
        b.inits.push(Init::Block {
            first: placed.first,
            positions: Arc::from(g.nodes.as_slice()),
        });
        // Links: spring-dampers (K, Z, L) family by family as generated.
        let (kk, _) = self.slot(&s.k, ArgClass::Stiffness, i);
        let (zz, _) = self.slot(&s.z, ArgClass::Damping, i);
        let k2 = s.k2().map(|e| self.slot(e, ArgClass::Stiffness, i).0);
        let kb = s.hinge().map(|e| self.slot(e, ArgClass::Stiffness, i).0);
        let shared_rest = (!reads_auto(&s.rest)).then(|| self.slot(&s.rest, ArgClass::None, i).0);
        let mut start = 0;
        while start < g.links.len() {
            let family = g.links[start].2;
            let mut end = start;
            while end < g.links.len() && g.links[end].2 == family {
                end += 1;
            }
            let stiffness = match family {
                crate::spec::space::LinkFamily::Second => k2.unwrap_or(kk),
                crate::spec::space::LinkFamily::Hinge => kb.unwrap_or(kk),
                _ => kk,
            };
            let mut base = [0u32; MAX_SLOTS];
            let mut step = [0u32; MAX_SLOTS];
            base[0] = stiffness as u32;
            base[1] = zz as u32;
            let links: Vec<(u32, u32)> = g.links[start..end]
                .iter()
                .map(|&(a, bb, _)| (placed.first + a, placed.first + bb))
                .collect();
            match shared_rest {
                Some(slot) => base[2] = slot as u32,
                None => {
                    base[2] = self.args.len() as u32;
                    step[2] = 1;
                    self.args.resize(self.args.len() + links.len(), 0.0);
                    for (r, &(a, bb)) in links.iter().enumerate() {
                        let l0 = distance(n.x0[a as usize], n.x0[bb as usize]);
                        let e = with_auto(&s.rest, l0);
                        self.bind(&e, ArgClass::None, base[2] as usize + r, i);
                    }
                }
            }
            let len = links.len() as u32;
            pending[SpaceLawKind::SpringDamper.index()].push(Pending::Laid {
                element: i,
                links,
                seg: Segment {
                    start: 0,
                    len,
                    base,
                    step,
                },
            });
            start = end;
        }
    }

    /// A group from its pending links: each run of explicit lines laid out column by column,
    /// each laid segment placed at its start.
    fn lay_out(&mut self, pending: Vec<Pending>) -> Group3 {
        let mut g = Group3::default();
        let mut run: Vec<Explicit> = Vec::new();
        let flush = |cx: &mut Self, g: &mut Group3, run: &mut Vec<Explicit>| {
            if run.is_empty() {
                return;
            }
            let len = run.len();
            let slots = run[0].args.len();
            let mut base = [0u32; MAX_SLOTS];
            for b in base.iter_mut().take(slots) {
                *b = cx.args.len() as u32;
                cx.args.resize(cx.args.len() + len, 0.0);
            }
            let mut step = [0u32; MAX_SLOTS];
            step[..slots].fill(1);
            g.segments.push(Segment {
                start: g.a.len() as u32,
                len: len as u32,
                base,
                step,
            });
            for (r, e) in run.drain(..).enumerate() {
                g.a.push(e.a);
                g.b.push(e.b);
                g.elements.push(e.element as u32);
                for (c, (expr, class)) in e.args.iter().enumerate() {
                    cx.bind(expr, *class, base[c] as usize + r, e.element);
                }
            }
        };
        for p in pending {
            match p {
                Pending::Explicit(e) => run.push(e),
                Pending::Laid {
                    links,
                    mut seg,
                    element,
                } => {
                    flush(self, &mut g, &mut run);
                    seg.start = g.a.len() as u32;
                    for (a, b) in links {
                        g.a.push(a);
                        g.b.push(b);
                        g.elements.push(element as u32);
                    }
                    g.segments.push(seg);
                }
            }
        }
        flush(self, &mut g, &mut run);
        g
    }

    /// `~gravity` and `~friction` (3-D spec §1.10): the per-step acceleration a/SR² (as
    /// given in raw mode; a scalar g is (0, 0, −g)), and Za (class Z).
    fn bind_medium(&mut self, space: &SpaceSpec, rate: Rate, b: &mut Bound) {
        if let Some(g) = &space.gravity {
            let comps = match g {
                Vector::Scalar(s) => [
                    Expr::Num(0.0),
                    Expr::Num(0.0),
                    Expr::Neg(Box::new(s.clone())),
                ],
                Vector::Xyz(c) => (**c).clone(),
            };
            let per_step = |e: Expr| match rate.mode {
                SampleRateMode::Scaled => Expr::Binary(
                    BinOp::Div,
                    Box::new(e),
                    Box::new(Expr::Num(rate.sr * rate.sr)),
                ),
                SampleRateMode::Raw => e,
            };
            let slots = comps.map(|e| self.slot(&per_step(e), ArgClass::None, usize::MAX).0 as u32);
            b.gravity = Some(slots);
        }
        if let Some(z) = &space.friction {
            b.friction = Some(self.slot(z, ArgClass::Damping, usize::MAX).0 as u32);
        }
    }

    /// The points a microphone hears: a structure's nodes, or a buffer scope's points.
    fn members(&mut self, set: &str, n: &Numbering, space: &SpaceSpec) -> Vec<u32> {
        if let Some(p) = n.structures.get(set) {
            return (0..p.geometry.nodes.len() as u32)
                .map(|k| p.first + k)
                .collect();
        }
        let Some(id) = self.spec.buffers.iter().position(|b| b == set) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (i, e) in space.elements.iter().enumerate() {
            if !e.buffers.contains(&(id as u32)) {
                continue;
            }
            let Some(first) = n.element_point[i] else {
                continue;
            };
            let count = match &e.kind {
                SpaceKind::Structure(_) => n
                    .structures
                    .get(e.label.as_str())
                    .map_or(0, |p| p.geometry.nodes.len()),
                SpaceKind::Mass { .. } | SpaceKind::Osc { .. } | SpaceKind::Ground { .. } => 1,
                _ => 0,
            };
            out.extend(first..first + count as u32);
        }
        out
    }
}

pub(super) fn use_input(inputs: &mut Vec<Vec<InputUse>>, channel: u32, u: InputUse) {
    let c = channel as usize;
    if inputs.len() < c {
        inputs.resize(c, Vec::new());
    }
    inputs[c - 1].push(u);
}

fn use_output(outputs: &mut Vec<OutputUse>, channel: u32, u: OutputUse) {
    let c = channel as usize;
    if outputs.len() < c {
        outputs.resize(c, OutputUse::Unused);
    }
    outputs[c - 1] = u;
}
