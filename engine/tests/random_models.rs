//! Random models through every path: a property test writes random valid scripts (every
//! single-mass kind, every macro structure, every law of the table with random columns,
//! parameters, connection points on the structures, inputs and outputs anywhere), compiles
//! each one and plays it on the interpreter, in native code (when it fits) and in voice lanes
//! (when it can run there), bit for bit, through strikes, noise, parameter and gain changes.
//! Nothing may panic. The law keywords and their columns come from the table
//! (`LawKind::ALL`), so a new law is in the test the day it is a row.

mod common;

use common::native::{self, Lcg};
use proptest::prelude::*;
use ressort_engine::lanes::{LaneEngine, LANES};
use ressort_engine::{compile, parse, CompileOptions, Engine, LawKind, ScaleClass};

/// Values a law's column may take, by the column's name in the table (`P` and `Q` are
/// parameters).
fn column_value(rng: &mut Lcg, name: &str) -> String {
    let pool: &[&str] = match name {
        "K" | "Knl" => &["0.", "0.01", "0.05", "0.1", "P"],
        "KnlP" | "KnlQ" => &["0.", "0.5", "2.", "10.", "Q"],
        "Klim" => &["0.05", "0.2", "1."],
        "Z" | "Znl" => &["0.", "0.0001", "0.001", "0.005"],
        "thresh" => &["0.", "0.001", "0.01", "-0.01"],
        "p" => &["1.", "2.5", "3."],
        "Vscale" => &["0.0001", "0.001", "0.1"],
        "smooth" => &["0", "1"],
        "Pscale" => &["0.001", "0.01", "0.05"],
        _ => &["0.", "0.01"],
    };
    rng.pick(pool).to_string()
}

/// A random valid script of up to a few dozen points.
fn random_script(seed: u64) -> String {
    let mut rng = Lcg(seed);
    let mut text = String::from("@P param 0.05\n@Q param 0.5\n@K param 0.1\n@at param 0.3\n");
    // Endpoints a link, an input or an output may name.
    let mut points: Vec<String> = Vec::new();
    let mut masses: Vec<String> = Vec::new();
    let x0s = ["0.", "-0.", "0.01", "-0.02"];
    for i in 0..1 + rng.below(8) {
        let x0 = *rng.pick(&x0s);
        let (line, label) = match rng.below(7) {
            0 => (format!("@p{i} ground {x0}\n"), format!("@p{i}")),
            1 => (
                format!("@p{i} osc 1.5 0.02 0.0001 0. {x0} 0.\n"),
                format!("@p{i}"),
            ),
            2 => (
                format!("@p{i} massG 1. 0.0001 {x0} {x0}\n"),
                format!("@p{i}"),
            ),
            3 => (format!("@p{i} mass P 0. {x0} 0.001\n"), format!("@p{i}")),
            4 if i > 0 => (format!("@in{i} posInput {x0}\n"), format!("@in{i}")),
            _ => (
                format!("@p{i} mass {}. 0. {x0} 0.\n", 1 + rng.below(3)),
                format!("@p{i}"),
            ),
        };
        if !label.starts_with("@in") && !line.contains("ground") {
            masses.push(label.clone());
        }
        points.push(label);
        text += &line;
    }
    // Macro structures, with connection points on them.
    let coordinates = ["0.", "0.3", "0.5", "1.", "at"];
    for s in 0..rng.below(3) {
        let n = 2 + rng.below(9);
        let label = format!("@s{s}");
        let (line, two_d) = match rng.below(6) {
            0 => (format!("{label} string {n} 1. K 0.001 0. 0.\n"), false),
            1 => (
                format!("{label} chain {n} 1. 0.05 0.0005 0.0001 0. 0.\n"),
                false,
            ),
            2 => (
                format!("{label} stiffString {n} 1. 0.05 -0.002 0.0005 0.00002 0. 0.\n"),
                false,
            ),
            k => {
                let kind = ["mesh", "cornerMesh", "closedMesh"][k - 3];
                let w = 2 + rng.below(4);
                (
                    format!("{label} {kind} {n} {w} 1. 0.05 0.001 0. 0.\n"),
                    true,
                )
            }
        };
        text += &line;
        for _ in 0..2 {
            let c = *rng.pick(&coordinates);
            let point = if two_d {
                format!("[{label} {c} {}]", rng.pick(&coordinates))
            } else {
                format!("[{label} {c}]")
            };
            points.push(point.clone());
            masses.push(point);
        }
    }
    if masses.is_empty() {
        text += "@pm mass 1. 0. 0.\n";
        masses.push("@pm".into());
        points.push("@pm".into());
    }
    // Links of every law of the table and the two short forms.
    for l in 0..1 + rng.below(24) {
        let a = rng.pick(&points).clone();
        let b = rng.pick(&points).clone();
        let line = match rng.below(LawKind::COUNT + 2) {
            k if k < LawKind::COUNT => {
                let row = LawKind::ALL[k].row();
                let optional = row.columns.len() - row.required;
                let n = row.required + rng.below(optional + 1);
                let columns: Vec<String> = row.columns[..n]
                    .iter()
                    .map(|c| column_value(&mut rng, c.name))
                    .collect();
                format!("@l{l} {} {a} {b} {}\n", row.keyword, columns.join(" "))
            }
            k if k == LawKind::COUNT => format!("@l{l} spring {a} {b} P\n"),
            _ => format!("@l{l} damper {a} {b} 0.001\n"),
        };
        text += &line;
    }
    let n_in = 1 + rng.below(3);
    for c in 0..n_in {
        text += &format!("@in{} frcInput {}\n", 20 + c, rng.pick(&masses));
    }
    for c in 1..=1 + rng.below(3) {
        let kind = if rng.below(3) == 0 {
            "frcOutput"
        } else {
            "posOutput"
        };
        text += &format!("@out{c} {kind} {}\n", rng.pick(&masses));
    }
    text
}

/// The script compiled at 48 kHz, `None` when it does not compile (the generator writes valid
/// scripts; a compile error is a result too, not a panic).
fn build(text: &str) -> Option<Engine> {
    let spec = parse(text)
        .spec
        .unwrap_or_else(|| panic!("does not parse:\n{text}"));
    compile(&spec, &CompileOptions::at(48_000.0)).ok()
}

/// The interpreter and the native code through 40 blocks of the scripted life of the `jit`
/// test ([`native::native_equals_interpreter`]). Returns whether native code ran.
fn native_equals_interpreter(text: &str, seed: u64) -> bool {
    build(text).is_some() && native::native_equals_interpreter(text, 48_000.0, 40, seed) > 0
}

/// Every lane of a lane group against a plain engine with the same gains and strikes, 60
/// blocks of 16 frames. Returns the loudest output sample, `None` when the model does not
/// run in lanes.
fn lanes_equal_plain(text: &str, seed: u64) -> Option<f64> {
    let template = build(text)?;
    let mut lanes = LaneEngine::new(&template)?;
    let mut loudest = 0.0f64;
    let mut rng = Lcg(seed ^ 0x5851_f42d);
    let mut plain: Vec<Engine> = (0..LANES).map(|_| template.clone()).collect();
    for (l, p) in plain.iter_mut().enumerate() {
        let (k, z) = (0.5 + rng.unit(), 0.5 + rng.unit());
        lanes.set_class_gain(l, ScaleClass::Stiffness, k);
        lanes.set_class_gain(l, ScaleClass::Damping, z);
        p.set_class_gain(ScaleClass::Stiffness, k);
        p.set_class_gain(ScaleClass::Damping, z);
        p.reset();
        lanes.reset_lane(l);
    }
    let (n_in, n_out) = (template.info().num_inputs(), template.info().num_outputs());
    let frames = 16;
    let mut lane_in = vec![0.0; n_in * frames * LANES];
    let mut lane_out = vec![0.0; n_out * frames * LANES];
    let mut one_in = vec![0.0; n_in * frames];
    let mut one_out = vec![0.0; n_out * frames];
    for block in 0..60 {
        lane_in.fill(0.0);
        if block % 20 == 0 {
            for v in lane_in.iter_mut().step_by(frames * LANES / 2 + 1) {
                *v = -0.02 * rng.unit();
            }
        }
        if block == 30 {
            if let Some(id) = template.param_id("at") {
                lanes.set_param(id, 0.71).unwrap();
                plain
                    .iter_mut()
                    .for_each(|p| p.set_param(id, 0.71).unwrap());
            }
        }
        lanes.process(frames, &lane_in, &mut lane_out);
        for (l, p) in plain.iter_mut().enumerate() {
            for c in 0..n_in {
                for n in 0..frames {
                    one_in[c * frames + n] = lane_in[(c * frames + n) * LANES + l];
                }
            }
            p.process(frames, &one_in, &mut one_out);
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
                        "lane {l}, output {c}, sample {}: plain {a} vs lane {b}\n{text}",
                        block * frames + n
                    );
                }
            }
        }
    }
    Some(loudest)
}

/// How many random models the property test plays (`PROPTEST_CASES` overrides it).
const CASES: u32 = 500;

proptest! {
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(CASES),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_models_play_alike_on_every_path(seed in any::<u64>()) {
        let text = random_script(seed);
        native_equals_interpreter(&text, seed);
        let _ = lanes_equal_plain(&text, seed);
    }
}

/// The generator reaches every path and every law: over a fixed set of seeds, most scripts
/// compile, many run native code, some run in lanes, and every keyword of the table appears.
#[test]
fn the_random_scripts_cover_every_path_and_law() {
    let (mut compiled, mut native, mut lanes, mut moved) = (0, 0, 0, 0);
    let mut keywords = std::collections::BTreeSet::new();
    let cases = 300;
    for seed in 0..cases {
        let text = random_script(seed);
        if seed == 7 {
            println!("seed 7:\n{text}");
        }
        for kind in LawKind::ALL {
            if text.contains(&format!(" {} ", kind.row().keyword)) {
                keywords.insert(kind.row().keyword);
            }
        }
        compiled += build(&text).is_some() as usize;
        native += native_equals_interpreter(&text, seed) as usize;
        if let Some(loudest) = lanes_equal_plain(&text, seed) {
            lanes += 1;
            moved += (loudest > 1e-9) as usize;
        }
    }
    println!(
        "{cases} random scripts: {compiled} compiled, {native} ran native code, {lanes} ran in \
         lanes ({moved} of them moved an output); laws written: {}",
        keywords.len()
    );
    assert!(compiled > cases as usize * 3 / 4, "{compiled} compiled");
    assert!(native > cases as usize / 4, "{native} ran native code");
    assert!(lanes > cases as usize / 20, "{lanes} ran in lanes");
    assert!(moved > lanes / 2, "{moved} of {lanes} moved an output");
    assert_eq!(keywords.len(), LawKind::COUNT, "laws written: {keywords:?}");
}
