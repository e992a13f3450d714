//! Modal analysis of a compiled model (spec §5.5, made exact for the discrete scheme).
//!
//! The model is linearised at its rest state (the positions of stage 0, spec §1.5, with zero
//! velocity); [`crate::analysis::network`] documents how each nonlinear law enters. With the
//! per-step masses M, the stiffness matrix K and the damping matrix Z over the moving points, the
//! state (x[n], x[n−1]) evolves by the companion matrix
//!
//! ```text
//! A = [ 2I − M⁻¹(K+Z)   M⁻¹Z − I ]
//!     [ I               0        ]
//! ```
//!
//! (for one oscillator, the recurrence of spec §5.1). Each eigenvalue r of A is a mode: its
//! frequency is f = SR·arg(r)/2π and its decay per sample |r|, so T60 = −3·ln 10 / (SR·ln|r|).
//!
//! * **Symmetric form.** S = M^−½·K·M^−½ has the eigenvalues λ of M⁻¹K with orthonormal
//!   vectors ψ; the mode shapes are φ = M^−½·ψ (spec §5.5 steps 2–3).
//! * **Proportional damping** (Γ = M^−½·Z·M^−½ diagonal in the basis ψ, eigenvalues γ): each
//!   mode is the scalar recurrence of spec §5.1 with K/M → λ and Z/M → γ, whose roots solve
//!   z² − (2 − λ − γ)·z + (1 − γ) = 0. Undamped, this is the law of spec §5.3:
//!   sin²(πf/SR) = λ/4.
//! * **Other damping**: the eigenvalues of the 2N companion matrix, for models up to
//!   [`COMPANION_LIMIT`] moving points; beyond that γ = ψᵀΓψ (spec §5.5 step 4), flagged by
//!   [`ModalAnalysis::proportional`] = false.
//! * **Large models** (more than [`DENSE_LIMIT`] moving points): the lowest modes by
//!   block shift-invert Lanczos on a sparse Cholesky factor of S − σI (`sparse.rs`), whose
//!   blocks find every copy of a repeated eigenvalue (square plates have paired modes).
//! * **Repeated eigenvalues** get one basis whatever the solver: the first copy is the shape
//!   the first linear input excites (`solve.rs`, `canonical_eigenspaces`).
//!
//! **Modal gain.** The impulse response of output o to a unit impulse on input i is
//! y[n] = Σ c·rⁿ over the eigenvalues; a mode's gain is the amplitude of its decaying
//! sinusoid, 2·|c| (|c| for a real root). For a force input and a position output in the
//! proportional case, c = φ_o·φ_i / (r − r̄), so the gain is |φ_o·φ_i| / Im r.

mod limit;
pub(crate) mod solve;
mod sparse;
pub(crate) mod system;

pub use limit::{ExactStability, StiffnessLimit};

use crate::analysis::network::{Network, Valuation};
use crate::Engine;
use system::System;

/// Above this many moving points the analysis computes only the lowest modes, with the
/// sparse solver.
pub const DENSE_LIMIT: usize = 1500;

/// The largest magnitude of an entry of the mass-normalised matrices M^−½·K·M^−½ and
/// M^−½·Z·M^−½ (per step) that the analyses give an eigensolver or a factorisation. A stable
/// model's entries are below 4 (spec §5.2), so no model worth analysing comes near; beyond it
/// the products inside the solvers overflow, and a script value of 10³⁰⁸ made a dense solver
/// assert (faer's real Schur decomposition) or never return.
pub const ANALYSIS_LIMIT: f64 = 1e50;

/// Up to this many moving points, non-proportional damping is solved exactly with the 2N
/// companion matrix; above, with the projected damping ψᵀΓψ.
pub const COMPANION_LIMIT: usize = 400;

/// How many modes the sparse solver computes when no count is given.
pub const DEFAULT_SPARSE_COUNT: usize = 50;

/// One mode of the linearised model.
#[derive(Clone, Debug, PartialEq)]
pub struct Mode {
    /// f = SR·arg(r)/2π.
    pub frequency_hz: f64,
    /// T60 = −3·ln 10 / (SR·ln|r|); infinite for an undamped mode.
    pub t60_s: f64,
    /// The eigenvalue r's modulus, the amplitude decay per sample.
    pub radius: f64,
    /// The undamped-equivalent eigenvalue λ = 2 − γ − 2·Re r with γ = 1 − |r|² (exactly the
    /// eigenvalue of M⁻¹K for proportional damping). Linear in the K-class gain.
    pub lambda: f64,
    /// Modal gains, input-major: `gains[i * num_outputs + o]` from input channel i + 1 to
    /// output channel o + 1, in output units per unit input impulse.
    pub gains: Vec<f64>,
    /// The complex residues behind the gains, in the same order, as (re, im) and scaled so
    /// that `gains[k]` = |`residues[k]`|. The copies of a repeated mode (the pairs of square
    /// plates) split the residue in a way that depends on the basis chosen in their
    /// eigenspace; their sum does not.
    pub residues: Vec<(f64, f64)>,
    /// The mode shape over [`crate::ModelInfo::points`] (0 on points that do not move),
    /// largest component 1.
    pub shape: Vec<f64>,
}

/// Which solver produced the modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// Dense symmetric eigendecomposition of S (every mode).
    Dense,
    /// Dense eigendecomposition of the 2N companion matrix (non-proportional damping).
    Companion,
    /// Sparse shift-invert Lanczos (the lowest modes).
    Sparse,
}

/// The modes of a model at one sample rate and set of parameter values and gains.
#[derive(Clone, Debug, PartialEq)]
pub struct ModalAnalysis {
    pub sample_rate_hz: f64,
    /// Sorted by frequency.
    pub modes: Vec<Mode>,
    pub num_inputs: usize,
    pub num_outputs: usize,
    /// Per input channel: false when it has no linear path to the moving points (an
    /// audio-rate parameter); its gains are 0.
    pub input_linear: Vec<bool>,
    /// Per output channel: false when it does not observe the moving points.
    pub output_linear: Vec<bool>,
    pub solver: Solver,
    /// True when the damping is proportional (or solved exactly by the companion matrix), so
    /// the decays are exact.
    pub proportional: bool,
    /// The number of moving points.
    pub degrees_of_freedom: usize,
    /// Why no mode was computed, when the analysis could not run on this model: values the
    /// eigensolvers cannot take, or a solver that failed. The model still plays (the
    /// instrument then uses the Gershgorin clamp and the impulse pitch estimate).
    pub skipped: Option<String>,
    /// A 3-D model's static equilibrium, where its modes are linearised (3-D spec §6.1): x, y
    /// and z of each point, in [`Mode::shape`]'s layout, so that a mode's shape moves around
    /// it. Empty for a 1-D model, linearised at its stage-0 positions (the engine's).
    pub rest: Vec<f64>,
}

impl ModalAnalysis {
    /// The gain of mode `mode` from input channel `input` to output channel `output`
    /// (1-based channels, as `@in1` / `@out1`).
    pub fn gain(&self, mode: usize, input: usize, output: usize) -> f64 {
        let (i, o) = (input.wrapping_sub(1), output.wrapping_sub(1));
        if i >= self.num_inputs || o >= self.num_outputs {
            return 0.0;
        }
        self.modes
            .get(mode)
            .map_or(0.0, |m| m.gains[i * self.num_outputs + o])
    }

    /// |Σ residue| over `modes` from `input` to `output` (1-based channels).
    fn residue_sum(&self, modes: std::ops::Range<usize>, input: usize, output: usize) -> f64 {
        let (i, o) = (input.wrapping_sub(1), output.wrapping_sub(1));
        if i >= self.num_inputs || o >= self.num_outputs {
            return 0.0;
        }
        let (re, im) = self.modes[modes]
            .iter()
            .map(|m| m.residues[i * self.num_outputs + o])
            .fold((0.0, 0.0), |a, r| (a.0 + r.0, a.1 + r.1));
        re.hypot(im)
    }

    /// The strongest mode above `min_hz` from `input` to `output` (1-based channels). The
    /// copies of a repeated mode count together, by the modulus of their summed residue: the
    /// amplitude of the one sinusoid they make, whatever basis the solver chose.
    pub fn strongest(&self, input: usize, output: usize, min_hz: f64) -> Option<&Mode> {
        let mut best: Option<(usize, f64)> = None;
        let mut k = 0;
        while k < self.modes.len() {
            let f = self.modes[k].frequency_hz;
            let mut end = k + 1;
            while end < self.modes.len()
                && (self.modes[end].frequency_hz - f).abs() <= 1e-9 * f.abs().max(1e-9)
            {
                end += 1;
            }
            let total = self.residue_sum(k..end, input, output);
            if f >= min_hz && total.is_finite() && best.is_none_or(|(_, g)| total > g) {
                best = Some((k, total));
            }
            k = end;
        }
        best.filter(|&(_, g)| g > 0.0).map(|(k, _)| &self.modes[k])
    }
}

/// The note name and cents of a frequency (A4 = 440 Hz, C4 = MIDI 60): ("A4", 0.0).
pub fn note_name(freq_hz: f64) -> Option<(String, f64)> {
    if !(freq_hz > 0.0 && freq_hz.is_finite()) {
        return None;
    }
    const NAMES: [&str; 12] = [
        "C", "C#", "D", "D#", "E", "F", "F#", "G", "G#", "A", "A#", "B",
    ];
    let midi = 69.0 + 12.0 * (freq_hz / 440.0).log2();
    let nearest = midi.round();
    let cents = 100.0 * (midi - nearest);
    let n = nearest as i64;
    let name = NAMES[n.rem_euclid(12) as usize];
    Some((format!("{name}{}", n.div_euclid(12) - 1), cents))
}

/// Parses a note name (`A4`, `C#3`, `Eb2`, case-insensitive) into its frequency (A4 = 440 Hz).
pub fn note_frequency(name: &str) -> Option<f64> {
    let s = name.trim();
    let mut chars = s.chars();
    let letter = chars.next()?.to_ascii_uppercase();
    let base = match letter {
        'C' => 0,
        'D' => 2,
        'E' => 4,
        'F' => 5,
        'G' => 7,
        'A' => 9,
        'B' => 11,
        _ => return None,
    };
    let rest: &str = &s[1..];
    let (shift, octave) = if let Some(o) = rest.strip_prefix('#') {
        (1, o)
    } else if let Some(o) = rest.strip_prefix('b') {
        (-1, o)
    } else {
        (0, rest)
    };
    let octave: i64 = octave.parse().ok()?;
    let midi = (octave + 1) * 12 + base + shift;
    Some(440.0 * 2f64.powf((midi as f64 - 69.0) / 12.0))
}

impl Engine {
    /// The modes of the model linearised at rest, with its current parameter values and host
    /// gains (spec §5.5): every mode, sorted by frequency, or the lowest `count`. Models with
    /// more than [`DENSE_LIMIT`] moving points give the lowest `count` (default
    /// [`DEFAULT_SPARSE_COUNT`]). Off the audio thread: it allocates and takes up to a few
    /// seconds on the largest models.
    ///
    /// A force input on a point with contacts open at rest (a hammer) also drives what those
    /// contacts strike, with weight 1: its gains are those of the blow it delivers.
    pub fn modes(&mut self, count: Option<usize>) -> ModalAnalysis {
        if self.space.is_some() {
            return self.modes_in_space(count);
        }
        let rest = self.rest_positions();
        let net = Network::walk(self, Valuation::Rest(&rest));
        let sys = System::assemble(self, &net, true);
        let (num_points, sample_rate) = (self.model.info.num_points, self.sample_rate_hz());
        // A failure inside a linear-algebra crate ends this analysis, not the host.
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            solve::modes(&sys, num_points, sample_rate, count)
        }))
        .unwrap_or_else(|_| {
            let mut empty = solve::unsolved(&sys, sample_rate);
            empty.skipped = Some("the eigensolver failed on this model".into());
            empty
        })
    }

    /// The modes of a 3-D model (3-D spec §6): linearised at its static equilibrium, three
    /// degrees of freedom per point ([`Mode::shape`] has x, y and z per point).
    fn modes_in_space(&mut self, count: Option<usize>) -> ModalAnalysis {
        self.apply_pending_changes();
        let eq = crate::analysis::space::equilibrium::equilibrium(self);
        let sys = crate::analysis::space::system::assemble(self, &eq.x, true);
        let (slots, sample_rate) = (3 * self.model.info.num_points, self.sample_rate_hz());
        let mut analysis = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            solve::modes(&sys, slots, sample_rate, count)
        }))
        .unwrap_or_else(|_| {
            let mut empty = solve::unsolved(&sys, sample_rate);
            empty.skipped = Some("the eigensolver failed on this model".into());
            empty
        });
        analysis.rest = eq.x[..self.model.info.num_points]
            .iter()
            .flatten()
            .copied()
            .collect();
        analysis
    }

    /// The reference pitch of issue 14: the frequency of the strongest mode (above 20 Hz) that
    /// output channel `output` hears from input channel `input` (1-based), for models of any
    /// size (the lowest [`DEFAULT_SPARSE_COUNT`] modes of large ones). A force input on a
    /// hammer reaches what the hammer strikes through its contacts, open at rest. None when
    /// no mode links them.
    pub fn reference_pitch(&mut self, input: usize, output: usize) -> Option<f64> {
        self.modes(None)
            .strongest(input, output, 20.0)
            .map(|m| m.frequency_hz)
    }
}
