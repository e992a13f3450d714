//! The macros' own laws (spec §2.7), written once against [`Arith`] like the interaction
//! laws: the node law of their moving nodes and the stiff string's second-neighbour springs.
//! The string and mesh kernels (`sim/kernels/`) run them on `f64`, the voice lanes
//! (`sim/lanes/structures.rs`) on native vectors, so both compute the same bits by
//! construction. The links between neighbouring nodes are the spring-damper of the table.

use super::Arith;

/// The per-step coefficients (a, b, 1/M) of the ground-friction node law of spec §2.7:
/// X[n+1] = (2 − Zo/M)·X + (Zo/M − 1)·X̃ + F/M.
#[inline(always)]
pub(crate) fn node_coefficients(m: f64, zo: f64) -> (f64, f64, f64) {
    let zm = zo / m;
    (2.0 - zm, zm - 1.0, 1.0 / m)
}

/// One node's next position: a·X + b·X̃ + F·(1/M), summed in that order.
#[inline(always)]
pub(crate) fn node_step<A: Arith>(
    ar: &A,
    (a, b, inv_m): (A::F, A::F, A::F),
    x: A::F,
    xp: A::F,
    f: A::F,
) -> A::F {
    ar.add(ar.add(ar.mul(a, x), ar.mul(b, xp)), ar.mul(f, inv_m))
}

/// The force of a stiff string's undamped K₂ spring between nodes a and b (spec §2.7.3):
/// f = K₂·(x_a − x_b), taken off a and added to b.
#[inline(always)]
pub(crate) fn stiffness_spring<A: Arith>(ar: &A, k2: A::F, xa: A::F, xb: A::F) -> A::F {
    ar.mul(k2, ar.sub(xa, xb))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::Scalar;

    /// The node law is the mass law of spec §2.1.2 with K = 0: a unit mass without friction
    /// moves on by its velocity, and a force F adds F/M.
    #[test]
    fn the_node_law_is_the_free_mass_with_ground_friction() {
        let c = node_coefficients(2.0, 0.0);
        assert_eq!(node_step(&Scalar, c, 1.0, 0.5, 0.0), 1.5);
        assert_eq!(node_step(&Scalar, c, 1.0, 0.5, 1.0), 2.0);
        let (a, b, _) = node_coefficients(2.0, 0.5);
        assert_eq!((a, b), (1.75, -0.75));
        assert_eq!(stiffness_spring(&Scalar, 0.5, 3.0, 1.0), 1.0);
    }
}
