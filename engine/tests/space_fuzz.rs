//! No 3-D script makes Ressort panic or produce a non-finite output (issue 39, tests): random
//! `~dim 3` scripts of every element, structure and adder, with ordinary and extreme values
//! (0, negative, 1e308, 1e-308, coincident points), parsed, printed back, compiled at a random
//! rate, played with impulses and noise on every input, analysed (stability, modes, the exact
//! limit). A script may be refused with diagnostics; whatever compiles either plays finite
//! outputs or is stopped by the guard.

use proptest::prelude::*;
use ressort_engine::lang::{parse, print};
use ressort_engine::{compile, CompileOptions};

/// Values for argument slots: ordinary, tiny, huge, zero, negative.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => (0.0001f64..2.0).prop_map(|v| format!("{v:.5}")),
        1 => Just("0".to_string()),
        1 => Just("-0.3".to_string()),
        1 => Just("1e308".to_string()),
        1 => Just("1e-308".to_string()),
    ]
}

/// Values for a length slot (a rest length, a contact distance, a radius): `auto` too.
fn length() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => value(),
        1 => Just("auto".to_string()),
        1 => Just("[0.9*auto]".to_string()),
    ]
}

/// A position: often one of a few shared points, so that endpoints coincide.
fn position() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => (-3i32..4, -3i32..4, -3i32..4).prop_map(|(x, y, z)| format!("[{x} {y} {z}]")),
        1 => Just("[0 0 0]".to_string()),
        1 => (-1.0f64..1.0).prop_map(|z| format!("{z:.3}")),
        1 => Just("[1e308 0 0]".to_string()),
    ]
}

fn direction() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("[0 0 1]".to_string()),
        Just("[1 0 0]".to_string()),
        Just("[0.3 -0.8 0.1]".to_string()),
        Just("[0 1e-200 0]".to_string()),
    ]
}

/// One random line; `n` names the masses `@m0` … that links may use.
fn line(n: usize) -> impl Strategy<Value = String> {
    let p = move || (0..n).prop_map(|i| format!("@m{i}"));
    let two = move || (p(), p());
    prop_oneof![
        (two(), value(), length()).prop_map(|((a, b), k, l)| format!("spring {a} {b} {k} {l}")),
        (two(), value()).prop_map(|((a, b), z)| format!("damper {a} {b} {z}")),
        (two(), value(), value(), length())
            .prop_map(|((a, b), k, z, l)| format!("springDamper {a} {b} {k} {z} {l}")),
        (two(), value()).prop_map(|((a, b), z)| format!("vdamper {a} {b} {z}")),
        (two(), value(), value(), length())
            .prop_map(|((a, b), k, z, l)| format!("rope {a} {b} {k} {z} {l}")),
        (two(), value(), value(), length())
            .prop_map(|((a, b), k, z, l)| format!("bubble {a} {b} {k} {z} {l}")),
        (two(), value(), value()).prop_map(|((a, b), k, d)| format!("attractor {a} {b} {k} {d}")),
        (two(), value(), value(), length(), value(), value())
            .prop_map(|((a, b), k, z, d, zt, mu)| format!("contact {a} {b} {k} {z} {d} {zt} {mu}")),
        (two(), value(), value(), value(), value(), length())
            .prop_map(|((a, b), s, c, k, z, d)| format!("nlContact {a} {b} {s} {c} {k} {z} {d}")),
        (p(), value(), value(), direction(), value(), value()).prop_map(
            |(a, k, z, n, c, r)| format!("planeContact {a} {k} {z} {n} {c} {r} 0.001 0.5")
        ),
        (two(), value(), value(), value(), length())
            .prop_map(|((a, b), k, q, z, l)| format!("nlSpring2 {a} {b} {k} {q} {z} {l}")),
        (two(), value(), value(), value(), length())
            .prop_map(|((a, b), k, q, z, l)| format!("nlSpring3 {a} {b} {k} {q} {z} {l}")),
        (two(), value(), value(), value(), value(), length()).prop_map(
            |((a, b), s, c, k, z, l)| format!("nlSpringDamper {a} {b} {s} {c} {k} {z} {l}")
        ),
        (two(), value(), value(), value())
            .prop_map(|((a, b), k, ps, z)| format!("nlPluck {a} {b} {k} {ps} {z}")),
        (two(), value(), value(), value(), direction())
            .prop_map(|((a, b), k, ps, z, d)| format!("nlPluck {a} {b} {k} {ps} {z} {d}")),
        (two(), value(), value()).prop_map(|((a, b), z, v)| format!("nlBow {a} {b} {z} {v}")),
        (two(), value(), value(), direction())
            .prop_map(|((a, b), z, v, d)| format!("nlBow {a} {b} {z} {v} 1 {d}")),
    ]
}

/// A structure, and whether it can be a connection point target.
fn structure() -> impl Strategy<Value = String> {
    prop_oneof![
        (2u32..12, value(), value(), length()).prop_map(|(n, k, z, l)| format!(
            "string3 {n} 1. {k} {z} [0 0 0] [{n} 0 0] {l} 'Zo=1e-5'"
        )),
        (2u32..6, 2u32..6, value(), value()).prop_map(|(a, b, k, l)| format!(
            "mesh3 {a} {b} 1. {k} 0.001 [0 0 0] [3 0 0] [0 3 0] {l} 'fix=borders diag'"
        )),
        (2u32..4, 2u32..4, 2u32..4, value()).prop_map(|(a, b, c, k)| format!(
            "lattice3 {a} {b} {c} 1. {k} 0.001 [0 0 0] [1 1 1] auto 'diag fix=z-'"
        )),
        (3u32..9, value()).prop_map(|(n, k)| format!(
            "ring3 {n} 1. {k} 0.001 [0 0 0] 2 [0 0 1] [0.95*auto] 'K2=0.01'"
        )),
        (0u32..2, value())
            .prop_map(|(s, k)| format!("icosphere {s} 1. {k} 0.0001 [0 0 0] 3 auto 'fix=pole'")),
    ]
}

fn script() -> impl Strategy<Value = String> {
    (
        1usize..6,
        proptest::collection::vec(position(), 6),
        proptest::collection::vec(value(), 6),
        proptest::collection::vec(line(5), 0..8),
        proptest::option::of(structure()),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(|(masses, pos, ms, lines, st, gravity, friction)| {
            let mut t = String::from("~dim 3\n");
            if gravity {
                t += "~gravity 9.81\n";
            }
            if friction {
                t += "~friction 0.0001\n";
            }
            let kinds = ["mass", "massZ", "massXY", "osc", "ground", "mass"];
            for i in 0..5 {
                let kind = if i < masses {
                    kinds[i % kinds.len()]
                } else {
                    "ground"
                };
                let line = match kind {
                    "ground" => format!("@m{i} ground {}\n", pos[i]),
                    "osc" => format!("@m{i} osc {} 0.01 0.001 {} [0 0 0]\n", ms[i], pos[i]),
                    k => format!("@m{i} {k} {} {} [0 0 0]\n", ms[i], pos[i]),
                };
                t += &line;
            }
            for (i, l) in lines.iter().enumerate() {
                t += &format!("@l{i} {l}\n");
            }
            if let Some(s) = st {
                t += &format!(
                    "@st {s}\n@sv vdampers @st 0.0001\n@cs contactSet @m0 @st 0.05 0.001 0.3\n"
                );
                t += "@out4 posOutput @st_m1 [0 1 0]\n@out5 mic @st [5 0 0] radial 1 1\n";
            }
            t += "@in1 frcInput @m0\n@in2 frcInputXYZ @m1\n@in5 posInput [0 0 2] [0 1 0]\n";
            t += "@pa spring @in5 @m2 0.01 auto\n";
            t += "@out1 posOutput @m0\n@out2 velOutput @m1 [1 0 0]\n@out3 distOutput @m0 @m2\n";
            t
        })
}

#[test]
fn random_3d_scripts_never_panic() {
    use proptest::test_runner::{Config, TestRunner};
    use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
    let cases = 600;
    let (parsed_n, compiled_n, tripped_n) = (
        AtomicUsize::new(0),
        AtomicUsize::new(0),
        AtomicUsize::new(0),
    );
    let mut runner = TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    });
    let rates = prop_oneof![Just(22050.0), Just(48000.0), Just(192000.0)];
    runner
        .run(&(script(), rates), |(text, rate)| {
            let parsed = parse(&text);
            let Some(spec) = parsed.spec else {
                // Refused, with diagnostics.
                prop_assert!(parsed.errors().next().is_some());
                return Ok(());
            };
            parsed_n.fetch_add(1, Relaxed);
            let again = parse(&print(&spec));
            prop_assert_eq!(again.spec.as_ref(), Some(&spec));
            let Ok(mut e) = compile(&spec, &CompileOptions::at(rate)) else {
                return Ok(());
            };
            compiled_n.fetch_add(1, Relaxed);
            let (n_in, n_out, frames) = (e.info().num_inputs(), e.info().num_outputs(), 2000);
            let mut input = vec![0.0; n_in * frames];
            for c in 0..n_in {
                input[c * frames] = 0.01;
                for f in (1..frames).step_by(7) {
                    input[c * frames + f] = if f % 3 == 0 {
                        f64::NAN
                    } else {
                        0.001 * ((f * 31 % 17) as f64 - 8.0)
                    };
                }
            }
            let mut out = vec![0.0; n_out * frames];
            let report = e.process(frames, &input, &mut out);
            if report.tripped {
                tripped_n.fetch_add(1, Relaxed);
            }
            prop_assert!(out.iter().all(|v| v.is_finite()), "{}", text);
            let _ = e.stability();
            let _ = e.modes(Some(8));
            let _ = e.exact_stability();
            let _ = e.static_equilibrium();
            Ok(())
        })
        .unwrap();
    let (p, c, t) = (
        parsed_n.into_inner(),
        compiled_n.into_inner(),
        tripped_n.into_inner(),
    );
    println!("{cases} random 3-D scripts: {p} parsed, {c} compiled, played and analysed ({t} stopped by the guard), 0 panics");
    assert!(c > cases as usize / 3, "only {c} of {cases} compiled");
}
