//! A 3-D model's simulation (3-D spec §1.5): its points move along x, y and z, in
//! structure-of-arrays state (§9.3). An [`Engine`](crate::Engine) of a 3-D model keeps its z
//! axis in its [`Points`] (the 1-D coordinate: a 3-D script's scalars are z, §1.7, and the
//! motion buffers' channel 0 is z, §3.5) and the x and y axes here, in the same layout, so
//! the flush, the guard and the fixed-point test run on each axis as they run on 1-D points.
//!
//! The stages of §1.5, each in its own file:
//!
//! * stage 2, the mass phase (`masses`): runs of points sharing an update law;
//! * stage 4, the interactions (`links`): one group per law of the 3-D table, in table order;
//! * stages 3 and 5, connection points (`proxies`);
//! * stages 1, 4 (force inputs) and 6, inputs and outputs (`io`).
//!
//! What no sample writes is the [`SpaceModel`], shared by every copy of the model behind an
//! `Arc` (a voice costs its state); what the controls move (the mass coefficients, the
//! connection points' weights, the unit directions) is derived into the state at a control
//! change ([`Space::derive`]).

use crate::sim::kernels::Points;
use std::sync::Arc;

pub(crate) mod io;
pub(crate) mod links;
pub(crate) mod masses;
pub(crate) mod proxies;

pub(crate) use io::{Avatar, DirectionSources, ForceInput, Mic, Output3, Probe3};
pub(crate) use links::Group3;
pub(crate) use masses::{Run, RunCoef};
pub(crate) use proxies::ProxyDef;

/// How a point's initial state is computed at stage 0 (3-D spec §1.5, §1.7).
#[derive(Clone, Debug)]
pub(crate) enum Init {
    /// Points `first..first + positions.len()` at constant positions with no velocity
    /// (structure nodes; grounds and fixed nodes among them have x̃ = x too).
    Block {
        first: u32,
        positions: Arc<[[f64; 3]]>,
    },
    /// One point at X₀ (three expressions) with x̃ = X₀ − v·factor, but x̃ = X₀ on the axes
    /// it does not move along (`fixed`: a ground's, an avatar's every axis, a `massZ`'s x and
    /// y; 3-D spec §2.1.3).
    Point {
        point: u32,
        x0: [crate::spec::expr::ExprRef; 3],
        v: [crate::spec::expr::ExprRef; 3],
        factor: f64,
        fixed: [bool; 3],
    },
}

/// What a compiled 3-D model is, beyond the 1-D [`Compiled`](crate::sim::compiled::Compiled):
/// never written after compilation, shared by every copy.
#[derive(Debug, Default)]
pub(crate) struct SpaceModel {
    /// The mass phase, in script order.
    pub runs: Vec<Run>,
    /// Points that never move but whose force is cleared in the mass phase: grounds and
    /// fixed structure nodes (their F is read by `frcOutput` as a reaction, §2.1.2).
    pub still: Vec<u32>,
    /// One group per law of the 3-D table, in table order.
    pub groups: Vec<Group3>,
    pub proxies: Vec<ProxyDef>,
    /// Index of the first connection point.
    pub proxy_base: u32,
    pub avatars: Vec<Avatar>,
    pub force_inputs: Vec<ForceInput>,
    pub outputs: Vec<Output3>,
    pub mics: Vec<Mic>,
    /// Stage 0, in point order.
    pub inits: Vec<Init>,
    /// The argument slots of `~gravity` (x, y, z acceleration, per step) and `~friction`.
    pub gravity: Option<[u32; 3]>,
    pub friction: Option<u32>,
    /// Derived items that read an audio-rate argument: re-derived every sample.
    pub audio_runs: Vec<u32>,
    pub audio_proxies: Vec<u32>,
    pub audio_directions: bool,
    /// Where the unit directions and the line avatars' P⊥ come from.
    pub directions: DirectionSources,
    /// Each `osc` run's point, in the order of [`Space::rest`].
    pub osc_points: Vec<u32>,
    /// The number of points, connection points included (every axis's length).
    pub len: usize,
}

/// The x and y axes of a 3-D model's state and what the controls derive (3-D spec §1.2).
#[derive(Clone, Debug)]
pub(crate) struct Space {
    pub model: Arc<SpaceModel>,
    /// The x axis: positions, delayed positions, force accumulators.
    pub ax: Points,
    /// The y axis.
    pub ay: Points,
    /// Each run's coefficients.
    pub coef: Vec<RunCoef>,
    /// The runs that update as one ([`masses::merge`]), and which runs read an audio-rate
    /// argument (never merged).
    pub spans: Vec<u32>,
    pub audio_run: Vec<bool>,
    /// The per-step acceleration of `~gravity` and the air friction Za.
    pub acc: [f64; 3],
    pub za: f64,
    /// Each connection point's nodes and weights (at most eight, unused ones weight 0).
    pub proxy_nodes: Vec<[u32; 8]>,
    pub proxy_weights: Vec<[f64; 8]>,
    /// Unit directions of the inputs and outputs, and each directional avatar's P⊥.
    pub directions: io::Directions,
    /// Each `osc` point's rest position, its initial position (§2.1.4), set at reset.
    pub rest: Vec<[f64; 3]>,
    /// The microphones' frozen weights and directions (§3.4), set at reset.
    pub mic_weights: Vec<f64>,
    pub mic_dirs: Vec<[f64; 3]>,
}

impl Space {
    /// A fresh state for `model` with `len` points per axis.
    pub fn new(model: Arc<SpaceModel>) -> Space {
        let len = model.len;
        let axis = || Points {
            x: vec![0.0; len],
            xp: vec![0.0; len],
            f: vec![0.0; len],
            s: Vec::new(),
        };
        let runs = model.runs.len();
        let proxies = model.proxies.len();
        let osc = model.runs.iter().filter(|r| r.rest.is_some()).count();
        let members: usize = model.mics.iter().map(|m| m.members.len()).sum();
        Space {
            ax: axis(),
            ay: axis(),
            coef: vec![RunCoef::default(); runs],
            spans: vec![1; runs],
            audio_run: {
                let mut audio = vec![false; runs];
                for &i in &model.audio_runs {
                    audio[i as usize] = true;
                }
                audio
            },
            acc: [0.0; 3],
            za: 0.0,
            proxy_nodes: vec![[0; 8]; proxies],
            proxy_weights: vec![[0.0; 8]; proxies],
            directions: io::Directions::new(&model),
            rest: vec![[0.0; 3]; osc],
            mic_weights: vec![0.0; members],
            mic_dirs: vec![[0.0; 3]; members],
            model,
        }
    }

    /// Derives everything the controls move from the argument values: each run's update
    /// coefficients (with the medium's friction and gravity), the connection points' weights
    /// and the unit directions. Off the sample loop, at a control change (and for what reads
    /// an audio-rate argument, every sample: [`Space::derive_audio`]).
    pub fn derive(&mut self, args: &[f64]) {
        let m = Arc::clone(&self.model);
        self.acc = m
            .gravity
            .map_or([0.0; 3], |s| s.map(|slot| args[slot as usize]));
        self.za = m.friction.map_or(0.0, |s| args[s as usize]);
        for (i, run) in m.runs.iter().enumerate() {
            self.coef[i] = run.coefficients(args, self.za, self.acc);
        }
        masses::merge(&m.runs, &self.coef, &self.audio_run, &mut self.spans);
        for (i, p) in m.proxies.iter().enumerate() {
            p.derive(args, &mut self.proxy_nodes[i], &mut self.proxy_weights[i]);
        }
        self.directions.derive(&m, args);
    }

    /// Re-derives what reads an audio-rate argument (stage 1 b).
    #[inline]
    pub fn derive_audio(&mut self, args: &[f64]) {
        let m = &*self.model;
        for &i in &m.audio_runs {
            self.coef[i as usize] = m.runs[i as usize].coefficients(args, self.za, self.acc);
        }
        for &i in &m.audio_proxies {
            let i = i as usize;
            m.proxies[i].derive(args, &mut self.proxy_nodes[i], &mut self.proxy_weights[i]);
        }
        if m.audio_directions {
            self.directions.derive(m, args);
        }
    }

    /// Stage 1 a: the avatars take their inputs.
    #[inline(always)]
    pub fn avatars(&mut self, z: &mut Points, input: &impl Fn(u32) -> f64) {
        let m = &*self.model;
        io::avatars(
            &m.avatars,
            &self.directions,
            [&mut self.ax, &mut self.ay, z],
            input,
        );
    }

    /// Stages 2 to 5 of one sample (3-D spec §1.5): the mass phase, the connection points'
    /// positions, the interactions and force inputs, the connection points' forces.
    #[inline(always)]
    pub fn step(
        &mut self,
        z: &mut Points,
        args: &[f64],
        input: &impl Fn(u32) -> f64,
        arch: pulp::Arch,
    ) {
        let m = &*self.model;
        let (ax, ay) = (&mut self.ax, &mut self.ay);
        masses::step(
            &m.runs,
            &self.coef,
            &self.spans,
            &self.rest,
            &m.still,
            [&mut *ax, &mut *ay, &mut *z],
        );
        let base = m.proxy_base as usize;
        proxies::update_positions(
            &m.proxies,
            base,
            &self.proxy_nodes,
            &self.proxy_weights,
            [&mut *ax, &mut *ay, &mut *z],
        );
        links::step(&m.groups, ax, ay, z, args, arch);
        io::force_inputs(
            &m.force_inputs,
            &self.directions,
            [&mut *ax, &mut *ay, &mut *z],
            input,
        );
        proxies::spread_forces(
            &m.proxies,
            base,
            &self.proxy_nodes,
            &self.proxy_weights,
            [&mut *ax, &mut *ay, &mut *z],
        );
    }

    /// The value of output `o` (stage 6).
    #[inline(always)]
    pub fn output(&self, o: &Output3, z: &Points) -> f64 {
        io::output(
            o,
            &self.model,
            &self.directions,
            &self.mic_weights,
            &self.mic_dirs,
            [&self.ax, &self.ay, z],
        )
    }

    /// Stage 0 (3-D spec §1.5): positions and delayed positions from the inits (the
    /// expressions evaluated with `eval`), the `osc` rest positions, the connection points at
    /// their interpolated positions with no velocity, the microphones' weights; every force
    /// cleared. The derived coefficients must be current ([`Space::derive`]).
    pub fn reset(
        &mut self,
        z: &mut Points,
        args: &[f64],
        mut eval: impl FnMut(crate::spec::expr::ExprRef) -> f64,
    ) {
        let m = Arc::clone(&self.model);
        for axis in [&mut self.ax, &mut self.ay, &mut *z] {
            axis.f.fill(0.0);
        }
        for init in &m.inits {
            match init {
                Init::Block { first, positions } => {
                    for (k, p) in positions.iter().enumerate() {
                        let i = *first as usize + k;
                        for (axis, v) in [&mut self.ax, &mut self.ay, &mut *z].into_iter().zip(p) {
                            axis.x[i] = *v;
                            axis.xp[i] = *v;
                        }
                    }
                }
                Init::Point {
                    point,
                    x0,
                    v,
                    factor,
                    fixed,
                } => {
                    let i = *point as usize;
                    for (c, axis) in [&mut self.ax, &mut self.ay, &mut *z]
                        .into_iter()
                        .enumerate()
                    {
                        let x = eval(x0[c]);
                        axis.x[i] = x;
                        axis.xp[i] = if fixed[c] { x } else { x - eval(v[c]) * factor };
                    }
                }
            }
        }
        for (r, &p) in self.rest.iter_mut().zip(&m.osc_points) {
            let p = p as usize;
            *r = [self.ax.x[p], self.ay.x[p], z.x[p]];
        }
        // Connection points start at their interpolated positions, still.
        let base = m.proxy_base as usize;
        for (i, d) in m.proxies.iter().enumerate() {
            for axis in [&mut self.ax, &mut self.ay, &mut *z] {
                let pos =
                    proxies::interpolate(d, &self.proxy_nodes[i], &self.proxy_weights[i], &axis.x);
                axis.x[base + i] = pos;
                axis.xp[base + i] = pos;
            }
        }
        io::freeze_mics(
            &m,
            &self.directions,
            args,
            [&self.ax, &self.ay, z],
            &mut self.mic_weights,
            &mut self.mic_dirs,
        );
    }

    /// The x and y axes, for the flush, the guard and the fixed-point test.
    pub fn planar_axes(&mut self) -> [&mut Points; 2] {
        [&mut self.ax, &mut self.ay]
    }
}
