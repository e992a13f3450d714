//! Voice lanes of a 3-D model (3-D spec §1.5): [`LANES`] copies stepped together, the copy the
//! fastest axis of each axis's state (`x[point][lane]` on x, y and z), as the 1-D lanes.
//!
//! Each lane computes exactly what a plain 3-D [`Engine`] computes with the same class gains
//! and inputs, the same IEEE operations in the same order, so it equals one bit for bit
//! (engine test `space_lanes`):
//!
//! * what the controls derive (the arguments, the runs' coefficients, the unit directions,
//!   the connection points' weights) and what stage 0 freezes (the `osc` rest positions, the
//!   microphones' weights) is computed by one plain engine per lane, the lane's *shadow*,
//!   with the lane's class gains: the scalar code itself, never a second copy of it. The
//!   shadows are never stepped; the vectorised stages read their arguments and coefficients
//!   packed lane by lane;
//! * the mass phase (stage 2) and the interactions (stage 4) run on the CPU's vectors: every
//!   3-D law through the lane [`Arith`](crate::laws::Arith) (`arith::Native`), its one source
//!   in `laws/space/` (a law's branches computed and chosen by a mask in each lane);
//! * the avatars, the connection points, the force inputs and the outputs (few values, or
//!   per-lane indices) run lane by lane on `f64`, as the scalar engine's `space/io.rs` and
//!   `space/proxies.rs` do.

use super::arith::Native;
use super::vector::Ops;
use super::{Lanes, LANES};
use crate::laws::space::{Ends, SpaceLaw, SpaceLawKind, SpaceLawVisitor};
use crate::sim::engine::{FLUSH_BELOW, FLUSH_INTERVAL};
use crate::sim::space::{Avatar, ForceInput, Group3, Output3, Probe3, Space, SpaceModel};
use crate::spec::ScaleClass;
use crate::{Engine, ParamError, ParamId};
use pulp::Simd;
use std::sync::Arc;

/// One axis of every lane: positions, delayed positions, force accumulators.
#[derive(Clone, Debug)]
struct Axis {
    x: Vec<Lanes>,
    xp: Vec<Lanes>,
    f: Vec<Lanes>,
}

impl Axis {
    fn new(n: usize) -> Axis {
        Axis {
            x: vec![Lanes::ZERO; n],
            xp: vec![Lanes::ZERO; n],
            f: vec![Lanes::ZERO; n],
        }
    }
}

/// A run's coefficients (`space::RunCoef`) in every lane.
#[derive(Clone, Copy, Debug)]
struct Coef {
    a: Lanes,
    b: Lanes,
    inv_m: Lanes,
    g: [Lanes; 3],
    acc: [Lanes; 3],
}

const ZERO_COEF: Coef = Coef {
    a: Lanes::ZERO,
    b: Lanes::ZERO,
    inv_m: Lanes::ZERO,
    g: [Lanes::ZERO; 3],
    acc: [Lanes::ZERO; 3],
};

/// [`LANES`] voices of one 3-D model. See the module documentation.
#[derive(Clone, Debug)]
pub(super) struct SpaceLanes {
    model: Arc<SpaceModel>,
    /// One plain engine per lane, with the lane's class gains: its arguments, derived
    /// coefficients, directions, connection points and stage-0 values are the lane's.
    shadows: Vec<Engine>,
    /// A lane's shadow changed (gain or parameter) since its values were packed.
    dirty: [bool; LANES],
    /// The shadows' arguments, per slot, per lane.
    args: Vec<Lanes>,
    coef: Vec<Coef>,
    /// Each `osc`'s rest position, per lane.
    rest: Vec<[Lanes; 3]>,
    /// The x, y and z axes.
    axes: [Axis; 3],
    /// z positions at the last [`SpaceLanes::motion`].
    last: Vec<Lanes>,
    samples_since_reset: [u64; LANES],
    tripped: [bool; LANES],
    position_limit: f64,
    point_limit: f64,
}

/// The 3-D part of a shadow (every shadow is a 3-D engine).
#[inline(always)]
fn space_of(e: &Engine) -> &Space {
    e.space
        .as_deref()
        .expect("a 3-D model's engine has its space")
}

impl SpaceLanes {
    /// [`LANES`] voices of the 3-D model `template` (reset), every lane at rest.
    pub fn new(template: &Engine) -> SpaceLanes {
        let space = space_of(template);
        let model = Arc::clone(&space.model);
        let n = model.len;
        let slots = template.args.len();
        let mut lanes = SpaceLanes {
            shadows: vec![template.clone(); LANES],
            dirty: [true; LANES],
            args: vec![Lanes::ZERO; slots],
            coef: vec![ZERO_COEF; model.runs.len()],
            rest: vec![[Lanes::ZERO; 3]; space.rest.len()],
            axes: [Axis::new(n), Axis::new(n), Axis::new(n)],
            last: vec![Lanes::ZERO; n],
            samples_since_reset: [0; LANES],
            tripped: [false; LANES],
            position_limit: template.position_limit(),
            point_limit: template.point_limit(),
            model,
        };
        for l in 0..LANES {
            lanes.reset_lane(l);
        }
        lanes
    }

    /// Sets a parameter of every lane's shadow.
    pub fn set_param(&mut self, id: ParamId, value: f64) -> Result<(), ParamError> {
        for (l, s) in self.shadows.iter_mut().enumerate() {
            let before = s.param(id);
            s.set_param(id, value)?;
            if before != Some(value) {
                self.dirty[l] = true;
            }
        }
        Ok(())
    }

    /// One lane's class gain.
    pub fn set_class_gain(&mut self, lane: usize, class: ScaleClass, gain: f64) {
        if lane < LANES && self.shadows[lane].class_gain(class) != gain {
            self.shadows[lane].set_class_gain(class, gain);
            self.dirty[lane] = true;
        }
    }

    /// Packs lane `l`'s shadow's arguments and coefficients (after applying its changes).
    fn pack(&mut self, l: usize) {
        let shadow = &mut self.shadows[l];
        shadow.apply_pending_changes();
        for (a, v) in self.args.iter_mut().zip(&shadow.args) {
            a[l] = *v;
        }
        let space = space_of(shadow);
        for (c, k) in self.coef.iter_mut().zip(&space.coef) {
            c.a[l] = k.a;
            c.b[l] = k.b;
            c.inv_m[l] = k.inv_m;
            for axis in 0..3 {
                c.g[axis][l] = k.g[axis];
                c.acc[axis][l] = k.acc[axis];
            }
        }
        self.dirty[l] = false;
    }

    /// Lane `lane` at the model's initial state (stage 0), as its shadow's reset computes it.
    pub fn reset_lane(&mut self, lane: usize) {
        if lane >= LANES {
            return;
        }
        self.shadows[lane].reset();
        self.pack(lane);
        let shadow = &self.shadows[lane];
        let space = space_of(shadow);
        for (axis, p) in self
            .axes
            .iter_mut()
            .zip([&space.ax, &space.ay, &shadow.points])
        {
            for i in 0..axis.x.len() {
                axis.x[i][lane] = p.x[i];
                axis.xp[i][lane] = p.xp[i];
                axis.f[i][lane] = p.f[i];
            }
        }
        for (i, last) in self.last.iter_mut().enumerate() {
            last[lane] = shadow.points.x[i];
        }
        for (r, v) in self.rest.iter_mut().zip(&space.rest) {
            for c in 0..3 {
                r[c][lane] = v[c];
            }
        }
        self.samples_since_reset[lane] = 0;
        self.tripped[lane] = false;
    }

    /// Copies lane `from` of `src` into lane `to` (see `LaneEngine::take_lane`).
    pub fn take_lane(&mut self, to: usize, src: &SpaceLanes, from: usize) {
        if to >= LANES || from >= LANES {
            return;
        }
        let copy = |dst: &mut [Lanes], s: &[Lanes]| {
            for (d, s) in dst.iter_mut().zip(s) {
                d[to] = s[from];
            }
        };
        for (d, s) in self.axes.iter_mut().zip(&src.axes) {
            copy(&mut d.x, &s.x);
            copy(&mut d.xp, &s.xp);
            copy(&mut d.f, &s.f);
        }
        copy(&mut self.last, &src.last);
        // The shadow takes the source lane's gains and its stage-0 values; its arguments and
        // coefficients are derived again from them at the next block (the same bits).
        let (dst, from_shadow) = (&mut self.shadows[to], &src.shadows[from]);
        for class in [ScaleClass::Stiffness, ScaleClass::Damping] {
            dst.set_class_gain(class, from_shadow.class_gain(class));
        }
        if let (Some(d), Some(s)) = (dst.space.as_deref_mut(), from_shadow.space.as_deref()) {
            d.rest.copy_from_slice(&s.rest);
            d.mic_weights.copy_from_slice(&s.mic_weights);
            d.mic_dirs.copy_from_slice(&s.mic_dirs);
        }
        for (d, s) in self.rest.iter_mut().zip(&src.rest) {
            for c in 0..3 {
                d[c][to] = s[c][from];
            }
        }
        self.dirty[to] = true;
        self.samples_since_reset[to] = src.samples_since_reset[from];
        self.tripped[to] = src.tripped[from];
    }

    pub fn is_tripped(&self, lane: usize) -> bool {
        self.tripped.get(lane).copied().unwrap_or(false)
    }

    /// Lane `lane`'s positions on axis `c` (0 x, 1 y, 2 z) into `out`.
    pub fn lane_axis(&self, lane: usize, c: usize, out: &mut [f64]) {
        if let Some(axis) = self.axes.get(c) {
            for (o, v) in out.iter_mut().zip(&axis.x) {
                *o = v[lane];
            }
        }
    }

    /// Lane `lane`'s z positions and delayed positions.
    pub fn lane_state(&self, lane: usize, x: &mut [f64], xp: &mut [f64]) {
        let z = &self.axes[2];
        for (o, v) in x.iter_mut().zip(&z.x) {
            *o = v[lane];
        }
        for (o, v) in xp.iter_mut().zip(&z.xp) {
            *o = v[lane];
        }
    }

    /// [`Engine::motion_level`] in every lane.
    #[inline(always)]
    pub fn motion<S: Simd>(&mut self, o: Ops<S>) -> Lanes {
        let mut level = Lanes::ZERO;
        let [ax, ay, az] = &self.axes;
        for ((x, xp), last) in az.x.iter().zip(&az.xp).zip(&mut self.last) {
            level = o.max_abs(o.sub(*x, *xp), level);
            level = o.max_abs(o.sub(*x, *last), level);
            *last = *x;
        }
        for axis in [ax, ay] {
            for (x, xp) in axis.x.iter().zip(&axis.xp) {
                level = o.max_abs(o.sub(*x, *xp), level);
            }
        }
        level
    }

    /// Brings the packed arguments up to date before a block.
    pub fn refresh(&mut self) {
        for l in 0..LANES {
            if self.dirty[l] {
                self.pack(l);
            }
        }
    }

    /// `frames` samples of every lane (the layout of `LaneEngine::process`).
    #[inline(always)]
    pub fn run<S: Simd>(
        &mut self,
        o: Ops<S>,
        frames: usize,
        inputs: &[f64],
        in_channels: usize,
        outputs: &mut [f64],
        out_channels: usize,
    ) {
        for n in 0..frames {
            let input = |ch: u32, l: usize| -> f64 {
                let ch = ch as usize;
                if ch < in_channels {
                    let v = inputs[(ch * frames + n) * LANES + l];
                    if v.is_finite() {
                        v
                    } else {
                        0.0
                    }
                } else {
                    0.0
                }
            };
            self.step(o, &input);
            self.write_outputs(n, frames, out_channels, outputs);
            let mut below = Lanes::ZERO;
            let mut due = false;
            for l in 0..LANES {
                self.samples_since_reset[l] += 1;
                if self.samples_since_reset[l].is_multiple_of(FLUSH_INTERVAL) {
                    below[l] = FLUSH_BELOW;
                    due = true;
                }
            }
            if due {
                for axis in &mut self.axes {
                    for v in axis
                        .x
                        .iter_mut()
                        .chain(axis.xp.iter_mut())
                        .chain(axis.f.iter_mut())
                    {
                        *v = o.zero_below(*v, below);
                    }
                }
            }
        }
        // The guard's scan of every position on every axis, at the end of the block.
        let mut beyond = Lanes::ZERO;
        for axis in &self.axes {
            for x in &axis.x {
                beyond = o.flag_beyond(*x, self.point_limit, beyond);
            }
        }
        for l in 0..LANES {
            if beyond[l] != 0.0 {
                self.tripped[l] = true;
            }
        }
    }

    /// Stages 1 to 5 of one sample in every lane (3-D spec §1.5, `Space::step`'s order).
    #[inline(always)]
    fn step<S: Simd>(&mut self, o: Ops<S>, input: &impl Fn(u32, usize) -> f64) {
        let m = &*self.model;
        let spaces: [&Space; LANES] = std::array::from_fn(|l| space_of(&self.shadows[l]));
        let [ax, ay, az] = &mut self.axes;
        // Stage 1 a: avatars, lane by lane (`io::avatars`).
        for av in &m.avatars {
            for (l, space) in spaces.iter().enumerate() {
                let d = &space.directions;
                let (point, target) = match *av {
                    Avatar::Line {
                        point,
                        channel,
                        dir,
                        perp,
                    } => {
                        let (a, p, s) = (
                            d.units[dir as usize],
                            d.perp[perp as usize],
                            input(channel, l),
                        );
                        (point, [0, 1, 2].map(|c| p[c] + s * a[c]))
                    }
                    Avatar::Xyz { point, channel } => (
                        point,
                        [
                            input(channel, l),
                            input(channel + 1, l),
                            input(channel + 2, l),
                        ],
                    ),
                };
                let k = point as usize;
                for (axis, v) in [&mut *ax, &mut *ay, &mut *az].into_iter().zip(target) {
                    axis.xp[k][l] = axis.x[k][l];
                    axis.x[k][l] = v;
                    axis.f[k][l] = 0.0;
                }
            }
        }
        // Stage 2: the mass phase (`masses::step`).
        for (run, k) in m.runs.iter().zip(&self.coef) {
            let range = run.first as usize..(run.first + run.count) as usize;
            for (c, axis) in [&mut *ax, &mut *ay, &mut *az].into_iter().enumerate() {
                let (x, xp, f) = (
                    &mut axis.x[range.clone()],
                    &mut axis.xp[range.clone()],
                    &mut axis.f[range.clone()],
                );
                if !run.axes[c] {
                    f.fill(Lanes::ZERO);
                    continue;
                }
                let (g, acc) = (k.g[c], k.acc[c]);
                match run.rest {
                    None => {
                        for ((x, xp), f) in x.iter_mut().zip(xp.iter_mut()).zip(f.iter_mut()) {
                            let y = o.add(
                                o.add(
                                    o.sub(o.mul(k.a, *x), o.mul(k.b, *xp)),
                                    o.mul(o.add(*f, g), k.inv_m),
                                ),
                                acc,
                            );
                            *xp = *x;
                            *x = y;
                            *f = Lanes::ZERO;
                        }
                    }
                    Some(r) => {
                        let at = self.rest[r as usize][c];
                        for ((x, xp), f) in x.iter_mut().zip(xp.iter_mut()).zip(f.iter_mut()) {
                            let (y, yp) = (o.sub(*x, at), o.sub(*xp, at));
                            let next = o.add(
                                o.add(
                                    o.sub(o.mul(k.a, y), o.mul(k.b, yp)),
                                    o.mul(o.add(*f, g), k.inv_m),
                                ),
                                acc,
                            );
                            *xp = *x;
                            *x = o.add(next, at);
                            *f = Lanes::ZERO;
                        }
                    }
                }
            }
        }
        for &i in &m.still {
            let i = i as usize;
            ax.f[i] = Lanes::ZERO;
            ay.f[i] = Lanes::ZERO;
            az.f[i] = Lanes::ZERO;
        }
        // Stage 3: connection points' positions, lane by lane (`proxies::update_positions`).
        let base = m.proxy_base as usize;
        for axis in [&mut *ax, &mut *ay, &mut *az] {
            for (i, d) in m.proxies.iter().enumerate() {
                let p = base + i;
                for (l, space) in spaces.iter().enumerate() {
                    let (nodes, w) = (&space.proxy_nodes[i], &space.proxy_weights[i]);
                    let mut pos = w[0] * axis.x[nodes[0] as usize][l];
                    for k in 1..d.width() {
                        pos += w[k] * axis.x[nodes[k] as usize][l];
                    }
                    axis.xp[p][l] = axis.x[p][l];
                    axis.x[p][l] = pos;
                    axis.f[p][l] = 0.0;
                }
            }
        }
        // Stage 4: the interactions, one group per law in table order, on the vectors.
        SpaceLawKind::visit_all(&mut Stage4 {
            o,
            groups: &m.groups,
            axes: [&mut *ax, &mut *ay, &mut *az],
            args: &self.args,
        });
        // Then the force inputs, lane by lane (`io::force_inputs`).
        for fi in &m.force_inputs {
            for (l, space) in spaces.iter().enumerate() {
                let (point, f) = match *fi {
                    ForceInput::Line {
                        point,
                        channel,
                        dir,
                    } => {
                        let (a, s) = (space.directions.units[dir as usize], input(channel, l));
                        (point, a.map(|c| s * c))
                    }
                    ForceInput::Xyz { point, channel } => (
                        point,
                        [
                            input(channel, l),
                            input(channel + 1, l),
                            input(channel + 2, l),
                        ],
                    ),
                };
                let k = point as usize;
                ax.f[k][l] += f[0];
                ay.f[k][l] += f[1];
                az.f[k][l] += f[2];
            }
        }
        // Stage 5: connection-point forces onto the nodes (`proxies::spread_forces`).
        for axis in [&mut *ax, &mut *ay, &mut *az] {
            for (i, d) in m.proxies.iter().enumerate() {
                for (l, space) in spaces.iter().enumerate() {
                    let fp = axis.f[base + i][l];
                    let (nodes, w) = (&space.proxy_nodes[i], &space.proxy_weights[i]);
                    for k in 0..d.width() {
                        axis.f[nodes[k] as usize][l] += w[k] * fp;
                    }
                }
            }
        }
    }

    /// Stage 6 and its guard in every lane, lane by lane (`io::output`): a lane whose output
    /// is non-finite or beyond the position limit trips, and writes 0 from this sample on.
    #[inline(always)]
    fn write_outputs(&mut self, n: usize, frames: usize, out_channels: usize, out: &mut [f64]) {
        let m = &*self.model;
        let [ax, ay, az] = &self.axes;
        let limit = self.position_limit;
        for l in 0..LANES {
            let space = space_of(&self.shadows[l]);
            let d = &space.directions;
            let at = |k: usize| [ax.x[k][l], ay.x[k][l], az.x[k][l]];
            let mut bad = false;
            for o in &m.outputs {
                let v = match *o {
                    Output3::Point {
                        probe, point, dir, ..
                    } => {
                        let k = point as usize;
                        let v = match probe {
                            Probe3::Position => at(k),
                            Probe3::Force => [ax.f[k][l], ay.f[k][l], az.f[k][l]],
                            Probe3::Velocity => [
                                ax.x[k][l] - ax.xp[k][l],
                                ay.x[k][l] - ay.xp[k][l],
                                az.x[k][l] - az.xp[k][l],
                            ],
                        };
                        dot(v, d.units[dir as usize])
                    }
                    Output3::Distance { a, b, .. } => {
                        let (p, q) = (at(a as usize), at(b as usize));
                        let dd = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
                        dot(dd, dd).sqrt()
                    }
                    Output3::Mic { mic, .. } => {
                        let mic = &m.mics[mic as usize];
                        let off = mic.offset as usize;
                        let mut sum = 0.0;
                        for (j, &p) in mic.members.iter().enumerate() {
                            let k = p as usize;
                            let v = [
                                ax.x[k][l] - ax.xp[k][l],
                                ay.x[k][l] - ay.xp[k][l],
                                az.x[k][l] - az.xp[k][l],
                            ];
                            sum += space.mic_weights[off + j] * dot(v, space.mic_dirs[off + j]);
                        }
                        sum
                    }
                };
                let ch = o.channel() as usize;
                if ch < out_channels {
                    out[(ch * frames + n) * LANES + l] = v;
                }
                bad |= !(v.abs() <= limit);
            }
            if bad {
                self.tripped[l] = true;
            }
            if self.tripped[l] {
                for ch in 0..out_channels {
                    out[(ch * frames + n) * LANES + l] = 0.0;
                }
            }
        }
    }
}

/// (a·b) for 3-vectors, as `io::dot`: (x + y) + z.
#[inline(always)]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2]
}

/// Stage 4 of every lane: each law's group (`space::links::step`).
struct Stage4<'a, S> {
    o: Ops<S>,
    groups: &'a [Group3],
    axes: [&'a mut Axis; 3],
    args: &'a [Lanes],
}

impl<S: Simd> SpaceLawVisitor for Stage4<'_, S> {
    #[inline(always)]
    fn visit<L: SpaceLaw>(&mut self, kind: SpaceLawKind) {
        let g = &self.groups[kind.index()];
        if !g.segments.is_empty() {
            apply::<S, L>(self.o, g, &mut self.axes, self.args);
        }
    }
}

/// One law's links in every lane: F₁ −= g, F₂ += g (F₁ only for a one-endpoint law), link
/// by link, as `space::links::apply`.
#[inline(always)]
fn apply<S: Simd, L: SpaceLaw>(o: Ops<S>, g: &Group3, axes: &mut [&mut Axis; 3], args: &[Lanes]) {
    let one = L::ROW.endpoints == 1;
    let slots = L::ROW.slots();
    for seg in &g.segments {
        for i in 0..seg.len {
            let link = (seg.start + i) as usize;
            let (a, b) = (g.a[link] as usize, g.b[link] as usize);
            let mut p = [0usize; SpaceLawKind::MAX_SLOTS];
            for (c, p) in p.iter_mut().enumerate().take(slots) {
                *p = (seg.base[c] + seg.step[c] * i) as usize;
            }
            let force = law_in_lanes::<S, L>(o.0, axes, a, b, args, &p);
            for (axis, f) in axes.iter_mut().zip(force) {
                axis.f[a] = o.sub(axis.f[a], f);
            }
            if !one {
                for (axis, f) in axes.iter_mut().zip(force) {
                    axis.f[b] = o.add(axis.f[b], f);
                }
            }
        }
    }
}

/// `L`'s vector g for the link (a, b) in every lane, native vector by native vector.
#[inline(always)]
fn law_in_lanes<S: Simd, L: SpaceLaw>(
    simd: S,
    axes: &[&mut Axis; 3],
    a: usize,
    b: usize,
    args: &[Lanes],
    slots: &[usize; SpaceLawKind::MAX_SLOTS],
) -> [Lanes; 3] {
    let arith = Native(simd);
    let mut out = [Lanes::ZERO; 3];
    #[inline(always)]
    fn v<S: Simd>(l: &Lanes) -> &[S::f64s] {
        S::as_simd_f64s(&l.0).0
    }
    let v = v::<S>;
    let [ax, ay, az] = axes;
    let (x1, xp1, x2, xp2) = (
        [v(&ax.x[a]), v(&ay.x[a]), v(&az.x[a])],
        [v(&ax.xp[a]), v(&ay.xp[a]), v(&az.xp[a])],
        [v(&ax.x[b]), v(&ay.x[b]), v(&az.x[b])],
        [v(&ax.xp[b]), v(&ay.xp[b]), v(&az.xp[b])],
    );
    let chunks = x1[0].len();
    for k in 0..chunks {
        let e = Ends {
            x1: [x1[0][k], x1[1][k], x1[2][k]],
            xp1: [xp1[0][k], xp1[1][k], xp1[2][k]],
            x2: [x2[0][k], x2[1][k], x2[2][k]],
            xp2: [xp2[0][k], xp2[1][k], xp2[2][k]],
        };
        let g = L::force(&arith, &e, |c| v(&args[slots[c]])[k]);
        for (o, g) in out.iter_mut().zip(g) {
            S::as_mut_simd_f64s(&mut o.0).0[k] = g;
        }
    }
    out
}
