//! The row sweep's inner loop ([`super::mesh`]'s `inner_row`) in AVX2 intrinsics, four
//! columns at a time.
//!
//! The compiler vectorises the plain loop too, but leaves a scalar tail of up to four
//! columns a row (its vector loop never runs to the row's last column because of the right
//! neighbour's load), and the plate spent 4 % of its time there. Here the vectors start
//! where the row's positions are aligned, and only the up to three columns before that and
//! those past the last whole vector run scalar.
//!
//! Every operation is the scalar loop's, in its order, lane by lane (no FMA), so the
//! positions are bit-identical (test `rows_and_passes_agree`).

use super::mesh::Stencil;
use core::arch::x86_64::*;

/// Four values from `s[j..]`.
#[inline(always)]
unsafe fn ld(s: &[f64], j: usize) -> __m256d {
    debug_assert!(j + 4 <= s.len());
    // SAFETY: the caller keeps j + 4 within `s` and runs with AVX.
    unsafe { _mm256_loadu_pd(s.as_ptr().add(j)) }
}

/// Stores four values at `s[j..]`.
#[inline(always)]
unsafe fn st(s: &mut [f64], j: usize, v: __m256d) {
    debug_assert!(j + 4 <= s.len());
    // SAFETY: the caller keeps j + 4 within `s` and runs with AVX.
    unsafe { _mm256_storeu_pd(s.as_mut_ptr().add(j), v) }
}

/// Columns 1 … W − 2 of a row as `inner_row`'s loop computes them, up to the last whole
/// vector: the up to three columns before the first aligned vector through
/// [`inner_column`](super::mesh::inner_column), then four at a time. Returns the first column
/// left to the scalar loop.
///
/// # Safety
/// The CPU has AVX2, and the slices are W long, W ≥ 3.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) unsafe fn inner_columns<const EXT: bool>(
    law: &Stencil,
    xr: &mut [f64],
    xpr: &mut [f64],
    xb: &[f64],
    xpb: &[f64],
    y_up: &[f64],
    y_row: &[f64],
    y_below: &mut [f64],
    e: &[f64],
) -> usize {
    let w = xr.len();
    assert!([xpr.len(), xb.len(), xpb.len(), y_up.len(), y_row.len()]
        .iter()
        .chain(&[y_below.len(), e.len()])
        .all(|&n| n == w));
    // The first whole vector starts where the row's positions are 32-byte aligned, so that
    // their loads and stores do not straddle cache lines (the row below, W further on, is
    // aligned too when W is a multiple of 4): 4 % faster on the 150-wide plate, 16 % on a
    // 300-wide one. The columns before it run scalar.
    let start = 1 + (4 - (xr.as_ptr() as usize / 8 + 1) % 4) % 4;
    if start >= w - 1 {
        return 1;
    }
    for j in 1..start {
        super::mesh::inner_column::<EXT>(law, j, xr, xpr, xb, xpb, y_up, y_row, y_below, e);
    }
    let end = start + (w.saturating_sub(1 + start) / 4) * 4;
    // SAFETY: AVX2 is there (the caller's contract); every access touches columns j − 1 …
    // j + 4 with j ≥ start ≥ 1 and j + 4 ≤ end ≤ W − 1, inside the rows.
    unsafe {
        let (a, b) = (_mm256_set1_pd(law.a), _mm256_set1_pd(law.b));
        let (k, z) = (_mm256_set1_pd(law.k), _mm256_set1_pd(law.z));
        let four = _mm256_set1_pd(4.0);
        let mut j = start;
        while j < end {
            // y = K′·x + Z′·(x − x̃) of the row below.
            let x_b = ld(xb, j);
            let v_b = _mm256_sub_pd(x_b, ld(xpb, j));
            let yb = _mm256_add_pd(_mm256_mul_pd(k, x_b), _mm256_mul_pd(z, v_b));
            st(y_below, j, yb);
            // ((y_l + y_r) + (y_u + y_d)) − 4·y
            let sides = _mm256_add_pd(ld(y_row, j - 1), ld(y_row, j + 1));
            let sum = _mm256_add_pd(sides, _mm256_add_pd(ld(y_up, j), yb));
            let mut laplacian = _mm256_sub_pd(sum, _mm256_mul_pd(four, ld(y_row, j)));
            if EXT {
                laplacian = _mm256_add_pd(laplacian, ld(e, j));
            }
            // X[n+1] = (a·X + b·X̃) + L
            let x = ld(xr, j);
            let inertia = _mm256_add_pd(_mm256_mul_pd(a, x), _mm256_mul_pd(b, ld(xpr, j)));
            st(xr, j, _mm256_add_pd(inertia, laplacian));
            st(xpr, j, x);
            j += 4;
        }
        j
    }
}
