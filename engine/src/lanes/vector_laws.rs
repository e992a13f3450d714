//! Branch-free versions of the nonlinear laws of [`crate::laws`] for every lane at once: each
//! branch of the scalar law computed in vectors with the same IEEE operations in the same
//! order, and the lane's branch chosen by a comparison mask (a select), so each lane gets the
//! scalar law's bits (unit tests below, over every branch, ±0, infinities and NaN).
//!
//! `nlBow` stays scalar, lane by lane: its smooth branch needs `exp`.

use super::vector::Ops;
use super::Lanes;
use pulp::Simd;

/// Defines `name(o, Δx, Δv, args…) -> Lanes`, running `body` on each native vector of the
/// lanes with `simd` the instruction set and `dx`, `dv` and the arguments that vector's values.
macro_rules! vector_law {
    ($(#[$doc:meta])* $name:ident($simd:ident, $dx:ident, $dv:ident $(, $arg:ident)*) $body:block) => {
        $(#[$doc])*
        #[inline(always)]
        #[allow(clippy::too_many_arguments)]
        pub(super) fn $name<S: Simd>(o: Ops<S>, $dx: Lanes, $dv: Lanes $(, $arg: Lanes)*) -> Lanes {
            let $simd = o.0;
            let mut out = Lanes::ZERO;
            let (out_v, _) = S::as_mut_simd_f64s(&mut out.0);
            let ($dx, _) = S::as_simd_f64s(&$dx.0);
            let ($dv, _) = S::as_simd_f64s(&$dv.0);
            $(let ($arg, _) = S::as_simd_f64s(&$arg.0);)*
            for i in 0..out_v.len() {
                let ($dx, $dv) = ($dx[i], $dv[i]);
                $(let $arg = $arg[i];)*
                out_v[i] = $body;
            }
            out
        }
    };
}

/// `laws::bounded_cubic` on native vectors: (force, the bounded-branch mask).
#[inline(always)]
fn bounded_cubic<S: Simd>(
    v: S,
    d: S::f64s,
    s: S::f64s,
    c: S::f64s,
    k: S::f64s,
) -> (S::f64s, S::m64s) {
    let zero = v.splat_f64s(0.0);
    let cdd = v.mul_f64s(v.mul_f64s(c, d), d);
    let cubic = v.mul_f64s(d, v.add_f64s(s, cdd));
    let (linear_s, linear_k) = (v.mul_f64s(s, d), v.mul_f64s(k, d));
    let c_zero = v.equal_f64s(c, zero);
    // s ≥ k or c < 0: the bounded branch whatever d; else bounded beyond the tipping point.
    let flat = v.or_m64s(v.less_than_or_equal_f64s(k, s), v.less_than_f64s(c, zero));
    let within = v.less_than_or_equal_f64s(cdd, v.sub_f64s(k, s));
    let bounded = v.and_m64s(v.not_m64s(c_zero), v.or_m64s(flat, v.not_m64s(within)));
    let force = v.select_f64s(c_zero, linear_s, v.select_f64s(bounded, linear_k, cubic));
    (force, bounded)
}

vector_law! {
    /// `laws::contact`: f = K(Δx + θ) + Z·Δv where Δx > −θ, else 0.
    contact(v, dx, dv, k, z, t) {
        let f = v.add_f64s(v.mul_f64s(k, v.add_f64s(dx, t)), v.mul_f64s(z, dv));
        v.select_f64s(v.greater_than_f64s(dx, v.neg_f64s(t)), f, v.splat_f64s(0.0))
    }
}

vector_law! {
    /// `laws::nl_contact`: with d = Δx + θ, the bounded cubic of d (k < s: k ← s, c ← 0)
    /// plus Z·Δv where d > 0, else 0.
    nl_contact(v, dx, dv, s, c, k, z, t) {
        let zero = v.splat_f64s(0.0);
        let d = v.add_f64s(dx, t);
        let swap = v.less_than_f64s(k, s);
        let (k, c) = (v.select_f64s(swap, s, k), v.select_f64s(swap, zero, c));
        let f = v.add_f64s(bounded_cubic(v, d, s, c, k).0, v.mul_f64s(z, dv));
        v.select_f64s(v.greater_than_f64s(d, zero), f, zero)
    }
}

vector_law! {
    /// `laws::nl_spring2`: f = K·Δx + Q·Δx·|Δx| + Z·Δv.
    nl_spring2(v, dx, dv, k, q, z) {
        let quadratic = v.mul_f64s(v.mul_f64s(q, dx), v.abs_f64s(dx));
        v.add_f64s(v.add_f64s(v.mul_f64s(k, dx), quadratic), v.mul_f64s(z, dv))
    }
}

vector_law! {
    /// `laws::nl_spring3`: f = K·Δx + Q·Δx³ + Z·Δv.
    nl_spring3(v, dx, dv, k, q, z) {
        let cubic = v.mul_f64s(v.mul_f64s(v.mul_f64s(q, dx), dx), dx);
        v.add_f64s(v.add_f64s(v.mul_f64s(k, dx), cubic), v.mul_f64s(z, dv))
    }
}

vector_law! {
    /// `laws::nl_spring_damper`: the bounded cubic of Δx plus Z·Δv, Z + 0.3·k in the bounded
    /// branch.
    nl_spring_damper(v, dx, dv, s, c, k, z) {
        let (fe, bounded) = bounded_cubic(v, dx, s, c, k);
        let damping = v.add_f64s(z, v.mul_f64s(v.splat_f64s(0.3), k));
        v.add_f64s(fe, v.mul_f64s(v.select_f64s(bounded, damping, z), dv))
    }
}

vector_law! {
    /// `laws::nl_pluck`: −(K − K_e)·Δx inside d_t, −sgn(Δx)·d_t·K + K_e·Δx + Z·Δv inside
    /// the scale, 0 beyond (d_t = scale/σ, K_e = K/σ).
    nl_pluck(v, dx, dv, k, scale, z) {
        let sharpness = v.splat_f64s(crate::laws::PLUCK_SHARPNESS);
        let d_t = v.div_f64s(scale, sharpness);
        let k_e = v.div_f64s(k, sharpness);
        let adx = v.abs_f64s(dx);
        let inner = v.mul_f64s(v.neg_f64s(v.sub_f64s(k, k_e)), dx);
        // sgn(Δx) as f64::signum: ±1 with Δx's sign (a NaN Δx lands in no band).
        let sign = v.or_f64s(v.and_f64s(dx, v.splat_f64s(-0.0)), v.splat_f64s(1.0));
        let band = v.mul_f64s(v.mul_f64s(v.neg_f64s(sign), d_t), k);
        let outer = v.add_f64s(v.add_f64s(band, v.mul_f64s(k_e, dx)), v.mul_f64s(z, dv));
        let beyond = v.select_f64s(v.less_than_f64s(adx, scale), outer, v.splat_f64s(0.0));
        v.select_f64s(v.less_than_f64s(adx, d_t), inner, beyond)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::LANES;
    use crate::laws;

    /// Values that reach every branch: both signs, zeros, tiny and huge, infinities, NaN.
    const VALUES: [f64; 16] = [
        0.0,
        -0.0,
        0.3,
        -0.3,
        1e-3,
        -1e-3,
        2.5,
        -2.5,
        0.05,
        -0.05,
        1e-310,
        1e200,
        -1e200,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
    ];

    /// A deterministic stream of picks from VALUES and of ordinary numbers.
    struct Picks(u64);

    impl Picks {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            // Half the draws from VALUES, so that arguments are often equal (s = k).
            let r = self.0 % 64;
            if r < 32 {
                VALUES[r as usize % 16]
            } else {
                // Ordinary values of either sign, 1e-3 to 10.
                let u = (self.0 >> 11) as f64 / (1u64 << 53) as f64;
                let m = 10f64.powf(-3.0 + 4.0 * u);
                if r.is_multiple_of(2) {
                    m
                } else {
                    -m
                }
            }
        }

        fn lanes(&mut self) -> Lanes {
            Lanes(std::array::from_fn(|_| self.next()))
        }
    }

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// Runs `law` for many draws of Δx, Δv and `N` arguments, on the CPU's instruction set
    /// and on scalars, and compares every lane with `scalar`.
    macro_rules! compare {
        ($law:ident, $scalar:expr, $($arg:ident),*) => {{
            struct Run {
                dx: Lanes,
                dv: Lanes,
                $($arg: Lanes,)*
            }
            impl pulp::WithSimd for Run {
                type Output = Lanes;
                #[inline(always)]
                fn with_simd<S: Simd>(self, simd: S) -> Lanes {
                    $law(Ops(simd), self.dx, self.dv $(, self.$arg)*)
                }
            }
            let mut picks = Picks(0x9e37_79b9_7f4a_7c15);
            let mut mismatches = 0;
            for _ in 0..4000 {
                let (dx, dv) = (picks.lanes(), picks.lanes());
                $(let $arg = picks.lanes();)*
                let native = pulp::Arch::new().dispatch(Run { dx, dv $(, $arg)* });
                let scalar = pulp::Scalar::new().vectorize(Run { dx, dv $(, $arg)* });
                for l in 0..LANES {
                    let want = $scalar(dx[l], dv[l] $(, $arg[l])*);
                    if !same(native[l], want) || !same(scalar[l], want) {
                        mismatches += 1;
                        if mismatches < 5 {
                            eprintln!(
                                "{}: dx {:e} dv {:e} {:?}: {:e} / {:e}, want {:e}",
                                stringify!($law),
                                dx[l],
                                dv[l],
                                [$($arg[l]),*],
                                native[l],
                                scalar[l],
                                want
                            );
                        }
                    }
                }
            }
            assert_eq!(mismatches, 0, "{} differs from its scalar law", stringify!($law));
        }};
    }

    #[test]
    fn contact_equals_the_scalar_law() {
        compare!(contact, laws::contact, k, z, t);
    }

    #[test]
    fn nl_contact_equals_the_scalar_law() {
        compare!(nl_contact, laws::nl_contact, s, c, k, z, t);
    }

    #[test]
    fn nl_springs_equal_the_scalar_laws() {
        compare!(nl_spring2, laws::nl_spring2, k, q, z);
        compare!(nl_spring3, laws::nl_spring3, k, q, z);
        compare!(nl_spring_damper, laws::nl_spring_damper, s, c, k, z);
    }

    #[test]
    fn nl_pluck_equals_the_scalar_law() {
        compare!(nl_pluck, laws::nl_pluck, k, scale, z);
    }
}
