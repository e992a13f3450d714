//! Small models compiled to machine code (`engine/src/sim/jit.rs`) play what the interpreter
//! plays, bit for bit: outputs, positions, delayed positions, forces, guard events and sample
//! counts, through odd block sizes, strikes, noise, non-finite input, parameter and gain
//! changes, guard trips and resets.

mod common;

use common::native::{bits, build, native_equals_interpreter, Lcg};
use ressort_engine::{compile, parse, CompileOptions};

/// Every law of the table (a test below holds it to that), both bow profiles, avatars, massG and
/// osc, gravity, a ground at −0, force outputs, an output on an avatar.
const MIXED: &str = "\
@K param 0.1
@Q param 0.5
@g ground -0.
@m1 mass 1. 0. 0.
@m2 mass 1.2 0.001 0. 0.
@m3 mass 0.9 0. 0.
@m4 osc 1. 0.05 0.0001 0. 0.
@m5 massG 1. 0.0001 0.2 0.19
@m6 mass 2. 0. 0.
@g2 ground 0.
@in2 posInput 0.01
@in3 posInput 0.
@r1 springDamper @g @m1 K 0.001
@r2 spring @m1 @m2 0.12
@r3 damper @m2 @m3 0.002
@r4 nlSpring2 @m3 @m4 0.1 Q 0.001
@r5 nlSpring3 @m4 @m5 0.1 2. 0.001
@r6 nlSpringDamper @m5 @m6 0.05 10. 0.2 0.001
@r7 springDamper @m6 @g2 0.1 0.001
@c contact @m2 @m5 0.05 0.001 0.
@n nlContact @m1 @m6 0.01 100. 0.5 0.001 0.01
@p nlPluck @m3 @in2 0.05 0.01 0.001
@b nlBow @m4 @in3 0.005 0.0001 1
@b2 nlBow @m1 @in3 0.005 0.0001
@f feltContact @m2 @m6 0.5 2.5 0.001 0.01
@in1 frcInput @m1
@in4 frcInput @m4
@out1 posOutput @m3
@out2 frcOutput @m2
@out3 posOutput @m5
@out4 frcOutput @m6
@out5 posOutput @in2
";

#[test]
fn native_code_equals_the_interpreter() {
    let n = native_equals_interpreter(MIXED, 48_000.0, 600, 1);
    assert!(n > 500, "ran native code in {n} blocks");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut native_models = 0;
    for folder in ["../models", "../../shared/bench/faust-mi/scripts"] {
        let Ok(entries) = std::fs::read_dir(dir.join(folder)) else {
            continue;
        };
        let mut paths: Vec<_> = entries.map(|e| e.unwrap().path()).collect();
        paths.sort();
        for path in paths {
            let text = std::fs::read_to_string(&path).unwrap();
            let Some(spec) = parse(&text).spec else {
                continue;
            };
            let small = compile(&spec, &CompileOptions::at(44_100.0))
                .expect("compiles")
                .native_code_bytes()
                .is_some();
            if small {
                native_models += 1;
                native_equals_interpreter(&text, 44_100.0, 300, 2);
            }
        }
    }
    // The faust-mi twins osc, osc_oscil, collision, collision_m2 and string10 and the small
    // presets (oscillators, Drunk Triangles, …).
    assert!(native_models >= 5, "{native_models} models ran native code");
}

/// A parameter that turns a plain mass into an oscillator sets the engine back on its
/// interpreter, and turning it back brings the native code back; the samples never differ.
#[test]
fn a_mass_that_stops_being_plain_leaves_the_native_code() {
    let text = "@K param 0.\n@G param 0.\n@g ground 0.\n@m osc 1. K 0. 0. 0.\n\
                @h mass 1. G 0. 0.\n@l springDamper @g @m 0.01 0.0001\n\
                @j springDamper @m @h 0.01 0.0001\n@in1 frcInput @m\n@out1 posOutput @h\n";
    let mut native = build(text, 44_100.0, true);
    let mut interpreted = build(text, 44_100.0, false);
    let (k, g) = (native.param_id("K").unwrap(), native.param_id("G").unwrap());
    let mut input = vec![0.0; 256];
    input[0] = -0.01;
    for (step, (kv, gv, runs_native)) in [
        (0.0, 0.0, true),
        (0.02, 0.0, false),
        (0.0, 0.0, true),
        (0.0, 1e-5, false),
        (0.0, 0.0, true),
    ]
    .into_iter()
    .enumerate()
    {
        for e in [&mut native, &mut interpreted] {
            e.set_param(k, kv).unwrap();
            e.set_param(g, gv).unwrap();
            e.apply_pending_changes();
        }
        assert_eq!(
            native.native_code_bytes().is_some(),
            runs_native,
            "step {step}"
        );
        let (mut a, mut b) = (vec![0.0; 256], vec![0.0; 256]);
        native.process(256, &input, &mut a);
        interpreted.process(256, &input, &mut b);
        assert!(a.iter().any(|v| *v != 0.0));
        assert_eq!(bits(&a), bits(&b), "step {step}");
        assert_eq!(bits(native.positions()), bits(interpreted.positions()));
        input[0] = 0.0;
    }
}

/// Random networks of up to 21 points: any law between any two points, masses of every kind,
/// avatars, inputs and outputs anywhere, arguments from parameters.
#[test]
fn random_networks_equal_the_interpreter() {
    let mut rng = Lcg(0x5eed);
    let mut native_models = 0;
    for case in 0..150 {
        let points = 2 + rng.next() as usize % 20;
        let mut text = String::from("@P param 0.05\n");
        let mut labels = Vec::new();
        for i in 0..points {
            let x0 = [0.0, -0.0, 0.01, -0.02][rng.next() as usize % 4];
            let line = match rng.next() % 8 {
                0 => format!("@p{i} ground {x0}\n"),
                1 => format!("@p{i} osc 1.5 0.02 0.0001 0. {x0} 0.\n"),
                2 => format!("@p{i} massG 1. 0.0001 {x0} {x0}\n"),
                3 => format!("@p{i} mass 1. 0.0002 {x0} 0.\n"),
                4 => format!("@p{i} mass P 0. {x0} 0.001\n"),
                5 if i > 0 => format!("@in{i} posInput {x0}\n"),
                _ => format!("@p{i} mass {}. 0. {x0} 0.\n", 1 + rng.next() % 3),
            };
            labels.push(if line.starts_with("@in") {
                format!("@in{i}")
            } else {
                format!("@p{i}")
            });
            text += &line;
        }
        let links = 1 + rng.next() as usize % 30;
        for l in 0..links {
            let a = &labels[rng.next() as usize % points];
            let b = &labels[rng.next() as usize % points];
            let law = match rng.next() % 10 {
                0 => "contact {a} {b} 0.05 0.001 0.001".to_string(),
                1 => "nlContact {a} {b} 0.01 100. 0.5 0.001 0.".to_string(),
                2 => "nlSpring2 {a} {b} 0.05 P 0.001".to_string(),
                3 => "nlSpring3 {a} {b} 0.05 2. 0.0001".to_string(),
                4 => "nlSpringDamper {a} {b} 0.05 10. 0.2 0.001".to_string(),
                5 => "nlPluck {a} {b} 0.05 0.01 0.001".to_string(),
                6 => format!("nlBow {{a}} {{b}} 0.005 0.0001 {}", rng.next() % 2),
                7 => "spring {a} {b} P".to_string(),
                _ => "springDamper {a} {b} 0.05 0.0005".to_string(),
            };
            text += &format!("@l{l} {}\n", law.replace("{a}", a).replace("{b}", b));
        }
        let masses: Vec<&String> = labels.iter().filter(|l| l.starts_with("@p")).collect();
        if masses.is_empty() {
            continue;
        }
        let pick = |rng: &mut Lcg| masses[rng.next() as usize % masses.len()].clone();
        // Now and then a model without a force input or without outputs.
        if case % 7 != 3 {
            text += &format!("@in{} frcInput {}\n", points + 1, pick(&mut rng));
        }
        if case % 5 != 2 {
            text += &format!("@out1 posOutput {}\n", pick(&mut rng));
            text += &format!("@out2 frcOutput {}\n", pick(&mut rng));
        }
        let Some(spec) = parse(&text).spec else {
            panic!("case {case} does not parse:\n{text}");
        };
        if compile(&spec, &CompileOptions::at(48_000.0)).is_err() {
            continue;
        }
        if native_equals_interpreter(&text, 48_000.0, 60, case) > 0 {
            native_models += 1;
        }
    }
    assert!(
        native_models > 100,
        "{native_models} models ran native code"
    );
}

/// MIXED writes every law of the table, so that each runs in native code against the
/// interpreter.
#[test]
fn the_mixed_model_writes_every_law() {
    common::assert_writes_every_law(MIXED);
}
