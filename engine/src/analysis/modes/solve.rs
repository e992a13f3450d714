//! From the linear system to the modes (spec §5.5): the symmetric eigenproblem of
//! S = M^−½·K·M^−½, the per-mode recurrence for proportional damping, the companion matrix
//! otherwise, and the residues of every (input, output) pair.

use super::sparse::lowest_eigenpairs;
use super::system::{Port, System};
use super::{
    ModalAnalysis, Mode, Solver, ANALYSIS_LIMIT, COMPANION_LIMIT, DEFAULT_SPARSE_COUNT, DENSE_LIMIT,
};
use faer::linalg::solvers::Solve;
use faer::{c64, Mat, Side};

/// Damping counts as proportional when the off-diagonal part of ψᵀΓψ is below this fraction
/// of its largest entry.
const PROPORTIONAL_TOLERANCE: f64 = 1e-9;

/// An analysis of `sys` with no mode yet.
pub(super) fn unsolved(sys: &System, sample_rate: f64) -> ModalAnalysis {
    ModalAnalysis {
        sample_rate_hz: sample_rate,
        modes: Vec::new(),
        num_inputs: sys.inputs.len(),
        num_outputs: sys.outputs.len(),
        input_linear: sys.inputs.iter().map(|p| p.linear).collect(),
        output_linear: sys.outputs.iter().map(|p| p.linear).collect(),
        solver: Solver::Dense,
        proportional: true,
        degrees_of_freedom: sys.len(),
        skipped: None,
        rest: Vec::new(),
    }
}

pub(super) fn modes(
    sys: &System,
    num_points: usize,
    sample_rate: f64,
    count: Option<usize>,
) -> ModalAnalysis {
    let n = sys.len();
    let inv_sqrt_m: Vec<f64> = sys.mass.iter().map(|m| 1.0 / m.sqrt()).collect();
    let s = sys.k.scaled(&inv_sqrt_m);
    let gamma = sys.z.scaled(&inv_sqrt_m);
    let mut analysis = unsolved(sys, sample_rate);
    if n == 0 {
        return analysis;
    }
    if let Some(bad) = sys.mass.iter().find(|m| !(m.is_finite() && **m > 0.0)) {
        analysis.skipped = Some(format!(
            "a moving mass of {bad:e}: masses must be finite and positive"
        ));
        return analysis;
    }
    if !(s.is_within(ANALYSIS_LIMIT) && gamma.is_within(ANALYSIS_LIMIT)) {
        analysis.skipped = Some(format!(
            "stiffness or damping over mass beyond {ANALYSIS_LIMIT:e} per step (or not finite)"
        ));
        return analysis;
    }
    let (lambdas, psi) = if n <= DENSE_LIMIT {
        let Ok(evd) = s.dense().self_adjoint_eigen(Side::Lower) else {
            return analysis;
        };
        let l: Vec<f64> = (0..n).map(|i| evd.S().column_vector()[i]).collect();
        (l, evd.U().to_owned())
    } else {
        analysis.solver = Solver::Sparse;
        let want = count.unwrap_or(DEFAULT_SPARSE_COUNT).min(n);
        match lowest_eigenpairs(&s, want) {
            Some(pair) => pair,
            None => return analysis,
        }
    };
    let mut psi = psi;
    canonical_eigenspaces(sys, &inv_sqrt_m, &lambdas, &mut psi);
    let m = lambdas.len();
    // γ_k = ψ_kᵀΓψ_k, and whether Γ is diagonal in the basis ψ (spec §5.5 step 4).
    let mut gammas = vec![0.0; m];
    let mut scale = 0.0f64;
    let mut col = vec![0.0; n];
    let mut g_psi = vec![0.0; n];
    let mut projected = Mat::<f64>::zeros(n, m);
    for k in 0..m {
        for i in 0..n {
            col[i] = psi[(i, k)];
        }
        gamma.mul(&col, &mut g_psi);
        for i in 0..n {
            projected[(i, k)] = g_psi[i];
        }
        gammas[k] = col.iter().zip(&g_psi).map(|(a, b)| a * b).sum();
        scale = scale.max(gammas[k].abs());
    }
    // Each column's residual ‖Γψ_k − γ_kψ_k‖ bounds that column's off-diagonal part of ψᵀΓψ
    // (ψ orthonormal): (ψᵀΓψ)_ik = ψ_iᵀ(Γψ_k − γ_kψ_k) for i ≠ k.
    let residual = (0..m)
        .map(|k| {
            (0..n)
                .map(|i| (projected[(i, k)] - gammas[k] * psi[(i, k)]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0f64, f64::max);
    let within =
        |off: f64, scale: f64| off <= PROPORTIONAL_TOLERANCE * scale.max(f64::MIN_POSITIVE);
    analysis.proportional = if analysis.solver == Solver::Dense {
        // Residuals under the tolerance prove the damping proportional in O(n·m); only above
        // it is the dense product (2n³ operations, as many as the eigendecomposition) formed
        // for the exact entries.
        within(residual, scale) || {
            let g = psi.transpose() * &projected;
            let mut off = 0.0f64;
            for j in 0..m {
                for i in 0..m {
                    if i != j {
                        off = off.max(g[(i, j)].abs());
                    }
                }
            }
            within(off, scale)
        }
    } else {
        // The residuals against Γ's own scale: the vectors are S's eigenvectors to a residual
        // relative to ‖S‖, not to the lowest modes' λ.
        let scale = gamma
            .entries
            .iter()
            .filter(|e| e.0 == e.1)
            .map(|e| e.2.abs())
            .fold(scale, f64::max);
        within(residual, scale)
    };
    if !analysis.proportional && n <= COMPANION_LIMIT {
        if let Some(modes) = companion_modes(sys, num_points, sample_rate) {
            analysis.solver = Solver::Companion;
            analysis.proportional = true;
            analysis.modes = modes;
            finish(&mut analysis, count);
            return analysis;
        }
    }
    for k in 0..m {
        let phi: Vec<f64> = (0..n).map(|i| psi[(i, k)] * inv_sqrt_m[i]).collect();
        analysis.modes.push(proportional_mode(
            sys,
            num_points,
            sample_rate,
            lambdas[k],
            gammas[k],
            &phi,
        ));
    }
    finish(&mut analysis, count);
    analysis
}

/// Two eigenvalues closer than this, relative to the largest computed, are one repeated
/// eigenvalue.
const REPEATED: f64 = 1e-9;

/// A repeated eigenvalue's vectors are any orthonormal basis of its eigenspace, and solvers
/// pick one by rounding: the copies' shapes and gains would change with the sample rate or
/// the solver. This picks one basis for every eigenspace: the first copy is the shape the
/// first linear input excites (the eigenspace's projection of its force vector), the others
/// are orthogonal to it, and so receive nothing from that input. The rotation is the
/// Householder reflection H with H·e₁ = a/‖a‖, a = Ψᵀ·w, w = M^−½·b the input in S's
/// coordinates.
fn canonical_eigenspaces(sys: &System, inv_sqrt_m: &[f64], lambdas: &[f64], psi: &mut Mat<f64>) {
    let Some(input) = sys.inputs.iter().find(|p| p.linear) else {
        return;
    };
    let n = psi.nrows();
    let w: Vec<f64> = (0..n)
        .map(|i| (input.p[i] + input.q[i]) * inv_sqrt_m[i])
        .collect();
    let scale = lambdas.iter().fold(0.0f64, |a, l| a.max(l.abs()));
    let mut k = 0;
    while k < lambdas.len() {
        let mut end = k + 1;
        while end < lambdas.len() && (lambdas[end] - lambdas[k]).abs() <= REPEATED * scale {
            end += 1;
        }
        let d = end - k;
        if d > 1 {
            let cols = psi.as_ref().subcols(k, d).to_owned();
            let a: Vec<f64> = (0..d)
                .map(|c| (0..n).map(|i| cols[(i, c)] * w[i]).sum())
                .collect();
            let norm = a.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm > 0.0 {
                // v = â − e₁; H = I − 2·v·vᵀ/‖v‖².
                let mut v: Vec<f64> = a.iter().map(|x| x / norm).collect();
                v[0] -= 1.0;
                let vv: f64 = v.iter().map(|x| x * x).sum();
                if vv > 1e-30 {
                    let h = Mat::<f64>::from_fn(d, d, |r, c| {
                        f64::from(u8::from(r == c)) - 2.0 * v[r] * v[c] / vv
                    });
                    let rotated = &cols * &h;
                    psi.as_mut().subcols_mut(k, d).copy_from(&rotated);
                }
            }
        }
        k = end;
    }
}

/// The eigenvectors a nonsymmetric solver returns for a repeated eigenvalue can be nearly
/// parallel (a 6-fold root of a square plate damped at its centre came out with gains of
/// 1e11, and V⁻¹'s huge rows spoiled its neighbours' too; even a pair's vectors at an angle
/// well away from 0 left errors of 1 % in the rebuilt impulse response). Any basis of the
/// eigenspace is a set of eigenvectors, so every repeated root gets a fresh, orthonormal one
/// (0.46 s for a 19 × 19 plate with a few hundred pairs): the eigenvectors are v = (x, x/r)
/// with Q(r)·x = 0,
///
/// ```text
///   Q(r) = r²·I − r·A₁₁ − A₁₂,   A₁₁ = 2I − M⁻¹(K + Z),   A₁₂ = M⁻¹Z − I,
/// ```
///
/// and two steps of block inverse iteration with Q at r (nearly singular) from fixed start
/// vectors, orthonormalised, give a well-conditioned basis of its null space. The conjugate
/// root gets the conjugate vectors.
fn repair_repeated_vectors(a: &Mat<f64>, roots: faer::ColRef<'_, c64>, v: &mut Mat<c64>) {
    let m = roots.nrows();
    let n = m / 2;
    let mut done = vec![false; m];
    for first in 0..m {
        let r = roots[first];
        if done[first] || !(r.im > 0.0) {
            continue;
        }
        let group: Vec<usize> = (first..m)
            .filter(|&b| !done[b] && (roots[b] - r).norm() <= REPEATED * r.norm())
            .collect();
        let conj: Vec<usize> = (0..m)
            .filter(|&b| !done[b] && (roots[b] - r.conj()).norm() <= REPEATED * r.norm())
            .collect();
        for &b in group.iter().chain(&conj) {
            done[b] = true;
        }
        let d = group.len();
        if d < 2 || conj.len() != d {
            continue;
        }
        let q = Mat::<c64>::from_fn(n, n, |i, j| {
            let diag = if i == j { r * r } else { c64::new(0.0, 0.0) };
            diag - r * a[(i, j)] - c64::new(a[(i, n + j)], 0.0)
        });
        let lu = q.partial_piv_lu();
        let mut x = Mat::<c64>::from_fn(n, d, |i, c| {
            let t = (i as f64 + 1.0) * 0.754_877_666_246_692_7 * (c + 1) as f64;
            c64::new(t.sin(), t.cos() * 0.5)
        });
        for _ in 0..2 {
            x = lu.solve(&x);
            orthonormalise_columns(&mut x);
        }
        for (c, (&col, &ccol)) in group.iter().zip(&conj).enumerate() {
            for i in 0..n {
                let xi = x[(i, c)];
                v[(i, col)] = xi;
                v[(n + i, col)] = xi / r;
                v[(i, ccol)] = xi.conj();
                v[(n + i, ccol)] = (xi / r).conj();
            }
        }
    }
}

/// Modified Gram–Schmidt, twice, on complex columns.
fn orthonormalise_columns(x: &mut Mat<c64>) {
    for col in 0..x.ncols() {
        for _ in 0..2 {
            for prev in 0..col {
                let d = (0..x.nrows()).fold(c64::new(0.0, 0.0), |acc, i| {
                    acc + x[(i, prev)].conj() * x[(i, col)]
                });
                for i in 0..x.nrows() {
                    let p = x[(i, prev)];
                    x[(i, col)] -= d * p;
                }
            }
        }
        let norm = (0..x.nrows())
            .map(|i| x[(i, col)].norm_sqr())
            .sum::<f64>()
            .sqrt();
        if norm > 0.0 {
            for i in 0..x.nrows() {
                x[(i, col)] /= c64::new(norm, 0.0);
            }
        }
    }
}

/// One oscillating root of the companion matrix: r, the outputs' coefficients α (of its
/// right eigenvector), the inputs' coefficients β (of its row of V⁻¹), and the position half x
/// of its right eigenvector. The residue from input c to output o is 2·α_o·β_c / r.
struct Root {
    r: c64,
    alpha: Vec<c64>,
    beta: Vec<c64>,
    x: Vec<c64>,
}

/// [`canonical_eigenspaces`] for the companion matrix: within one repeated root the unitary
/// Householder reflection H (Hermitian) with H·β = a·e₁ for input `c`'s coefficients β. The
/// new rows of V⁻¹ are H·W and the new vectors V·H, so every β becomes H·β and every α and x
/// becomes Hᵀ·α (H is Hermitian: (V·Hᴴ)ⱼ = Σₖ vₖ·H_kj), and the residues' sum is kept.
fn canonical_roots(roots: &mut [Root], c: usize) {
    let d = roots.len();
    let b: Vec<c64> = roots.iter().map(|r| r.beta[c]).collect();
    let norm = b.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
    if !(norm > 0.0) {
        return;
    }
    // a = −e^{i·arg b₀}·‖b‖, v = b − a·e₁, H = I − 2·v·vᴴ/(vᴴv).
    let phase = if b[0].norm() > 0.0 {
        b[0] / b[0].norm()
    } else {
        c64::new(1.0, 0.0)
    };
    let mut v = b.clone();
    v[0] += phase * norm;
    let vv: f64 = v.iter().map(|z| z.norm_sqr()).sum();
    if !(vv > 0.0) {
        return;
    }
    let h = |j: usize, k: usize| {
        let delta = if j == k { 1.0 } else { 0.0 };
        c64::new(delta, 0.0) - v[j] * v[k].conj() * (2.0 / vv)
    };
    let zero = c64::new(0.0, 0.0);
    // β' = H·β for every input.
    for input in 0..roots[0].beta.len() {
        let old: Vec<c64> = roots.iter().map(|r| r.beta[input]).collect();
        for j in 0..d {
            roots[j].beta[input] = (0..d).fold(zero, |a, k| a + h(j, k) * old[k]);
        }
    }
    // α' = Hᵀ·α and x' = Hᵀ·x: column j of V·H.
    for output in 0..roots[0].alpha.len() {
        let old: Vec<c64> = roots.iter().map(|r| r.alpha[output]).collect();
        for j in 0..d {
            roots[j].alpha[output] = (0..d).fold(zero, |a, k| a + old[k] * h(k, j));
        }
    }
    for i in 0..roots[0].x.len() {
        let old: Vec<c64> = roots.iter().map(|r| r.x[i]).collect();
        for j in 0..d {
            roots[j].x[i] = (0..d).fold(zero, |a, k| a + old[k] * h(k, j));
        }
    }
}

/// Gains below this fraction of their (input, output) pair's largest are rounding (the copy
/// of a pair that an input does not excite): they read as exactly 0.
const ROUNDING_GAIN: f64 = 1e-12;

/// Sorts by frequency and keeps the lowest `count`; gains at rounding level become 0.
fn finish(analysis: &mut ModalAnalysis, count: Option<usize>) {
    let pairs = analysis.num_inputs * analysis.num_outputs;
    for pair in 0..pairs {
        let largest = analysis
            .modes
            .iter()
            .map(|m| m.gains[pair])
            .fold(0.0f64, f64::max);
        for m in &mut analysis.modes {
            if m.gains[pair] <= ROUNDING_GAIN * largest {
                m.gains[pair] = 0.0;
                m.residues[pair] = (0.0, 0.0);
            }
        }
    }
    analysis
        .modes
        .sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    if let Some(c) = count {
        analysis.modes.truncate(c);
    }
}

/// f = SR·arg(r)/2π and T60 = −3·ln 10 / (SR·ln|r|) (infinite when |r| ≥ 1).
fn frequency_and_t60(r: c64, radius: f64, sample_rate: f64) -> (f64, f64) {
    let f = sample_rate * r.im.atan2(r.re).abs() / (2.0 * std::f64::consts::PI);
    let t60 = if radius < 1.0 {
        -3.0 * std::f64::consts::LN_10 / (sample_rate * radius.ln())
    } else {
        f64::INFINITY
    };
    (f, t60)
}

/// The value of a port at eigenvalue r along a real shape φ: (p + q·(1 − 1/r))·φ.
fn port_at(port: &Port, phi: &[f64], r: c64) -> c64 {
    let p: f64 = port.p.iter().zip(phi).map(|(a, b)| a * b).sum();
    let q: f64 = port.q.iter().zip(phi).map(|(a, b)| a * b).sum();
    c64::new(p, 0.0) + c64::new(q, 0.0) * (c64::new(1.0, 0.0) - r.inv())
}

/// A shape over the material points, largest component ±1.
fn shape_over_points(sys: &System, num_points: usize, x: impl Fn(usize) -> f64) -> Vec<f64> {
    let mut shape = vec![0.0; num_points];
    let mut big = 0.0f64;
    for (i, &p) in sys.point.iter().enumerate() {
        shape[p as usize] = x(i);
        big = big.max(x(i).abs());
    }
    if big > 0.0 {
        for v in &mut shape {
            *v /= big;
        }
    }
    shape
}

/// One mode of the recurrence q[n+1] = (2 − λ − γ)·q[n] + (γ − 1)·q[n−1] + φᵀf[n] (spec §5.1
/// with K/M → λ, Z/M → γ): roots of z² − (2 − λ − γ)·z + (1 − γ) = 0; with q[1] = φᵀb the
/// response is φᵀb·(rⁿ − r₂ⁿ)/(r − r₂), so the residue of r is α·β/(r − r₂).
fn proportional_mode(
    sys: &System,
    num_points: usize,
    sample_rate: f64,
    lambda: f64,
    gamma: f64,
    phi: &[f64],
) -> Mode {
    let a = 2.0 - lambda - gamma;
    let b = 1.0 - gamma;
    let disc = a * a - 4.0 * b;
    // |r|² = r·r̄ = 1 − γ exactly for a complex pair: an undamped mode keeps |r| = 1.
    let (r, r2, complex) = if disc < 0.0 {
        let r = c64::new(a / 2.0, (-disc).sqrt() / 2.0);
        (r, r.conj(), true)
    } else {
        let (r1, r2) = ((a + disc.sqrt()) / 2.0, (a - disc.sqrt()) / 2.0);
        let (big, small) = if r1.abs() >= r2.abs() {
            (r1, r2)
        } else {
            (r2, r1)
        };
        (c64::new(big, 0.0), c64::new(small, 0.0), false)
    };
    let radius = if complex { b.max(0.0).sqrt() } else { r.norm() };
    let (frequency_hz, t60_s) = frequency_and_t60(r, radius, sample_rate);
    let denom = r - r2;
    let mut residues = Vec::with_capacity(sys.inputs.len() * sys.outputs.len());
    for input in &sys.inputs {
        let beta = port_at(input, phi, r);
        for output in &sys.outputs {
            let alpha = port_at(output, phi, r);
            let c = if denom.norm() > 1e-300 {
                alpha * beta / denom * if complex { 2.0 } else { 1.0 }
            } else {
                // A double root (a free body, r = 1): the response grows linearly.
                alpha * beta
            };
            residues.push((c.re, c.im));
        }
    }
    Mode {
        frequency_hz,
        t60_s,
        radius,
        lambda,
        gains: residues.iter().map(|c| c.0.hypot(c.1)).collect(),
        residues,
        shape: shape_over_points(sys, num_points, |i| phi[i]),
    }
}

/// Matrices up to this order take the unblocked QR (see [`eigen_real`]).
const UNBLOCKED_LIMIT: usize = 400;

/// The eigenvalues and right eigenvectors of a real matrix, by faer's unblocked double-shift
/// QR (LAPACK's xLAHQR, at most 30·max(10, n) sweeps, then an error) up to
/// [`UNBLOCKED_LIMIT`], rather than its multishift QR with aggressive early deflation. That
/// one's deflation window is sorted by a bubble sort that restarts after every swap of two
/// Schur blocks; on some companion matrices a 2×2 block swapped forward compares larger again
/// after the swap's standardisation, and the sort never ends (faer 0.24.4,
/// `aggressive_early_deflation`: a damped 8 × 8 membrane with an air cavity, 70 points, spun
/// for ever in `schur_swap_22`). The unblocked QR has no such loop, but its price grows
/// faster: a damped 138-mass string's `ressort modes` takes 0.12 s against 0.06 s, a 378-mass
/// one 2.5 s against 0.9 s (release build, Nov 28), so larger matrices keep the multishift QR
/// (docs/NOTES.md). None when the QR does not converge.
fn eigen_real(a: &Mat<f64>) -> Option<(Mat<c64>, faer::Col<c64>)> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::{self, ComputeEigenvectors, EvdParams};
    let n = a.nrows();
    let mut params: faer::Spec<EvdParams, f64> = Default::default();
    if n <= UNBLOCKED_LIMIT {
        params.schur.blocking_threshold = usize::MAX;
    }
    let mut u = Mat::<f64>::zeros(n, n);
    let mut s_re = faer::diag::Diag::<f64>::zeros(n);
    let mut s_im = faer::diag::Diag::<f64>::zeros(n);
    let par = faer::Par::Seq;
    let scratch = evd::evd_scratch::<f64>(
        n,
        ComputeEigenvectors::No,
        ComputeEigenvectors::Yes,
        par,
        params,
    );
    let mut buffer = MemBuffer::try_new(scratch).ok()?;
    evd::evd_real(
        a.as_ref(),
        s_re.as_mut(),
        s_im.as_mut(),
        None,
        Some(u.as_mut()),
        par,
        MemStack::new(&mut buffer),
        params,
    )
    .ok()?;
    // Complex pairs are stored as (re, im) column pairs, the first with Im > 0.
    let mut v = Mat::<c64>::zeros(n, n);
    let mut s = faer::Col::<c64>::zeros(n);
    let mut j = 0;
    while j < n {
        let im = s_im[j];
        if im == 0.0 || j + 1 == n {
            s[j] = c64::new(s_re[j], 0.0);
            for i in 0..n {
                v[(i, j)] = c64::new(u[(i, j)], 0.0);
            }
            j += 1;
        } else {
            s[j] = c64::new(s_re[j], im);
            s[j + 1] = c64::new(s_re[j], -im);
            for i in 0..n {
                v[(i, j)] = c64::new(u[(i, j)], u[(i, j + 1)]);
                v[(i, j + 1)] = c64::new(u[(i, j)], -u[(i, j + 1)]);
            }
            j += 2;
        }
    }
    Some((v, s))
}

/// The eigenvalues of the 2N companion matrix, with residues (C·v)(w·B)/r from the right
/// eigenvectors v and the rows w of V⁻¹. Complex eigenvalues with Im r > 0 are listed once per
/// conjugate pair; real (non-oscillating) roots are not listed.
fn companion_modes(sys: &System, num_points: usize, sample_rate: f64) -> Option<Vec<Mode>> {
    let n = sys.len();
    let k = sys.k.dense();
    let z = sys.z.dense();
    let mut a = Mat::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        let inv_m = 1.0 / sys.mass[i];
        for j in 0..n {
            a[(i, j)] = -(k[(i, j)] + z[(i, j)]) * inv_m;
            a[(i, n + j)] = z[(i, j)] * inv_m;
        }
        a[(i, i)] += 2.0;
        a[(i, n + i)] -= 1.0;
        a[(n + i, i)] = 1.0;
    }
    let (mut v, s) = eigen_real(&a)?;
    repair_repeated_vectors(&a, s.as_ref(), &mut v);
    let lu = v.partial_piv_lu();
    // Right-hand sides: [M⁻¹p; 0] and [M⁻¹q; 0] of every input.
    let ni = sys.inputs.len();
    let mut rhs = Mat::<c64>::zeros(2 * n, 2 * ni);
    for (c, input) in sys.inputs.iter().enumerate() {
        for i in 0..n {
            rhs[(i, 2 * c)] = c64::new(input.p[i] / sys.mass[i], 0.0);
            rhs[(i, 2 * c + 1)] = c64::new(input.q[i] / sys.mass[i], 0.0);
        }
    }
    let wb = lu.solve(&rhs);
    let one = c64::new(1.0, 0.0);
    // Every oscillating root with its output and input coefficients and its shape.
    let mut roots: Vec<Root> = Vec::new();
    for m in 0..2 * n {
        let r = s[m];
        if !(r.im > 1e-12 * r.norm().max(1e-300)) {
            continue;
        }
        let vel = one - r.inv();
        let beta = (0..ni)
            .map(|c| wb[(m, 2 * c)] + wb[(m, 2 * c + 1)] * vel)
            .collect();
        // y = p·x[n] + q·(x[n] − x[n−1]) on v = (x[n], x[n−1]).
        let alpha = sys
            .outputs
            .iter()
            .map(|o| {
                (0..n)
                    .map(|i| v[(i, m)] * (o.p[i] + o.q[i]) - v[(n + i, m)] * o.q[i])
                    .fold(c64::new(0.0, 0.0), |a, b| a + b)
            })
            .collect();
        let x = (0..n).map(|i| v[(i, m)]).collect();
        roots.push(Root { r, alpha, beta, x });
    }
    roots.sort_by(|a, b| a.r.arg().total_cmp(&b.r.arg()));
    let first_input = sys.inputs.iter().position(|p| p.linear);
    let mut k = 0;
    while k < roots.len() {
        let mut end = k + 1;
        while end < roots.len()
            && (roots[end].r - roots[k].r).norm() <= REPEATED * roots[k].r.norm()
        {
            end += 1;
        }
        if let (true, Some(c)) = (end - k > 1, first_input) {
            canonical_roots(&mut roots[k..end], c);
        }
        k = end;
    }
    let mut modes = Vec::new();
    for root in &roots {
        let r = root.r;
        let (frequency_hz, t60_s) = frequency_and_t60(r, r.norm(), sample_rate);
        let mut residues = Vec::with_capacity(ni * sys.outputs.len());
        for beta in &root.beta {
            for alpha in &root.alpha {
                let c = alpha * beta / r * 2.0;
                residues.push((c.re, c.im));
            }
        }
        // The real part of the shape after rotating its largest component onto the real axis.
        let big = root
            .x
            .iter()
            .copied()
            .max_by(|a, b| a.norm().total_cmp(&b.norm()))
            .unwrap_or(one);
        let rot = if big.norm() > 0.0 {
            big.conj() / big.norm()
        } else {
            one
        };
        let radius = r.norm();
        let gamma = 1.0 - radius * radius;
        modes.push(Mode {
            frequency_hz,
            t60_s,
            radius,
            lambda: 2.0 - gamma - 2.0 * r.re,
            gains: residues.iter().map(|c| c.0.hypot(c.1)).collect(),
            residues,
            shape: shape_over_points(sys, num_points, |i| (root.x[i] * rot).re),
        });
    }
    Some(modes)
}
