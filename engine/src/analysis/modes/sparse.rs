//! The lowest eigenpairs of a large sparse symmetric S (spec §5.5 for models too large for a
//! dense eigendecomposition): block shift-invert Lanczos with full reorthogonalisation.
//!
//! S − σI (σ slightly below 0, so free structures with λ = 0 stay factorable) is factored once
//! by sparse Cholesky. The operator A = (S − σI)⁻¹ has eigenvalues θ = 1/(λ − σ): the lowest λ
//! are the largest θ, well separated from the bulk that crowds near 0, which is where Lanczos
//! converges first. With Q the orthonormal Krylov basis built block by block,
//!
//! ```text
//!   A·Q_j = Q_{j−1}·R_{j−1}ᵀ + Q_j·T_j + Q_{j+1}·R_j       (block three-term recurrence)
//!   T = Qᵀ·A·Q,   Ritz pairs (θ, Q·y) from T·y = θ·y,   residual ‖R_last·y_last‖
//! ```
//!
//! Three choices make it robust where a library's single-vector restarted Lanczos was not:
//! - **Blocks of [`BLOCK`] vectors.** A Krylov method started from one vector sees one copy of a
//!   repeated eigenvalue; square plates have exactly paired modes, f(k₁, k₂) = f(k₂, k₁). A
//!   block of b vectors sees every copy of an eigenvalue up to multiplicity b.
//! - **Full reorthogonalisation** (classical Gram–Schmidt, twice) against the whole basis, so
//!   that rounding never makes ghost copies of a converged pair and T is Qᵀ·A·Q to rounding.
//! - **A relative convergence test**, residual ≤ [`TOLERANCE`]·θ. The per-step K and M of a
//!   model scale with the sample rate, so θ does; an absolute test converges at one rate and
//!   crawls at another.

use super::system::SymSparse;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt;
use faer::{Accum, Mat, MatMut, Par, Side};

/// Vectors per Lanczos block: every copy of an eigenvalue up to this multiplicity is found.
const BLOCK: usize = 4;
/// A Ritz pair (θ, x) has converged when ‖A·x − θ·x‖ ≤ TOLERANCE·θ.
const TOLERANCE: f64 = 1e-11;
/// Extra pairs that must converge beyond those asked for, so that the last wanted ones are
/// not mistaken for a cluster's first.
const GUARD: usize = 4;
/// The basis grows to at most this many times the pairs asked for (plus a floor).
const MAX_BASIS_FACTOR: usize = 6;
const MAX_BASIS_FLOOR: usize = 120;
/// Basis columns added between two Rayleigh–Ritz checks.
const CHECK_EVERY: usize = 16;
/// A new column keeping less than this fraction of its norm through the orthogonalisation
/// is in the span already (an invariant subspace was found): a fresh start vector replaces it.
const BREAKDOWN: f64 = 1e-9;

/// A deterministic start vector, every component non-zero, different for every `seed`.
fn start_vector(seed: usize) -> impl Fn(usize) -> f64 {
    let a = 0.754_877_666_246_692_7 * (seed + 1) as f64;
    move |i| 1.0 + 0.5 * ((i as f64 + 1.0) * a).sin() + 0.25 * ((i as f64 + 3.0) * a * 1.7).cos()
}

/// w ← w − Q·(Qᵀ·w), twice; returns the coefficients of both passes, summed (m × cols).
fn project_out(q: faer::MatRef<'_, f64>, mut w: MatMut<'_, f64>) -> Mat<f64> {
    let mut total = Mat::<f64>::zeros(q.ncols(), w.ncols());
    if q.ncols() == 0 {
        return total;
    }
    for _ in 0..2 {
        let c = q.transpose() * w.as_ref();
        faer::linalg::matmul::matmul(w.as_mut(), Accum::Add, q, c.as_ref(), -1.0, Par::Seq);
        total += &c;
    }
    total
}

/// Appends the columns of `w` (already orthogonal to the basis) to the basis, orthonormalising
/// them among themselves (modified Gram–Schmidt). Returns R with w = Q_new·R (R upper
/// triangular; a column in the span already gets a zero row and a fresh start vector).
fn append_block(q: &mut Mat<f64>, m: &mut usize, mut w: Mat<f64>, seed: &mut usize) -> Mat<f64> {
    let (n, b) = (w.nrows(), w.ncols());
    let mut r = Mat::<f64>::zeros(b, b);
    let first = *m;
    for c in 0..b {
        if *m >= n {
            break;
        }
        let before = w.col(c).norm_l2();
        for p in first..*m {
            let d = q.col(p).transpose() * w.col(c);
            r[(p - first, c)] += d;
            let qp = q.col(p).to_owned();
            w.col_mut(c)
                .iter_mut()
                .zip(qp.iter())
                .for_each(|(x, y)| *x -= d * y);
        }
        let mut norm = w.col(c).norm_l2();
        let mut v = w.col(c).to_owned();
        if !(norm > BREAKDOWN * before.max(f64::MIN_POSITIVE)) {
            // Deflation: continue from a fresh direction orthogonal to the whole basis.
            *seed += 1;
            let f = start_vector(*seed);
            let mut fresh = Mat::<f64>::from_fn(n, 1, |i, _| f(i));
            project_out(q.as_ref().subcols(0, *m), fresh.as_mut());
            v = fresh.col(0).to_owned();
            norm = v.norm_l2();
            if !(norm > 0.0) {
                break;
            }
        } else {
            r[(*m - first, c)] = norm;
        }
        let inv = 1.0 / norm;
        if q.ncols() <= *m {
            q.resize_with(n, *m + 1, |_, _| 0.0);
        }
        q.col_mut(*m)
            .iter_mut()
            .zip(v.iter())
            .for_each(|(x, y)| *x = y * inv);
        *m += 1;
    }
    r
}

/// The `want` lowest eigenvalues of S (ascending) and their orthonormal vectors (columns).
pub(super) fn lowest_eigenpairs(s: &SymSparse, want: usize) -> Option<(Vec<f64>, Mat<f64>)> {
    let n = s.n;
    let want = want.min(n);
    if want == 0 {
        return Some((Vec::new(), Mat::zeros(n, 0)));
    }
    let max_diag = s
        .entries
        .iter()
        .filter(|e| e.0 == e.1)
        .map(|e| e.2.abs())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let sigma = -1e-6 * max_diag;
    let shifted = SymSparse::combine(1.0, s, 0.0, s, &vec![-sigma; n]);
    let llt: Llt<u32, f64> = shifted.lower()?.sp_cholesky(Side::Lower).ok()?;

    let need = (want + GUARD).min(n);
    let limit = n.min(MAX_BASIS_FACTOR * need + MAX_BASIS_FLOOR);
    let b = BLOCK.min(n);
    // Room for the block beyond the last one expanded, whose R gives the residuals.
    let cap = n.min(limit + 2 * b);
    // Reserved, and filled a column at a time: the plate converges in 236 of its 452 columns,
    // and the pages of the rest, never written, never become resident (the analysed plate's
    // peak 130 → 89 MB).
    let mut q = Mat::<f64>::with_capacity(n, cap);
    q.resize_with(n, 0, |_, _| 0.0);
    // h[.., j] = Qᵀ·A·q_j, with the next block's R below the diagonal block.
    let mut h = Mat::<f64>::zeros(cap, cap);
    let mut m = 0;
    let mut seed = b;
    let start = Mat::<f64>::from_fn(n, b, |i, c| start_vector(c)(i));
    append_block(&mut q, &mut m, start, &mut seed);

    let mut j0 = 0; // the first column of the block to expand
    let mut checked = 0;
    while j0 < m && j0 < limit {
        let j1 = m;
        // W = A·Q_j by the Cholesky factor, orthogonalised against the whole basis.
        let mut w = q.as_ref().subcols(j0, j1 - j0).to_owned();
        llt.solve_in_place(w.as_mut());
        let c = project_out(q.as_ref().subcols(0, m), w.as_mut());
        h.as_mut().submatrix_mut(0, j0, m, j1 - j0).copy_from(&c);
        let r = append_block(&mut q, &mut m, w, &mut seed);
        let added = m - j1;
        h.as_mut()
            .submatrix_mut(j1, j0, added, j1 - j0)
            .copy_from(r.as_ref().subrows(0, added));
        j0 = j1;
        let last = j0 >= m || j0 >= limit;
        if j0 < need || (j0 - checked < CHECK_EVERY && !last) {
            continue;
        }
        // Rayleigh–Ritz on the expanded columns 0..j0.
        checked = j0;
        let t = Mat::<f64>::from_fn(j0, j0, |a, c| 0.5 * (h[(a, c)] + h[(c, a)]));
        let evd = t.self_adjoint_eigen(Side::Lower).ok()?;
        let theta = evd.S().column_vector();
        let y = evd.U();
        // A Ritz pair's residual is its coupling to the columns not yet expanded.
        let tail = h.as_ref().submatrix(j0, 0, m - j0, j0);
        let converged = (0..j0)
            .rev()
            .take(need)
            .take_while(|&k| (tail * y.col(k)).norm_l2() <= TOLERANCE * theta[k].abs())
            .count();
        if converged >= need || last {
            // Largest θ first: the lowest λ = σ + 1/θ, ascending.
            let pick: Vec<usize> = (0..j0).rev().take(converged.min(want)).collect();
            let sel = Mat::<f64>::from_fn(j0, pick.len(), |a, c| y[(a, pick[c])]);
            let vectors = q.as_ref().subcols(0, j0) * &sel;
            let lambdas: Vec<f64> = pick.iter().map(|&k| sigma + 1.0 / theta[k]).collect();
            return Some(verified(s, lambdas, vectors, 1e-9 * max_diag));
        }
    }
    None
}

/// The pairs that hold in S itself: ‖S·x − λ·x‖ ≤ `tolerance`.
fn verified(
    s: &SymSparse,
    lambdas: Vec<f64>,
    vectors: Mat<f64>,
    tolerance: f64,
) -> (Vec<f64>, Mat<f64>) {
    let n = s.n;
    let mut x = vec![0.0; n];
    let mut sx = vec![0.0; n];
    let mut keep = Vec::new();
    for (k, &lambda) in lambdas.iter().enumerate() {
        x.iter_mut()
            .zip(vectors.col(k).iter())
            .for_each(|(a, b)| *a = *b);
        s.mul(&x, &mut sx);
        let res = sx
            .iter()
            .zip(&x)
            .map(|(a, b)| (a - lambda * b).powi(2))
            .sum::<f64>()
            .sqrt();
        if res <= tolerance {
            keep.push(k);
        }
    }
    let out = Mat::<f64>::from_fn(n, keep.len(), |i, c| vectors[(i, keep[c])]);
    (keep.iter().map(|&k| lambdas[k]).collect(), out)
}
