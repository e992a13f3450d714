//! The lowest eigenpairs of a large sparse symmetric S (spec §5.5 for models too large for a
//! dense eigendecomposition): block shift-invert Lanczos with full reorthogonalisation and
//! thick restarts.
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
//! Four choices make it robust where a library's single-vector restarted Lanczos was not, and
//! bound its memory:
//! - **Blocks of [`BLOCK`] vectors.** A Krylov method started from one vector sees one copy of a
//!   repeated eigenvalue; square plates have exactly paired modes, f(k₁, k₂) = f(k₂, k₁). A
//!   block of b vectors sees every copy of an eigenvalue up to multiplicity b.
//! - **Full reorthogonalisation** (classical Gram–Schmidt, twice) against the whole basis, so
//!   that rounding never makes ghost copies of a converged pair and T is Qᵀ·A·Q to rounding.
//! - **A relative convergence test**, residual ≤ [`TOLERANCE`]·θ. The per-step K and M of a
//!   model scale with the sample rate, so θ does; an absolute test converges at one rate and
//!   crawls at another.
//! - **Thick restarts** (Wu and Simon's thick-restart Lanczos, the symmetric case of Stewart's
//!   Krylov–Schur method). The basis holds about twice the p pairs that must converge
//!   ([`BASIS_FACTOR`]) and one block; when it is full, the best Ritz vectors replace it
//!   (`Krylov::restart`) and the expansion goes on from the last block. Its memory is
//!   n × (2p + b) doubles whatever the convergence takes (the 150 × 150 plate's basis 42 → 20
//!   MB), and the orthogonalisation's cost per column stops growing with the columns made.
use super::system::SymSparse;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

/// Vectors per Lanczos block: every copy of an eigenvalue up to this multiplicity is found.
const BLOCK: usize = 4;
/// A Ritz pair (θ, x) has converged when ‖A·x − θ·x‖ ≤ TOLERANCE·θ.
const TOLERANCE: f64 = 1e-11;
/// Extra pairs that must converge beyond those asked for, so that the last wanted ones are
/// not mistaken for a cluster's first.
const GUARD: usize = 4;
/// The basis holds at most max(BASIS_FACTOR·p, p + BASIS_FLOOR) expanded columns for the p
/// pairs that must converge, and one block beyond them; then it restarts. The 150 × 150
/// plate's 54 pairs converge in 240 columns expanded through 4 restarts of a 112-column basis
/// (236 columns without restarts).
const BASIS_FACTOR: usize = 2;
const BASIS_FLOOR: usize = 40;
/// The columns expanded (operator applications) in all, restarts included, are at most this
/// many times the pairs plus a floor: every analysis ends, converged or not (about 3× what the
/// plate takes; the pairs that converged by then are returned).
const MAX_EXPANDED_FACTOR: usize = 8;
const MAX_EXPANDED_FLOOR: usize = 240;
/// Rows of the basis rotated at a time in a restart (the scratch is this many rows of the
/// kept columns).
const ROTATE_ROWS: usize = 512;
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

/// Q[:, 0..k] ← Q[:, 0..j]·Y for Y of j × k (k ≤ j), [`ROTATE_ROWS`] rows at a time, so that
/// the product needs a slab of scratch rather than a second n × k matrix.
fn rotate_in_place(q: &mut Mat<f64>, y: MatRef<'_, f64>) {
    let (n, j, k) = (q.nrows(), y.nrows(), y.ncols());
    let mut slab = Mat::<f64>::zeros(ROTATE_ROWS.min(n), k);
    let mut row = 0;
    while row < n {
        let len = ROTATE_ROWS.min(n - row);
        let mut out = slab.as_mut().subrows_mut(0, len);
        let rows = q.as_ref().submatrix(row, 0, len, j);
        faer::linalg::matmul::matmul(out.as_mut(), Accum::Replace, rows, y, 1.0, Par::Seq);
        q.as_mut()
            .submatrix_mut(row, 0, len, k)
            .copy_from(out.as_ref());
        row += len;
    }
}

/// The Krylov basis and its projection: expanded columns 0..`j0` and the block `j0..m` still
/// to expand, with A·Q[.., 0..j0] = Q[.., 0..m]·H[0..m, 0..j0].
struct Krylov {
    /// The orthonormal basis, n × m; its capacity is the cap of the basis.
    q: Mat<f64>,
    /// h[.., j] = Qᵀ·A·q_j; below the expanded square, the unexpanded block's coupling.
    h: Mat<f64>,
    j0: usize,
    m: usize,
    /// The last start vector used (a deflated column takes the next).
    seed: usize,
}

impl Krylov {
    /// Thick restart: the `keep` Ritz vectors of largest θ (the last columns of `y`, whose
    /// values are the last of `theta`) become the basis, and the unexpanded block follows them.
    ///
    /// ```text
    ///   A·Q_j = Q_j·T + Q_r·B,   T = Y·Θ·Yᵀ   ⇒   A·(Q_j·Y_k) = (Q_j·Y_k)·Θ_k + Q_r·(B·Y_k)
    /// ```
    ///
    /// so the new H is diagonal on the kept columns, Θ_k, with the coupling B·Y_k (the kept
    /// pairs' residuals) below it, and the expansion goes on from the block Q_r.
    fn restart(&mut self, theta: faer::ColRef<'_, f64>, y: MatRef<'_, f64>, keep: usize) {
        let (j0, r) = (self.j0, self.m - self.j0);
        let y_k = y.subcols(j0 - keep, keep);
        let coupling = self.h.as_ref().submatrix(j0, 0, r, j0) * y_k;
        rotate_in_place(&mut self.q, y_k);
        let (mut kept, block) = self.q.as_mut().split_at_col_mut(j0);
        for c in 0..r {
            kept.as_mut()
                .col_mut(keep + c)
                .copy_from(block.as_ref().col(c));
        }
        let n = self.q.nrows();
        self.q.truncate(n, keep + r);
        self.h.fill(0.0);
        for c in 0..keep {
            self.h[(c, c)] = theta[j0 - keep + c];
        }
        self.h
            .as_mut()
            .submatrix_mut(keep, 0, r, keep)
            .copy_from(&coupling);
        self.j0 = keep;
        self.m = keep + r;
    }
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
    drop(shifted);

    let need = (want + GUARD).min(n);
    let b = BLOCK.min(n);
    // The expanded columns before a restart, and the block beyond them; below n, a restart
    // frees room for the next block whenever it would not fit.
    let basis = (BASIS_FACTOR * need).max(need + BASIS_FLOOR);
    let cap = n.min(basis + b);
    let restarts = cap < n;
    let max_expanded = MAX_EXPANDED_FACTOR * need + MAX_EXPANDED_FLOOR;
    // Reserved once: the basis never grows beyond `cap` columns.
    let mut q = Mat::<f64>::with_capacity(n, cap);
    q.resize_with(n, 0, |_, _| 0.0);
    let mut k = Krylov {
        q,
        h: Mat::<f64>::zeros(cap, cap),
        j0: 0,
        m: 0,
        seed: b,
    };
    let start = Mat::<f64>::from_fn(n, b, |i, c| start_vector(c)(i));
    append_block(&mut k.q, &mut k.m, start, &mut k.seed);

    let mut expanded = 0;
    let mut checked = 0;
    while k.j0 < k.m {
        let (j0, j1) = (k.j0, k.m);
        // W = A·Q_j by the Cholesky factor, orthogonalised against the whole basis.
        let mut w = k.q.as_ref().subcols(j0, j1 - j0).to_owned();
        llt.solve_in_place(w.as_mut());
        let c = project_out(k.q.as_ref().subcols(0, j1), w.as_mut());
        k.h.as_mut().submatrix_mut(0, j0, j1, j1 - j0).copy_from(&c);
        let r = append_block(&mut k.q, &mut k.m, w, &mut k.seed);
        let added = k.m - j1;
        k.h.as_mut()
            .submatrix_mut(j1, j0, added, j1 - j0)
            .copy_from(r.as_ref().subrows(0, added));
        expanded += j1 - j0;
        k.j0 = j1;
        // No room for the next block: restart (or, when the basis may grow to n, go on).
        let full = restarts && k.m + b > cap;
        let last = k.j0 >= k.m || expanded >= max_expanded;
        if !(full || last) && (k.j0 < need || k.j0 - checked < CHECK_EVERY) {
            continue;
        }
        // Rayleigh–Ritz on the expanded columns 0..j0.
        let j0 = k.j0;
        checked = j0;
        let t = Mat::<f64>::from_fn(j0, j0, |a, c| 0.5 * (k.h[(a, c)] + k.h[(c, a)]));
        let evd = t.self_adjoint_eigen(Side::Lower).ok()?;
        let theta = evd.S().column_vector();
        let y = evd.U();
        // A Ritz pair's residual is its coupling to the columns not yet expanded.
        let tail = k.h.as_ref().submatrix(j0, 0, k.m - j0, j0);
        let converged = (0..j0)
            .rev()
            .take(need)
            .take_while(|&c| (tail * y.col(c)).norm_l2() <= TOLERANCE * theta[c].abs())
            .count();
        if converged >= need || last {
            // Largest θ first: the lowest λ = σ + 1/θ, ascending. The vectors are formed in
            // the basis's own columns, and copied out once the factor is freed.
            let pick: Vec<usize> = (0..j0).rev().take(converged.min(want)).collect();
            let sel = Mat::<f64>::from_fn(j0, pick.len(), |a, c| y[(a, pick[c])]);
            let lambdas: Vec<f64> = pick.iter().map(|&c| sigma + 1.0 / theta[c]).collect();
            drop(llt);
            rotate_in_place(&mut k.q, sel.as_ref());
            let Krylov { q, h, .. } = k;
            drop(h);
            let vectors = q.as_ref().subcols(0, pick.len()).to_owned();
            drop(q);
            return Some(verified(s, lambdas, vectors, 1e-9 * max_diag));
        }
        if full {
            // Keep the converged pairs and half the others, at least the pairs needed, and
            // leave room for one block to expand.
            let keep = (converged + (j0 - converged) / 2)
                .max(need)
                .min(cap - 2 * b);
            k.restart(theta, y, keep);
            checked = k.j0;
        }
    }
    None
}

/// The pairs that hold in S itself: ‖S·x − λ·x‖ ≤ `tolerance` (the others are left out).
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
    if keep.len() == lambdas.len() {
        return (lambdas, vectors);
    }
    let out = Mat::<f64>::from_fn(n, keep.len(), |i, c| vectors[(i, keep[c])]);
    (keep.iter().map(|&k| lambdas[k]).collect(), out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed–fixed chain of unit springs and masses: S = tridiag(−1, 2, −1), whose
    /// eigenvalues are λ_j = 4·sin²(jπ / 2(n + 1)).
    fn chain(n: usize) -> SymSparse {
        let mut raw: Vec<(u32, u32, f64)> = (0..n as u32).map(|i| (i, i, 2.0)).collect();
        raw.extend((1..n as u32).map(|i| (i, i - 1, -1.0)));
        SymSparse::from_entries(n, raw)
    }

    /// Through restarts (30 pairs and the guard's 4 in a basis of 74 columns and a block; the
    /// chain takes 124 columns, two restarts), the pairs are the closed form's and the vectors
    /// stay orthonormal.
    #[test]
    fn restarted_pairs_are_the_closed_form_and_orthonormal() {
        let n = 3000;
        let (lambdas, vectors) = lowest_eigenpairs(&chain(n), 30).expect("it converges");
        assert_eq!(lambdas.len(), 30);
        for (j, l) in lambdas.iter().enumerate() {
            let s = ((j + 1) as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64)).sin();
            let exact = 4.0 * s * s;
            assert!(
                (l - exact).abs() <= 1e-9 * exact,
                "λ{}: {l} vs {exact}",
                j + 1
            );
        }
        let gram = vectors.transpose() * &vectors;
        for a in 0..30 {
            for c in 0..30 {
                let expect = if a == c { 1.0 } else { 0.0 };
                assert!((gram[(a, c)] - expect).abs() < 1e-10, "QᵀQ at ({a}, {c})");
            }
        }
    }
}
