//! A 3-D model's inputs and outputs (3-D spec §3): avatars (stage 1), force inputs (stage 4),
//! point outputs, distances and microphones (stage 6). Directions are unit vectors derived
//! from their arguments at a control change ([`Directions`]); a zero one gives no force and
//! outputs 0 (§1.7).

use super::super::kernels::Points;
use super::SpaceModel;

/// What a directional element points along: an index into [`Directions::units`], from the
/// argument slots at the same index of [`Directions::slots`].
pub(crate) type Dir = u32;

/// A position input (3-D spec §3.1).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Avatar {
    /// `posInput pos {dir}`: x ← P⊥ + in·â, with P⊥ = P − (P·â)â (`perp` indexes
    /// [`Directions::perp`]) from the declared position's slots.
    Line {
        point: u32,
        channel: u32,
        dir: Dir,
        perp: u32,
    },
    /// `posInputXYZ`: x ← (in_N, in_N+1, in_N+2).
    Xyz { point: u32, channel: u32 },
}

/// A force input (3-D spec §3.2).
#[derive(Clone, Copy, Debug)]
pub(crate) enum ForceInput {
    /// F += in·â.
    Line { point: u32, channel: u32, dir: Dir },
    /// F += (in_N, in_N+1, in_N+2).
    Xyz { point: u32, channel: u32 },
}

/// What a point output reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Probe3 {
    Position,
    Force,
    Velocity,
}

/// An output (3-D spec §3.3, §3.4).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Output3 {
    /// x·â, F·â or (x − x̃)·â of a point.
    Point {
        channel: u32,
        probe: Probe3,
        point: u32,
        dir: Dir,
    },
    /// ℓ = |x₁ − x₂|.
    Distance { channel: u32, a: u32, b: u32 },
    /// A microphone, by index into [`SpaceModel::mics`].
    Mic { channel: u32, mic: u32 },
}

impl Output3 {
    pub fn channel(&self) -> u32 {
        match self {
            Output3::Point { channel, .. }
            | Output3::Distance { channel, .. }
            | Output3::Mic { channel, .. } => *channel,
        }
    }
}

/// A microphone (3-D spec §3.4): its member points, its position's slots, its direction (or
/// radial) and its exponent and near-field clamp.
#[derive(Clone, Debug)]
pub(crate) struct Mic {
    pub members: Vec<u32>,
    pub at: [u32; 3],
    /// `None`: radial.
    pub dir: Option<Dir>,
    pub q: u32,
    pub r0: u32,
    /// Where its members start in [`super::Space::mic_weights`].
    pub offset: u32,
}

/// The unit directions of a model's directional elements and its line avatars' P⊥.
#[derive(Clone, Debug, Default)]
pub(crate) struct Directions {
    pub units: Vec<[f64; 3]>,
    pub perp: Vec<[f64; 3]>,
}

/// Where the directions come from: each direction's three slots, each line avatar's
/// position's three slots and its direction.
#[derive(Clone, Debug, Default)]
pub(crate) struct DirectionSources {
    pub slots: Vec<[u32; 3]>,
    pub perp: Vec<([u32; 3], Dir)>,
}

/// v/|v|, or 0.
pub(crate) fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n > 0.0 && n.is_finite() {
        v.map(|c| c / n)
    } else {
        [0.0; 3]
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2]
}

impl Directions {
    pub fn new(m: &SpaceModel) -> Directions {
        Directions {
            units: vec![[0.0; 3]; m.directions.slots.len()],
            perp: vec![[0.0; 3]; m.directions.perp.len()],
        }
    }

    /// The unit directions and P⊥ from the argument values.
    pub fn derive(&mut self, m: &SpaceModel, args: &[f64]) {
        let read = |s: [u32; 3]| s.map(|k| args[k as usize]);
        for (u, s) in self.units.iter_mut().zip(&m.directions.slots) {
            *u = unit(read(*s));
        }
        for (p, (s, dir)) in self.perp.iter_mut().zip(&m.directions.perp) {
            let at = read(*s);
            let a = self.units[*dir as usize];
            let along = dot(at, a);
            *p = [0, 1, 2].map(|c| at[c] - along * a[c]);
        }
    }
}

/// Stage 1 a: the avatars.
#[inline(always)]
pub(crate) fn avatars(
    list: &[Avatar],
    d: &Directions,
    axes: [&mut Points; 3],
    input: &impl Fn(u32) -> f64,
) {
    let [x, y, z] = axes;
    for av in list {
        let (point, target) = match *av {
            Avatar::Line {
                point,
                channel,
                dir,
                perp,
            } => {
                let (a, p, s) = (d.units[dir as usize], d.perp[perp as usize], input(channel));
                (point, [0, 1, 2].map(|c| p[c] + s * a[c]))
            }
            Avatar::Xyz { point, channel } => (
                point,
                [input(channel), input(channel + 1), input(channel + 2)],
            ),
        };
        let k = point as usize;
        for (axis, v) in [&mut *x, &mut *y, &mut *z].into_iter().zip(target) {
            axis.xp[k] = axis.x[k];
            axis.x[k] = v;
            axis.f[k] = 0.0;
        }
    }
}

/// Stage 4's force inputs, after the interactions.
#[inline(always)]
pub(crate) fn force_inputs(
    list: &[ForceInput],
    d: &Directions,
    axes: [&mut Points; 3],
    input: &impl Fn(u32) -> f64,
) {
    let [x, y, z] = axes;
    for fi in list {
        let (point, f) = match *fi {
            ForceInput::Line {
                point,
                channel,
                dir,
            } => {
                let (a, s) = (d.units[dir as usize], input(channel));
                (point, a.map(|c| s * c))
            }
            ForceInput::Xyz { point, channel } => (
                point,
                [input(channel), input(channel + 1), input(channel + 2)],
            ),
        };
        let k = point as usize;
        x.f[k] += f[0];
        y.f[k] += f[1];
        z.f[k] += f[2];
    }
}

/// The value of output `o` (stage 6).
#[inline(always)]
pub(crate) fn output(
    o: &Output3,
    m: &SpaceModel,
    d: &Directions,
    mic_weights: &[f64],
    mic_dirs: &[[f64; 3]],
    axes: [&Points; 3],
) -> f64 {
    let [x, y, z] = axes;
    let at = |k: usize| [x.x[k], y.x[k], z.x[k]];
    match *o {
        Output3::Point {
            probe, point, dir, ..
        } => {
            let k = point as usize;
            let v = match probe {
                Probe3::Position => at(k),
                Probe3::Force => [x.f[k], y.f[k], z.f[k]],
                Probe3::Velocity => [x.x[k] - x.xp[k], y.x[k] - y.xp[k], z.x[k] - z.xp[k]],
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
                let v = [x.x[k] - x.xp[k], y.x[k] - y.xp[k], z.x[k] - z.xp[k]];
                sum += mic_weights[off + j] * dot(v, mic_dirs[off + j]);
            }
            sum
        }
    }
}

/// The microphones' weights and directions at stage 0 (3-D spec §3.4), from the initial
/// positions on `axes`: ρ = |P − X₀|, w = 1/max(ρ, r₀)^q, ê = â or (P − X₀)/ρ (0 at ρ = 0).
pub(crate) fn freeze_mics(
    m: &SpaceModel,
    d: &Directions,
    args: &[f64],
    axes: [&Points; 3],
    weights: &mut [f64],
    dirs: &mut [[f64; 3]],
) {
    let [x, y, z] = axes;
    for mic in &m.mics {
        let at = mic.at.map(|s| args[s as usize]);
        let (q, r0) = (args[mic.q as usize], args[mic.r0 as usize]);
        for (j, &p) in mic.members.iter().enumerate() {
            let k = p as usize;
            let rel = [at[0] - x.x[k], at[1] - y.x[k], at[2] - z.x[k]];
            let rho = dot(rel, rel).sqrt();
            let w = 1.0 / rho.max(r0).powf(q);
            let e = match mic.dir {
                Some(dir) => d.units[dir as usize],
                None if rho > 0.0 => rel.map(|c| c / rho),
                None => [0.0; 3],
            };
            weights[mic.offset as usize + j] = if w.is_finite() { w } else { 0.0 };
            dirs[mic.offset as usize + j] = e;
        }
    }
}
