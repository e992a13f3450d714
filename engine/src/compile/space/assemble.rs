//! The last step of a 3-D model: its metadata, its motion layout (the initial x and y of
//! every point, which in 3-D are physical), the shared [`SpaceModel`] and the engine, reset
//! to stage 0.

use super::bind::Bound;
use super::Numbering;
use crate::compile::context::Cx;
use crate::compile::errors::CompileErrors;
use crate::compile::labels::Params;
use crate::compile::{CompileOptions, Rate};
use crate::laws::NUM_ARG_CLASSES;
use crate::sim::control::ControlArgs;
use crate::sim::engine::{Compiled, Engine, Points, DEFAULT_POSITION_LIMIT};
use crate::sim::info::{InputUse, ModelInfo, ParamInfo};
use crate::sim::motion::{MotionLayout, NamedBuffer};
use crate::sim::space::{Space, SpaceModel};
use std::sync::Arc;

impl<'a> Cx<'a> {
    pub(super) fn assemble_space(
        self,
        options: &CompileOptions,
        rate: Rate,
        params: Params,
        n: Numbering,
        b: Bound,
    ) -> Result<Engine, CompileErrors> {
        if !self.errors.is_empty() {
            return Err(CompileErrors(self.errors));
        }
        let space = self.spec.space.as_deref().expect("a 3-D spec");
        let num_points = n.len();
        let num_proxies = b.proxies.defs.len();
        let total = num_points + num_proxies;
        let num_interactions: usize = b.groups.iter().map(|g| g.len()).sum();
        // The motion layout: every point's initial x and y, and the named buffers' members.
        let mut motion = MotionLayout {
            x: n.x0.iter().map(|p| finite(p[0])).collect(),
            y: n.x0.iter().map(|p| finite(p[1])).collect(),
            named: self
                .spec
                .buffers
                .iter()
                .map(|name| NamedBuffer {
                    name: name.clone(),
                    members: Vec::new(),
                })
                .collect(),
        };
        for (i, e) in space.elements.iter().enumerate() {
            let Some(first) = n.element_point[i] else {
                continue;
            };
            let count = n.points[first as usize..]
                .iter()
                .take_while(|p| p.owner == n.points[first as usize].owner)
                .count() as u32;
            for &buf in &e.buffers {
                if let Some(named) = motion.named.get_mut(buf as usize) {
                    named.members.extend(first..first + count);
                }
            }
        }
        // An audio-rate parameter reads its own input channel, as in 1-D.
        let mut inputs = b.inputs;
        for r in &params.audio {
            let name = self.spec.params[r.index as usize].name.clone();
            super::bind::use_input(&mut inputs, r.channel + 1, InputUse::Param(name));
        }
        let info = ModelInfo {
            sample_rate_hz: rate.sr,
            sample_rate_mode: rate.mode,
            num_points,
            num_connection_points: num_proxies,
            num_interactions,
            points: n.points,
            owners: n.owners,
            params: params
                .info
                .into_iter()
                .zip(&self.param_is_coordinate)
                .map(|(p, &coordinate)| ParamInfo { coordinate, ..p })
                .collect(),
            inputs,
            outputs: b.output_uses,
            motion,
        };
        let audio_defaults = params
            .audio
            .iter()
            .map(|r| params.values[r.index as usize])
            .collect();
        let audio_directions = b.audio_directions && !self.audio_bindings.is_empty();
        let model = SpaceModel {
            runs: b.runs,
            still: b.still,
            groups: b.groups,
            proxies: b.proxies.defs,
            proxy_base: num_points as u32,
            avatars: b.avatars,
            force_inputs: b.force_inputs,
            outputs: b.outputs,
            mics: b.mics,
            inits: b.inits,
            gravity: b.gravity,
            friction: b.friction,
            audio_runs: b.audio_runs,
            audio_proxies: b.proxies.audio,
            audio_directions,
            directions: b.directions,
            osc_points: b.osc_points,
            len: total,
        };
        let control = ControlArgs::new(
            self.control_bindings,
            &self.program,
            &params.values,
            &self.args,
            [0; 4],
            0,
            std::iter::empty(),
        );
        let stack = self.program.new_stack();
        let compiled = Compiled {
            info,
            program: self.program,
            avatars: Vec::new(),
            audio_params: params.audio,
            force_inputs: Vec::new(),
            pos_outputs: Vec::new(),
            frc_outputs: Vec::new(),
            frc_sources: Vec::new(),
            audio_bindings: self.audio_bindings,
            audio_masses: Vec::new(),
            audio_proxies: Vec::new(),
            class_scale: crate::compile::assemble::class_scales(rate.mode, rate.sr),
            init_runs: Vec::new(),
            init_fixed_points: Vec::new(),
            motion_interval: options.motion_interval.max(1),
        };
        let mut engine = Engine {
            model: Arc::new(compiled),
            points: Points {
                x: vec![0.0; total],
                xp: vec![0.0; total],
                f: vec![0.0; total],
                s: Vec::new(),
            },
            args: self.args,
            singles: Default::default(),
            macros: Default::default(),
            proxies: Default::default(),
            interactions: Default::default(),
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
            arch: pulp::Arch::new(),
            native: None,
            native_fits: false,
            space: Some(Box::new(Space::new(Arc::new(model)))),
        };
        engine.reset();
        // A small 3-D model also gets its sample loop as machine code (`sim/jit/space.rs`).
        if options.jit {
            engine.attach_native_code();
        }
        Ok(engine)
    }
}

fn finite(v: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        0.0
    }
}
