//! `feltContact`, the power-law (Hertzian) contact of a felt hammer, against closed forms: the
//! time a mass stays on the felt and how it shortens with the blow, the rebound without
//! damping, the stability rule's bound, and the modes of a mass resting pressed on the felt.

mod common;

use common::{engine, render, spec};
use ressort_engine::StabilityWarning;
use std::f64::consts::PI;

/// A mass of 1 falling at `v` units per step onto a rigid stop at 0 through a felt of
/// stiffness `k` and exponent `p` (raw per-step values); returns how many steps it stays in
/// contact and the speed it leaves with.
fn blow(k: f64, p: f64, v: f64) -> (usize, f64) {
    let text = format!(
        "~samplerate raw\n@g ground 0.\n@h mass 1. 0.02 {v}\n\
         @f feltContact @g @h {k} {p} 0.\n@out1 posOutput @h\n"
    );
    let mut e = engine(&spec(&text), 44_100.0);
    let x = &render(&mut e, 20_000, 64, &[])[0];
    let first = x
        .iter()
        .position(|&x| x < 0.0)
        .expect("the mass reaches the felt");
    let last = first
        + x[first..]
            .iter()
            .position(|&x| x >= 0.0)
            .expect("and leaves it");
    let leave = x[last + 10] - x[last + 9];
    (last - first, leave)
}

/// ∫₀¹ du / √(1 − u^q), by u = 1 − s², which leaves a smooth integrand (Simpson's rule).
fn contact_integral(q: f64) -> f64 {
    let n = 20_000;
    let h = 1.0 / n as f64;
    let g = |s: f64| {
        if s == 0.0 {
            2.0 / q.sqrt()
        } else {
            2.0 * s / (1.0 - (1.0 - s * s).powf(q)).sqrt()
        }
    };
    let sum: f64 = (0..=n)
        .map(|i| {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * g(i as f64 * h)
        })
        .sum();
    sum * h / 3.0
}

/// Hertz: a mass m meeting a felt K·δᵖ at speed v presses it to δ = ((p+1)·m·v²/2K)^(1/(p+1))
/// and stays 2·(δ/v)·∫₀¹ du/√(1 − u^(p+1)) in contact, so a blow four times harder is
/// 4^((p−1)/(p+1)) times shorter; without damping it leaves at the speed it came.
#[test]
fn contact_time_follows_hertz() {
    let (k, p) = (0.0034, 2.5);
    let mut times = Vec::new();
    for v in [0.001, 0.004] {
        let (steps, leave) = blow(k, p, -v);
        let depth = ((p + 1.0) * v * v / (2.0 * k)).powf(1.0 / (p + 1.0));
        let closed = 2.0 * depth / v * contact_integral(p + 1.0);
        let error = (steps as f64 - closed).abs() / closed;
        eprintln!("v {v}: {steps} steps in contact, Hertz {closed:.1}, leaves at {leave:.6}");
        assert!(error < 0.02, "v {v}: {steps} steps, Hertz says {closed:.1}");
        assert!((leave - v).abs() < 0.01 * v, "v {v}: leaves at {leave}");
        times.push(steps as f64);
    }
    let ratio = times[0] / times[1];
    let closed = 4f64.powf((p - 1.0) / (p + 1.0));
    assert!(
        (ratio / closed - 1.0).abs() < 0.02,
        "{ratio} against {closed}"
    );
}

/// The stability rule counts the felt's linear part (none for p ≠ 1, with its damping) and
/// notes that it stiffens without bound; with p = 1 it is the linear contact.
#[test]
fn the_stability_rule_reads_the_felt() {
    let report = |k: f64, p: f64| {
        let text = format!(
            "~samplerate raw\n@g ground 0.\n@h mass 1. 0.1 0.\n@f feltContact @g @h {k} {p} 0.\n"
        );
        engine(&spec(&text), 44_100.0).stability()
    };
    let r = report(50.0, 3.0);
    assert_eq!(r.masses[0].k_eq, 0.0);
    assert!(r.is_stable());
    assert!(r.warnings.iter().any(|w| matches!(
        w,
        StabilityWarning::Unbounded {
            keyword: "feltContact",
            ..
        }
    )));
    // p = 1 is the linear contact: bounded, no note, and K beyond 4M is beyond the limit of
    // a single mass.
    let r = report(0.5, 1.0);
    assert!((r.masses[0].k_eq - 0.5).abs() < 1e-12);
    assert!(!report(4.5, 1.0).is_stable());
    assert!(!r
        .warnings
        .iter()
        .any(|w| matches!(w, StabilityWarning::Unbounded { .. })));
}

/// A mass resting pressed θ into the felt rings at its tangent stiffness p·K·θ^(p−1)
/// (sin²(πf/SR) = λ/4 with λ = k/M); resting away from it, the felt adds nothing.
#[test]
fn modes_read_the_felt_at_rest() {
    let (k, p, theta, sr): (f64, f64, f64, f64) = (2.0, 2.5, 0.01, 48_000.0);
    let text = format!(
        "~samplerate raw\n@g ground 0.\n@h mass 1. 0. 0.\n\
         @f feltContact @g @h {k} {p} 0. {theta}\n\
         @in1 frcInput @h\n@out1 posOutput @h\n"
    );
    let a = engine(&spec(&text), sr).modes(None);
    assert_eq!(a.modes.len(), 1);
    let tangent = p * k * theta.powf(p - 1.0);
    let f = sr / PI * (tangent / 4.0).sqrt().asin();
    let got = a.modes[0].frequency_hz;
    assert!((got - f).abs() < 1e-9 * f, "{got} Hz against {f} Hz");

    let away = text.replace(&format!(" {theta}\n"), " -0.01\n");
    let a = engine(&spec(&away), sr).modes(None);
    assert!(
        a.modes.iter().all(|m| m.frequency_hz == 0.0),
        "{:?}",
        a.modes
    );
}
