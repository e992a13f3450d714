//! The row sweep's two-row loop ([`super::mesh`]'s `pair_nodes`) in AVX2 intrinsics, four
//! columns at a time, for the large plates on CPUs whose best instruction set is AVX2.
//!
//! The compiler vectorises the plain loop too, but how it does so moves with unrelated edits:
//! it carries the row links s_j to the next column with two shuffles per row, and once it
//! also began carrying the positions that way (twelve shuffles instead of four, all on the
//! pipes the additions use), and it leaves a scalar tail of three or four columns per pair of
//! rows. Here each row link is carried by one `vperm2f128` and one `vshufpd`, every load is
//! an unaligned load of the old state, and only columns past the last whole vector run
//! scalar.
//!
//! Every operation is the scalar loop's, in its order, lane by lane (no FMA), so the
//! positions are bit-identical (test `rows_and_passes_are_bit_identical` runs both).

use super::mesh::NodeLaw;
use core::arch::x86_64::*;

/// [p₃, c₀, c₁, c₂]: the previous vector's last lane shifted in front of the current one's
/// first three, the row links s_j−1 of columns j … j + 3.
#[inline(always)]
unsafe fn shift_in(previous: __m256d, current: __m256d) -> __m256d {
    // SAFETY: the caller runs with AVX (see `pair_columns`).
    unsafe {
        let middle = _mm256_permute2f128_pd::<0x21>(previous, current); // [p₂, p₃, c₀, c₁]
        _mm256_shuffle_pd::<0b0101>(middle, current)
    }
}

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

/// The last lane.
#[inline(always)]
unsafe fn last(v: __m256d) -> f64 {
    // SAFETY: the caller runs with AVX.
    unsafe {
        let high = _mm256_extractf128_pd::<1>(v);
        _mm_cvtsd_f64(_mm_unpackhi_pd(high, high))
    }
}

/// f = K·Δx + Z·Δv (`laws::spring_damper`).
#[inline(always)]
unsafe fn link(k: __m256d, z: __m256d, dx: __m256d, dv: __m256d) -> __m256d {
    // SAFETY: the caller runs with AVX.
    unsafe { _mm256_add_pd(_mm256_mul_pd(k, dx), _mm256_mul_pd(z, dv)) }
}

/// Columns 1 … 4m of two rows (m = ⌊(W − 2)/4⌋), as `pair_nodes`' loop computes them, from
/// the row links of column 0 (`s0_left`, `s1_left`). Returns the next column and the row
/// links it needs on its left.
///
/// # Safety
/// The CPU has AVX2 (the engine's instruction set is pulp's V3), and the slices have the
/// lengths `pair_nodes` gives them: W each, W ≥ 2.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) unsafe fn pair_columns<const EXT: bool>(
    law: &NodeLaw,
    x0: &mut [f64],
    xp0: &mut [f64],
    x1: &mut [f64],
    xp1: &mut [f64],
    v0: &[f64],
    x2: &[f64],
    xp2: &[f64],
    v2_out: &mut [f64],
    up: &mut [f64],
    e0: &[f64],
    e1: &[f64],
    s0_left: f64,
    s1_left: f64,
) -> (usize, f64, f64) {
    let w = x0.len();
    assert!([
        xp0.len(),
        x1.len(),
        xp1.len(),
        v0.len(),
        x2.len(),
        xp2.len()
    ]
    .iter()
    .chain(&[v2_out.len(), up.len(), e0.len(), e1.len()])
    .all(|&n| n == w));
    let columns = (w.saturating_sub(2) / 4) * 4;
    // SAFETY: AVX2 is there (the caller's contract); every load and store below touches
    // columns j … j + 4 with j + 4 ≤ columns + 1 ≤ W − 1, inside the rows.
    unsafe {
        let (a, b, inv_m) = (
            _mm256_set1_pd(law.a),
            _mm256_set1_pd(law.b),
            _mm256_set1_pd(law.inv_m),
        );
        let (k, z) = (_mm256_set1_pd(law.k), _mm256_set1_pd(law.z));
        let (mut s0_prev, mut s1_prev) = (_mm256_set1_pd(s0_left), _mm256_set1_pd(s1_left));
        let mut j = 1;
        while j < 1 + columns {
            // Row r: its velocities come from the row above.
            let (x0c, x0n) = (ld(x0, j), ld(x0, j + 1));
            let (v0c, v0n) = (ld(v0, j), ld(v0, j + 1));
            let s0_right = link(k, z, _mm256_sub_pd(x0c, x0n), _mm256_sub_pd(v0c, v0n));
            let s0_l = shift_in(s0_prev, s0_right);
            s0_prev = s0_right;
            // Row r + 1.
            let (x1c, x1n) = (ld(x1, j), ld(x1, j + 1));
            let (xp1c, xp1n) = (ld(xp1, j), ld(xp1, j + 1));
            let v1c = _mm256_sub_pd(x1c, xp1c);
            let v1n = _mm256_sub_pd(x1n, xp1n);
            let s1_right = link(k, z, _mm256_sub_pd(x1c, x1n), _mm256_sub_pd(v1c, v1n));
            let s1_l = shift_in(s1_prev, s1_right);
            s1_prev = s1_right;
            // Row r + 2: its velocities go to the next pair of rows.
            let x2c = ld(x2, j);
            let v2 = _mm256_sub_pd(x2c, ld(xp2, j));
            st(v2_out, j, v2);
            let s01 = link(k, z, _mm256_sub_pd(x0c, x1c), _mm256_sub_pd(v0c, v1c));
            let s12 = link(k, z, _mm256_sub_pd(x1c, x2c), _mm256_sub_pd(v1c, v2));
            let f0 = _mm256_add_pd(_mm256_sub_pd(s0_l, s0_right), ld(up, j));
            let mut f0 = _mm256_sub_pd(f0, s01);
            let f1 = _mm256_add_pd(_mm256_sub_pd(s1_l, s1_right), s01);
            let mut f1 = _mm256_sub_pd(f1, s12);
            if EXT {
                f0 = _mm256_add_pd(f0, ld(e0, j));
                f1 = _mm256_add_pd(f1, ld(e1, j));
            }
            st(up, j, s12);
            // X[n+1] = (a·X + b·X̃) + F·(1/M).
            let inertia0 = _mm256_add_pd(_mm256_mul_pd(a, x0c), _mm256_mul_pd(b, ld(xp0, j)));
            st(x0, j, _mm256_add_pd(inertia0, _mm256_mul_pd(f0, inv_m)));
            st(xp0, j, x0c);
            let inertia1 = _mm256_add_pd(_mm256_mul_pd(a, x1c), _mm256_mul_pd(b, xp1c));
            st(x1, j, _mm256_add_pd(inertia1, _mm256_mul_pd(f1, inv_m)));
            st(xp1, j, x1c);
            j += 4;
        }
        if columns == 0 {
            (1, s0_left, s1_left)
        } else {
            (j, last(s0_prev), last(s1_prev))
        }
    }
}
