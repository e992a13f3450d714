//! Voice lanes (issue 12): [`LANES`] copies of one compiled model stepped together, the copy
//! the fastest axis of the state (`x[point][lane]`), so that every kernel runs all the lanes
//! in one or two vector instructions (`vector`). The copies share the structure and the parameters;
//! each lane has its own state, class gains (its tuning, Release, polyphonic modulation), inputs,
//! outputs, guard and flush phase.
//!
//! Each lane computes exactly what a plain [`Engine`] computes with the same gains and inputs:
//! the same IEEE operations in the same order (spec §1.5's stages, the laws of spec §2), so a
//! lane equals a plain engine bit for bit (engine test `lanes`). Arguments are
//! `expression value × (class scale × lane gain)`, as [`Engine`]'s `class_factors`.
//!
//! Macros, connection points and avatars run in lanes too (`structures`). Models with
//! audio-rate parameters, and models of more than [`MAX_LANE_POINTS`] points, are not laned
//! ([`LaneEngine::supports`]); they keep one [`Engine`] per voice.

use crate::laws::LawKind;
use crate::laws::{ArgClass, NUM_ARG_CLASSES};
use crate::sim::engine::{single_law, Proxies};
use crate::sim::engine::{FLUSH_BELOW, FLUSH_INTERVAL};
use crate::spec::ScaleClass;
use crate::{Engine, ParamError, ParamId};

mod arith;
mod links;
mod space;
mod structures;
mod vector;

pub(crate) use arith::Native;
use links::Stage4;
use vector::Ops;

/// Voices per lane group.
pub const LANES: usize = 8;

/// The largest model that runs in lanes. A group steps all its lanes while any of them
/// sounds and costs about three engines (`VoiceBank::new`), which pays from half a group of
/// sounding voices for models up to this size: 16 voices of the 102-point faust-mi string
/// cost 1,111 ns in two groups, where 16 engines would cost 16 × 194 ns = 3,100 ns. The
/// limit itself was set with four lanes and not moved since.
pub const MAX_LANE_POINTS: usize = 256;

/// The shortest run of singles with equal coefficients that the mass pass runs reading them
/// once ([`LaneEngine::find_mass_runs`]).
const UNIFORM_MASS_RUN: usize = 8;

/// One f64 per lane, aligned to a cache line so that no vector load or store of a lane
/// group's value splits one.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct Lanes([f64; LANES]);

impl Lanes {
    const ZERO: Lanes = Lanes([0.0; LANES]);

    /// `v` in every lane.
    #[inline(always)]
    fn splat(v: f64) -> Lanes {
        Lanes([v; LANES])
    }
}

impl std::ops::Deref for Lanes {
    type Target = [f64; LANES];
    #[inline(always)]
    fn deref(&self) -> &[f64; LANES] {
        &self.0
    }
}

impl std::ops::DerefMut for Lanes {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [f64; LANES] {
        &mut self.0
    }
}

/// [`LANES`] voices of one model. See the module documentation.
#[derive(Clone, Debug)]
pub struct LaneEngine {
    /// The model: structure, parameters, expressions, and (after `reset`) the rest state.
    template: Engine,
    /// The template's rest state is stale (a parameter changed since it was taken).
    rest_stale: bool,
    /// Expression value of every control binding, by slot (no class factor).
    raw: Vec<f64>,
    /// Host gain of each class, per lane.
    gains: [[f64; NUM_ARG_CLASSES]; LANES],
    /// Arguments per slot, per lane.
    args: Vec<Lanes>,
    /// Single mass-type coefficients per point, per lane (spec §2.1.2).
    a: Vec<Lanes>,
    b: Vec<Lanes>,
    inv_m: Vec<Lanes>,
    gravity: Vec<Lanes>,
    x: Vec<Lanes>,
    xp: Vec<Lanes>,
    f: Vec<Lanes>,
    /// The singles in runs that cover them in order, as (start, end, uniform): a uniform run's
    /// singles have the same coefficients, lane by lane, and the mass pass reads them once
    /// ([`LaneEngine::find_mass_runs`]). The first `mass_run_count`; room for one run per
    /// single (a length, not a capacity, so that clones keep it).
    mass_runs: Vec<(u32, u32, bool)>,
    mass_run_count: usize,
    /// A single's coefficients changed since the runs were found.
    mass_runs_stale: bool,
    /// Positions at the last [`LaneEngine::motion`].
    last: Vec<Lanes>,
    /// Connection points: the template's, placed by the coordinates every lane shares.
    proxies: Proxies,
    /// Node velocities of the mesh being computed.
    scratch_v: Vec<Lanes>,
    params_dirty: bool,
    gains_dirty: [bool; LANES],
    /// The class factors each lane's arguments were last computed with.
    seen: [[f64; NUM_ARG_CLASSES]; LANES],
    samples_since_reset: [u64; LANES],
    tripped: [bool; LANES],
    arch: pulp::Arch,
    /// A 3-D model's lanes (`space.rs`): then the 1-D state above is empty.
    space: Option<Box<space::SpaceLanes>>,
}

impl LaneEngine {
    /// Whether a model runs in lanes: no audio-rate parameters (they re-derive arguments
    /// every sample), and at most [`MAX_LANE_POINTS`] points.
    pub fn supports(engine: &Engine) -> bool {
        engine.model.audio_params.is_empty()
            && engine.model.audio_bindings.is_empty()
            && engine.points.x.len() <= MAX_LANE_POINTS
    }

    /// [`LANES`] voices of `template`, every lane at rest with the template's class gains.
    /// Allocates: call it off the audio thread. `None` when the model is not supported.
    pub fn new(template: &Engine) -> Option<LaneEngine> {
        if !LaneEngine::supports(template) {
            return None;
        }
        let mut template = template.clone();
        template.reset();
        let space = template
            .space
            .is_some()
            .then(|| Box::new(space::SpaceLanes::new(&template)));
        // A 3-D model's state is in `space`; the 1-D fields stay empty.
        let n = if space.is_some() {
            0
        } else {
            template.points.x.len()
        };
        // Slots no binding writes keep the values the compiler gave them.
        let args = template.args.iter().map(|&v| Lanes([v; LANES])).collect();
        let singles = template.singles.len();
        let largest_macro = template.macros.scratch_v.len();
        let proxies = template.proxies.clone();
        // Slots no binding writes keep the compiler's value, as `ControlArgs::raw`.
        let raw = template.control.raw().to_vec();
        let zero = Lanes::ZERO;
        let mut lanes = LaneEngine {
            gains: [template.class_gain; LANES],
            template,
            rest_stale: false,
            raw,
            args,
            a: vec![zero; singles],
            b: vec![zero; singles],
            inv_m: vec![zero; singles],
            gravity: vec![zero; singles],
            mass_runs: vec![(0, 0, false); singles],
            mass_run_count: 0,
            mass_runs_stale: true,
            x: vec![zero; n],
            xp: vec![zero; n],
            f: vec![zero; n],
            last: vec![zero; n],
            proxies,
            scratch_v: vec![zero; largest_macro],
            params_dirty: true,
            gains_dirty: [true; LANES],
            seen: [[0.0; NUM_ARG_CLASSES]; LANES],
            samples_since_reset: [0; LANES],
            tripped: [false; LANES],
            arch: lane_arch(),
            space,
        };
        if lanes.space.is_some() {
            return Some(lanes);
        }
        lanes.refresh();
        for l in 0..LANES {
            lanes.reset_lane(l);
        }
        Some(lanes)
    }

    /// The model every lane runs.
    pub fn template(&self) -> &Engine {
        &self.template
    }

    /// Sets a parameter of every lane (they share parameters), from the next block on.
    /// Realtime-safe.
    pub fn set_param(&mut self, id: ParamId, value: f64) -> Result<(), ParamError> {
        if let Some(space) = &mut self.space {
            space.set_param(id, value)?;
        }
        let before = self.template.param(id);
        self.template.set_param(id, value)?;
        if before != Some(value) {
            self.params_dirty = true;
            self.rest_stale = true;
        }
        Ok(())
    }

    /// [`Engine::set_class_gain`] for one lane. Realtime-safe.
    pub fn set_class_gain(&mut self, lane: usize, class: ScaleClass, gain: f64) {
        let slot = match class {
            ScaleClass::Stiffness => ArgClass::Stiffness,
            ScaleClass::Damping => ArgClass::Damping,
            ScaleClass::None | ScaleClass::Gravity => return,
        } as usize;
        if let Some(space) = &mut self.space {
            return space.set_class_gain(lane, class, gain);
        }
        if lane < LANES && gain.is_finite() && gain >= 0.0 && self.gains[lane][slot] != gain {
            self.gains[lane][slot] = gain;
            self.gains_dirty[lane] = true;
        }
    }

    /// Puts lane `lane` at the model's initial state (spec §1.5 stage 0) at the current
    /// parameters, and clears its guard. Realtime-safe.
    pub fn reset_lane(&mut self, lane: usize) {
        if let Some(space) = &mut self.space {
            return space.reset_lane(lane);
        }
        if lane >= LANES {
            return;
        }
        if self.rest_stale {
            self.template.reset();
            self.rest_stale = false;
        }
        self.refresh();
        let p = &self.template.points;
        for (i, ((x, xp), f)) in self
            .x
            .iter_mut()
            .zip(&mut self.xp)
            .zip(&mut self.f)
            .enumerate()
        {
            x[lane] = p.x[i];
            xp[lane] = p.xp[i];
            f[lane] = p.f[i];
            self.last[i][lane] = p.x[i];
        }
        self.samples_since_reset[lane] = 0;
        self.tripped[lane] = false;
    }

    /// Copies lane `from` of `src` into lane `to` of `self`: its state, arguments,
    /// coefficients, gains, guard and flush phase, so that the lane goes on exactly as it would
    /// have in `src` (the voice bank packs sounding voices into fewer groups). Both groups run
    /// the same model with the same parameters. Realtime-safe.
    pub fn take_lane(&mut self, to: usize, src: &LaneEngine, from: usize) {
        if let (Some(d), Some(s)) = (&mut self.space, &src.space) {
            return d.take_lane(to, s, from);
        }
        if to >= LANES || from >= LANES {
            return;
        }
        let copy = |dst: &mut [Lanes], s: &[Lanes]| {
            for (d, s) in dst.iter_mut().zip(s) {
                d[to] = s[from];
            }
        };
        copy(&mut self.args, &src.args);
        copy(&mut self.a, &src.a);
        copy(&mut self.b, &src.b);
        copy(&mut self.inv_m, &src.inv_m);
        copy(&mut self.gravity, &src.gravity);
        self.mass_runs_stale = true;
        copy(&mut self.x, &src.x);
        copy(&mut self.xp, &src.xp);
        copy(&mut self.f, &src.f);
        copy(&mut self.last, &src.last);
        self.gains[to] = src.gains[from];
        self.seen[to] = src.seen[from];
        self.gains_dirty[to] = src.gains_dirty[from];
        self.samples_since_reset[to] = src.samples_since_reset[from];
        self.tripped[to] = src.tripped[from];
    }

    /// Whether lane `lane`'s guard has tripped (a non-finite or runaway value): its outputs
    /// stay 0 until [`LaneEngine::reset_lane`].
    pub fn is_tripped(&self, lane: usize) -> bool {
        if let Some(space) = &self.space {
            return space.is_tripped(lane);
        }
        self.tripped.get(lane).copied().unwrap_or(false)
    }

    /// Lane `lane`'s positions along axis `c` (0 x, 1 y, 2 z, as [`Engine::axis`]), point by
    /// point, into `out` (as many as it holds): a 1-D model's x and y are empty.
    pub fn lane_axis(&self, lane: usize, c: usize, out: &mut [f64]) {
        if lane >= LANES {
            return;
        }
        match &self.space {
            Some(space) => space.lane_axis(lane, c, out),
            None if c == 2 => {
                for (o, v) in out.iter_mut().zip(&self.x) {
                    *o = v[lane];
                }
            }
            None => {}
        }
    }

    /// Lane `lane`'s positions and delayed positions, point by point, into `x` and `xp`
    /// (as many as they hold).
    pub fn lane_state(&self, lane: usize, x: &mut [f64], xp: &mut [f64]) {
        if let Some(space) = &self.space {
            return space.lane_state(lane, x, xp);
        }
        for (o, v) in x.iter_mut().zip(&self.x) {
            *o = v[lane];
        }
        for (o, v) in xp.iter_mut().zip(&self.xp) {
            *o = v[lane];
        }
    }

    /// How far each lane moved: the largest distance any point moved in the last sample or
    /// since the last call, per lane (the voice bank's rest detection). Realtime-safe.
    pub fn motion(&mut self) -> [f64; LANES] {
        struct Motion<'a>(&'a mut LaneEngine);
        impl pulp::WithSimd for Motion<'_> {
            type Output = Lanes;
            #[inline(always)]
            fn with_simd<S: pulp::Simd>(self, simd: S) -> Lanes {
                let o = Ops(simd);
                let lanes = self.0;
                if let Some(space) = &mut lanes.space {
                    return space.motion(o);
                }
                let mut level = Lanes::ZERO;
                for ((x, xp), last) in lanes.x.iter().zip(&lanes.xp).zip(&mut lanes.last) {
                    level = o.max_abs(o.sub(*x, *xp), level);
                    level = o.max_abs(o.sub(*x, *last), level);
                    *last = *x;
                }
                level
            }
        }
        let arch = self.arch;
        arch.dispatch(Motion(self)).0
    }

    /// Re-evaluates the arguments and coefficients after a parameter or gain change. A
    /// parameter change re-evaluates every binding and lane; a gain change (a note's tuning,
    /// an MPE bend: every chunk while it moves) rescales only the arguments of the classes
    /// whose factor moved in that lane and re-derives only the singles whose arguments
    /// changed, as `ControlArgs` does for the plain engine (same operations, same bits).
    fn refresh(&mut self) {
        let t = &mut self.template;
        let full = self.params_dirty;
        if full {
            for bind in &t.control.bindings {
                self.raw[bind.slot as usize] =
                    t.model.program.eval(bind.expr, &t.params, &mut t.stack);
            }
            self.gains_dirty = [true; LANES];
            self.params_dirty = false;
            // Which bands read one set of arguments: compared before the class factors, so
            // that they stay equal in every lane whatever its gains (as `Engine` does).
            t.interactions.find_uniform(&self.raw);
        }
        for l in 0..LANES {
            if !self.gains_dirty[l] {
                continue;
            }
            // The factors as `Engine::class_factors` forms them: scale × gain.
            let mut scale = t.model.class_scale;
            for (s, g) in scale.iter_mut().zip(self.gains[l]) {
                *s *= g;
            }
            let s = &t.singles;
            let derive = |args: &[Lanes], out: &mut [&mut Vec<Lanes>; 4], i: usize| {
                let arg = |c: usize| args[s.cols[c] + i][l];
                let law = single_law(s.fixed[i], arg(0), arg(1), arg(2), arg(3));
                for (o, v) in out.iter_mut().zip(law) {
                    o[i][l] = v;
                }
            };
            self.mass_runs_stale = true;
            let mut out = [&mut self.a, &mut self.b, &mut self.inv_m, &mut self.gravity];
            if full {
                for bind in &t.control.bindings {
                    let slot = bind.slot as usize;
                    self.args[slot][l] = self.raw[slot] * scale[bind.class as usize];
                }
                for i in 0..s.len() {
                    derive(&self.args, &mut out, i);
                }
            } else {
                for (c, &f) in scale.iter().enumerate() {
                    if f.to_bits() == self.seen[l][c].to_bits() {
                        continue;
                    }
                    let (plain, derived) = t.control.rescaled(c);
                    for &slot in plain {
                        let slot = slot as usize;
                        self.args[slot][l] = self.raw[slot] * f;
                    }
                    for (slot, single) in derived {
                        let v = self.raw[slot] * f;
                        if v.to_bits() != self.args[slot][l].to_bits() {
                            self.args[slot][l] = v;
                            if let Some(i) = single {
                                // Derived right away: a single reads four slots, and
                                // re-deriving one twice gives the same bits.
                                derive(&self.args, &mut out, i);
                            }
                        }
                    }
                }
            }
            self.seen[l] = scale;
            self.gains_dirty[l] = false;
        }
        if full {
            // Coordinates are unscaled arguments (class None): every lane has the same.
            let args = &self.args;
            for i in 0..self.proxies.len() {
                self.proxies.derive_with(i, |slot| args[slot][0]);
            }
        }
    }

    /// Splits the singles into runs: at least [`UNIFORM_MASS_RUN`] consecutive singles whose
    /// four coefficients are equal, bit for bit and lane by lane (a string's masses, each
    /// lane with its own tuning), and the singles between such runs. Never allocates.
    fn find_mass_runs(&mut self) {
        let bits = |v: &Lanes| v.map(f64::to_bits);
        let coefficients =
            |i: usize| [&self.a[i], &self.b[i], &self.inv_m[i], &self.gravity[i]].map(bits);
        let runs = &mut self.mass_runs;
        let mut count = 0usize;
        let n = self.a.len();
        let mut start = 0;
        while start < n {
            let first = coefficients(start);
            let end = (start + 1..n)
                .find(|&i| coefficients(i) != first)
                .unwrap_or(n);
            let uniform = end - start >= UNIFORM_MASS_RUN;
            match count.checked_sub(1).map(|last| &mut runs[last]) {
                Some((_, last_end, false)) if !uniform => *last_end = end as u32,
                _ => {
                    runs[count] = (start as u32, end as u32, uniform);
                    count += 1;
                }
            }
            start = end;
        }
        self.mass_run_count = count;
        self.mass_runs_stale = false;
    }

    /// Runs `frames` samples of every lane. `inputs` holds the input channels one after the
    /// other, each `frames` samples of [`LANES`] values (`inputs[(c·frames + n)·LANES + l]`);
    /// `outputs` the same for the output channels. Non-finite inputs count as 0; a tripped
    /// lane writes zeros. Returns which lanes tripped during this block. Realtime-safe.
    pub fn process(&mut self, frames: usize, inputs: &[f64], outputs: &mut [f64]) -> [bool; LANES] {
        let per_channel = frames * LANES;
        let out_channels = outputs.len().checked_div(per_channel).unwrap_or(0);
        let in_channels = inputs.len().checked_div(per_channel).unwrap_or(0);
        outputs[..out_channels * per_channel].fill(0.0);
        if let Some(space) = &mut self.space {
            space.refresh();
            let before: [bool; LANES] = std::array::from_fn(|l| space.is_tripped(l));
            let arch = self.arch;
            arch.dispatch(SpaceBlock {
                lanes: space,
                frames,
                inputs,
                in_channels,
                outputs,
                out_channels,
            });
            return std::array::from_fn(|l| space.is_tripped(l) && !before[l]);
        }
        if self.params_dirty || self.gains_dirty.iter().any(|d| *d) {
            self.refresh();
        }
        if self.mass_runs_stale {
            self.find_mass_runs();
        }
        let before = self.tripped;
        let arch = self.arch;
        arch.dispatch(LaneBlock {
            lanes: self,
            frames,
            inputs,
            in_channels,
            outputs,
            out_channels,
        });
        std::array::from_fn(|l| self.tripped[l] && !before[l])
    }

    #[inline(always)]
    fn run<S: pulp::Simd>(
        &mut self,
        o: Ops<S>,
        frames: usize,
        inputs: &[f64],
        in_channels: usize,
        outputs: &mut [f64],
        out_channels: usize,
    ) {
        for n in 0..frames {
            self.step(o, n, frames, inputs, in_channels);
            self.write_outputs(o, n, frames, out_channels, outputs);
            // Lanes whose flush is due flush below FLUSH_BELOW, the others below 0 (never).
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
                self.flush(o, below);
            }
        }
        self.scan_positions(o);
    }

    /// One sample of every lane: stages 1 a, 2 a, 2 b, 3, 4 (interactions, then force inputs)
    /// and 5 of spec §1.5, in the plain engine's order.
    #[inline(always)]
    fn step<S: pulp::Simd>(
        &mut self,
        o: Ops<S>,
        n: usize,
        frames: usize,
        inputs: &[f64],
        in_channels: usize,
    ) {
        // The input of channel `ch` for lane `l` (non-finite and missing channels read 0).
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
        // Stage 1 a: avatars.
        for r in &self.template.model.avatars {
            let k = r.index as usize;
            for l in 0..LANES {
                self.xp[k][l] = self.x[k][l];
                self.x[k][l] = input(r.channel, l);
                self.f[k][l] = 0.0;
            }
        }
        // Stage 2 a: X[n+1] = a·X + b·X̃ + (F − g)·(1/M).
        let count = self.a.len();
        let (x, xp, f) = (
            &mut self.x[..count],
            &mut self.xp[..count],
            &mut self.f[..count],
        );
        let (a, b, g, inv_m) = (
            &self.a[..count],
            &self.b[..count],
            &self.gravity[..count],
            &self.inv_m[..count],
        );
        for &(start, end, uniform) in &self.mass_runs[..self.mass_run_count] {
            let (start, end) = (start as usize, end as usize);
            if uniform {
                let coefficients = (a[start], b[start], g[start], inv_m[start]);
                for i in start..end {
                    update_single(o, &mut x[i], &mut xp[i], &mut f[i], coefficients);
                }
            } else {
                for i in start..end {
                    let coefficients = (a[i], b[i], g[i], inv_m[i]);
                    update_single(o, &mut x[i], &mut xp[i], &mut f[i], coefficients);
                }
            }
        }
        // Stage 2 b: macros; stage 3: connection points.
        let macros = &self.template.macros;
        let (x, xp, f) = (&mut self.x[..], &mut self.xp[..], &mut self.f[..]);
        let v = &mut self.scratch_v[..];
        for mac in &macros.lines {
            structures::line_step(o, mac, false, x, xp, f, &self.args);
        }
        for mac in &macros.stiff {
            structures::line_step(o, mac, true, x, xp, f, &self.args);
        }
        for mac in &macros.meshes {
            structures::mesh_step(o, mac, x, xp, f, v, &self.args);
        }
        structures::place_connection_points(o, &self.proxies, x, xp, f);
        // Stage 4: the interactions, one loop per law, then the force inputs.
        let it = &self.template.interactions;
        let args = &self.args[..];
        let (x, xp, f) = (&self.x[..], &self.xp[..], &mut self.f[..]);
        LawKind::visit_all(&mut Stage4 {
            o,
            interactions: it,
            args,
            x,
            xp,
            f,
        });
        for r in &self.template.model.force_inputs {
            // A silent or missing channel adds 0, as the plain engine does (−0 + 0 = +0).
            let fi = &mut f[r.index as usize];
            for (l, v) in fi.iter_mut().enumerate() {
                *v += input(r.channel, l);
            }
        }
        // Stage 5: connection-point forces onto the macro nodes.
        structures::spread_connection_forces(o, &self.proxies, f);
    }

    /// Stage 6: frame `n` of every output of every lane; a lane whose output is non-finite
    /// or beyond the position limit trips (its outputs are 0 from this sample on, on every
    /// channel of this frame, as the plain engine clears them).
    #[inline(always)]
    fn write_outputs<S: pulp::Simd>(
        &mut self,
        o: Ops<S>,
        n: usize,
        frames: usize,
        out_channels: usize,
        outputs: &mut [f64],
    ) {
        let limit = self.template.position_limit;
        let t = &self.template;
        // Copies only: the checks stay out of this closure, which is compiled on its own.
        let mut put = |channel: u32, v: &Lanes| {
            let ch = channel as usize;
            if ch < out_channels {
                let at = (ch * frames + n) * LANES;
                outputs[at..at + LANES].copy_from_slice(&v.0);
            }
        };
        let mut beyond = Lanes::ZERO;
        for r in &t.model.pos_outputs {
            let v = self.x[r.index as usize];
            beyond = o.flag_beyond(v, limit, beyond);
            put(r.channel, &v);
        }
        for &(channel, start, len) in &t.model.frc_outputs {
            let sources = &t.model.frc_sources[start as usize..(start + len) as usize];
            // Σ F as `Iterator::sum` forms it: −0 + F₁ = F₁ bit for bit, then in order.
            let mut total = Lanes::splat(-0.0);
            for &p in sources {
                total = o.add(total, self.f[p as usize]);
            }
            beyond = o.flag_beyond(total, limit, beyond);
            put(channel, &total);
        }
        for l in 0..LANES {
            if beyond[l] != 0.0 {
                self.tripped[l] = true;
            }
        }
        if self.tripped.iter().any(|&t| t) {
            for l in (0..LANES).filter(|&l| self.tripped[l]) {
                for ch in 0..out_channels {
                    outputs[(ch * frames + n) * LANES + l] = 0.0;
                }
            }
        }
    }

    /// [`Engine`]'s flush: every position, delayed position and pending force smaller than
    /// `below` in its lane becomes 0 (`below` is [`FLUSH_BELOW`] in the lanes due, 0 in the
    /// others).
    #[inline(always)]
    fn flush<S: pulp::Simd>(&mut self, o: Ops<S>, below: Lanes) {
        for v in self
            .x
            .iter_mut()
            .chain(self.xp.iter_mut())
            .chain(self.f.iter_mut())
        {
            *v = o.zero_below(*v, below);
        }
    }

    /// Checks every position of every lane at the end of a block: a lane with one beyond the
    /// point limit ([`Engine::point_limit`]), or not a number, trips.
    #[inline(always)]
    fn scan_positions<S: pulp::Simd>(&mut self, o: Ops<S>) {
        let limit = self.template.point_limit();
        let mut beyond = Lanes::ZERO;
        for x in &self.x {
            beyond = o.flag_beyond(*x, limit, beyond);
        }
        for l in 0..LANES {
            if beyond[l] != 0.0 {
                self.tripped[l] = true;
            }
        }
    }
}

/// Stage 2 a for one single in every lane: X[n+1] = a·X + b·X̃ + (F − g)·(1/M) (spec
/// §2.1.2), then X̃ ← X, X ← X[n+1], F ← 0.
#[inline(always)]
fn update_single<S: pulp::Simd>(
    o: Ops<S>,
    x: &mut Lanes,
    xp: &mut Lanes,
    f: &mut Lanes,
    (a, b, g, inv_m): (Lanes, Lanes, Lanes, Lanes),
) {
    let (now, before, force) = (*x, *xp, *f);
    let next = o.add(
        o.add(o.mul(a, now), o.mul(b, before)),
        o.mul(o.sub(force, g), inv_m),
    );
    *xp = now;
    *x = next;
    *f = Lanes::ZERO;
}

/// The instruction set lanes run with: the best the CPU has (pulp's runtime detection), so a
/// group's [`Lanes`] is one AVX-512 register, two AVX2 ones, or eight scalars. The same IEEE
/// operations on every path (no fused multiply-add), so the same samples.
fn lane_arch() -> pulp::Arch {
    pulp::Arch::new()
}

/// One block of [`LaneEngine::process`] as a pulp operation (see `Engine::process`).
struct LaneBlock<'a> {
    lanes: &'a mut LaneEngine,
    frames: usize,
    inputs: &'a [f64],
    in_channels: usize,
    outputs: &'a mut [f64],
    out_channels: usize,
}

impl pulp::WithSimd for LaneBlock<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        self.lanes.run(
            Ops(simd),
            self.frames,
            self.inputs,
            self.in_channels,
            self.outputs,
            self.out_channels,
        )
    }
}

/// One block of a 3-D model's lanes as a pulp operation.
struct SpaceBlock<'a> {
    lanes: &'a mut space::SpaceLanes,
    frames: usize,
    inputs: &'a [f64],
    in_channels: usize,
    outputs: &'a mut [f64],
    out_channels: usize,
}

impl pulp::WithSimd for SpaceBlock<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        self.lanes.run(
            Ops(simd),
            self.frames,
            self.inputs,
            self.in_channels,
            self.outputs,
            self.out_channels,
        )
    }
}
