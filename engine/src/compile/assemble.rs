//! The last step: the motion layout (rendering coordinates and named buffers, spec §6.3), the
//! model's metadata, and the engine itself, reset to its initial state.

use super::bind::Bound;
use super::context::Cx;
use super::errors::CompileErrors;
use super::kinds::Kinds;
use super::labels::Params;
use super::points::Numbering;
use super::{CompileOptions, Rate};
use crate::laws::{ArgClass, NUM_ARG_CLASSES};
use crate::sim::control::ControlArgs;
use crate::sim::engine::{Compiled, Engine, Points, DEFAULT_POSITION_LIMIT};
use crate::sim::info::{ModelInfo, ParamInfo};
use crate::sim::motion::{MotionLayout, NamedBuffer};
use crate::spec::label_map::LabelMap;
use crate::spec::{Element, ElementKind, SampleRateMode, ScaleClass, Vector};
use std::sync::Arc;

impl<'a> Cx<'a> {
    /// Builds the engine, or returns every error the passes found.
    pub fn assemble(
        self,
        options: &CompileOptions,
        rate: Rate,
        params: Params,
        numbering: Numbering,
        kinds: Kinds<'a>,
        bound: Bound,
    ) -> Result<Engine, CompileErrors> {
        if !self.errors.is_empty() {
            return Err(CompileErrors(self.errors));
        }
        let motion = self.motion_layout(&params, &numbering);
        let num_points = numbering.len();
        let num_proxies = self.proxies.len();
        let total = num_points + num_proxies;
        let mut proxies = self.proxies;
        proxies.base = kinds.proxy_base;
        let stack = self.program.new_stack();
        let Kinds {
            avatars,
            io,
            num_interactions,
            ..
        } = kinds;
        let info = ModelInfo {
            sample_rate_hz: rate.sr,
            sample_rate_mode: rate.mode,
            num_points,
            num_connection_points: num_proxies,
            num_interactions,
            points: numbering.points,
            owners: numbering.owners,
            params: params
                .info
                .into_iter()
                .zip(&self.param_is_coordinate)
                .map(|(p, &coordinate)| ParamInfo { coordinate, ..p })
                .collect(),
            inputs: io.inputs,
            outputs: io.outputs,
            motion,
        };
        // Parameters start at their declared values: an audio-rate one at its default.
        let audio_defaults = params
            .audio
            .iter()
            .map(|r| params.values[r.index as usize])
            .collect();
        let mut audio_slots = vec![false; self.args.len()];
        let mut slot_class = vec![u8::MAX; self.args.len()];
        for b in &self.audio_bindings {
            audio_slots[b.slot as usize] = true;
        }
        for b in self.control_bindings.iter().chain(&self.audio_bindings) {
            slot_class[b.slot as usize] = b.class as u8;
        }
        let mut interactions = bound.interactions;
        let mut longest_chain = 0;
        for g in interactions.groups_mut() {
            g.find_chains();
            g.find_rows(bound.singles.len());
            g.mark_varying(&audio_slots, &slot_class);
            longest_chain = longest_chain.max(g.longest_chain());
        }
        let mut singles = bound.singles;
        singles.force_set = interactions.find_setters(singles.len(), total);
        let control = ControlArgs::new(
            self.control_bindings,
            &self.program,
            &params.values,
            &self.args,
            singles.cols,
            singles.len(),
            proxies.coord_slots.iter().flatten().copied(),
        );
        let mut macros = bound.macros;
        macros.scratch_ext = vec![(0, 0.0); 4 * num_proxies];
        let arch = crate::sim::kernels::arch_for(&macros);
        let model = Compiled {
            info,
            program: self.program,
            avatars: avatars.into_iter().map(|(_, route)| route).collect(),
            audio_params: params.audio,
            force_inputs: io.force_inputs,
            pos_outputs: io.pos_outputs,
            frc_outputs: io.frc_outputs,
            frc_sources: io.frc_sources,
            audio_bindings: self.audio_bindings,
            audio_masses: bound.audio_masses,
            audio_proxies: self.proxy_audio,
            class_scale: class_scales(rate.mode, rate.sr),
            init_runs: bound.init_runs,
            init_fixed_points: numbering.fixed_points,
            motion_interval: options.motion_interval.max(1),
        };
        let mut engine = Engine {
            model: Arc::new(model),
            points: Points {
                x: vec![0.0; total],
                xp: vec![0.0; total],
                f: vec![0.0; total],
                s: vec![0.0; longest_chain],
            },
            args: self.args,
            singles,
            macros,
            proxies,
            interactions,
            params: params.values,
            audio_defaults,
            stack,
            control,
            class_gain: [1.0; NUM_ARG_CLASSES],
            params_dirty: true,
            position_limit: DEFAULT_POSITION_LIMIT,
            guard: None,
            samples_since_reset: 0,
            motion: None,
            motion_counter: 0,
            rest: Default::default(),
            arch,
            native: None,
            native_fits: false,
            space: None,
        };
        engine.reset();
        if options.jit {
            engine.attach_native_code();
        }
        Ok(engine)
    }

    /// Rendering coordinates of every material point and the members of the named buffers.
    fn motion_layout(&self, params: &Params, numbering: &Numbering) -> MotionLayout {
        let spec = self.spec;
        let defaults: LabelMap<&str, f64> = spec
            .params
            .iter()
            .zip(&params.values)
            .map(|(p, v)| (p.name.as_str(), *v))
            .collect();
        let lookup = |n: &str| defaults.get(n).copied();
        let num_points = numbering.len();
        let mut motion = MotionLayout {
            x: vec![0.0; num_points],
            y: vec![0.0; num_points],
            named: spec
                .buffers
                .iter()
                .map(|name| NamedBuffer {
                    name: name.clone(),
                    members: Vec::new(),
                })
                .collect(),
        };
        for (owner, &i) in numbering.owner_element.iter().enumerate() {
            let e = &spec.elements[i];
            let first = self.element_point[i].unwrap_or(0) as usize;
            let count = numbering.points[first..]
                .iter()
                .take_while(|p| p.owner == owner as u32)
                .count();
            layout_points(e, first, count, &lookup, &mut motion);
            for &b in &e.buffers {
                if let Some(buf) = motion.named.get_mut(b as usize) {
                    buf.members.extend(first as u32..(first + count) as u32);
                }
            }
        }
        motion
    }
}

/// The scale factor of every argument class at `sr` (spec §1.7).
pub(super) fn class_scales(mode: SampleRateMode, sr: f64) -> [f64; NUM_ARG_CLASSES] {
    let k = ScaleClass::Stiffness.factor(mode, sr);
    let z = ScaleClass::Damping.factor(mode, sr);
    let mut s = [1.0; NUM_ARG_CLASSES];
    s[ArgClass::None as usize] = 1.0;
    s[ArgClass::Stiffness as usize] = k;
    s[ArgClass::Damping as usize] = z;
    s[ArgClass::Gravity as usize] = ScaleClass::Gravity.factor(mode, sr);
    s[ArgClass::LegacyGravity as usize] = k;
    s[ArgClass::VelocityScale as usize] = z;
    s
}

/// Rendering coordinates of an element's points (spec §2.7 "Rendering coordinates", §6.3).
fn layout_points(
    e: &Element,
    first: usize,
    count: usize,
    lookup: &impl Fn(&str) -> Option<f64>,
    motion: &mut MotionLayout,
) {
    let xy = |v: &Vector| -> (f64, f64) {
        match v.xy() {
            Some((x, y)) => (x.eval(lookup), y.eval(lookup)),
            None => (0.0, 0.0),
        }
    };
    let mut put = |k: usize, (x, y): (f64, f64)| {
        motion.x[first + k] = if x.is_finite() { x } else { 0.0 };
        motion.y[first + k] = if y.is_finite() { y } else { 0.0 };
    };
    match &e.kind {
        ElementKind::Macro(mac) => {
            let (x0, y0) = xy(&mac.pos);
            let both = mac.pos.xy().is_some() && mac.vel.xy().is_some();
            let (x1, y1) = if both { xy(&mac.vel) } else { (x0, y0) };
            let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
            for k in 0..count {
                let p = if mac.kind.is_2d() {
                    let w = mac.width as usize;
                    let (i, j) = (k / w, k % w);
                    let ti = i as f64 / (mac.length as f64 - 1.0);
                    let tj = j as f64 / (mac.width as f64 - 1.0);
                    (lerp(x0, x1, ti), lerp(y0, y1, tj))
                } else {
                    let t = k as f64 / (count as f64 - 1.0).max(1.0);
                    (lerp(x0, x1, t), lerp(y0, y1, t))
                };
                put(k, p);
            }
        }
        ElementKind::Mass { pos, .. }
        | ElementKind::Osc { pos, .. }
        | ElementKind::Ground { pos }
        | ElementKind::MassG { pos, .. }
        | ElementKind::PosInput { pos, .. } => {
            put(0, e.tag_xy.unwrap_or_else(|| xy(pos)));
        }
        _ => {}
    }
}
