//! Stage 2 of a 3-D model, the mass phase (3-D spec §2.1): every moving point in script order,
//! a generator's nodes at its line, by the common update law
//!
//! ```text
//! A = 2 − (K_o + Z_o + Z_a)/M,   B = 1 − (Z_o + Z_a)/M
//! Y = x − P_rest,  Ỹ = x̃ − P_rest
//! Y_new = ((A·Y) − (B·Ỹ)) + (F + G)·(1/M) + a        per free axis
//! x̃ ← x,  x ← Y_new + P_rest,  F ← 0
//! ```
//!
//! with K_o, Z_o the `osc`'s own (a structure node's Z_o is its `Zo=`, §4.0), Z_a `~friction`,
//! G the per-mass gravity force, a the per-step `~gravity` acceleration and P_rest the `osc`'s
//! initial position (0 otherwise). A locked axis (`massZ`, `massXY`, `lock=`) keeps x = x̃ and
//! discards its force. With Z_a = 0 a `mass` has A = 2 and B = 1 exactly.

use crate::sim::kernels::Points;

/// A run of points sharing an update law: an explicit mass-type element (one point) or a
/// structure's free nodes between its fixed ones.
#[derive(Clone, Debug)]
pub(crate) struct Run {
    pub first: u32,
    pub count: u32,
    /// Which axes move (x, y, z).
    pub axes: [bool; 3],
    /// The argument slots of M, of the `osc`'s K, of its Z (or a node's Zo).
    pub m: u32,
    pub k: Option<u32>,
    pub z: Option<u32>,
    /// The per-mass gravity force's slots (x, y, z), for explicit masses.
    pub gravity: Option<[u32; 3]>,
    /// An `osc`: the index of its rest position in [`super::Space::rest`].
    pub rest: Option<u32>,
}

/// A run's coefficients: A, B, 1/M, and per axis the gravity force G and the acceleration a
/// (both 0 on a locked axis). In C layout: the native code reads it as nine `f64`s
/// (`jit/space.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(crate) struct RunCoef {
    pub a: f64,
    pub b: f64,
    pub inv_m: f64,
    pub g: [f64; 3],
    pub acc: [f64; 3],
}

impl Run {
    /// The coefficients from the argument values, the air friction `za` and the per-step
    /// acceleration `acc` (per-step values, after scaling).
    pub fn coefficients(&self, args: &[f64], za: f64, acc: [f64; 3]) -> RunCoef {
        let m = args[self.m as usize];
        let k = self.k.map_or(0.0, |s| args[s as usize]);
        let z = self.z.map_or(0.0, |s| args[s as usize]);
        let g = self
            .gravity
            .map_or([0.0; 3], |s| s.map(|slot| args[slot as usize]));
        let free = |c: usize, v: f64| if self.axes[c] { v } else { 0.0 };
        RunCoef {
            a: 2.0 - ((k + z) + za) / m,
            b: 1.0 - (z + za) / m,
            inv_m: 1.0 / m,
            g: [0, 1, 2].map(|c| free(c, g[c])),
            acc: [0, 1, 2].map(|c| free(c, acc[c])),
        }
    }
}

impl RunCoef {
    /// The same coefficients, bit for bit.
    fn same(&self, o: &RunCoef) -> bool {
        let bits = |k: &RunCoef| {
            let mut v = [k.a, k.b, k.inv_m, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
            v[3..6].copy_from_slice(&k.g);
            v[6..].copy_from_slice(&k.acc);
            v.map(f64::to_bits)
        };
        bits(self) == bits(o)
    }
}

/// Which runs update as one (`spans[i]` runs from run i, 0 inside a span): consecutive runs of
/// adjacent points with the same axes, no rest position, no audio-rate argument (`audio[i]`)
/// and coefficients equal bit for bit. A script written element by element has a run per
/// mass; as one run its masses are one loop instead of a thousand. Each point's update is the
/// same operations on the same values, so the merged phase gives the same bits. One entry
/// per run, so that re-deriving never allocates.
pub(crate) fn merge(runs: &[Run], coef: &[RunCoef], audio: &[bool], spans: &mut [u32]) {
    let mut i = 0;
    while i < runs.len() {
        let mut n = 1;
        let alone = |j: usize| runs[j].rest.is_some() || audio[j];
        if !alone(i) {
            while i + n < runs.len() {
                let (prev, next) = (&runs[i + n - 1], &runs[i + n]);
                if alone(i + n)
                    || next.first != prev.first + prev.count
                    || next.axes != runs[i].axes
                    || !coef[i + n].same(&coef[i])
                {
                    break;
                }
                n += 1;
            }
        }
        spans[i] = n as u32;
        spans[i + 1..i + n].fill(0);
        i += n;
    }
}

/// Stage 2 on the axes `p` (x, y, z): every span of runs ([`merge`]) by its first run's law,
/// then the still points' forces cleared.
#[inline(always)]
pub(crate) fn step(
    runs: &[Run],
    coef: &[RunCoef],
    spans: &[u32],
    rest: &[[f64; 3]],
    still: &[u32],
    p: [&mut Points; 3],
) {
    let [px, py, pz] = p;
    let mut i = 0;
    while i < runs.len() {
        let (run, k) = (&runs[i], &coef[i]);
        let n = (spans[i] as usize).max(1);
        let last = &runs[i + n - 1];
        i += n;
        let range = run.first as usize..(last.first + last.count) as usize;
        for (c, axis) in [&mut *px, &mut *py, &mut *pz].into_iter().enumerate() {
            let (x, xp, f) = (
                &mut axis.x[range.clone()],
                &mut axis.xp[range.clone()],
                &mut axis.f[range.clone()],
            );
            if !run.axes[c] {
                f.fill(0.0);
                continue;
            }
            let (g, acc) = (k.g[c], k.acc[c]);
            match run.rest {
                None => {
                    for ((x, xp), f) in x.iter_mut().zip(xp.iter_mut()).zip(f.iter_mut()) {
                        let y = ((k.a * *x) - (k.b * *xp)) + (*f + g) * k.inv_m + acc;
                        *xp = *x;
                        *x = y;
                        *f = 0.0;
                    }
                }
                Some(r) => {
                    let at = rest[r as usize][c];
                    for ((x, xp), f) in x.iter_mut().zip(xp.iter_mut()).zip(f.iter_mut()) {
                        let (y, yp) = (*x - at, *xp - at);
                        let next = ((k.a * y) - (k.b * yp)) + (*f + g) * k.inv_m + acc;
                        *xp = *x;
                        *x = next + at;
                        *f = 0.0;
                    }
                }
            }
        }
    }
    for &i in still {
        let i = i as usize;
        px.f[i] = 0.0;
        py.f[i] = 0.0;
        pz.f[i] = 0.0;
    }
}
