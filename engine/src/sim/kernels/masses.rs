//! Stage 2 a of spec §1.5: single mass-type elements (`mass`, `osc`, `ground`, `massG`).

use super::Points;

/// Stage 2 a: single mass-type elements, points `0..len`.
///
/// X[n+1] = a·X[n] + b·X[n−1] + (F − g)·(1/M), with a = 2 − (K+Z)/M and b = Z/M − 1 (spec
/// §2.1.2; K = Z = 0 for `mass`, which gives 2X − X̃ + (F − g)/M, spec §2.1.1).
///
/// Plain masses (a = 2, b = −1, g = +0: a `mass` without gravity, the bulk of any string or
/// mesh written element by element) run a loop that reads four arrays instead of seven:
/// X[n+1] = (2·X − X̃) + F·(1/M). It is the general update's arithmetic exactly: 2·X and
/// −1·X̃ are exact, 2X + (−X̃) is 2X − X̃, and F − (+0) is F (test
/// `plain_masses_equal_the_general_update`). A plain run whose masses all have the same 1/M
/// (a string or mesh of equal masses) reads it once instead of per point: one array fewer
/// in the loop that dominates large element-by-element models.
#[derive(Clone, Debug, Default)]
pub(crate) struct SingleMasses {
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    pub inv_m: Vec<f64>,
    /// Per-step gravity force g (subtracted from F).
    pub gravity: Vec<f64>,
    /// Grounds: never move (cold, used by `derive`).
    pub fixed: Vec<bool>,
    /// Masses whose coefficients follow audio-rate arguments: never run as plain.
    pub audio: Vec<bool>,
    /// Masses whose force a band of links sets in stage 4 rather than adds to
    /// ([`Interactions::find_setters`](super::links::Interactions::find_setters)): the mass
    /// pass leaves their F as it is instead of clearing it, since the band overwrites it
    /// before anything else reads or adds to it.
    pub force_set: Vec<bool>,
    /// Argument columns in `Engine::args`: M, K, Z, gravity.
    pub cols: [usize; 4],
    /// Runs of points as (start, len, update, clear F), `runs[..num_runs]`, from
    /// [`SingleMasses::classify`] (sized for the worst case as a length: `clone` keeps
    /// lengths, not capacities).
    pub runs: Vec<(u32, u32, Update, bool)>,
    pub num_runs: usize,
}

/// The coefficients (a, b, 1/M, g) of a single mass-type element from its M, K, Z and gravity
/// (spec §2.1.2): a = 2 − (K+Z)/M, b = Z/M − 1. A ground is the M → ∞ limit (1, 0, 0, 0).
/// Shared by the plain engine and the voice lanes, which must compute the same bits.
#[inline]
pub(crate) fn single_law(fixed: bool, m: f64, k: f64, z: f64, gravity: f64) -> [f64; 4] {
    if fixed {
        [1.0, 0.0, 0.0, 0.0]
    } else {
        [2.0 - (k + z) / m, z / m - 1.0, 1.0 / m, gravity]
    }
}

/// How a run of single masses is updated (the same arithmetic in each, bit for bit).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Update {
    /// a·X + b·X̃ + (F − g)·(1/M).
    #[default]
    General,
    /// (2·X − X̃) + F·(1/M).
    Plain,
    /// (2·X − X̃) + F·(1/M) with one 1/M for the whole run.
    PlainUniform,
}

impl SingleMasses {
    pub fn len(&self) -> usize {
        self.a.len()
    }

    /// Recomputes the coefficients of point `i` from its arguments. Call
    /// [`SingleMasses::classify`] once the changed points are derived.
    #[inline]
    pub fn derive(&mut self, i: usize, args: &[f64]) {
        let arg = |c: usize| args[self.cols[c] + i];
        [self.a[i], self.b[i], self.inv_m[i], self.gravity[i]] =
            single_law(self.fixed[i], arg(0), arg(1), arg(2), arg(3));
    }

    /// Whether point `i` runs the plain update (bit patterns compared: a −0 gravity is not
    /// plain, since F − (−0) turns a −0 force into +0).
    pub(crate) fn is_plain(&self, i: usize) -> bool {
        !self.audio[i]
            && self.a[i].to_bits() == 2.0f64.to_bits()
            && self.b[i].to_bits() == (-1.0f64).to_bits()
            && self.gravity[i].to_bits() == 0
    }

    /// Whether point `i`'s force is set by a band (see [`SingleMasses::force_set`]).
    fn is_force_set(&self, i: usize) -> bool {
        self.force_set.get(i).copied().unwrap_or(false)
    }

    /// Splits the points into runs of plain and general updates, and of forces to clear or
    /// to leave for a band to set. Never allocates once `runs` has its length (one run per
    /// point at worst).
    pub fn classify(&mut self) {
        let n = self.len();
        if self.runs.len() < n {
            // Only when the model is built (or for a default value).
            self.runs.resize(n, (0, 0, Update::General, true));
        }
        self.num_runs = 0;
        let mut i = 0;
        while i < n {
            let plain = self.is_plain(i);
            let set = self.is_force_set(i);
            let mut end = i + 1;
            while end < n && self.is_plain(end) == plain && self.is_force_set(end) == set {
                end += 1;
            }
            let first = self.inv_m[i].to_bits();
            let update = if !plain {
                Update::General
            } else if self.inv_m[i..end].iter().all(|v| v.to_bits() == first) {
                Update::PlainUniform
            } else {
                Update::Plain
            };
            self.runs[self.num_runs] = (i as u32, (end - i) as u32, update, !set);
            self.num_runs += 1;
            i = end;
        }
    }

    #[inline(always)]
    pub(crate) fn step(&self, p: &mut Points) {
        let n = self.len();
        let (x, xp, f) = (&mut p.x[..n], &mut p.xp[..n], &mut p.f[..n]);
        // Every array sliced to n up front: no bounds checks, and no reloads of the vectors'
        // pointers between the stores (this loop is inlined into the whole sample loop).
        let (a, b, g, inv_m) = (
            &self.a[..n],
            &self.b[..n],
            &self.gravity[..n],
            &self.inv_m[..n],
        );
        for &(start, len, update, clear) in &self.runs[..self.num_runs] {
            let r = start as usize..(start + len) as usize;
            let coefficients = (
                &a[r.clone()],
                &b[r.clone()],
                &g[r.clone()],
                &inv_m[r.clone()],
            );
            let (x, xp, f) = (&mut x[r.clone()], &mut xp[r.clone()], &mut f[r]);
            if clear {
                run::<true>(update, x, xp, f, coefficients);
            } else {
                run::<false>(update, x, xp, f, coefficients);
            }
        }
    }
}

/// One run of [`SingleMasses::step`]: every point moves with `update`, and with `CLEAR` its
/// force is cleared for stage 4 to add to (a run whose forces a band sets keeps them: see
/// [`SingleMasses::force_set`]).
#[inline(always)]
fn run<const CLEAR: bool>(
    update: Update,
    x: &mut [f64],
    xp: &mut [f64],
    f: &mut [f64],
    (a, b, g, inv_m): (&[f64], &[f64], &[f64], &[f64]),
) {
    let n = x.len();
    let (xp, f, inv_m) = (&mut xp[..n], &mut f[..n], &inv_m[..n]);
    match update {
        Update::PlainUniform => {
            let inv_m = inv_m[0];
            for i in 0..n {
                let next = (2.0 * x[i] - xp[i]) + f[i] * inv_m;
                xp[i] = x[i];
                x[i] = next;
                if CLEAR {
                    f[i] = 0.0;
                }
            }
        }
        Update::Plain => {
            for i in 0..n {
                let next = (2.0 * x[i] - xp[i]) + f[i] * inv_m[i];
                xp[i] = x[i];
                x[i] = next;
                if CLEAR {
                    f[i] = 0.0;
                }
            }
        }
        Update::General => {
            let (a, b, g) = (&a[..n], &b[..n], &g[..n]);
            for i in 0..n {
                let next = a[i] * x[i] + b[i] * xp[i] + (f[i] - g[i]) * inv_m[i];
                xp[i] = x[i];
                x[i] = next;
                if CLEAR {
                    f[i] = 0.0;
                }
            }
        }
    }
}

/// The size of a run entry that [`Engine`](crate::Engine)'s doc comment counts.
#[cfg(target_arch = "x86_64")]
const _: () = assert!(std::mem::size_of::<(u32, u32, Update, bool)>() == 12);
