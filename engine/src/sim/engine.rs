//! The compiled model and its simulation: flat arrays grouped by element kind, run sample by
//! sample in the stage order of spec §1.5.
//!
//! Lifecycle: [`crate::compile`] (allocates, off the audio thread) → [`Engine::process`] /
//! [`Engine::set_param`] / [`Engine::reset`] (realtime: no allocation, lock, log or I/O) → drop
//! (off the audio thread).
//!
//! Layout of the point arrays (`x`, `xp`, `f`), which is also the generic motion-buffer order of
//! spec §6.2 for the first three ranges:
//!
//! ```text
//! [ single mass-type elements | macro nodes, macro by macro | avatars | connection points ]
//! ```
//!
//! Stage 2 a runs one loop over the first range with per-point coefficients (a ground is the
//! M → ∞ limit: a = 1, b = 0, 1/M = 0, so it never moves and needs no branch). Each macro kind has
//! its own stencil kernel. Each interaction law has its own loop over endpoint index arrays.
//! Names never reach this module's hot paths; there is no per-element `match`.

use crate::laws::{ArgClass, NUM_ARG_CLASSES};
pub(crate) use crate::sim::compiled::Compiled;
pub(crate) use crate::sim::compiled::{Binding, InitRule, InitRun, Route};
use crate::sim::control::{Changed, ControlArgs};
use crate::sim::display;
pub use crate::sim::display::{IoKind, IoPoint};
use crate::sim::flush::flush_tiny;
pub use crate::sim::flush::{FLUSH_BELOW, FLUSH_INTERVAL};
use crate::sim::guard;
pub use crate::sim::guard::{GuardEvent, GuardKind};
use crate::sim::info::ModelInfo;
use crate::sim::jit::NativeCode;
pub(crate) use crate::sim::kernels::masses::{single_law, SingleMasses};
pub(crate) use crate::sim::kernels::Points;
use crate::sim::motion::MotionStore;
use crate::sim::rest;
pub(crate) use crate::sim::rest::Rest;
use crate::spec::ScaleClass;
use std::sync::Arc;

/// The host buffers' shape for one block of [`Engine::process`]: `in_channels` slices of
/// `frames` samples back to back in `inputs`; the outputs, passed beside it, are
/// `out_channels` such slices.
#[derive(Clone, Copy)]
pub(crate) struct BlockIo<'a> {
    pub frames: usize,
    pub inputs: &'a [f64],
    pub in_channels: usize,
    pub out_channels: usize,
}

pub(crate) use crate::sim::kernels::links::{Group, Interactions};
pub(crate) use crate::sim::kernels::macros::{LineMacro, MacroSlots, Macros, MeshMacro};
pub(crate) use crate::sim::kernels::proxies::Proxies;

/// The default runaway limit on outputs, in model units. Reference models move by less than a
/// few units.
pub const DEFAULT_POSITION_LIMIT: f64 = 1.0e4;

/// How many times the position limit a point may travel before the guard trips on it. The
/// outputs, which reach the ears, are held to the limit itself; a point no output hears is
/// guarded for the numbers only (10¹² by default, where the model's own motion still has
/// 10⁻⁴ of resolution). A large steady force on a soft spring moves a point that far without
/// any instability: a hammer hung on K = 10⁻⁴, pushed away from its membrane by a sidechain's
/// DC at Force Gain +38 dB, passed 10⁴ in 9 ms and silenced the instrument with a guard trip
/// while every output was at rest.
pub const POINT_LIMIT_FACTOR: f64 = 1.0e8;

/// A compiled model and one running copy of it: the immutable model ([`Compiled`], shared by
/// every copy behind an `Arc`) and this copy's state. Built by [`crate::compile`]. A clone is a
/// new voice: it copies the state and shares the model.
///
/// 3,728 bytes on x86-64 (checked below; 2,376 of them are the vector headers of the nine
/// law groups), and on the heap: 24 bytes per point (x, x̃, F), 8 per link of the longest
/// chain, 8 per argument slot, 47 per single mass (a, b, 1/M, g, three flags and a run), 16
/// per node of the largest macro (its scratch), 12 per link (endpoints and element) and 2 per
/// chain of the law groups.
#[derive(Clone, Debug)]
pub struct Engine {
    /// Labels and metadata, expressions, routes and initial-state runs: never written after
    /// compilation.
    pub(crate) model: Arc<Compiled>,

    // Hot state, read or written at every sample.
    pub(crate) points: Points,
    /// Per-step argument values (after scaling and class gains), column by column.
    pub(crate) args: Vec<f64>,
    pub(crate) singles: SingleMasses,
    pub(crate) macros: Macros,
    pub(crate) proxies: Proxies,
    pub(crate) interactions: Interactions,
    /// Current parameter values, by parameter id.
    pub(crate) params: Vec<f64>,
    /// The declared default of each entry of `model.audio_params`, added to its input; set by
    /// [`Engine::set_param`].
    pub(crate) audio_defaults: Vec<f64>,
    pub(crate) stack: crate::spec::expr::EvalStack,

    // Controls: written at a block boundary after a change.
    /// Arguments that depend on no audio-rate parameter: brought up to date at a block
    /// boundary after a control parameter or a class gain changed.
    pub(crate) control: ControlArgs,
    /// Host gain of each class (1 unless the host changes it).
    pub(crate) class_gain: [f64; NUM_ARG_CLASSES],
    pub(crate) params_dirty: bool,

    // Guard and motion.
    pub(crate) position_limit: f64,
    pub(crate) guard: Option<GuardEvent>,
    pub(crate) samples_since_reset: u64,
    pub(crate) motion: Option<Arc<MotionStore>>,
    pub(crate) motion_counter: u32,
    /// Whether the state is known to be a fixed point of the sample loop ([`Rest`]).
    pub(crate) rest: Rest,
    /// The instruction set the sample loop runs with, detected once: the loop is compiled for
    /// the baseline, AVX2 and AVX-512 (pulp's x86-v3 and x86-v4), and [`Engine::process`]
    /// picks the best the CPU has. Without FMA contraction all give the same IEEE operations,
    /// so the same samples.
    pub(crate) arch: pulp::Arch,
    /// The sample loop compiled to machine code, for small models ([`crate::sim::jit`]); shared
    /// by the engine's copies, as `model` is.
    pub(crate) native: Option<Arc<NativeCode>>,
    /// Whether `native` runs the model as it stands ([`crate::sim::jit::NativeCode::fits`]):
    /// updated with the coefficients at every control change.
    pub(crate) native_fits: bool,
    /// A 3-D model's x and y axes and everything but its z axis, which is `points`
    /// ([`crate::sim::space`]); `None` for a 1-D model, whose kinds are the fields above.
    pub(crate) space: Option<Box<crate::sim::space::Space>>,
}

/// One block of [`Engine::process`] as a pulp operation: `with_simd` is inlined into the
/// instruction set's `#[target_feature]` entry point, and with it the whole sample loop.
struct Block<'a> {
    engine: &'a mut Engine,
    /// The samples `start..end` of the block.
    start: usize,
    end: usize,
    io: BlockIo<'a>,
    outputs: &'a mut [f64],
}

impl pulp::WithSimd for Block<'_> {
    type Output = usize;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> usize {
        self.engine.run(self.start..self.end, self.io, self.outputs)
    }
}

/// Whether every input sample reads as +0: +0 itself, or a non-finite value (read as 0).
/// On 32-bit halves and without a short circuit within 64 samples, so that it vectorises on
/// plain x86-64 (SSE2 has no 64-bit compare): a tiny model's whole block costs little more
/// than a scalar scan of its input.
pub(crate) fn silent(inputs: &[f64]) -> bool {
    inputs.chunks(64).all(|chunk| {
        let mut loud = 0u32;
        for v in chunk {
            let bits = v.to_bits();
            let (hi, lo) = ((bits >> 32) as u32, bits as u32);
            // Finite (the exponent is not all ones) and not +0.
            loud |= ((hi & 0x7ff0_0000 != 0x7ff0_0000) & ((hi | lo) != 0)) as u32;
        }
        loud == 0
    })
}

/// An error setting a parameter.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamError {
    /// No parameter has that id.
    UnknownParam(u32),
    /// The value is NaN or infinite.
    NonFinite(f64),
}

impl std::fmt::Display for ParamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ParamError::UnknownParam(id) => write!(f, "no parameter with id {id}"),
            ParamError::NonFinite(v) => write!(f, "parameter value {v} is not finite"),
        }
    }
}

impl std::error::Error for ParamError {}

/// A parameter handle, stable for the life of one compiled model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ParamId(pub u32);

/// What one [`Engine::process`] call did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BlockReport {
    /// Frames simulated (not silenced by the guard).
    pub simulated: usize,
    /// True when the guard tripped during this block.
    pub tripped: bool,
}

impl Engine {
    /// The model's metadata: counts, labels, parameters, channels, motion layout.
    pub fn info(&self) -> &ModelInfo {
        &self.model.info
    }

    /// Where the model's inputs and outputs sit, for displays (spec §6): one entry per force
    /// input, position input (its avatar), position output and force output, located on a
    /// material point of the generic motion buffer.
    pub fn io_points(&self) -> Vec<IoPoint> {
        match &self.space {
            Some(space) => display::space_io_points(space, self.model.info.num_points),
            None => display::io_points(&self.model, &self.proxies),
        }
    }

    /// The explicit interactions as pairs of material points (connection points replaced by
    /// their heaviest node), for drawing a structure. Macro-internal links are not listed:
    /// they join consecutive nodes of a string and neighbours of a mesh (spec §2.7).
    pub fn links(&self) -> Vec<(u32, u32)> {
        match &self.space {
            // A 3-D model's structures are links like any other (3-D spec §4.0).
            Some(space) => display::space_links(space, self.model.info.num_points),
            None => display::links(&self.model, &self.proxies, &self.interactions),
        }
    }

    /// The positions of every point on each axis, x, y, z: a 1-D model's x and y are empty.
    pub fn axes(&self) -> [&[f64]; 3] {
        [self.axis(0), self.axis(1), self.axis(2)]
    }

    /// The sample rate the model was compiled for, in Hz.
    pub fn sample_rate_hz(&self) -> f64 {
        self.model.info.sample_rate_hz
    }

    /// Looks up a parameter by name (off the audio thread: it compares strings).
    pub fn param_id(&self, name: &str) -> Option<ParamId> {
        self.model
            .info
            .params
            .iter()
            .position(|p| p.name == name)
            .map(|i| ParamId(i as u32))
    }

    /// The current value of a parameter. An audio-rate one holds its default plus its last
    /// input sample; before the first sample, and from [`Engine::set_param`] to the next
    /// sample, it holds its default.
    pub fn param(&self, id: ParamId) -> Option<f64> {
        self.params.get(id.0 as usize).copied()
    }

    /// Sets a parameter. It takes effect at the start of the next [`Engine::process`] call
    /// (spec §3.5), or at [`Engine::apply_pending_changes`]. For an audio-rate parameter
    /// (`audioParam @inN default`) it sets the default, the centre its input modulates
    /// around: from the next sample on the parameter is `value` + input N. Realtime-safe.
    pub fn set_param(&mut self, id: ParamId, value: f64) -> Result<(), ParamError> {
        let i = id.0 as usize;
        if i >= self.params.len() {
            return Err(ParamError::UnknownParam(id.0));
        }
        if !value.is_finite() {
            return Err(ParamError::NonFinite(value));
        }
        if let Some(r) = self.model.audio_params.iter().position(|r| r.index == id.0) {
            // The default is read at every sample (stage 1 b), so it acts from the first
            // sample of the next block. The value itself becomes the default until then, so
            // the stability analysis and a reset see the new centre.
            if self.audio_defaults[r] != value {
                self.audio_defaults[r] = value;
                self.params[i] = value;
                self.params_dirty = true;
            }
        } else if self.params[i] != value {
            self.params[i] = value;
            self.params_dirty = true;
        }
        Ok(())
    }

    /// Multiplies every argument of a scaling class by `gain` on top of the sample-rate factor:
    /// the host's global Stiffness (K class) and Damping (Z class: Z, Znl, Zo) controls. Other
    /// classes ignore it. Non-finite or negative gains are ignored. Takes effect at the next
    /// block. Realtime-safe.
    pub fn set_class_gain(&mut self, class: ScaleClass, gain: f64) {
        let slot = match class {
            ScaleClass::Stiffness => ArgClass::Stiffness,
            ScaleClass::Damping => ArgClass::Damping,
            ScaleClass::None | ScaleClass::Gravity => return,
        } as usize;
        if gain.is_finite() && gain >= 0.0 && self.class_gain[slot] != gain {
            self.class_gain[slot] = gain;
            self.params_dirty = true;
        }
    }

    /// The host gain of a class (1 by default).
    pub fn class_gain(&self, class: ScaleClass) -> f64 {
        match class {
            ScaleClass::Stiffness => self.class_gain[ArgClass::Stiffness as usize],
            ScaleClass::Damping => self.class_gain[ArgClass::Damping as usize],
            ScaleClass::None | ScaleClass::Gravity => 1.0,
        }
    }

    /// The runaway limit on outputs, in model units.
    pub fn position_limit(&self) -> f64 {
        self.position_limit
    }

    /// The runaway limit on the points' positions: [`POINT_LIMIT_FACTOR`] × the position
    /// limit.
    pub fn point_limit(&self) -> f64 {
        self.position_limit * POINT_LIMIT_FACTOR
    }

    /// Sets the runaway limit (non-finite or non-positive values are ignored).
    pub fn set_position_limit(&mut self, limit: f64) {
        if limit.is_finite() && limit > 0.0 {
            self.position_limit = limit;
        }
    }

    /// The guard's event since the last reset. While it is set, the engine outputs silence.
    pub fn guard_event(&self) -> Option<GuardEvent> {
        self.guard
    }

    /// True while the guard holds the engine silent.
    pub fn is_tripped(&self) -> bool {
        self.guard.is_some()
    }

    /// Attaches (or detaches, with `None`) the motion store that stage 7 writes. While none is
    /// attached, the refresh counter does not advance (spec §6.1). Realtime-safe, but dropping
    /// the last `Arc` of a store frees it: detach off the audio thread.
    pub fn set_motion_store(
        &mut self,
        store: Option<Arc<MotionStore>>,
    ) -> Option<Arc<MotionStore>> {
        self.motion_counter = 0;
        std::mem::replace(&mut self.motion, store)
    }

    /// The motion refresh interval R, in samples.
    pub fn motion_interval(&self) -> u32 {
        self.model.motion_interval
    }

    /// Current positions of every point: the material points of [`ModelInfo::points`], then
    /// the connection points.
    pub fn positions(&self) -> &[f64] {
        &self.points.x
    }

    /// Whether the model is three-dimensional (`~dim 3`).
    pub fn is_3d(&self) -> bool {
        self.space.is_some()
    }

    /// A 3-D model's link count per law of the 3-D table, in [`SpaceLawKind::ALL`] order
    /// (empty for a 1-D model): what the differential tests check they cover.
    ///
    /// [`SpaceLawKind::ALL`]: crate::laws::space::SpaceLawKind::ALL
    #[doc(hidden)]
    pub fn space_law_links(&self) -> Vec<usize> {
        self.space.as_ref().map_or(Vec::new(), |s| {
            s.model.groups.iter().map(|g| g.len()).collect()
        })
    }

    /// The positions along axis `c` (0 x, 1 y, 2 z) of every point, in the order of
    /// [`Engine::positions`]: a 1-D model's positions are its z axis, its x and y are empty.
    pub fn axis(&self, c: usize) -> &[f64] {
        match (&self.space, c) {
            (Some(s), 0) => &s.ax.x,
            (Some(s), 1) => &s.ay.x,
            (_, 2) => &self.points.x,
            _ => &[],
        }
    }

    /// The state along axis `c` (0 x, 1 y, 2 z) of every point: positions, delayed
    /// positions and forces, in the order of [`Engine::positions`] (a 1-D model's x and y
    /// are empty): what the differential tests compare.
    #[doc(hidden)]
    pub fn axis_state(&self, c: usize) -> [&[f64]; 3] {
        let p = match (&self.space, c) {
            (Some(s), 0) => &s.ax,
            (Some(s), 1) => &s.ay,
            (_, 2) => &self.points,
            _ => return [&[], &[], &[]],
        };
        [&p.x, &p.xp, &p.f]
    }

    /// How much the model moved: the largest |x − x̃| of any point on any axis, and of
    /// |x − last| on the z axis (`last` is updated to x; the positions' length). A voice
    /// bank frees a voice whose level stays below its threshold.
    pub fn motion_level(&self, last: &mut [f64]) -> f64 {
        let mut level: f64 = 0.0;
        let p = &self.points;
        for ((x, xp), last) in p.x.iter().zip(&p.xp).zip(last.iter_mut()) {
            level = level.max((x - xp).abs()).max((x - *last).abs());
            *last = *x;
        }
        if let Some(space) = &self.space {
            for axis in [&space.ax, &space.ay] {
                for (x, xp) in axis.x.iter().zip(&axis.xp) {
                    level = level.max((x - xp).abs());
                }
            }
        }
        level
    }

    /// What input channel `channel` (0-based) holds when nothing feeds it, for a position
    /// input: its avatar's declared position along its direction (3-D spec §3.1: the channel
    /// is the coordinate along â, P·â; an XYZ avatar's channels its coordinates). `None` when
    /// no avatar reads it.
    pub fn avatar_rest(&self, channel: usize) -> Option<f64> {
        let space = self.space.as_ref()?;
        let m = &space.model;
        for av in &m.avatars {
            match *av {
                crate::sim::space::Avatar::Line {
                    channel: c, perp, ..
                } if c as usize == channel => {
                    let (slots, dir) = m.directions.perp[perp as usize];
                    let at = slots.map(|k| self.args[k as usize]);
                    let d = space.directions.units[dir as usize];
                    return Some((at[0] * d[0] + at[1] * d[1]) + at[2] * d[2]);
                }
                crate::sim::space::Avatar::Xyz { point, channel: c } => {
                    let c = c as usize;
                    if (c..c + 3).contains(&channel) {
                        let axis = channel - c;
                        let init = self.axis(axis).get(point as usize).copied();
                        return init;
                    }
                }
                _ => {}
            }
        }
        None
    }

    /// Delayed positions x̃, in the order of [`Engine::positions`].
    pub fn delayed_positions(&self) -> &[f64] {
        &self.points.xp
    }

    /// Force accumulators, in the order of [`Engine::positions`]. The nodes of a mesh of
    /// [`ROW_SWEEP_NODES`](crate::sim::kernels::mesh::ROW_SWEEP_NODES) nodes or more hold only the
    /// forces their connection points spread: the row sweep computes the mesh's own link
    /// forces when it uses them.
    pub fn forces(&self) -> &[f64] {
        &self.points.f
    }

    /// Restores the initial state of spec §1.5 stage 0: positions from the current parameter
    /// values, delayed positions from the initial velocities, every force cleared, the guard
    /// and the motion counter reset. Parameters keep their values. Realtime-safe.
    pub fn reset(&mut self) {
        self.refresh_control();
        if let Some(space) = &mut self.space {
            let (program, params, stack) = (&self.model.program, &self.params, &mut self.stack);
            space.reset(&mut self.points, &self.args, |e| {
                program.eval(e, params, stack)
            });
            self.flush_all();
            self.guard = None;
            self.rest = Rest::Moving;
            self.samples_since_reset = 0;
            self.motion_counter = 0;
            return;
        }
        self.points.f.fill(0.0);
        self.macros.reset();
        for run in &self.model.init_runs {
            let x0 = self
                .model
                .program
                .eval(run.x0, &self.params, &mut self.stack);
            let xp = match run.rule {
                InitRule::Fixed => x0,
                InitRule::Velocity { v, factor } => {
                    x0 - self.model.program.eval(v, &self.params, &mut self.stack) * factor
                }
                InitRule::Delayed { xr0, factor } => {
                    x0 - (x0 - self.model.program.eval(xr0, &self.params, &mut self.stack)) * factor
                }
            };
            let range = run.first as usize..(run.first + run.count) as usize;
            self.points.x[range.clone()].fill(x0);
            self.points.xp[range].fill(xp);
        }
        for &p in &self.model.init_fixed_points {
            self.points.xp[p as usize] = self.points.x[p as usize];
        }
        // Connection points start at their interpolated position with no velocity.
        for i in 0..self.proxies.len() {
            let pos = self.proxies.interpolate(i, &self.points.x);
            let k = self.proxies.base + i;
            self.points.x[k] = pos;
            self.points.xp[k] = pos;
        }
        flush_tiny(&mut self.points);
        self.guard = None;
        self.rest = Rest::Moving;
        self.samples_since_reset = 0;
        self.motion_counter = 0;
    }

    /// The positions of stage 0 (spec §1.5) with the current parameter values, every point
    /// then every connection point, without touching the running state: the rest state the
    /// modal analysis linearises at. Allocates (off the audio thread).
    pub(crate) fn rest_positions(&mut self) -> Vec<f64> {
        self.apply_pending_changes();
        let mut x = vec![0.0; self.points.x.len()];
        for run in &self.model.init_runs {
            let x0 = self
                .model
                .program
                .eval(run.x0, &self.params, &mut self.stack);
            x[run.first as usize..(run.first + run.count) as usize].fill(x0);
        }
        for i in 0..self.proxies.len() {
            x[self.proxies.base + i] = self.proxies.interpolate(i, &x);
        }
        x
    }

    /// Applies parameter and gain changes now instead of at the next block.
    pub fn apply_pending_changes(&mut self) {
        if self.params_dirty {
            self.refresh_control();
        }
    }

    /// Re-evaluates every argument that depends on no audio-rate parameter, then the derived
    /// coefficients. Runs at a block boundary, only after a change.
    fn refresh_control(&mut self) {
        let scale = self.class_factors();
        let changed = self.control.refresh(
            &self.model.program,
            &self.params,
            &mut self.stack,
            &scale,
            &mut self.args,
        );
        self.refresh_audio_args(&scale);
        if let Some(space) = &mut self.space {
            space.derive(&self.args);
        }
        match changed {
            Changed::All => {
                for i in 0..self.singles.len() {
                    self.singles.derive(i, &self.args);
                }
                self.singles.classify();
                for i in 0..self.proxies.len() {
                    self.proxies.derive(i, &self.args);
                }
            }
            Changed::Some { proxies, .. } => {
                for &i in self.control.dirty_singles() {
                    self.singles.derive(i as usize, &self.args);
                }
                if !self.control.dirty_singles().is_empty() {
                    self.singles.classify();
                }
                // Audio-rate arguments follow the class factors too.
                for &i in &self.model.audio_masses {
                    self.singles.derive(i as usize, &self.args);
                }
                for i in 0..self.proxies.len() {
                    if proxies || self.model.audio_proxies.contains(&(i as u32)) {
                        self.proxies.derive(i, &self.args);
                    }
                }
            }
        }
        // Which chains read one set of arguments: compared before the class factors (one per
        // column), so that a change of factor alone cannot change the answer.
        if matches!(changed, Changed::All | Changed::Some { values: true, .. }) {
            self.interactions.find_uniform(self.control.raw());
        }
        self.native_fits = self
            .native
            .as_ref()
            .is_some_and(|code| code.fits(&self.parts()));
        // New coefficients end a fixed point (`rest.rs`), whichever call applied them.
        self.rest = Rest::Moving;
        self.params_dirty = false;
    }

    #[inline]
    fn class_factors(&self) -> [f64; NUM_ARG_CLASSES] {
        let mut f = self.model.class_scale;
        for (f, g) in f.iter_mut().zip(self.class_gain) {
            *f *= g;
        }
        f
    }

    /// Evaluates the audio-rate arguments (stage 1 b consequences).
    #[inline]
    fn refresh_audio_args(&mut self, scale: &[f64; NUM_ARG_CLASSES]) {
        for b in &self.model.audio_bindings {
            self.args[b.slot as usize] =
                self.model
                    .program
                    .eval(b.expr, &self.params, &mut self.stack)
                    * scale[b.class as usize];
        }
    }

    /// Runs `frames` samples. `inputs` holds the input channels one after the other, each
    /// `frames` long (channel c at `inputs[c*frames..(c+1)*frames]`); channels it does not hold
    /// are silent, and non-finite input samples count as 0. `outputs` receives the output
    /// channels the same way; channels beyond its length are not written.
    ///
    /// Processing N frames in one call gives bit-identical results to N calls of one frame.
    /// While the guard is tripped, the outputs are zero. Realtime-safe.
    pub fn process(&mut self, frames: usize, inputs: &[f64], outputs: &mut [f64]) -> BlockReport {
        let out_channels = outputs.len().checked_div(frames).unwrap_or(0);
        let in_channels = inputs.len().checked_div(frames).unwrap_or(0);
        outputs[..out_channels * frames].fill(0.0);
        if self.params_dirty {
            self.refresh_control();
        }
        let was_tripped = self.guard.is_some();
        let mut simulated = 0;
        if !was_tripped {
            // Quiet: every input sample reads as +0 (non-finite ones count as 0), and no
            // motion store wants the frames written. Asked only of a model at rest or
            // coming to rest: the scan costs a tiny model as much as its samples.
            let quiet = |e: &Engine| e.motion.is_none() && silent(&inputs[..in_channels * frames]);
            if self.rest != Rest::Moving && !quiet(self) {
                self.rest = Rest::Moving;
            }
            let io = BlockIo {
                frames,
                inputs,
                in_channels,
                out_channels,
            };
            let block = |engine: &mut Engine, outputs: &mut [f64], start: usize, end: usize| {
                if engine.native_fits && engine.motion.is_none() {
                    return engine.run_native(start..end, io, outputs);
                }
                engine.run_interpreted(start..end, io, outputs)
            };
            let mut start = 0;
            if self.rest == Rest::Still && frames > 0 {
                // Still after a silent sample: one more decides whether this is a fixed point.
                simulated = block(self, outputs, 0, 1);
                start = 1;
                self.rest = if self.guard.is_none() && self.stationary() {
                    Rest::Fixed
                } else {
                    Rest::Moving
                };
            }
            if self.guard.is_none() && start < frames {
                simulated = if self.rest == Rest::Fixed {
                    self.hold(start, frames, outputs, out_channels)
                } else {
                    let n = block(self, outputs, start, frames);
                    if self.guard.is_none() && self.stationary() && quiet(self) {
                        self.rest = Rest::Still;
                    }
                    n
                };
            }
            if self.guard.is_none() {
                let limit = self.point_limit();
                let mut bad = guard::scan_positions(&self.points.x, limit);
                if let Some(space) = &self.space {
                    bad = bad
                        .or_else(|| guard::scan_positions(&space.ax.x, limit))
                        .or_else(|| guard::scan_positions(&space.ay.x, limit));
                }
                if let Some((kind, point)) = bad {
                    self.trip(kind, Some(point), None);
                }
            }
        }
        BlockReport {
            simulated,
            tripped: !was_tripped && self.guard.is_some(),
        }
    }

    /// Samples `samples` of a block on the interpreter, with the instruction set of
    /// `self.arch`. Returns how many samples ran (fewer when the guard trips).
    pub(crate) fn run_interpreted(
        &mut self,
        samples: std::ops::Range<usize>,
        io: BlockIo<'_>,
        outputs: &mut [f64],
    ) -> usize {
        self.arch.dispatch(Block {
            start: samples.start,
            end: samples.end,
            engine: self,
            io,
            outputs,
        })
    }

    /// The sample loop of [`Engine::process`], inlined into each instruction set's copy.
    /// Returns how many samples ran (fewer when the guard trips).
    ///
    /// Stage 7 (the motion buffers) runs only on the samples where the motion counter is 0:
    /// the samples between them run a loop without it, and so does every sample while no
    /// store is attached.
    #[inline(always)]
    fn run(
        &mut self,
        samples: std::ops::Range<usize>,
        io: BlockIo<'_>,
        outputs: &mut [f64],
    ) -> usize {
        let scale = self.class_factors();
        let mut n = samples.start;
        let frames_end = samples.end;
        while n < frames_end {
            let watched = self.motion.is_some();
            let until_write = match (watched, self.motion_counter) {
                (false, _) => frames_end,
                (true, 0) => 0,
                (true, c) => (self.model.motion_interval - c) as usize,
            };
            let end = frames_end.min(n + until_write);
            for k in n..end {
                if self.sample::<false>(k, &io, outputs, &scale) {
                    return k + 1;
                }
            }
            if watched {
                self.motion_counter = ((self.motion_counter as usize + (end - n))
                    % self.model.motion_interval as usize)
                    as u32;
            }
            n = end;
            if n < frames_end && watched {
                // The counter is 0: this sample writes the motion buffers.
                if self.sample::<true>(n, &io, outputs, &scale) {
                    return n + 1;
                }
                self.motion_counter = 1 % self.model.motion_interval;
                n += 1;
            }
        }
        frames_end
    }

    /// Sample `n` of a block: stages 1 to 7, the guard's check and the periodic flush.
    /// Returns true when the guard tripped (the rest of the block's outputs are then 0).
    #[inline(always)]
    fn sample<const MOTION: bool>(
        &mut self,
        n: usize,
        io: &BlockIo<'_>,
        outputs: &mut [f64],
        scale: &[f64; NUM_ARG_CLASSES],
    ) -> bool {
        let input = |ch: u32| -> f64 {
            let ch = ch as usize;
            if ch < io.in_channels {
                let v = io.inputs[ch * io.frames + n];
                if v.is_finite() {
                    v
                } else {
                    0.0
                }
            } else {
                0.0
            }
        };
        self.step(&input, scale);
        // Stage 7: motion buffers, on the first sample and then every R samples.
        if MOTION {
            if let Some(store) = &self.motion {
                store.write(&self.points.x[..self.model.info.num_points]);
            }
        }
        if self.outputs_or_trip(n, io.frames, io.out_channels, outputs) {
            return true;
        }
        self.samples_since_reset += 1;
        if self.samples_since_reset.is_multiple_of(FLUSH_INTERVAL) {
            self.flush_all();
        }
        false
    }

    /// The periodic flush on every axis.
    #[inline(always)]
    pub(crate) fn flush_all(&mut self) {
        flush_tiny(&mut self.points);
        if let Some(space) = &mut self.space {
            for axis in space.planar_axes() {
                flush_tiny(axis);
            }
        }
    }

    /// Whether every point of every axis stands still ([`rest::stationary`]).
    fn stationary(&self) -> bool {
        rest::stationary(&self.points)
            && self
                .space
                .as_ref()
                .is_none_or(|s| rest::stationary(&s.ax) && rest::stationary(&s.ay))
    }

    /// One sample: stages 1 to 5 of spec §1.5 (stage 6 is `write_outputs`, stage 7 in
    /// `sample`).
    #[inline(always)]
    fn step(&mut self, input: &impl Fn(u32) -> f64, scale: &[f64; NUM_ARG_CLASSES]) {
        if self.space.is_some() {
            return self.step_space(input, scale);
        }
        // Stage 1 a: avatars.
        for r in &self.model.avatars {
            let k = r.index as usize;
            self.points.xp[k] = self.points.x[k];
            self.points.x[k] = input(r.channel);
            self.points.f[k] = 0.0;
        }
        // Stage 1 b: audio-rate parameters, and the arguments and coefficients that use them.
        if !self.model.audio_params.is_empty() {
            // Default + signal (`ParamKind::Audio`): spec §1.5 stage 1 b with the default of
            // this project's `audioParam @inN default`; 0 gives the spec's in_N(n) exactly.
            for (r, d) in self.model.audio_params.iter().zip(&self.audio_defaults) {
                self.params[r.index as usize] = d + input(r.channel);
            }
            self.refresh_audio_args(scale);
            for &i in &self.model.audio_masses {
                self.singles.derive(i as usize, &self.args);
            }
            for &i in &self.model.audio_proxies {
                self.proxies.derive(i as usize, &self.args);
            }
        }
        // Stage 2 a: single mass-type elements; 2 b: macros and their internal links.
        self.singles.step(&mut self.points);
        let avx2 = crate::sim::kernels::is_avx2(self.arch);
        self.macros
            .step(&mut self.points, &self.args, &self.proxies, avx2);
        // Stage 3: connection-point positions.
        self.proxies.update_positions(&mut self.points);
        // Stage 4: interactions, then force inputs.
        self.interactions.step(&mut self.points, &self.args);
        for r in &self.model.force_inputs {
            self.points.f[r.index as usize] += input(r.channel);
        }
        // Stage 5: connection-point force spreading.
        self.proxies.spread_forces(&mut self.points);
    }

    /// One sample of a 3-D model: stages 1 to 5 of 3-D spec §1.5.
    #[inline(always)]
    fn step_space(&mut self, input: &impl Fn(u32) -> f64, scale: &[f64; NUM_ARG_CLASSES]) {
        let Some(space) = &mut self.space else {
            return;
        };
        // Stage 1 a: avatars.
        space.avatars(&mut self.points, input);
        // Stage 1 b: audio-rate parameters and what they move.
        if !self.model.audio_params.is_empty() {
            for (r, d) in self.model.audio_params.iter().zip(&self.audio_defaults) {
                self.params[r.index as usize] = d + input(r.channel);
            }
            for b in &self.model.audio_bindings {
                self.args[b.slot as usize] =
                    self.model
                        .program
                        .eval(b.expr, &self.params, &mut self.stack)
                        * scale[b.class as usize];
            }
            space.derive_audio(&self.args);
        }
        // Stages 2 to 5.
        space.step(&mut self.points, &self.args, input, self.arch);
    }

    /// Samples `start..frames` of a block at a fixed point ([`Rest::Fixed`], `rest.rs`): the
    /// outputs repeat (stage 6 and its guard still run), the state stays, the sample count goes on.
    /// Returns the samples done, as [`Engine::run`].
    pub(crate) fn hold(
        &mut self,
        start: usize,
        frames: usize,
        outputs: &mut [f64],
        out_channels: usize,
    ) -> usize {
        for n in start..frames {
            // Only a lowered position limit can make a held output bad.
            if self.outputs_or_trip(n, frames, out_channels, outputs) {
                return n + 1;
            }
            self.samples_since_reset += 1;
        }
        frames
    }

    /// Holds the engine silent from now on, with what the guard saw.
    pub(crate) fn trip(&mut self, kind: GuardKind, point: Option<u32>, output: Option<u32>) {
        self.guard = Some(GuardEvent {
            sample: self.samples_since_reset,
            kind,
            point,
            output,
        });
    }

    /// Stage 6 and its guard: writes frame `n` of every output; on a bad value, trips and
    /// clears the block's outputs from `n` on. Returns whether it tripped.
    #[inline(always)]
    pub(crate) fn outputs_or_trip(
        &mut self,
        n: usize,
        frames: usize,
        out_channels: usize,
        outputs: &mut [f64],
    ) -> bool {
        let Some(bad) = self.write_outputs(n, frames, out_channels, outputs) else {
            return false;
        };
        self.trip(bad.0, None, Some(bad.1));
        for ch in 0..out_channels {
            outputs[ch * frames + n..(ch + 1) * frames].fill(0.0);
        }
        true
    }

    /// Stage 6: writes frame `n` of every output. Returns the first bad value's kind and
    /// channel, if any.
    #[inline(always)]
    fn write_outputs(
        &self,
        n: usize,
        frames: usize,
        out_channels: usize,
        outputs: &mut [f64],
    ) -> Option<(GuardKind, u32)> {
        let limit = self.position_limit;
        let mut bad = None;
        let mut put = |channel: u32, v: f64| {
            let ch = channel as usize;
            if ch < out_channels {
                outputs[ch * frames + n] = v;
            }
            if bad.is_none() {
                if !v.is_finite() {
                    bad = Some((GuardKind::NonFinite, channel));
                } else if v.abs() > limit {
                    bad = Some((GuardKind::Runaway, channel));
                }
            }
        };
        if let Some(space) = &self.space {
            for o in &space.model.outputs {
                put(o.channel(), space.output(o, &self.points));
            }
            return bad;
        }
        for r in &self.model.pos_outputs {
            put(r.channel, self.points.x[r.index as usize]);
        }
        for &(channel, start, len) in &self.model.frc_outputs {
            let sources = &self.model.frc_sources[start as usize..(start + len) as usize];
            let total = sources.iter().map(|&p| self.points.f[p as usize]).sum();
            put(channel, total);
        }
        bad
    }
}

/// The size written in [`Engine`]'s doc comment.
#[cfg(target_arch = "x86_64")]
const _: () = assert!(std::mem::size_of::<Engine>() == 3728);
