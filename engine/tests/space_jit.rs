//! Small 3-D models compiled to machine code (`engine/src/sim/jit/space.rs`) play what the
//! interpreter plays, bit for bit: outputs, every axis's positions, delayed positions and
//! forces, guard events and sample counts, through odd block sizes, strikes and noise on
//! every input, non-finite input, parameter and gain changes, guard trips and resets
//! (`common::native::native_equals_interpreter`).

mod common;

use common::native::{bits, build, native_equals_interpreter, Lcg};
use ressort_engine::laws::space::SpaceLawKind;
use ressort_engine::{compile, parse, CompileOptions};

/// Element by element: every 3-D law of the table (a test below holds the scripts to that),
/// every mass-type element (`mass` with and without its own damping and gravity, `massZ`,
/// `massXY`, `osc`, `ground`), `~gravity`, `~friction`, every input kind (`frcInput` along z
/// and along a direction, `frcInputXYZ`, `posInput` along a direction, `posInputXYZ`) and
/// every point output kind (`posOutput` along z and projected, `velOutput`, `distOutput`,
/// `frcOutput` on a mass and on a ground), arguments from parameters.
const ELEMENTS: &str = "\
~dim 3
~gravity 9.81
~friction 0.0001
@K param 0.1
@Z param 0.001
@g ground [0 0 0]
@m1 mass 1. [0.1 0 0] [0 0 0]
@m2 mass 1.2 0.001 [1 0.1 0] [0 0 0]
@m3 massZ 0.9 [1 1 0] [0 0 0]
@m4 massXY 1.1 [0 1 0.1] [0 0 0]
@m5 osc 1. 0.05 0.0001 [0.0001 0 0.0002] [0.5 0.5 0.5] [0 0 0]
@m6 mass 1. [0.001 0.002 -0.001] [2 0 0] [0 0 0]
@g2 ground [2 1 0]
@l1 spring @g @m1 K auto
@l2 spring @m1 @m2 0.12 [0.9*auto]
@l3 damper @m2 @m3 Z
@l4 springDamper @m3 @m4 K Z auto
@l5 vdamper @m4 @m5 0.001
@l6 rope @m5 @m6 0.1 0.001 1.
@l7 bubble @m6 @g2 0.1 0.001 2.
@l8 attractor @m1 @m6 0.0001 0.1
@l9 contact @m2 @m5 0.05 0.001 1. 0.001 0.3
@l10 contact @m1 @m3 0.05 0.001 1.
@l11 nlContact @m1 @m5 0.01 100. 0.5 0.001 1.
@l12 planeContact @m6 0.05 0.001 [0 0 1] 0 0.1 0.001 0.5
@l13 nlSpring2 @m3 @m4 0.1 0.5 0.001 auto
@l14 nlSpring3 @m4 @m5 0.1 2. 0.001 auto
@l15 nlSpringDamper @m2 @m4 0.05 10. 0.2 0.001 auto
@l16 nlPluck @m3 @g 0.05 0.001 0.001
@l17 nlPluck @m1 @g2 0.05 0.001 0.001 [0 0 1]
@l18 nlBow @m4 @g 0.005 0.0001 1
@l19 nlBow @m5 @g2 0.005 0.0001
@l20 nlBow @m6 @g 0.005 0.0001 0 [1 0 0]
@l21 nlBow @m2 @g 0.005 0.0001 1 [0.3 -0.8 0.1]
@in1 frcInput @m1
@in2 frcInputXYZ @m2
@in5 posInput [0 0 2] [0 1 0]
@pa spring @in5 @m2 0.01 auto
@in6 posInputXYZ [1 0 2]
@pb springDamper @in6 @m6 0.01 0.001 auto
@in9 frcInput @m4 [1 1 0]
@out1 posOutput @m1
@out2 velOutput @m2 [1 0 0]
@out3 distOutput @m1 @m6
@out4 frcOutput @m3
@out5 frcOutput @g [0 1 0]
@out6 posOutput @m5 [0.3 0.3 0.9]
";

/// Small structures without connection points: a string with its fixed ends and node
/// damping, a membrane locked to its plane, their shared arguments (one slot for every link),
/// microphones directional and radial, inputs and outputs on their nodes.
const STRUCTURES: &str = "\
~dim 3
~gravity 1
@K param 0.1
@s string3 3 1. K 0.001 [0 0 0] [3 0 0] [0.9*auto] 'Zo=1e-5'
@me mesh3 2 2 1. 0.1 0.001 [0 0 -2] [2 0 -2] [0 2 -2] [0.95*auto] 'lock=z'
@h mass 1. [1 1 1] [0 0 0]
@c1 spring @s_m2 @h 0.05 auto
@c2 vdamper @me_m1_1 @h 0.001
@in1 frcInputXYZ @s_m1
@in4 frcInput @h [0 1 1]
@in5 frcInput @me_m1_1
@out1 mic @s [0 0 5] [0 0 1] 2 0.5
@out2 mic @me [5 0 0] radial 1 1
@out3 velOutput @s_m2 [0 1 0]
@out4 posOutput @h [1 0 0]
@out5 frcOutput @me_m0_1 [1 0 0]
";

#[test]
fn every_3d_element_runs_native_code_as_the_interpreter() {
    let e = build(ELEMENTS, 48_000.0, true);
    assert!(e.is_3d() && e.fits_native_code());
    assert!(
        e.native_code_bytes().is_some(),
        "the 3-D model got its code"
    );
    let n = native_equals_interpreter(ELEMENTS, 48_000.0, 600, 1);
    assert!(n > 500, "ran native code in {n} blocks");
    let n = native_equals_interpreter(ELEMENTS, 44_100.0, 300, 7);
    assert!(n > 250, "ran native code in {n} blocks");
}

#[test]
fn small_3d_structures_and_microphones_run_native_code_as_the_interpreter() {
    assert!(build(STRUCTURES, 48_000.0, true)
        .native_code_bytes()
        .is_some());
    let n = native_equals_interpreter(STRUCTURES, 48_000.0, 600, 3);
    assert!(n > 500, "ran native code in {n} blocks");
}

/// The scripts above write every law of the 3-D table, so that each runs in native code
/// against the interpreter (a law added to the table fails here until a script writes it).
#[test]
fn the_3d_native_scripts_write_every_law() {
    let e = build(ELEMENTS, 48_000.0, true);
    let links = e.space_law_links();
    for kind in SpaceLawKind::ALL {
        assert!(links[kind.index()] > 0, "ELEMENTS writes no {kind:?}");
    }
}

/// Strikes hard enough to make the contacts, the plucks and the bows engage and the guard
/// trip, and a position limit that trips on the first sample: the same samples, the same
/// guard event.
#[test]
fn strong_strikes_and_guard_trips_give_the_interpreter_bits() {
    for (strike, limit) in [(3.0, 1e4), (300.0, 1e4), (0.01, 1e-9)] {
        let mut native = build(ELEMENTS, 48_000.0, true);
        let mut interpreted = build(ELEMENTS, 48_000.0, false);
        for e in [&mut native, &mut interpreted] {
            e.set_position_limit(limit);
        }
        let (ins, outs) = (native.info().num_inputs(), native.info().num_outputs());
        let frames = 64;
        let mut input = vec![0.0; ins * frames];
        for c in 0..ins {
            input[c * frames + c] = strike * if c % 2 == 0 { 1.0 } else { -0.5 };
        }
        for block in 0..200 {
            assert!(native.native_code_bytes().is_some());
            let (mut a, mut b) = (vec![0.0; outs * frames], vec![0.0; outs * frames]);
            let ra = native.process(frames, &input, &mut a);
            let rb = interpreted.process(frames, &input, &mut b);
            let at = format!("strike {strike}, limit {limit}, block {block}");
            assert_eq!(bits(&a), bits(&b), "{at}");
            assert_eq!(ra, rb, "{at}");
            assert_eq!(native.guard_event(), interpreted.guard_event(), "{at}");
            for c in 0..3 {
                assert_eq!(bits(native.axis(c)), bits(interpreted.axis(c)), "{at}");
            }
            input.fill(0.0);
        }
        if limit < 1.0 {
            assert!(native.guard_event().is_some(), "the guard trips");
        }
    }
}

/// What the native code does not compile falls back to the interpreter: a connection point,
/// an audio-rate parameter, a model too large, a law with as many links as the interpreter
/// evaluates at once on the CPU's vectors.
#[test]
fn what_the_3d_code_does_not_handle_runs_on_the_interpreter() {
    let proxy = "~dim 3\n@s string3 4 1. 0.1 0.001 [0 0 0] [3 0 0] auto\n\
                 @in1 frcInput [@s 0.4]\n@out1 posOutput @s_m2\n";
    let audio = "~dim 3\n@K audioParam @in2 0.1\n@g ground [0 0 0]\n@m mass 1. [0 0 1] [0 0 0]\n\
                 @l spring @g @m K auto\n@in1 frcInput @m\n@out1 posOutput @m\n";
    let large = "~dim 3\n@s string3 40 1. 0.1 0.001 [0 0 0] [3 0 0] auto\n\
                 @in1 frcInput @s_m3\n@out1 posOutput @s_m5\n";
    let chain = chain3(7);
    for text in [proxy, audio, large, chain.as_str()] {
        let e = build(text, 48_000.0, true);
        assert!(!e.fits_native_code(), "{text}");
        assert!(e.native_code_bytes().is_none(), "{text}");
        assert_eq!(native_equals_interpreter(text, 48_000.0, 40, 5), 0);
    }
}

/// Random element-by-element 3-D networks: any law between any two points, every mass kind,
/// avatars, inputs and outputs anywhere, arguments from parameters.
#[test]
fn random_3d_networks_equal_the_interpreter() {
    let mut rng = Lcg(0x3d3d);
    let mut native_models = 0;
    let pos = |rng: &mut Lcg| {
        let mut c = || (rng.below(5) as f64 - 2.0) * 0.25;
        format!("[{} {} {}]", c(), c(), c())
    };
    let dirs = ["[0 0 1]", "[1 0 0]", "[0.3 -0.8 0.1]", "[0 1 1]"];
    for case in 0..80 {
        let points = 2 + rng.below(10);
        let mut text = String::from("~dim 3\n@P param 0.05\n");
        if rng.below(2) == 0 {
            text += "~gravity 0.5\n";
        }
        if rng.below(2) == 0 {
            text += "~friction 0.0001\n";
        }
        let mut labels = Vec::new();
        let mut masses = Vec::new();
        for i in 0..points {
            let p = pos(&mut rng);
            let line = match rng.below(8) {
                0 => format!("@p{i} ground {p}\n"),
                1 => format!("@p{i} osc 1.5 0.02 0.0001 {p} [0 0 0]\n"),
                2 => format!("@p{i} massZ 1. {p} [0 0 0.001]\n"),
                3 => format!("@p{i} massXY 1. 0.0002 {p} [0 0 0]\n"),
                4 => format!("@p{i} mass P [0.001 0 0.002] {p} [0 0.001 0]\n"),
                5 if i > 0 => format!("@in{i} posInput {p} {}\n", rng.pick(&dirs)),
                6 if i > 0 => format!("@in{i} posInputXYZ {p}\n"),
                _ => format!("@p{i} mass {}. {p} [0 0 0]\n", 1 + rng.below(3)),
            };
            let label = line.split(' ').next().unwrap().to_string();
            if label.starts_with("@p") {
                masses.push(label.clone());
            }
            labels.push(label);
            text += &line;
        }
        if masses.is_empty() {
            continue;
        }
        let links = 1 + rng.below(16);
        for l in 0..links {
            let a = rng.pick(&labels).clone();
            let b = rng.pick(&labels).clone();
            let d = rng.pick(&dirs);
            let law = match rng.below(14) {
                0 => format!("contact {a} {b} 0.05 0.001 0.5 0.001 0.3"),
                1 => format!("nlContact {a} {b} 0.01 100. 0.5 0.001 0.5"),
                2 => format!("nlSpring2 {a} {b} 0.05 P 0.001 auto"),
                3 => format!("nlSpring3 {a} {b} 0.05 2. 0.0001 auto"),
                4 => format!("nlSpringDamper {a} {b} 0.05 10. 0.2 0.001 auto"),
                5 => format!("nlPluck {a} {b} 0.05 0.01 0.001 {d}"),
                6 => format!("nlBow {a} {b} 0.005 0.0001 {}", rng.below(2)),
                7 => format!("spring {a} {b} P auto"),
                8 => format!("rope {a} {b} 0.1 0.001 0.3"),
                9 => format!("attractor {a} {b} 0.0001 0.1"),
                10 => format!("planeContact {a} 0.05 0.001 {d} 0 0.1 0.001 0.5"),
                11 => format!("vdamper {a} {b} 0.001"),
                12 => format!("damper {a} {b} 0.002"),
                _ => format!("springDamper {a} {b} 0.05 0.0005 [0.9*auto]"),
            };
            text += &format!("@l{l} {law}\n");
        }
        let n_in = points + 1;
        if case % 7 != 3 {
            let m = rng.pick(&masses);
            text += &match rng.below(3) {
                0 => format!("@in{n_in} frcInput {m}\n"),
                1 => format!("@in{n_in} frcInput {m} {}\n", rng.pick(&dirs)),
                _ => format!("@in{n_in} frcInputXYZ {m}\n"),
            };
        }
        if case % 5 != 2 {
            let (m1, m2) = (rng.pick(&labels).clone(), rng.pick(&labels).clone());
            text += &format!("@out1 posOutput {m1} {}\n", rng.pick(&dirs));
            text += &format!("@out2 frcOutput {} [0 1 0]\n", rng.pick(&masses));
            text += &format!("@out3 velOutput {m2}\n@out4 distOutput {m1} {m2}\n");
        }
        let Some(spec) = parse(&text).spec else {
            continue;
        };
        if compile(&spec, &CompileOptions::at(48_000.0)).is_err() {
            continue;
        }
        if native_equals_interpreter(&text, 48_000.0, 40, case) > 0 {
            native_models += 1;
        }
    }
    assert!(native_models > 40, "{native_models} models ran native code");
}

/// A chain of `n` masses between two grounds, struck in 3-D on its third mass, heard on two
/// axes.
fn chain3(n: usize) -> String {
    let mut t = String::from("~dim 3\n@g ground [0 0 0]\n");
    for i in 1..=n {
        t += &format!("@m{i} mass 1. [{i} 0 0] [0 0 0]\n");
    }
    t += &format!("@g2 ground [{} 0 0]\n", n + 1);
    t += "@l0 springDamper @g @m1 0.1 0.001 [0.95*auto]\n";
    for i in 1..=n {
        let b = if i == n {
            "@g2".to_string()
        } else {
            format!("@m{}", i + 1)
        };
        t += &format!("@l{i} springDamper @m{i} {b} 0.1 0.001 [0.95*auto]\n");
    }
    let (strike, hear) = (n.min(3), (n * 2 / 3).max(1));
    t += &format!("@in1 frcInputXYZ @m{strike}\n@out1 posOutput @m{hear} [0 1 0]\n");
    t + &format!("@out2 posOutput @m{hear}\n")
}

/// The ELEMENTS model and 3-D chains of 3, 5, 10 and 16 masses, one engine on the interpreter
/// and one on native code, ns per sample (`cargo test --release -p ressort-engine --test
/// space_jit bench -- --ignored --nocapture`).
#[test]
#[ignore]
fn bench_small_3d_models_native_against_the_interpreter() {
    let mut models = vec![("ELEMENTS".to_string(), ELEMENTS.to_string())];
    for n in [3, 5, 6, 7, 10, 16] {
        models.push((format!("{n}-mass chain"), chain3(n)));
    }
    for (name, text) in &models {
        let mut ns = [0.0; 2];
        for (k, jit) in [false, true].into_iter().enumerate() {
            let mut e = build(text, 48_000.0, jit);
            if jit && e.native_code_bytes().is_none() {
                println!("{name}: no native code (too large: it runs on the interpreter)");
                break;
            }
            let (ins, outs) = (e.info().num_inputs(), e.info().num_outputs());
            let (frames, blocks) = (64, 6_000);
            let mut input = vec![0.0; ins * frames];
            let mut output = vec![0.0; outs * frames];
            let t = std::time::Instant::now();
            for b in 0..blocks {
                // A strike every 100 blocks keeps the model moving (no fixed point to hold).
                if b % 100 == 0 {
                    input[0] = 0.01;
                }
                e.process(frames, &input, &mut output);
                input[0] = 0.0;
            }
            ns[k] = t.elapsed().as_nanos() as f64 / (blocks * frames) as f64;
            assert!(e.guard_event().is_none());
        }
        if ns[1] > 0.0 {
            println!(
                "{name} at 48 kHz: interpreter {:.1} ns/sample, native {:.1} ns/sample ({:.2}×)",
                ns[0],
                ns[1],
                ns[0] / ns[1]
            );
        }
    }
}
