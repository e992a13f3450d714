//! Voice lanes: every lane of a `LaneEngine` computes what a plain `Engine` computes with the
//! same class gains and inputs, bit for bit (issue 12: "a bank of one equals today's engine").

mod common;

use common::{engine, spec};
use ressort_engine::lanes::{LaneEngine, LANES};
use ressort_engine::{Engine, ModelSpec, ScaleClass};

/// A gallery model as published, as the presets of `models/` stood before the instrument's
/// exciters: the Oscillator tutorials' bow and plectrum forces as literals (the presets press
/// them through an `audioParam`, which keeps a model out of the lanes), and every output the
/// originals had (the falling balls and hammers move from the first sample).
fn published(name: &str) -> ModelSpec {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/legacy")
        .join(name);
    spec(&std::fs::read_to_string(path).unwrap())
}

/// An element-by-element network with every law of the table (a test below holds it to
/// that), both bow profiles, two force inputs and a force output.
const MIXED: &str = "\
@g ground 0.
@m1 mass 1. 0. 0.
@m2 mass 1.2 0. 0.
@m3 mass 0.9 0. 0.
@m4 osc 1. 0.05 0.0001 0. 0.
@m5 mass 1. 0. 0.
@g2 ground 0.
@r1 springDamper @g @m1 0.1 0.001
@r2 spring @m1 @m2 0.12
@r3 damper @m2 @m3 0.002
@r4 nlSpring2 @m3 @m4 0.1 0.5 0.001
@r5 nlSpring3 @m4 @m5 0.1 2. 0.001
@r6 springDamper @m5 @g2 0.1 0.001
@c contact @m2 @m5 0.05 0.001 0.
@p nlPluck @m3 @g 0.05 0.001 0.001
@n nlContact @m1 @m5 0.01 100. 0.5 0.001 0.01
@r7 nlSpringDamper @m2 @m4 0.05 10. 0.2 0.001
@b nlBow @m4 @g 0.005 0.0001 1
@b2 nlBow @m1 @g 0.005 0.0001
@f feltContact @m2 @m3 0.5 2.5 0.001 0.01
@in1 frcInput @m1
@in2 frcInput @m4
@out1 posOutput @m3
@out2 frcOutput @m2
";

/// Runs `lanes` and one plain engine per lane for `blocks` blocks of `frames`, lane l with
/// stiffness gain `k[l]`, damping gain `z[l]` and an impulse of `strike[l]` on every input,
/// and compares every output sample's bits.
fn lanes_equal_plain(
    spec: &ModelSpec,
    sr: f64,
    k: [f64; LANES],
    z: [f64; LANES],
    strike: [f64; LANES],
) {
    let template = engine(spec, sr);
    let mut lanes = LaneEngine::new(&template).expect("the model runs in lanes");
    let mut plain: Vec<Engine> = (0..LANES).map(|_| template.clone()).collect();
    for l in 0..LANES {
        lanes.set_class_gain(l, ScaleClass::Stiffness, k[l]);
        lanes.set_class_gain(l, ScaleClass::Damping, z[l]);
        plain[l].set_class_gain(ScaleClass::Stiffness, k[l]);
        plain[l].set_class_gain(ScaleClass::Damping, z[l]);
        plain[l].reset();
        lanes.reset_lane(l);
    }
    let (n_in, n_out) = (template.info().num_inputs(), template.info().num_outputs());
    let frames = 16;
    let mut lane_in = vec![0.0; n_in * frames * LANES];
    let mut lane_out = vec![0.0; n_out * frames * LANES];
    let mut one_in = vec![0.0; n_in * frames];
    let mut one_out = vec![0.0; n_out * frames];
    let mut loudest = 0.0f64;
    for block in 0..400 {
        // Every 8 blocks one lane's tuning moves (a note's bend), alternately its stiffness
        // and its damping gain, as a voice's class gains move in the bank.
        if block % 8 == 4 {
            let l = block / 8 % LANES;
            let g = 1.0 + 0.002 * block as f64;
            let class = if block % 16 == 4 {
                ScaleClass::Stiffness
            } else {
                ScaleClass::Damping
            };
            let base = if class == ScaleClass::Stiffness {
                k[l]
            } else {
                z[l]
            };
            lanes.set_class_gain(l, class, base * g);
            plain[l].set_class_gain(class, base * g);
        }
        // Halfway, a parameter named `at` (a connection point's coordinate) moves in every
        // copy: the lanes re-place their connection points.
        if block == 200 {
            if let Some(id) = template.param_id("at") {
                lanes.set_param(id, 0.71).unwrap();
                for p in &mut plain {
                    p.set_param(id, 0.71).unwrap();
                }
            }
        }
        lane_in.fill(0.0);
        for c in 0..n_in {
            for l in 0..LANES {
                if block == 0 {
                    lane_in[(c * frames) * LANES + l] = strike[l];
                }
            }
        }
        lanes.process(frames, &lane_in, &mut lane_out);
        for l in 0..LANES {
            for c in 0..n_in {
                for n in 0..frames {
                    one_in[c * frames + n] = lane_in[(c * frames + n) * LANES + l];
                }
            }
            plain[l].process(frames, &one_in, &mut one_out);
            for c in 0..n_out {
                for n in 0..frames {
                    let (a, b) = (
                        one_out[c * frames + n],
                        lane_out[(c * frames + n) * LANES + l],
                    );
                    loudest = loudest.max(a.abs());
                    assert_eq!(
                        a.to_bits(),
                        b.to_bits(),
                        "lane {l}, output {c}, sample {}: plain {a} vs lane {b}",
                        block * frames + n
                    );
                }
            }
        }
    }
    assert!(loudest > 1e-6, "the model hardly moved: {loudest}");
}

/// An element-by-element string: its links form a chain (`Group::apply`).
fn chain_string() -> String {
    long_string(24, None)
}

/// A string of `n` masses written element by element; link `odd` (if any) is stiffer, so
/// the chain's links do not all read the same arguments.
fn long_string(n: usize, odd: Option<usize>) -> String {
    let mut text = String::from("@g0 ground 0.\n@g1 ground 0.\n");
    for i in 0..n {
        text += &format!("@m{i} mass 1. 0. 0.\n");
    }
    text += "@l0 springDamper @g0 @m0 0.1 0.001\n";
    for i in 0..n - 1 {
        let k = if odd == Some(i) { 0.12 } else { 0.1 };
        text += &format!("@l{} springDamper @m{i} @m{} {k} 0.001\n", i + 1, i + 1);
    }
    text += &format!("@e springDamper @m{} @g1 0.1 0.001\n", n - 1);
    text + "@in1 frcInput @m5\n@out1 posOutput @m17\n"
}

/// A 6 × 5 mesh written element by element: bands of links within rows and between them.
fn element_mesh() -> String {
    let (len, w) = (6, 5);
    let mut text = String::from("@g ground 0.\n");
    for i in 0..len * w {
        text += &format!("@n{i} mass 1. 0. 0.\n");
    }
    for r in 0..len {
        for c in 0..w - 1 {
            let i = r * w + c;
            text += &format!("@h{i} springDamper @n{i} @n{} 0.1 0.001\n", i + 1);
        }
    }
    for i in 0..(len - 1) * w {
        text += &format!("@v{i} springDamper @n{i} @n{} 0.1 0.001\n", i + w);
    }
    text + "@p springDamper @g @n0 0.1 0.001\n@in1 frcInput @n7\n@out1 posOutput @n22\n"
}

/// Macros of every kind with connection points (inputs, outputs and interactions on them,
/// one placed by a parameter), a hammer striking one through a contact, and an avatar plucking
/// another.
const STRUCTURES: &str = "\
@at param 0.6
@s string 24 1. 0.1 0.0005 0.0001 0. 0.
@t stiffString 16 1. 0.12 0.03 0.0004 0. 0.
@c chain 6 1. 0.2 0.001 0. 0.
@m mesh 5 4 1. 0.1 0.001 0.00005 0. 0.
@k cornerMesh 4 6 1.3 0.09 0.002 0. 0.
@q closedMesh 6 5 0.8 0.11 0.001 0.0002 0. 0.
@h mass 1. 0.2 0.
@g ground 0.
@hit contact @h [@s 0.3] 0.05 0.002 0.
@hang springDamper @g @h 0.001 0.01
@j springDamper [@s 0.8] [@t 0.4] 0.02 0.001
@u springDamper [@t 0.9] [@m 0.3 0.6] 0.03 0.001
@w springDamper [@m 0.8 0.2] [@k 0.5 0.5] 0.02 0.0005
@y springDamper [@k 0.2 0.9] [@q 0.4 0.7] 0.02 0.0005
@e springDamper [@c 0.] [@q 0.6 0.5] 0.01 0.001
@pl nlPluck [@c 0.5] @in2 0.05 0.001 0.001
@in1 frcInput @h
@in2 posInput 0.
@in3 frcInput [@q 0.3 0.3]
@out1 posOutput [@s at]
@out2 posOutput [@q 0.5 0.4]
@out3 frcOutput [@k 0.5 0.5]
";

#[test]
fn each_lane_is_a_plain_engine_bit_for_bit() {
    // Different gains and strikes in every lane, whatever LANES is.
    let pick = |values: [f64; 8]| -> [f64; LANES] { std::array::from_fn(|l| values[l % 8]) };
    let k = pick([1.0, 0.5, 1.7, 2.3, 0.8, 1.25, 3.1, 0.65]);
    let z = pick([1.0, 2.0, 0.6, 1.3, 0.9, 1.7, 0.45, 1.1]);
    let strike = pick([-0.01, -0.02, 0.015, -0.005, 0.008, -0.012, 0.02, -0.003]);
    lanes_equal_plain(&spec(MIXED), 48_000.0, k, z, strike);
    lanes_equal_plain(&spec(&chain_string()), 48_000.0, k, z, strike);
    lanes_equal_plain(&spec(&element_mesh()), 48_000.0, k, z, strike);
    // Long chains: uniform (the first link's arguments, per lane) and not.
    lanes_equal_plain(&spec(&long_string(100, None)), 48_000.0, k, z, strike);
    lanes_equal_plain(&spec(&long_string(100, Some(40))), 48_000.0, k, z, strike);
    // Written from its far end: a reversed chain in the plain engine, scattered in lanes.
    let forward = chain_string();
    let reversed: String = forward
        .lines()
        .map(|l| match l.split_whitespace().collect::<Vec<_>>()[..] {
            [label, "springDamper", a, b, k, z] => {
                format!("{label} springDamper {b} {a} {k} {z}\n")
            }
            _ => format!("{l}\n"),
        })
        .collect();
    lanes_equal_plain(&spec(&reversed), 48_000.0, k, z, strike);
    lanes_equal_plain(&spec(STRUCTURES), 48_000.0, k, z, strike);
    for name in [
        "mesh-15x15.mdl",
        "plucked-oscillator.mdl",
        "bowed-oscillator.mdl",
        "fretted-string.mdl",
        "hammer-oscillator.mdl",
        "gravity-oscillator.mdl",
        "struck-string.mdl",
    ] {
        lanes_equal_plain(&published(name), 48_000.0, k, z, strike);
    }
    lanes_equal_plain(&published("drunk-triangles.mdl"), 48_000.0, k, z, strike);
    lanes_equal_plain(
        &published("drunk-triangles.mdl"),
        44_100.0,
        [1.0; LANES],
        [1.0; LANES],
        strike,
    );
}

/// A lane reset mid-flight starts again from rest while the others ring on; a lane that
/// blows up trips alone.
#[test]
fn a_lane_resets_and_trips_alone() {
    let template = engine(&spec(MIXED), 48_000.0);
    let mut lanes = LaneEngine::new(&template).unwrap();
    let frames = 16;
    let n_out = template.info().num_outputs();
    let mut input = vec![0.0; 2 * frames * LANES];
    for l in 0..LANES {
        input[l] = -0.01;
    }
    // Lane 2 gets a force no model survives.
    input[2] = 1e300;
    let mut out = vec![0.0; n_out * frames * LANES];
    let mut tripped = [false; LANES];
    for _ in 0..20 {
        let t = lanes.process(frames, &input, &mut out);
        for l in 0..LANES {
            tripped[l] |= t[l];
        }
        input.fill(0.0);
    }
    assert_eq!(tripped, std::array::from_fn(|l| l == 2));
    assert!(lanes.is_tripped(2));
    // The tripped lane is silent, the others ring.
    let lane_peak = |l: usize, out: &[f64]| {
        (0..n_out * frames)
            .map(|i| out[i * LANES + l].abs())
            .fold(0.0, f64::max)
    };
    assert_eq!(lane_peak(2, &out), 0.0);
    assert!(lane_peak(0, &out) > 0.0);
    lanes.reset_lane(2);
    assert!(!lanes.is_tripped(2));
    let mut x = vec![0.0; template.info().num_points];
    let mut xp = vec![0.0; template.info().num_points];
    lanes.lane_state(2, &mut x, &mut xp);
    let mut rest = template.clone();
    rest.reset();
    assert_eq!(&x[..], &rest.positions()[..x.len()]);
}

/// MIXED writes every law of the table, so that each runs in lanes against the plain engine.
#[test]
fn the_mixed_model_writes_every_law() {
    common::assert_writes_every_law(MIXED);
}
