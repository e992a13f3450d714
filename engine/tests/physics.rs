//! The physics against closed forms (spec §5): oscillator frequency and decay, energy of an
//! undamped string, and pitch across sample rates.

mod common;

use common::{cents, engine, impulse, peak_frequency, render};
use ressort_engine::{Endpoint, MacroKind, ModelBuilder, ModelSpec};
use std::f64::consts::PI;

/// An undamped or damped `osc` (M, K, Z script values) with a force input and a position
/// output.
fn oscillator(m: f64, k: f64, z: f64) -> ModelSpec {
    let mut b = ModelBuilder::new();
    b.osc("o", m, k, z, 0.0, 0.0);
    b.frc_input(1, Endpoint::label("o"));
    b.pos_output(1, Endpoint::label("o"));
    b.build()
}

/// The exact undamped frequency: cos(2πf/SR) = 1 − K/2M with per-step K (spec §5.3).
fn exact_frequency(m: f64, k_per_step: f64, sr: f64) -> f64 {
    sr / (2.0 * PI) * (1.0 - k_per_step / (2.0 * m)).acos()
}

#[test]
fn oscillator_frequency_matches_the_exact_law_within_a_tenth_of_a_cent() {
    let frames = 1 << 18;
    let mut worst: f64 = 0.0;
    for &(m, k) in &[
        (1.0, 0.1),
        (1.0, 0.003),
        (2.5, 1.7),
        (1.0, 3.2),
        (0.3, 0.0007),
    ] {
        for &sr in &[44_100.0, 96_000.0] {
            let mut e = engine(&oscillator(m, k, 0.0), sr);
            let out = render(&mut e, frames, 4096, &[impulse(0.01, frames)]);
            // Per-step K in scaled mode: K·(44100/SR)².
            let k_step = k * (44_100.0 / sr) * (44_100.0 / sr);
            let expected = exact_frequency(m, k_step, sr);
            let measured = peak_frequency(&out[0], sr, 1.0, sr / 2.0 - 1.0);
            let error = cents(measured, expected);
            assert!(
                error.abs() < 0.1,
                "M={m} K={k} SR={sr}: measured {measured:.4} Hz, exact {expected:.4} Hz \
                 ({error:.4} cents)"
            );
            worst = worst.max(error.abs());
        }
    }
    eprintln!("oscillator pitch: worst error against the exact law {worst:.5} cents");
}

#[test]
fn oscillator_decay_matches_rho() {
    // X_n = χ·ρⁿ·cos(nω + φ) with ρ = √(1 − Z/M) (spec §5.1). The envelope is sampled at the
    // local maxima of |x|; a least-squares line through ln|peak| gives ln ρ.
    for &(m, k, z) in &[(1.0, 0.01, 0.001), (2.0, 0.05, 0.0004), (1.0, 0.2, 0.01)] {
        let frames = 40_000;
        let mut b = ModelBuilder::new();
        b.raw();
        b.osc("o", m, k, z, 1.0, 0.0);
        b.pos_output(1, Endpoint::label("o"));
        let out = render(&mut engine(&b.build(), 44_100.0), frames, 1000, &[]);
        let x = &out[0];
        let peaks: Vec<(f64, f64)> = (1..frames - 1)
            .filter(|&i| x[i].abs() > x[i - 1].abs() && x[i].abs() >= x[i + 1].abs())
            .filter(|&i| x[i].abs() > 1e-12)
            .map(|i| (i as f64, x[i].abs().ln()))
            .collect();
        assert!(peaks.len() > 20, "too few peaks");
        let n = peaks.len() as f64;
        let (sx, sy) = peaks
            .iter()
            .fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
        let (mx, my) = (sx / n, sy / n);
        let (num, den) = peaks.iter().fold((0.0, 0.0), |(a, b), p| {
            (a + (p.0 - mx) * (p.1 - my), b + (p.0 - mx) * (p.0 - mx))
        });
        let slope = num / den;
        let expected = (1.0 - z / m).sqrt().ln();
        eprintln!(
            "decay M={m} K={k} Z={z}: ln ρ measured {slope:.6e}, √(1 − Z/M) gives {expected:.6e}"
        );
        assert!(
            ((slope - expected) / expected).abs() < 1e-3,
            "M={m} K={k} Z={z}: ln ρ measured {slope:e}, expected {expected:e}"
        );
    }
}

/// The discrete energy of leapfrog, conserved exactly by the undamped scheme:
/// E = Σ ½·M·(x − x̃)² + Σ_links ½·K·Δx·Δx̃ (per-step units).
fn string_energy(x: &[f64], xp: &[f64], nodes: std::ops::Range<usize>, m: f64, k: f64) -> f64 {
    let kinetic: f64 = nodes
        .clone()
        .map(|i| 0.5 * m * (x[i] - xp[i]) * (x[i] - xp[i]))
        .sum();
    let potential: f64 = nodes
        .clone()
        .zip(nodes.clone().skip(1))
        .map(|(a, b)| 0.5 * k * (x[a] - x[b]) * (xp[a] - xp[b]))
        .sum();
    kinetic + potential
}

#[test]
fn undamped_string_keeps_its_discrete_energy() {
    // A string macro and its expanded per-element network, both with Z = 0, struck once;
    // over 10⁶ samples the discrete energy must drift by less than 1e-9 relative.
    let nodes = 64;
    let (m, k) = (1.0, 0.45);
    let mut b = ModelBuilder::new();
    b.raw();
    b.macro_1d("s", MacroKind::String, nodes as u32, m, k, 0.0);
    b.frc_input(1, Endpoint::at("s", 0.31));
    b.pos_output(1, Endpoint::at("s", 0.77));
    let macro_model = b.build();

    let mut b = ModelBuilder::new();
    b.raw();
    b.ground("n0", 0.0);
    for i in 1..nodes - 1 {
        b.mass(&format!("n{i}"), m, 0.0, 0.0);
    }
    b.ground(&format!("n{}", nodes - 1), 0.0);
    for i in 0..nodes - 1 {
        b.spring_damper(
            &format!("r{i}"),
            Endpoint::label(&format!("n{i}")),
            Endpoint::label(&format!("n{}", i + 1)),
            k,
            0.0,
        );
    }
    b.frc_input(1, Endpoint::label("n20"));
    b.pos_output(1, Endpoint::label("n48"));
    let expanded = b.build();

    for (name, spec) in [("macro", macro_model), ("expanded", expanded)] {
        let mut e = engine(&spec, 44_100.0);
        // The impulse acts at step 2; energy is constant from then on.
        render(&mut e, 2, 2, &[impulse(0.05, 2)]);
        let e0 = string_energy(e.positions(), e.delayed_positions(), 0..nodes, m, k);
        assert!(e0 > 1e-6, "{name}: no energy injected");
        let mut worst: f64 = 0.0;
        let block = vec![0.0; 10_000];
        let mut out = vec![0.0; 10_000];
        for step in 0..100 {
            e.process(10_000, &block, &mut out);
            let energy = string_energy(e.positions(), e.delayed_positions(), 0..nodes, m, k);
            let drift = ((energy - e0) / e0).abs();
            worst = worst.max(drift);
            assert!(
                drift < 1e-9,
                "{name}: relative energy drift {drift:e} after {} samples",
                (step + 1) * 10_000
            );
        }
        eprintln!("{name}: worst relative energy drift over 10⁶ samples: {worst:e}");
    }
}

#[test]
fn string_pitch_is_the_same_in_hz_at_four_sample_rates() {
    // A 40-node string (tutorial 06 values, undamped) plucked by an impulse. Its fundamental
    // follows the leapfrog law f₁ = SR/π·asin(√(K/M)·sin(π/2(N_m+1))) with per-step K
    // (spec §5.3); with the scaling of §1.7 this stays within half a cent at every rate.
    let nodes = 40;
    let spec = {
        let mut b = ModelBuilder::new();
        b.macro_1d("s", MacroKind::String, nodes, 1.0, 0.5, 0.0);
        b.frc_input(1, Endpoint::at("s", 0.3));
        b.pos_output(1, Endpoint::at("s", 0.9));
        b.build()
    };
    let moving = (nodes - 2) as f64;
    let mut pitches = Vec::new();
    for &sr in &[44_100.0, 48_000.0, 96_000.0, 192_000.0] {
        let frames = if sr > 100_000.0 { 1 << 20 } else { 1 << 19 };
        let mut e = engine(&spec, sr);
        let out = render(&mut e, frames, 8192, &[impulse(0.01, frames)]);
        let k_step = 0.5 * (44_100.0 / sr) * (44_100.0 / sr);
        let exact = sr / PI * (k_step.sqrt() * (PI / (2.0 * (moving + 1.0))).sin()).asin();
        let measured = peak_frequency(&out[0], sr, exact * 0.8, exact * 1.2);
        let error = cents(measured, exact);
        assert!(
            error.abs() < 0.1,
            "SR {sr}: measured {measured:.4} Hz, exact law {exact:.4} Hz ({error:.4} cents)"
        );
        pitches.push((sr, measured));
    }
    eprintln!("string fundamental by sample rate: {pitches:?}");
    let reference = pitches[0].1;
    for &(sr, f) in &pitches {
        let c = cents(f, reference);
        assert!(
            c.abs() < 0.5,
            "SR {sr}: {f:.4} Hz is {c:.3} cents from 44.1 kHz"
        );
    }
}

#[test]
fn oscillator_pitch_across_sample_rates_follows_the_exact_law() {
    // For a single oscillator the scaled K keeps the low-frequency limit √(K/M)·44100/2π; the
    // exact law bends the pitch by a predictable amount (here < 2 cents at 222 Hz).
    let mut pitches = Vec::new();
    for &sr in &[44_100.0, 48_000.0, 96_000.0, 192_000.0] {
        let frames = 1 << 19;
        let mut e = engine(&oscillator(1.0, 0.001, 0.0), sr);
        let out = render(&mut e, frames, 8192, &[impulse(0.01, frames)]);
        let k_step = 0.001 * (44_100.0 / sr) * (44_100.0 / sr);
        let exact = exact_frequency(1.0, k_step, sr);
        let measured = peak_frequency(&out[0], sr, 100.0, 400.0);
        assert!(
            cents(measured, exact).abs() < 0.1,
            "SR {sr}: {measured} vs {exact}"
        );
        pitches.push(measured);
    }
    for f in &pitches {
        assert!(cents(*f, pitches[0]).abs() < 0.1);
    }
}

/// Issue 11, denormals: a decaying model never reaches the subnormal range. Its tail ends in
/// exact zeros (the state is flushed below 10⁻¹⁵⁰ every 64 samples), no output sample is
/// subnormal, and the flush does not depend on the block size.
#[test]
fn a_decaying_tail_ends_in_zeros_not_subnormals() {
    // Two coupled oscillators that lose about 10⁻³ of their amplitude per sample.
    let text = "@g ground 0.\n@m mass 1. 0. 0.\n@s springDamper @g @m 0.05 0.004\n\
                @m2 mass 1. 0. 0.\n@s2 springDamper @m2 @g 0.03 0.004\n\
                @c spring @m @m2 0.01\n\
                @in1 frcInput @m\n@out1 posOutput @m2\n@out2 frcOutput @m\n";
    let spec = ressort_engine::parse(text).spec.expect("parses");
    let frames = 600_000;
    let mut e = engine(&spec, 44_100.0);
    let out = render(&mut e, frames, 333, &[impulse(1.0, frames)]);
    let subnormal = out.iter().flatten().filter(|v| v.is_subnormal()).count();
    assert_eq!(subnormal, 0, "subnormal output samples");
    assert!(
        out[0].iter().any(|v| v.abs() > 1e-3),
        "the model was struck"
    );
    let tail = &out[0][frames - 1000..];
    let loudest = tail.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(
        tail.iter().all(|&v| v == 0.0),
        "the tail is not exactly 0: {loudest:e}"
    );
    assert!(e.positions().iter().all(|&v| v == 0.0));
    // Without the flush it would still ring around 10⁻¹⁰⁰ or below: find where it fell under
    // the flush level, and check the flush is not what silenced it early.
    let last_loud = out[0].iter().rposition(|v| v.abs() > 1e-140).unwrap();
    assert!(last_loud > 10_000, "it decayed too early ({last_loud})");
    println!("above 1e-140 until sample {last_loud}; the last 1000 samples are exactly 0");
    // Block sizes 1 and 333 give the same samples.
    let mut one = engine(&spec, 44_100.0);
    let by_one = render(&mut one, frames, 1, &[impulse(1.0, frames)]);
    assert!(by_one == out, "the flush depends on the block size");
}

/// A state that starts subnormal (a script's tiny initial position) is flushed at the reset.
#[test]
fn a_subnormal_initial_state_is_flushed_at_reset() {
    let spec = ressort_engine::parse("@o osc 1. 0.01 0. 1e-310 0.\n@out1 posOutput @o\n")
        .spec
        .expect("parses");
    let mut e = engine(&spec, 44_100.0);
    let out = render(&mut e, 256, 256, &[]);
    assert!(out[0].iter().all(|&v| v == 0.0), "{:?}", &out[0][..4]);
}
