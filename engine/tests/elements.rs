//! Every element of spec §2 against a step computed by hand from its equations.
//!
//! Models run in raw mode (`~samplerate raw`) unless a test is about scaling, so script values
//! are the per-step values of the equations.

mod common;

use common::{engine, impulse, render};
use ressort_engine::{
    Endpoint, Expr, Law, LawKind, MacroKind, MacroSpec, ModelBuilder, ModelSpec, ScaleClass, Vector,
};

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-14 * (1.0 + a.abs().max(b.abs()))
}

#[track_caller]
fn assert_close(found: f64, expected: f64, what: &str) {
    assert!(
        close(found, expected),
        "{what}: found {found}, expected {expected}"
    );
}

/// Two raw masses (M₁ = 1, M₂ = 2) with initial positions and per-step velocities, joined by
/// `law`. Outputs: x₁, x₂, F₁, F₂.
fn pair(law: Law, x1: f64, v1: f64, x2: f64, v2: f64) -> ModelSpec {
    let mut b = ModelBuilder::new();
    b.raw();
    b.mass("m1", 1.0, x1, v1);
    b.mass("m2", 2.0, x2, v2);
    b.interaction("link", law, Endpoint::label("m1"), Endpoint::label("m2"));
    b.pos_output(1, Endpoint::label("m1"));
    b.pos_output(2, Endpoint::label("m2"));
    b.frc_output(3, Endpoint::label("m1"));
    b.frc_output(4, Endpoint::label("m2"));
    b.build()
}

/// Checks a law: after step 1 the masses have moved freely to x + v, the link computes
/// f(Δx, Δv) with Δx = (x₁+v₁) − (x₂+v₂) and Δv = v₁ − v₂, F₁ = −f and F₂ = +f (spec §1.3),
/// and step 2 applies them: X₁ = 2x₁ − x̃₁ − f/M₁, X₂ = 2x₂ − x̃₂ + f/M₂.
#[track_caller]
fn check_law(name: &str, law: Law, x1: f64, v1: f64, x2: f64, v2: f64, f: f64) {
    let mut e = engine(&pair(law, x1, v1, x2, v2), 44_100.0);
    let out = render(&mut e, 2, 2, &[]);
    let (p1, p2) = (x1 + v1, x2 + v2);
    assert_close(out[0][0], p1, &format!("{name}: x1 after step 1"));
    assert_close(out[1][0], p2, &format!("{name}: x2 after step 1"));
    assert_close(out[2][0], -f, &format!("{name}: F1"));
    assert_close(out[3][0], f, &format!("{name}: F2"));
    assert_close(
        out[0][1],
        2.0 * p1 - x1 - f,
        &format!("{name}: x1 after step 2"),
    );
    assert_close(
        out[1][1],
        2.0 * p2 - x2 + f / 2.0,
        &format!("{name}: x2 after step 2"),
    );
}

fn n(v: f64) -> Expr {
    Expr::Num(v)
}

#[test]
fn linear_links() {
    // Δx = (0.1 + 0.02) − (0.5 − 0.01) = −0.37, Δv = 0.03.
    let (x1, v1, x2, v2) = (0.1, 0.02, 0.5, -0.01);
    check_law("spring", Law::spring(n(0.3)), x1, v1, x2, v2, 0.3 * -0.37);
    check_law("damper", Law::damper(n(0.2)), x1, v1, x2, v2, 0.2 * 0.03);
    check_law(
        "springDamper",
        Law::new(LawKind::SpringDamper, [n(0.3), n(0.2)]),
        x1,
        v1,
        x2,
        v2,
        0.3 * -0.37 + 0.2 * 0.03,
    );
}

#[test]
fn contact_engaged_and_free() {
    let law = || Law::new(LawKind::Contact, [n(0.3), n(0.2), n(0.1)]);
    // Δx = 0.01 − 0.05 = −0.04 > −θ: engaged, f = K(Δx + θ) + ZΔv with Δv = 0.01.
    check_law(
        "contact engaged",
        law(),
        0.0,
        0.01,
        0.05,
        0.0,
        0.3 * 0.06 + 0.2 * 0.01,
    );
    // Δx = −0.19 < −θ: free.
    check_law("contact free", law(), 0.0, 0.01, 0.2, 0.0, 0.0);
}

#[test]
fn nl_contact_regions() {
    let law = || {
        Law::new(
            LawKind::NlContact,
            [n(0.01), n(0.1), n(0.4), n(0.01), n(0.0)],
        )
    };
    // Tipping distance b = √((0.4 − 0.01)/0.1) ≈ 1.975.
    // Cubic: Δx = 0.5, Δv = 0.02: f = 0.5(0.01 + 0.1·0.25) + 0.01·0.02.
    check_law(
        "nlContact cubic",
        law(),
        0.48,
        0.02,
        0.0,
        0.0,
        0.5 * 0.035 + 0.0002,
    );
    // Bounded: Δx = 3: f = 0.4·3 + 0.01·0.02.
    check_law(
        "nlContact bounded",
        law(),
        2.98,
        0.02,
        0.0,
        0.0,
        1.2 + 0.0002,
    );
    // Not engaged: Δx = −0.3.
    check_law("nlContact free", law(), -0.32, 0.02, 0.0, 0.0, 0.0);
}

#[test]
fn nonlinear_springs() {
    // Δx = −0.4, Δv = −0.01.
    let (x1, v1, x2, v2) = (-0.39, -0.01, 0.0, 0.0);
    check_law(
        "nlSpring2",
        Law::new(LawKind::NlSpring2, [n(0.1), n(0.5), n(0.01)]),
        x1,
        v1,
        x2,
        v2,
        0.1 * -0.4 - 0.5 * 0.16 + 0.01 * -0.01,
    );
    check_law(
        "nlSpring3",
        Law::new(LawKind::NlSpring3, [n(0.1), n(0.5), n(0.01)]),
        x1,
        v1,
        x2,
        v2,
        0.1 * -0.4 + 0.5 * -0.064 + 0.01 * -0.01,
    );
    let nlsd = || {
        Law::new(
            LawKind::NlSpringDamper,
            [n(0.03), n(0.005), n(0.8), n(0.0002)],
        )
    };
    // b = √(0.77/0.005) ≈ 12.4. Cubic at Δx = 2: 2(0.03 + 0.005·4) + 0.0002·Δv, Δv = 0.1.
    check_law(
        "nlSpringDamper cubic",
        nlsd(),
        1.9,
        0.1,
        0.0,
        0.0,
        0.1 + 0.0002 * 0.1,
    );
    // Bounded at Δx = 20: 0.8·20 + (0.0002 + 0.3·0.8)·Δv.
    check_law(
        "nlSpringDamper bounded",
        nlsd(),
        19.9,
        0.1,
        0.0,
        0.0,
        16.0 + (0.0002 + 0.24) * 0.1,
    );
}

#[test]
fn pluck_bands() {
    let law = || Law::new(LawKind::Pluck, [n(0.5), n(0.1), n(0.001)]);
    // d_t = 0.01, K_e = 0.05. Inner band (Δx = 0.005, Δv = 0.004): no damping.
    check_law(
        "nlPluck inner",
        law(),
        0.001,
        0.004,
        0.0,
        0.0,
        -(0.5 - 0.05) * 0.005,
    );
    // Outer band (Δx = −0.05, Δv = −0.01): −sgn(Δx)·d_t·K + K_e·Δx + Z·Δv.
    check_law(
        "nlPluck outer",
        law(),
        -0.04,
        -0.01,
        0.0,
        0.0,
        0.01 * 0.5 + 0.05 * -0.05 + 0.001 * -0.01,
    );
    // Beyond the scale: nothing.
    check_law("nlPluck free", law(), 0.19, 0.01, 0.0, 0.0, 0.0);
}

#[test]
fn bow_profiles() {
    let bow = |smooth: f64| Law::new(LawKind::Bow, [n(1.2), n(0.001), n(smooth)]);
    // Piecewise, v_t = scale/3. Stick at Δv = 0.0002: (Z − Z/3)Δv.
    check_law("nlBow stick", bow(0.0), 0.5, 0.0002, 0.0, 0.0, 0.8 * 0.0002);
    // Slip at Δv = −0.0005: sgn(Δv)·v_t·Z − (Z/3)·Δv.
    check_law(
        "nlBow slip",
        bow(0.0),
        0.5,
        0.0,
        0.0,
        0.0005,
        -(0.001 / 3.0) * 1.2 - 0.4 * -0.0005,
    );
    // Beyond the scale.
    check_law("nlBow free", bow(0.0), 0.5, 0.002, 0.0, 0.0, 0.0);
    // Smooth at Δv = 0.0003: 0.63·Z·Δv·exp(−4(Δv/scale)² + ½).
    let dv: f64 = 0.0003;
    let f = 0.63 * 1.2 * dv * (-4.0 * (dv / 0.001) * (dv / 0.001) + 0.5).exp();
    check_law("nlBow smooth", bow(1.0), 0.5, dv, 0.0, 0.0, f);
}

#[test]
fn law_is_symmetric_under_endpoint_swap() {
    // Spec §1.3: for laws odd in (Δx, Δv), swapping the endpoints gives identical physics.
    let law = Law::new(LawKind::NlSpring3, [n(0.1), n(0.5), n(0.01)]);
    let mut b = ModelBuilder::new();
    b.raw();
    b.mass("m1", 1.0, 0.3, 0.01).mass("m2", 1.5, -0.2, 0.0);
    b.interaction(
        "l",
        law.clone(),
        Endpoint::label("m2"),
        Endpoint::label("m1"),
    );
    b.pos_output(1, Endpoint::label("m1"));
    let mut swapped = engine(&b.build(), 44_100.0);
    let mut b = ModelBuilder::new();
    b.raw();
    b.mass("m1", 1.0, 0.3, 0.01).mass("m2", 1.5, -0.2, 0.0);
    b.interaction("l", law, Endpoint::label("m1"), Endpoint::label("m2"));
    b.pos_output(1, Endpoint::label("m1"));
    let mut straight = engine(&b.build(), 44_100.0);
    let a = render(&mut swapped, 500, 64, &[]);
    let b = render(&mut straight, 500, 64, &[]);
    for (x, y) in a[0].iter().zip(&b[0]) {
        assert!((x - y).abs() < 1e-15);
    }
}

#[test]
fn mass_with_gravity_raw_and_scaled() {
    // Raw: X = 2·1 − 0.9 + (0 − 0.5)/2 = 0.85 (gravity is a force subtracted from F).
    let mut b = ModelBuilder::new();
    b.raw();
    b.mass_with_gravity("m", 2.0, 0.5, 1.0, 0.1);
    b.pos_output(1, Endpoint::label("m"));
    let out = render(&mut engine(&b.build(), 44_100.0), 2, 2, &[]);
    assert_close(out[0][0], 0.85, "raw gravity, step 1");
    assert_close(out[0][1], 2.0 * 0.85 - 1.0 - 0.25, "raw gravity, step 2");

    // Scaled at 88.2 kHz: g × (44100/SR)²/44100, x̃ = X₀ − v/SR.
    let sr = 88_200.0;
    let mut b = ModelBuilder::new();
    b.mass_with_gravity("m", 2.0, 0.5, 1.0, 0.1 * sr);
    b.pos_output(1, Endpoint::label("m"));
    let out = render(&mut engine(&b.build(), sr), 1, 1, &[]);
    let g = 0.5 * 0.25 / 44_100.0;
    assert_close(out[0][0], 2.0 - 0.9 - g / 2.0, "scaled gravity, step 1");
}

#[test]
fn osc_recurrence_raw_and_scaled() {
    // X = (2 − (K+Z)/M)·X₀ + (Z/M − 1)·X̃ + (F − g)/M with M = 2, K = 0.3, Z = 0.1,
    // X₀ = 1, X̃ = 0.8: (2 − 0.2)·1 + (0.05 − 1)·0.8 = 1.04.
    let mut b = ModelBuilder::new();
    b.raw();
    b.osc("o", 2.0, 0.3, 0.1, 1.0, 0.2);
    b.pos_output(1, Endpoint::label("o"));
    let out = render(&mut engine(&b.build(), 44_100.0), 1, 1, &[]);
    assert_close(out[0][0], 1.04, "raw osc");

    // Scaled at 88.2 kHz: K × 1/4, Z × 1/2, so script K = 1.2, Z = 0.2 give the same step.
    let sr = 88_200.0;
    let mut b = ModelBuilder::new();
    b.osc("o", 2.0, 1.2, 0.2, 1.0, 0.2 * sr);
    b.pos_output(1, Endpoint::label("o"));
    let out = render(&mut engine(&b.build(), sr), 1, 1, &[]);
    assert_close(out[0][0], 1.04, "scaled osc");
    assert_eq!(ScaleClass::Stiffness.factor(Default::default(), sr), 0.25);
}

#[test]
fn ground_never_moves_and_reports_reaction() {
    let mut b = ModelBuilder::new();
    b.raw();
    b.ground("g", 0.25);
    b.mass("m", 1.0, 0.0, 0.0);
    b.spring_damper("s", Endpoint::label("g"), Endpoint::label("m"), 0.5, 0.0);
    b.frc_input(1, Endpoint::label("g"));
    b.pos_output(1, Endpoint::label("g"));
    b.frc_output(2, Endpoint::label("g"));
    let out = render(
        &mut engine(&b.build(), 44_100.0),
        3,
        3,
        &[vec![1.0, 1.0, 1.0]],
    );
    for n in 0..3 {
        assert_eq!(out[0][n], 0.25, "ground moved at {n}");
    }
    // Reaction at step 1: Δx = 0.25 − 0 → f = 0.125, F_g = −0.125, plus the force input 1
    // (which has no effect on the ground's position).
    assert_close(out[1][0], -0.125 + 1.0, "ground reaction");
}

#[test]
fn mass_g_legacy_delayed_position() {
    // Raw: x̃ = X_R0 and per-step gravity: X = 2·1 − 0.98 − 0.01/2.
    let mut b = ModelBuilder::new();
    b.raw();
    b.element(
        "p",
        ressort_engine::ElementKind::MassG {
            m: n(2.0),
            gravity: n(0.01),
            pos: 1.0.into(),
            delayed: 0.98.into(),
        },
    );
    b.pos_output(1, Endpoint::label("p"));
    let out = render(&mut engine(&b.build(), 44_100.0), 1, 1, &[]);
    assert_close(out[0][0], 2.0 - 0.98 - 0.005, "raw massG");
    // Scaled at 88.2 kHz: gravity × (44100/SR)² and x̃ = X₀ − (X₀ − X_R0)·44100/SR.
    let sr = 88_200.0;
    let mut b = ModelBuilder::new();
    b.element(
        "p",
        ressort_engine::ElementKind::MassG {
            m: n(2.0),
            gravity: n(0.01),
            pos: 1.0.into(),
            delayed: 0.98.into(),
        },
    );
    b.pos_output(1, Endpoint::label("p"));
    let out = render(&mut engine(&b.build(), sr), 1, 1, &[]);
    let xp = 1.0 - 0.02 * 0.5;
    assert_close(out[0][0], 2.0 - xp - 0.01 * 0.25 / 2.0, "scaled massG");
}

#[test]
fn pos_input_appears_at_once_and_reacts_next_step() {
    // Spec §1.6: a position input sample appears at once as the avatar's position; connected
    // points react from the next step. frcOutput on the avatar is the reaction force.
    let mut b = ModelBuilder::new();
    b.raw();
    b.pos_input(1, 0.0);
    b.mass("m", 1.0, 0.0, 0.0);
    b.spring_damper("s", Endpoint::label("in1"), Endpoint::label("m"), 0.5, 0.1);
    b.pos_output(1, Endpoint::label("in1"));
    b.pos_output(2, Endpoint::label("m"));
    b.frc_output(3, Endpoint::label("in1"));
    let out = render(
        &mut engine(&b.build(), 44_100.0),
        3,
        1,
        &[vec![0.2, 0.2, 0.2]],
    );
    assert_eq!(out[0][0], 0.2);
    assert_eq!(out[1][0], 0.0, "the mass reacts only at the next step");
    // f = 0.5·0.2 + 0.1·(0.2 − 0) = 0.12; the avatar's reaction is −f.
    assert_close(out[2][0], -0.12, "avatar reaction force");
    assert_close(out[1][1], 0.12, "mass after step 2");
}

#[test]
fn force_input_moves_its_target_at_the_next_step() {
    let mut b = ModelBuilder::new();
    b.raw();
    b.mass("m", 4.0, 0.0, 0.0);
    b.frc_input(1, Endpoint::label("m"));
    b.pos_output(1, Endpoint::label("m"));
    b.frc_output(2, Endpoint::label("m"));
    let out = render(&mut engine(&b.build(), 44_100.0), 3, 2, &[impulse(1.0, 3)]);
    assert_eq!(out[0][0], 0.0);
    assert_eq!(
        out[1][0], 1.0,
        "frcOutput shows the force that will act next"
    );
    assert_close(out[0][1], 0.25, "F/M at step 2");
    assert_close(out[0][2], 0.5, "constant velocity afterwards");
}

/// A line macro with a force input exactly on node 1 (α = 1/(N−1)) and outputs on nodes 0..3.
fn line_macro(kind: MacroKind, nodes: u32, k2: Option<f64>) -> ModelSpec {
    let mut b = ModelBuilder::new();
    b.raw();
    b.macro_spec(
        "s",
        MacroSpec {
            kind,
            length: nodes,
            width: 1,
            m: n(1.0),
            k: n(0.5),
            k2: k2.map(n),
            z: n(0.2),
            zo: n(0.1),
            pos: 0.0.into(),
            vel: 0.0.into(),
        },
    );
    let at = |k: u32| Endpoint::at("s", k as f64 / (nodes - 1) as f64);
    b.frc_input(1, at(1));
    for k in 0..4 {
        b.pos_output(k + 1, at(k));
    }
    b.build()
}

#[test]
fn string_and_chain_macro_steps() {
    // Step 1: F = 1 lands on node 1. Step 2: x₁ = 1. Links: s₀ = K(0 − 1) + Z(0 − 1) = −0.7,
    // s₁ = 0.7, s₂ = 0, so F = [0.7, −1.4, 0.7, 0]. Step 3 (Zo = 0.1):
    // x₁ = (2 − 0.1)·1 + (0.1 − 1)·0 − 1.4 = 0.5, x₂ = 0.7; node 0 is fixed for a string
    // and moves to 0.7 for a chain.
    for (kind, node0) in [(MacroKind::String, 0.0), (MacroKind::Chain, 0.7)] {
        let mut e = engine(&line_macro(kind, 4, None), 44_100.0);
        let out = render(&mut e, 3, 1, &[impulse(1.0, 3)]);
        assert_eq!(out[1][1], 1.0, "{kind:?} step 2");
        assert_close(out[1][2], 0.5, &format!("{kind:?} node 1"));
        assert_close(out[2][2], 0.7, &format!("{kind:?} node 2"));
        assert_close(out[0][2], node0, &format!("{kind:?} node 0"));
        // The last node of a string is fixed too; a chain's gets nothing yet.
        assert_eq!(out[3][2], 0.0);
    }
}

#[test]
fn stiff_string_step() {
    // As the string, plus undamped K₂ springs on (0,1), (0,2), (1,3), (2,3), (3,3).
    // Step 2: x = [0, 1, 0, 0]. K₂ forces with K₂ = 0.3: (0,1): t = −0.3 → F₀ += 0.3,
    // F₁ −= 0.3; (1,3): t = 0.3 → F₁ −= 0.3, F₃ += 0.3. So F₁ = −1.4 − 0.6 = −2.0 and
    // x₁ = 1.9 − 2.0 = −0.1 at step 3; F₂ = 0.7 → x₂ = 0.7.
    let mut e = engine(&line_macro(MacroKind::StiffString, 4, Some(0.3)), 44_100.0);
    let out = render(&mut e, 3, 3, &[impulse(1.0, 3)]);
    assert_close(out[1][2], -0.1, "stiff string node 1");
    assert_close(out[2][2], 0.7, "stiff string node 2");
    assert_eq!(out[0][2], 0.0, "fixed end");
}

/// Explicit elements equivalent to a line macro (spec §4.1, §4.2): grounds for fixed ends,
/// `osc M 0 Zo` nodes, spring-dampers in the macro's order.
fn expanded_line(kind: MacroKind, nodes: usize, k: f64, k2: f64, z: f64, zo: f64) -> ModelSpec {
    let mut b = ModelBuilder::new();
    b.raw();
    let fixed = |i: usize| kind != MacroKind::Chain && (i == 0 || i == nodes - 1);
    for i in 0..nodes {
        if fixed(i) {
            b.ground(&format!("n{i}"), 0.0);
        } else {
            b.osc(&format!("n{i}"), 1.0, 0.0, zo, 0.0, 0.0);
        }
    }
    let l = |i: usize| Endpoint::label(&format!("n{i}"));
    for i in 0..nodes - 1 {
        b.spring_damper(&format!("r{i}"), l(i), l(i + 1), k, z);
    }
    if kind == MacroKind::StiffString {
        let last = nodes as isize - 1;
        for i in -1..=last {
            let (a, bb) = (i.clamp(0, last) as usize, (i + 2).clamp(0, last) as usize);
            if a != bb {
                b.spring_damper(&format!("k{}", i + 1), l(a), l(bb), k2, 0.0);
            }
        }
    }
    b.frc_input(1, l(3));
    b.pos_output(1, l(nodes / 2));
    b.pos_output(2, l(nodes - 2));
    b.build()
}

fn macro_line(kind: MacroKind, nodes: usize, k: f64, k2: f64, z: f64, zo: f64) -> ModelSpec {
    let mut b = ModelBuilder::new();
    b.raw();
    b.macro_spec(
        "s",
        MacroSpec {
            kind,
            length: nodes as u32,
            width: 1,
            m: n(1.0),
            k: n(k),
            k2: (kind == MacroKind::StiffString).then(|| n(k2)),
            z: n(z),
            zo: n(zo),
            pos: 0.0.into(),
            vel: 0.0.into(),
        },
    );
    let at = |i: usize| Endpoint::at("s", i as f64 / (nodes - 1) as f64);
    b.frc_input(1, at(3));
    b.pos_output(1, at(nodes / 2));
    b.pos_output(2, at(nodes - 2));
    b.build()
}

#[track_caller]
fn assert_same_signal(a: &[Vec<f64>], b: &[Vec<f64>], what: &str) {
    let scale = a
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(1e-30);
    for (c, (x, y)) in a.iter().zip(b).enumerate() {
        for (i, (p, q)) in x.iter().zip(y).enumerate() {
            assert!(
                (p - q).abs() <= 1e-12 * scale,
                "{what}: channel {c} differs at sample {i}: {p} vs {q}"
            );
        }
    }
}

#[test]
fn line_macros_equal_their_expanded_networks() {
    for kind in [MacroKind::String, MacroKind::Chain, MacroKind::StiffString] {
        let input = [impulse(0.01, 3000)];
        let mut m = engine(&macro_line(kind, 23, 0.4, 0.15, 0.002, 1e-4), 44_100.0);
        let mut x = engine(&expanded_line(kind, 23, 0.4, 0.15, 0.002, 1e-4), 44_100.0);
        let a = render(&mut m, 3000, 256, &input);
        let b = render(&mut x, 3000, 256, &input);
        assert!(a[0].iter().any(|v| v.abs() > 1e-6), "{kind:?} did not move");
        assert_same_signal(&a, &b, &format!("{kind:?}"));
    }
}

#[test]
fn meshes_equal_their_expanded_networks() {
    let (l, w) = (7usize, 5usize);
    for kind in [
        MacroKind::Mesh,
        MacroKind::CornerMesh,
        MacroKind::ClosedMesh,
    ] {
        let mut b = ModelBuilder::new();
        b.raw();
        b.macro_spec(
            "me",
            MacroSpec {
                kind,
                length: l as u32,
                width: w as u32,
                m: n(1.0),
                k: n(0.2),
                k2: None,
                z: n(0.001),
                zo: n(2e-4),
                pos: 0.0.into(),
                vel: 0.0.into(),
            },
        );
        let at = |i: usize, j: usize| {
            Endpoint::at2("me", i as f64 / (l - 1) as f64, j as f64 / (w - 1) as f64)
        };
        b.frc_input(1, at(2, 2));
        b.pos_output(1, at(3, 1));
        b.pos_output(2, at(5, 3));
        let macro_spec = b.build();

        let pinned = |i: usize, j: usize| match kind {
            MacroKind::Mesh => false,
            MacroKind::CornerMesh => (i == 0 || i == l - 1) && (j == 0 || j == w - 1),
            _ => i == 0 || i == l - 1 || j == 0 || j == w - 1,
        };
        let mut b = ModelBuilder::new();
        b.raw();
        let name = |i: usize, j: usize| format!("m{i}_{j}");
        for i in 0..l {
            for j in 0..w {
                if pinned(i, j) {
                    b.ground(&name(i, j), 0.0);
                } else {
                    b.osc(&name(i, j), 1.0, 0.0, 2e-4, 0.0, 0.0);
                }
            }
        }
        let lab = |i: usize, j: usize| Endpoint::label(&name(i, j));
        for i in 0..l {
            for j in 0..w - 1 {
                b.spring_damper(&format!("h{i}_{j}"), lab(i, j), lab(i, j + 1), 0.2, 0.001);
            }
        }
        for i in 0..l - 1 {
            for j in 0..w {
                b.spring_damper(&format!("v{i}_{j}"), lab(i, j), lab(i + 1, j), 0.2, 0.001);
            }
        }
        b.frc_input(1, lab(2, 2));
        b.pos_output(1, lab(3, 1));
        b.pos_output(2, lab(5, 3));
        let expanded = b.build();

        let input = [impulse(0.01, 2000)];
        let a = render(&mut engine(&macro_spec, 44_100.0), 2000, 100, &input);
        let b = render(&mut engine(&expanded, 44_100.0), 2000, 100, &input);
        assert!(a[0].iter().any(|v| v.abs() > 1e-7), "{kind:?} did not move");
        assert_same_signal(&a, &b, &format!("{kind:?}"));
    }
}

#[test]
fn connection_points_interpolate_and_spread_without_loss() {
    // A chain at rest: a force of 0.5 at α = 0.37 over 10 nodes lands on nodes 3 and 4 with
    // weights 0.67 and 0.33 (p = 3.33), and the node forces sum to the input exactly.
    let mut b = ModelBuilder::new();
    b.raw();
    b.macro_1d("c", MacroKind::Chain, 10, 1.0, 0.3, 0.01);
    b.frc_input(1, Endpoint::at("c", 0.37));
    b.frc_output(1, Endpoint::at("c", 0.37));
    let mut e = engine(&b.build(), 44_100.0);
    let out = render(&mut e, 1, 1, &[vec![0.5]]);
    assert_eq!(
        out[0][0], 0.5,
        "frcOutput on a connection point is the applied force"
    );
    let f = e.forces();
    let p = 0.37 * 9.0;
    let a = p - 3.0;
    assert_close(f[3], (1.0 - a) * 0.5, "node 3 share");
    assert_close(f[4], a * 0.5, "node 4 share");
    let total: f64 = f[..10].iter().sum();
    assert_close(total, 0.5, "total force on the chain");

    // Bilinear weights on a mesh; an interaction between a mass and a connection point keeps
    // the total force zero (action = reaction) whatever the weights.
    let mut b = ModelBuilder::new();
    b.raw();
    b.mesh("me", MacroKind::Mesh, 6, 5, 1.0, 0.1, 0.001);
    b.mass("h", 1.0, 0.3, -0.01);
    b.spring_damper(
        "l",
        Endpoint::at2("me", 0.43, 0.71),
        Endpoint::label("h"),
        0.2,
        0.05,
    );
    b.frc_input(1, Endpoint::at2("me", 0.43, 0.71));
    let mut e = engine(&b.build(), 44_100.0);
    render(&mut e, 1, 1, &[vec![0.25]]);
    // Single masses come first in point order (spec §6.2): h is point 0, the mesh 1..=30.
    let f = e.forces();
    let on_mass = f[0];
    let on_mesh: f64 = f[1..31].iter().sum();
    assert!(
        (on_mesh + on_mass - 0.25).abs() < 1e-15,
        "{on_mesh} + {on_mass}"
    );
    // Weights: p_X = 0.43·5 = 2.15, p_Y = 0.71·4 = 2.84.
    let (ai, aj) = (0.43 * 5.0 - 2.0, 0.71 * 4.0 - 2.0);
    let w = [
        (1.0 - ai) * (1.0 - aj),
        ai * (1.0 - aj),
        (1.0 - ai) * aj,
        ai * aj,
    ];
    let nodes = [2 * 5 + 2, 3 * 5 + 2, 2 * 5 + 3, 3 * 5 + 3].map(|n| n + 1);
    let fp = f[nodes[0]] / w[0];
    for (node, weight) in nodes.iter().zip(w) {
        assert_close(f[*node], weight * fp, "bilinear share");
    }
}

#[test]
fn connection_point_clamps_at_the_ends() {
    // α = 1 puts the whole weight on the last node; α outside [0, 1] is clamped.
    let mut b = ModelBuilder::new();
    b.raw();
    b.macro_1d("c", MacroKind::Chain, 5, 1.0, 0.0, 0.0);
    b.frc_input(1, Endpoint::at("c", 1.0));
    b.frc_input(2, Endpoint::at("c", -3.0));
    let mut e = engine(&b.build(), 44_100.0);
    render(&mut e, 1, 1, &[vec![1.0], vec![2.0]]);
    assert_eq!(e.forces()[4], 1.0);
    assert_eq!(e.forces()[0], 2.0);
}

#[test]
fn macro_rendering_coordinates_follow_the_double_bracket_rule() {
    let mut b = ModelBuilder::new();
    b.macro_spec(
        "me",
        MacroSpec {
            kind: MacroKind::Mesh,
            length: 3,
            width: 2,
            m: n(1.0),
            k: n(0.1),
            k2: None,
            z: n(0.0),
            zo: n(0.0),
            pos: Vector::from([0.0, 10.0, 0.0]),
            vel: Vector::from([2.0, 11.0, 0.0]),
        },
    );
    let e = engine(&b.build(), 44_100.0);
    let m = &e.info().motion;
    // i runs along x (0, 1, 2), j along y (10, 11); node index i·W + j.
    assert_eq!(m.x, vec![0.0, 0.0, 1.0, 1.0, 2.0, 2.0]);
    assert_eq!(m.y, vec![10.0, 11.0, 10.0, 11.0, 10.0, 11.0]);
}
