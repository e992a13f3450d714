//! The static equilibrium of a 3-D model (3-D spec §6.1): the positions where the static
//! forces balance (the elastic parts of every law, the `osc` rest forces, gravity), about
//! which the modes are defined. Gravity sags a model, a free pre-tensioned structure shrinks,
//! a membrane fixed at its corners bows: the initial geometry is not the equilibrium in
//! general.
//!
//! Newton's method: solve (K_t + μI)·δ = R(x) with the tangent stiffness K_t of the
//! linearised system at x (geometric terms included, `system`), μ = 10⁻⁹·tr(K_t)/n for rigid
//! modes and mechanisms, x ← x + α·δ with α halved until |R| falls, until
//! |R|∞ < 10⁻¹² × the typical force. A component with no fixed point, avatar or `osc` of K > 0
//! is free: uniform gravity does not deform it in its own falling frame, so it is analysed
//! without (§6.1 item 4). Bounded work: at most [`MAX_ITERATIONS`] steps.

use super::{endpoint_nodes, links, point_terms};
use crate::laws::space::Ends;
use crate::laws::Scalar;
use crate::Engine;
use faer::linalg::solvers::Solve;
use faer::Side;

/// The most Newton steps.
pub const MAX_ITERATIONS: usize = 60;

/// The equilibrium found (or the best point reached).
#[derive(Clone, Debug)]
pub(crate) struct Equilibrium {
    /// Every point's and connection point's position.
    pub x: Vec<[f64; 3]>,
    pub converged: bool,
    pub iterations: usize,
    /// The largest residual force left, relative to the typical force.
    pub residual: f64,
}

/// The stage-0 positions of every point and connection point (the current parameter values).
pub(crate) fn initial_positions(e: &Engine) -> Vec<[f64; 3]> {
    let mut c = e.clone();
    c.set_motion_store(None);
    c.reset();
    (0..c.axis(2).len())
        .map(|i| [c.axis(0)[i], c.axis(1)[i], c.axis(2)[i]])
        .collect()
}

/// Which points belong to a component that nothing holds (no fixed point, avatar or `osc`
/// with K > 0, through links engaged at `x`).
fn free_points(e: &Engine, x: &[[f64; 3]]) -> Vec<bool> {
    let Some(space) = &e.space else {
        return Vec::new();
    };
    let n = e.model.info.num_points;
    let terms = point_terms(e);
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    let union = |p: &mut Vec<usize>, a: usize, b: usize| {
        let (ra, rb) = (find(p, a), find(p, b));
        if ra != rb {
            p[ra] = rb;
        }
    };
    for l in links(space, &e.args) {
        if l.kind.row().endpoints == 1 {
            continue;
        }
        let xa = x.get(l.a as usize).copied().unwrap_or([0.0; 3]);
        let xb = x.get(l.b as usize).copied().unwrap_or([0.0; 3]);
        if matches!(
            l.kind.linearise(&l.p, xa, xb),
            crate::laws::space::Linear3::Open
        ) {
            continue;
        }
        let a = endpoint_nodes(space, n, l.a);
        let b = endpoint_nodes(space, n, l.b);
        for &(i, _) in a.iter().chain(&b) {
            union(&mut parent, a[0].0, i);
        }
    }
    let mut held = vec![false; n];
    for p in 0..n {
        if !terms.mass[p].is_finite() || terms.k_ground[p] > 0.0 {
            let r = find(&mut parent, p);
            held[r] = true;
        }
    }
    // Plane contacts engaged hold a point too.
    for l in links(space, &e.args) {
        if l.kind.row().endpoints == 1 {
            let xa = x.get(l.a as usize).copied().unwrap_or([0.0; 3]);
            if !matches!(
                l.kind.linearise(&l.p, xa, xa),
                crate::laws::space::Linear3::Open
            ) {
                for (node, _) in endpoint_nodes(space, n, l.a) {
                    let r = find(&mut parent, node);
                    held[r] = true;
                }
            }
        }
    }
    (0..n)
        .map(|p| {
            let r = find(&mut parent, p);
            !held[r]
        })
        .collect()
}

/// The static forces at `x` on every point (zero velocity), and the typical force.
fn residual(e: &Engine, x: &mut [[f64; 3]], free: &[bool]) -> (Vec<[f64; 3]>, f64) {
    let Some(space) = &e.space else {
        return (Vec::new(), 0.0);
    };
    let n = e.model.info.num_points;
    // Connection points follow their nodes.
    for (i, d) in space.model.proxies.iter().enumerate() {
        let mut pos = [0.0; 3];
        for k in 0..d.width() {
            let node = space.proxy_nodes[i][k] as usize;
            for c in 0..3 {
                pos[c] += space.proxy_weights[i][k] * x[node][c];
            }
        }
        x[n + i] = pos;
    }
    let mut f = vec![[0.0; 3]; x.len()];
    let mut typical: f64 = 0.0;
    for l in links(space, &e.args) {
        let one = l.kind.row().endpoints == 1;
        let (xa, xb) = (x[l.a as usize], x[l.b as usize]);
        let g = l.kind.force(
            &Scalar,
            &Ends {
                x1: xa,
                xp1: xa,
                x2: xb,
                xp2: xb,
            },
            &l.p,
        );
        typical = typical.max(g.iter().fold(0.0, |m: f64, v| m.max(v.abs())));
        for c in 0..3 {
            f[l.a as usize][c] -= g[c];
            if !one {
                f[l.b as usize][c] += g[c];
            }
        }
    }
    // Connection points' forces to their nodes.
    for (i, d) in space.model.proxies.iter().enumerate() {
        let fp = f[n + i];
        for k in 0..d.width() {
            let node = space.proxy_nodes[i][k] as usize;
            for c in 0..3 {
                f[node][c] += space.proxy_weights[i][k] * fp[c];
            }
        }
    }
    let args = &e.args;
    for run in &space.model.runs {
        let m = args[run.m as usize];
        let k = run.k.map_or(0.0, |s| args[s as usize]);
        let g = run
            .gravity
            .map_or([0.0; 3], |s| s.map(|slot| args[slot as usize]));
        for p in run.first..run.first + run.count {
            let p = p as usize;
            for c in 0..3 {
                if !run.axes[c] {
                    continue;
                }
                let weight = if free[p] {
                    0.0
                } else {
                    g[c] + m * space.acc[c]
                };
                let rest = match run.rest {
                    Some(ri) => -k * (x[p][c] - space.rest[ri as usize][c]),
                    None => 0.0,
                };
                f[p][c] += weight + rest;
                typical = typical.max(weight.abs());
            }
        }
    }
    (f, typical)
}

/// The equilibrium from the stage-0 positions.
pub(crate) fn equilibrium(e: &Engine) -> Equilibrium {
    let mut x = initial_positions(e);
    let free = free_points(e, &x);
    let n = e.model.info.num_points;
    let (mut f, typical) = residual(e, &mut x, &free);
    let terms = point_terms(e);
    let norm = |f: &[[f64; 3]]| -> f64 {
        let mut m: f64 = 0.0;
        for p in 0..n {
            for c in 0..3 {
                if terms.mass[p].is_finite() && terms.axes[p][c] {
                    m = m.max(f[p][c].abs());
                }
            }
        }
        m
    };
    let tolerance = 1e-12 * typical.max(f64::MIN_POSITIVE);
    let mut r = norm(&f);
    let mut iterations = 0;
    while r > tolerance && iterations < MAX_ITERATIONS && r.is_finite() {
        iterations += 1;
        let sys = super::system::assemble(e, &x, false);
        let nd = sys.len();
        if nd == 0 {
            break;
        }
        let trace: f64 = sys
            .k
            .entries
            .iter()
            .filter(|(i, j, _)| i == j)
            .map(|(_, _, v)| *v)
            .sum();
        let mu = 1e-9 * (trace / nd as f64).abs().max(f64::MIN_POSITIVE);
        let shifted = crate::analysis::modes::system::SymSparse::combine(
            1.0,
            &sys.k,
            0.0,
            &sys.k,
            &vec![mu; nd],
        );
        let Some(lower) = shifted.lower() else { break };
        let Ok(llt) = lower.sp_cholesky(Side::Lower) else {
            break;
        };
        let mut rhs = faer::Mat::<f64>::zeros(nd, 1);
        for (d, &pc) in sys.point.iter().enumerate() {
            let (p, c) = (pc as usize / 3, pc as usize % 3);
            rhs[(d, 0)] = f[p][c];
        }
        llt.solve_in_place(rhs.as_mut());
        let mut alpha = 1.0;
        let mut improved = false;
        for _ in 0..30 {
            let mut trial = x.clone();
            for (d, &pc) in sys.point.iter().enumerate() {
                let (p, c) = (pc as usize / 3, pc as usize % 3);
                trial[p][c] += alpha * rhs[(d, 0)];
            }
            let (tf, _) = residual(e, &mut trial, &free);
            let tr = norm(&tf);
            if tr < r && tr.is_finite() {
                x = trial;
                f = tf;
                r = tr;
                improved = true;
                break;
            }
            alpha *= 0.5;
        }
        if !improved {
            break;
        }
    }
    Equilibrium {
        x,
        converged: r <= tolerance,
        iterations,
        residual: r / typical.max(f64::MIN_POSITIVE),
    }
}

/// How the static equilibrium of a 3-D model was found (3-D spec §6.1), for reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EquilibriumReport {
    /// The residual force met the tolerance (10⁻¹² of the typical force).
    pub converged: bool,
    /// Newton steps taken (0 when the initial geometry is already at rest).
    pub iterations: usize,
    /// The largest residual force left, relative to the typical force.
    pub residual: f64,
}

impl Engine {
    /// A 3-D model's static equilibrium as the modal analysis finds it (None for a 1-D
    /// model, which is linearised at its stage-0 positions). Off the audio thread.
    pub fn static_equilibrium(&mut self) -> Option<EquilibriumReport> {
        self.space.as_ref()?;
        self.apply_pending_changes();
        let eq = equilibrium(self);
        Some(EquilibriumReport {
            converged: eq.converged,
            iterations: eq.iterations,
            residual: eq.residual,
        })
    }
}
