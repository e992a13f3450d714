//! Voice lanes of 3-D models (issue 39): every lane of a `LaneEngine` of a 3-D model computes
//! what a plain 3-D `Engine` computes with the same class gains and inputs, bit for bit, for
//! every 3-D law, element, structure, input and output; and the voice bank runs a 3-D model's
//! voices in lanes.

mod common;

use common::{engine, spec};
use ressort_engine::lanes::{LaneEngine, LANES};
use ressort_engine::laws::space::SpaceLawKind;
use ressort_engine::{Engine, ModelSpec, ScaleClass};

/// Element by element: every 3-D law of the table (a test below holds the scripts to that),
/// every mass-type element, `~gravity`, per-mass gravity (scalar and vector), `~friction`,
/// every input kind and every point output kind.
const ELEMENTS: &str = "\
~dim 3
~gravity 9.81
~friction 0.0001
@g ground [0 0 0]
@m1 mass 1. [0.1 0 0] [0 0 0]
@m2 mass 1.2 0.001 [1 0.1 0] [0 0 0]
@m3 massZ 0.9 [1 1 0] [0 0 0]
@m4 massXY 1.1 [0 1 0.1] [0 0 0]
@m5 osc 1. 0.05 0.0001 [0.0001 0 0.0002] [0.5 0.5 0.5] [0 0 0]
@m6 mass 1. [0.001 0.002 -0.001] [2 0 0] [0 0 0]
@g2 ground [2 1 0]
@l1 spring @g @m1 0.1 auto
@l2 spring @m1 @m2 0.12 [0.9*auto]
@l3 damper @m2 @m3 0.002
@l4 springDamper @m3 @m4 0.1 0.001 auto
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

/// Every structure, with connection points on each (interactions, inputs and outputs on
/// them, one placed by a parameter), the structure adders, a hammer on a contact set,
/// microphones radial and directional.
const STRUCTURES: &str = "\
~dim 3
~gravity 1
@at param 0.3
@s string3 12 1. 0.1 0.001 [0 0 0] [3 0 0] [0.9*auto] 'Zo=1e-5'
@me mesh3 4 3 1. 0.1 0.001 [0 0 0] [3 0 0] [0 3 0] auto 'fix=borders diag'
@lz mesh3 3 3 1. 0.1 0.001 [0 0 -2] [2 0 -2] [0 2 -2] [0.9*auto] 'lock=z fix=borders'
@la lattice3 2 3 2 1. 0.1 0.001 [0 0 4] [1 1 1] auto 'diag fix=z-'
@r ring3 6 1. 0.1 0.001 [0 0 -3] 2 [0 0 1] [0.95*auto] 'K2=0.01'
@ic icosphere 1 1. 0.1 0.0001 [5 5 5] 3 auto 'fix=pole'
@h mass 1. [1 1 1] [0 0 0]
@c1 spring [@s at] @h 0.05 auto
@c2 springDamper [@me 0.4 0.6] @h 0.05 0.001 auto
@c3 spring [@la 0.2 0.5 0.7] @h 0.05 auto
@c4 spring [@r 0.25] @h 0.05 auto
@c5 springDamper [@lz 0.5 0.5] @h 0.05 0.001 auto
@sv vdampers @s 0.0001
@cs contactSet @h @ic 0.05 0.001 0.3
@in1 frcInput [@s 0.6]
@in2 frcInputXYZ @h
@out1 posOutput [@s 0.7] [0 0 1]
@out2 mic @ic [5 0 0] radial 1 1
@out3 mic @s [0 0 5] [0 0 1] 2 0.5
@out4 frcOutput [@r 0.5]
@out5 velOutput @s_m5 [0 1 0]
@out6 posOutput [@la 0.5 0.5 0.5]
";

/// A string of `n` nodes struck at a connection point, heard at another.
fn string3(n: usize) -> String {
    format!(
        "~dim 3\n@s string3 {n} 1. 0.1 0.0005 [0 0 0] [{n} 0 0] [0.95*auto] 'Zo=1e-5'\n\
         @in1 frcInputXYZ [@s 0.3]\n@out1 posOutput [@s 0.7] [0 0 1]\n\
         @out2 posOutput [@s 0.6] [0 1 0]\n"
    )
}

/// Runs `lanes` and one plain engine per lane for 300 blocks of 16 frames, lane l with
/// stiffness gain `k[l]`, damping gain `z[l]` and its own impulses on every input, and
/// compares every output sample's bits.
fn lanes_equal_plain(spec: &ModelSpec, k: [f64; LANES], z: [f64; LANES], strike: [f64; LANES]) {
    let template = engine(spec, 48_000.0);
    assert!(template.is_3d());
    let mut lanes = LaneEngine::new(&template).expect("the 3-D model runs in lanes");
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
    let mut loudest = vec![0.0f64; n_out];
    for block in 0..300 {
        // A lane's gains move every 8 blocks, as a voice's tuning in the bank.
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
        // A parameter moves in every copy halfway (a connection point's coordinate).
        if block == 150 {
            if let Some(id) = template.param_id("at") {
                lanes.set_param(id, 0.71).unwrap();
                for p in &mut plain {
                    p.set_param(id, 0.71).unwrap();
                }
            }
        }
        // Lane 3 restarts at block 100, on both sides.
        if block == 100 {
            lanes.reset_lane(3 % LANES);
            plain[3 % LANES].reset();
        }
        lane_in.fill(0.0);
        for c in 0..n_in {
            for l in 0..LANES {
                let at = (c * frames + (c + l) % frames) * LANES + l;
                if block == 0 || block == 101 {
                    lane_in[at] = strike[l] * (1.0 + 0.3 * c as f64);
                }
                // A little noise on the inputs all along, NaN once (read as 0).
                if block % 5 == 2 {
                    lane_in[at] = if block == 57 && l == 1 {
                        f64::NAN
                    } else {
                        1e-4 * strike[l] * ((block * 7 + c * 3 + l) % 11) as f64
                    };
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
                    loudest[c] = loudest[c].max(a.abs());
                    assert_eq!(
                        a.to_bits(),
                        b.to_bits(),
                        "lane {l}, output {c}, sample {}: plain {a:e} vs lane {b:e}",
                        block * frames + n
                    );
                }
            }
        }
    }
    println!("loudest output samples: {loudest:?}");
    assert!(
        loudest.iter().any(|v| *v > 1e-9),
        "the model hardly moved: {loudest:?}"
    );
    let tripped = (0..LANES).filter(|&l| plain[l].is_tripped()).count();
    println!("{tripped} of {LANES} lanes tripped (bit for bit with their engines)");
    // The lanes' positions on every axis are the engines' (a tripped engine stops, its lane
    // runs on silent).
    let mut axis = vec![0.0; template.positions().len()];
    for (l, p) in plain.iter().enumerate() {
        assert_eq!(p.is_tripped(), lanes.is_tripped(l), "lane {l}");
        if p.is_tripped() {
            continue;
        }
        for c in 0..3 {
            lanes.lane_axis(l, c, &mut axis);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&axis), bits(p.axis(c)), "lane {l}, axis {c}");
        }
    }
}

fn gains() -> ([f64; LANES], [f64; LANES], [f64; LANES]) {
    let pick = |values: [f64; 8]| -> [f64; LANES] { std::array::from_fn(|l| values[l % 8]) };
    (
        pick([1.0, 0.5, 1.7, 2.3, 0.8, 1.25, 3.1, 0.65]),
        pick([1.0, 2.0, 0.6, 1.3, 0.9, 1.7, 0.45, 1.1]),
        pick([-0.01, -0.02, 0.015, -0.005, 0.008, -0.012, 0.02, -0.003]),
    )
}

#[test]
fn each_3d_lane_is_a_plain_engine_bit_for_bit() {
    let (k, z, strike) = gains();
    lanes_equal_plain(&spec(ELEMENTS), k, z, strike);
    lanes_equal_plain(&spec(STRUCTURES), k, z, strike);
    // Strong strikes: the contacts and the bow's branches differ from lane to lane.
    lanes_equal_plain(&spec(ELEMENTS), k, z, strike.map(|s| s * 300.0));
    lanes_equal_plain(&spec(STRUCTURES), k, z, strike.map(|s| s * 100.0));
}

/// The scripts above write every law of the 3-D table, so that each runs in lanes against
/// the plain engine (a law added to the table fails here until a script writes it).
#[test]
fn the_3d_scripts_write_every_law() {
    let mut links = vec![0usize; SpaceLawKind::COUNT];
    for text in [ELEMENTS, STRUCTURES] {
        let e = engine(&spec(text), 48_000.0);
        for (total, n) in links.iter_mut().zip(e.space_law_links()) {
            *total += n;
        }
    }
    for kind in SpaceLawKind::ALL {
        assert!(links[kind.index()] > 0, "no script writes {kind:?}");
    }
}

/// A lane that blows up trips alone; the others go on.
#[test]
fn a_3d_lane_trips_alone() {
    let template = engine(&spec(&string3(20)), 48_000.0);
    let mut lanes = LaneEngine::new(&template).unwrap();
    let frames = 64;
    let (n_in, n_out) = (template.info().num_inputs(), template.info().num_outputs());
    let mut input = vec![0.0; n_in * frames * LANES];
    input[LANES] = 0.01;
    input[2 % LANES] = 1e300;
    let mut out = vec![0.0; n_out * frames * LANES];
    let mut tripped = [false; LANES];
    for _ in 0..20 {
        let t = lanes.process(frames, &input, &mut out);
        for l in 0..LANES {
            tripped[l] |= t[l];
        }
        input.fill(0.0);
    }
    assert!(tripped[2 % LANES] && lanes.is_tripped(2 % LANES));
    assert!(!lanes.is_tripped(1));
    lanes.reset_lane(2 % LANES);
    assert!(!lanes.is_tripped(2 % LANES));
}

/// Moving a voice from one group to another (the bank's packing) goes on exactly.
#[test]
fn a_3d_lane_moves_to_another_group_exactly() {
    let template = engine(&spec(STRUCTURES), 48_000.0);
    let mut a = LaneEngine::new(&template).unwrap();
    let mut b = LaneEngine::new(&template).unwrap();
    let mut plain = template.clone();
    plain.set_class_gain(ScaleClass::Stiffness, 1.3);
    plain.reset();
    a.set_class_gain(5, ScaleClass::Stiffness, 1.3);
    a.reset_lane(5);
    let frames = 32;
    let (n_in, n_out) = (template.info().num_inputs(), template.info().num_outputs());
    let mut lane_in = vec![0.0; n_in * frames * LANES];
    let mut one_in = vec![0.0; n_in * frames];
    lane_in[5] = 0.05;
    one_in[0] = 0.05;
    let mut lane_out = vec![0.0; n_out * frames * LANES];
    let mut one_out = vec![0.0; n_out * frames];
    for block in 0..40 {
        if block == 20 {
            b.take_lane(1, &a, 5);
        }
        let (group, lane) = if block < 20 { (&mut a, 5) } else { (&mut b, 1) };
        group.process(frames, &lane_in, &mut lane_out);
        plain.process(frames, &one_in, &mut one_out);
        for c in 0..n_out {
            for n in 0..frames {
                let (x, y) = (
                    one_out[c * frames + n],
                    lane_out[(c * frames + n) * LANES + lane],
                );
                assert_eq!(x.to_bits(), y.to_bits(), "block {block}, output {c}");
            }
        }
        lane_in.fill(0.0);
        one_in.fill(0.0);
    }
}

/// 16 voices of a 150-node 3-D string: two lane groups against 16 engines, ns per sample
/// (`cargo test --release -p ressort-engine --test space_lanes -- --ignored --nocapture`).
#[test]
#[ignore]
fn bench_16_voices_of_a_3d_string() {
    let template = engine(&spec(&string3(150)), 48_000.0);
    let (n_in, n_out) = (template.info().num_inputs(), template.info().num_outputs());
    let (frames, blocks) = (64, 750);
    let mut groups = vec![LaneEngine::new(&template).unwrap(); 16 / LANES];
    let mut engines = vec![template.clone(); 16];
    let mut lane_in = vec![0.0; n_in * frames * LANES];
    let mut lane_out = vec![0.0; n_out * frames * LANES];
    let mut one_in = vec![0.0; n_in * frames];
    let mut one_out = vec![0.0; n_out * frames];
    for l in 0..LANES {
        lane_in[l] = 0.01 * (l + 1) as f64;
    }
    one_in[0] = 0.01;
    let t = std::time::Instant::now();
    for b in 0..blocks {
        for g in &mut groups {
            g.process(frames, &lane_in, &mut lane_out);
        }
        if b == 0 {
            lane_in.fill(0.0);
        }
    }
    let lanes_ns = t.elapsed().as_nanos() as f64 / (blocks * frames) as f64;
    let t = std::time::Instant::now();
    for b in 0..blocks {
        for e in &mut engines {
            e.process(frames, &one_in, &mut one_out);
        }
        if b == 0 {
            one_in.fill(0.0);
        }
    }
    let engines_ns = t.elapsed().as_nanos() as f64 / (blocks * frames) as f64;
    println!(
        "16 voices of string3 150 at 48 kHz: lanes {lanes_ns:.0} ns/sample, engines \
         {engines_ns:.0} ns/sample ({:.2}×)",
        engines_ns / lanes_ns
    );
}
