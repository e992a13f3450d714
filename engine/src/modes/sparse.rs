//! The lowest eigenpairs of a large sparse symmetric S (spec §5.5 for models too large for a
//! dense eigendecomposition): shift-invert Lanczos. S − σI (σ slightly below 0, so free
//! structures with λ = 0 stay factorable) is factored once by sparse Cholesky; the eigenvalues
//! θ of (S − σI)⁻¹ with the largest magnitude are the λ = σ + 1/θ nearest σ, the lowest.
//!
//! A Krylov method started from one vector sees one copy of a repeated eigenvalue in exact
//! arithmetic (square plates have paired modes, f(k₁, k₂) = f(k₂, k₁)), and in floating point
//! may also return spurious copies of a converged one. So the solver runs twice, in parallel,
//! from different start vectors, each finding its own vector of every repeated eigenspace, and
//! merges the runs by Rayleigh–Ritz on the union of their vectors, keeping the pairs whose
//! residual has converged. Two runs find both copies of the pairs of square plates; three-fold
//! or higher multiplicities would need more.

use super::system::SymSparse;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::solvers::Solve;
use faer::matrix_free::eigen::{
    partial_self_adjoint_eigen, partial_self_adjoint_eigen_scratch, PartialEigenParams,
};
use faer::matrix_free::LinOp;
use faer::reborrow::ReborrowMut;
use faer::sparse::linalg::solvers::Llt;
use faer::{Mat, MatMut, MatRef, Par, Side};

/// Lanczos runs from different start vectors: two find both copies of every pair.
const RUNS: usize = 2;
/// The Krylov solver's convergence tolerance.
const LANCZOS_TOLERANCE: f64 = f64::EPSILON * 128.0;
/// Extra eigenpairs asked of each run, so that the last wanted ones converge.
const GUARD: usize = 10;

/// x ↦ (S − σI)⁻¹·x by the sparse Cholesky factor.
#[derive(Debug)]
struct ShiftInvert<'a> {
    llt: &'a Llt<u32, f64>,
    n: usize,
}

impl LinOp<f64> for ShiftInvert<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.n
    }
    fn ncols(&self) -> usize {
        self.n
    }
    fn apply(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _s: &mut MemStack) {
        out.copy_from(rhs);
        self.llt.solve_in_place(out.rb_mut());
    }
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, s: &mut MemStack) {
        self.apply(out, rhs, par, s);
    }
}

/// One Lanczos run: the eigenpairs (θ, vector) it converged, largest θ first.
fn run(op: &ShiftInvert<'_>, want: usize, seed: f64) -> Vec<(f64, Vec<f64>)> {
    let n = op.nrows();
    let want = want.min(n);
    let par = Par::Seq;
    let params = PartialEigenParams::default();
    let mut mem = MemBuffer::new(partial_self_adjoint_eigen_scratch(op, want, par, params));
    // A deterministic start with every component non-zero, different for every seed.
    let mut v0 = Mat::<f64>::from_fn(n, 1, |i, _| 1.0 + 0.5 * ((i as f64 + 1.0) * seed).sin());
    let norm = v0.norm_l2();
    if !(norm > 0.0) {
        return Vec::new();
    }
    v0 /= faer::Scale(norm);
    let mut vecs = Mat::<f64>::zeros(n, want);
    let mut vals = vec![0.0; want];
    let info = partial_self_adjoint_eigen(
        vecs.as_mut(),
        &mut vals,
        op,
        v0.col(0),
        LANCZOS_TOLERANCE,
        par,
        MemStack::new(&mut mem),
        params,
    );
    (0..info.n_converged_eigen)
        .filter(|&k| vals[k] > 0.0)
        .map(|k| (vals[k], (0..n).map(|i| vecs[(i, k)]).collect()))
        .collect()
}

/// Orthonormal columns spanning the vectors (modified Gram–Schmidt, twice), dropping the
/// ones already in the span (a Krylov solver's spurious copies of a converged vector).
fn orthonormalise(vectors: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    let mut cols: Vec<Vec<f64>> = Vec::with_capacity(vectors.len());
    for mut v in vectors {
        let start = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        for _ in 0..2 {
            for c in &cols {
                let d: f64 = c.iter().zip(&v).map(|(a, b)| a * b).sum();
                for (x, y) in v.iter_mut().zip(c) {
                    *x -= d * y;
                }
            }
        }
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm > 1e-6 * start {
            v.iter_mut().for_each(|x| *x /= norm);
            cols.push(v);
        }
    }
    cols
}

/// The Ritz pairs of S on an orthonormal basis Q (eigenpairs of QᵀSQ), ascending, keeping
/// those whose residual ‖Sq − λq‖ is below `tolerance`: the converged eigenpairs.
fn rayleigh_ritz(s: &SymSparse, basis: Vec<Vec<f64>>, tolerance: f64) -> (Vec<Vec<f64>>, Vec<f64>) {
    let (n, m) = (s.n, basis.len());
    if m == 0 {
        return (basis, Vec::new());
    }
    let q = Mat::<f64>::from_fn(n, m, |i, j| basis[j][i]);
    let mut sq = Mat::<f64>::zeros(n, m);
    let mut y = vec![0.0; n];
    for (j, v) in basis.iter().enumerate() {
        s.mul(v, &mut y);
        for i in 0..n {
            sq[(i, j)] = y[i];
        }
    }
    let h = q.transpose() * &sq;
    let h = Mat::<f64>::from_fn(m, m, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
    let Ok(evd) = h.self_adjoint_eigen(Side::Lower) else {
        return (Vec::new(), Vec::new());
    };
    let ritz = &q * evd.U();
    let s_ritz = &sq * evd.U();
    let mut vecs = Vec::new();
    let mut vals = Vec::new();
    for k in 0..m {
        let lambda = evd.S().column_vector()[k];
        let residual = (0..n)
            .map(|i| (s_ritz[(i, k)] - lambda * ritz[(i, k)]).powi(2))
            .sum::<f64>()
            .sqrt();
        if residual <= tolerance {
            vecs.push((0..n).map(|i| ritz[(i, k)]).collect());
            vals.push(lambda);
        }
    }
    (vecs, vals)
}

/// The `want` lowest eigenvalues of S (ascending) and their orthonormal vectors (columns).
pub(super) fn lowest_eigenpairs(s: &SymSparse, want: usize) -> Option<(Vec<f64>, Mat<f64>)> {
    let n = s.n;
    let max_diag = s
        .entries
        .iter()
        .filter(|e| e.0 == e.1)
        .map(|e| e.2.abs())
        .fold(0.0, f64::max);
    let sigma = -1e-6 * max_diag.max(f64::MIN_POSITIVE);
    let shifted = SymSparse::combine(1.0, s, 0.0, s, &vec![-sigma; n]);
    let llt = shifted.lower()?.sp_cholesky(Side::Lower).ok()?;
    let ask = (want + GUARD).min(n);
    let tolerance = 1e-9 * max_diag.max(f64::MIN_POSITIVE);
    // The runs are independent: each on its own thread (the factor is shared read-only).
    let op = ShiftInvert { llt: &llt, n };
    let runs: Vec<Vec<(f64, Vec<f64>)>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..RUNS)
            .map(|k| {
                let op = &op;
                scope.spawn(move || run(op, ask, 0.7548776662466927 * (k + 1) as f64))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_default())
            .collect()
    });
    let candidates: Vec<Vec<f64>> = runs.into_iter().flatten().map(|(_, v)| v).collect();
    let (mut basis, mut lambdas) = rayleigh_ritz(s, orthonormalise(candidates), tolerance);
    basis.truncate(want);
    lambdas.truncate(want);
    let vectors = Mat::<f64>::from_fn(n, basis.len(), |i, j| basis[j][i]);
    Some((lambdas, vectors))
}
