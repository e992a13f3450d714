//! Analyses that always end: values a script may legally hold (10³⁰⁸, 10⁻³⁰⁸, 0, negative,
//! huge ratios) reach the modal analysis and the exact stability limit, which refuse what an
//! eigensolver cannot take and say why, and never panic or spin. The model still plays, on the
//! Gershgorin clamp.

mod common;

use ressort_engine::instrument;
use ressort_engine::ParamId;
use std::time::Instant;

fn preset(name: &str) -> String {
    std::fs::read_to_string(format!("{}/../models/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// Fretted String with the osc's damping at 10³⁰⁸ (the first script), and a link's damping
/// at 0 besides (the second): a random session in a VST3 host once froze inside the state load
/// of the second, and the first made the modal analysis panic inside faer.
fn fretted_variants() -> [String; 2] {
    let text = preset("fretted-string.mdl");
    let huge = text.replace(
        "@low_m60 osc low_M 0 low_Zosc 0. 0.",
        "@low_m60 osc low_M 0 1e308 0. 0.",
    );
    assert_ne!(huge, text, "the preset still has the line this test edits");
    let both = huge.replace(
        "@low_r37 springDamper @low_m35 @low_m36 low_K low_Z",
        "@low_r37 springDamper @low_m35 @low_m36 low_K 0",
    );
    assert_ne!(both, huge);
    [huge, both]
}

#[test]
fn an_extreme_damping_skips_the_exact_analyses_and_the_model_still_plays() {
    for text in fretted_variants() {
        let spec = common::spec(&text);
        let mut engine = common::engine(&spec, 48_000.0);
        let analysis = engine.modes(Some(10));
        let why = analysis
            .skipped
            .as_deref()
            .expect("the analysis says it skipped");
        assert!(why.contains("beyond"), "{why}");
        assert!(!engine.exact_stability().applies());

        let mut p = instrument::prepare("fretted", &text, 48_000.0).expect("the model plays");
        assert!(p.facts().envelope.max_stiffness(1.0).is_finite());
        let k = p.facts().note_input.unwrap_or(0);
        let inputs = p.engine.info().num_inputs();
        let outputs = p.engine.info().num_outputs();
        let mut input = vec![0.0; inputs * 4800];
        input[k * 4800] = 0.01;
        let mut out = vec![0.0; outputs * 4800];
        p.engine.process(4800, &input, &mut out);
        assert!(out.iter().all(|v| v.is_finite()));
    }
}

/// Every declared parameter of every preset up to 200 points, set in turn to each extreme
/// value, through the modal analysis and the exact limit: no panic, and every analysis ends
/// (a hang fails the run). Prints the case count, the analyses refused and the longest.
#[test]
fn extreme_values_in_every_parameter_never_panic_or_hang() {
    const VALUES: [f64; 5] = [1e308, -1e308, 1e-308, 0.0, 1e30];
    let dir = format!("{}/../models", env!("CARGO_MANIFEST_DIR"));
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".mdl"))
        .collect();
    names.sort();
    let (mut cases, mut skipped, mut failed) = (0, 0, 0);
    let mut longest = (0.0f64, String::new());
    for name in &names {
        let spec = common::spec(&preset(name));
        let template = common::engine(&spec, 48_000.0);
        if template.positions().len() > 200 {
            continue;
        }
        for (id, param) in template.info().params.iter().enumerate() {
            for value in VALUES {
                let mut engine = template.clone();
                if engine.set_param(ParamId(id as u32), value).is_err() {
                    continue;
                }
                let start = Instant::now();
                let analysis = engine.modes(Some(8));
                let exact = engine.exact_stability();
                let limit = exact.max_stiffness(1.0);
                let gershgorin = engine.gershgorin_stiffness_limit(1.0);
                let seconds = start.elapsed().as_secs_f64();
                assert!(
                    limit.is_none_or(|g| !g.is_nan()) && !gershgorin.is_nan(),
                    "{name} {}={value:e}: limit {limit:?}, Gershgorin {gershgorin}",
                    param.name
                );
                cases += 1;
                skipped += usize::from(analysis.skipped.is_some());
                failed += usize::from(
                    analysis
                        .skipped
                        .as_deref()
                        .is_some_and(|why| why.contains("failed")),
                );
                if seconds > longest.0 {
                    longest = (seconds, format!("{name} {}={value:e}", param.name));
                }
            }
        }
    }
    println!(
        "{cases} cases, {skipped} analyses skipped with a reason ({failed} of them a solver \
         that failed), longest {:.3} s ({})",
        longest.0, longest.1
    );
    assert!(cases > 200, "only {cases} cases");
}

/// A damped 8 × 8 membrane driving an air mass through a cavity spring, read by dampers to two
/// grounds (an early kick-drum design): with the head's damping at 0.004 its companion matrix
/// sent faer's multishift QR into a sort that never ended, so `ressort modes` and every load
/// of the script spun for ever. The analysis now takes the unblocked QR, and ends.
#[test]
fn a_companion_matrix_that_spun_faers_multishift_qr_is_analysed() {
    let text = "@Head param 0.004\n\
                @m closedMesh 8 8 1. 0.001063 Head 0.00001 0. 0.\n\
                @air mass 4. 0. 0.\n@ga ground 0.\n\
                @helm springDamper @ga @air 0.00025 0.00005\n\
                @cav spring @air [@m 0.5 0.5] 0.0002\n\
                @gh ground 0.1\n@h mass 2. 0.1 0.\n\
                @sh springDamper @gh @h 0.0001 0.05\n\
                @hit nlContact [@m 0.5 0.5] @h 0.0002 20 0.05 0.002\n\
                @in1 frcInput @h\n@in2 frcInput [@m 0.5 0.5]\n\
                @mic1 ground 0.\n@mic2 ground 0.\n\
                @r1 damper @mic1 @air 0.0006\n@r2 damper @mic1 [@m 0.5 0.5] 0.0005\n\
                @r3 damper @mic2 @air 0.0006\n@r4 damper @mic2 [@m 0.3 0.6] 0.0005\n\
                @out1 frcOutput @mic1\n@out2 frcOutput @mic2\n";
    let (tx, rx) = std::sync::mpsc::channel();
    let script = text.to_string();
    std::thread::spawn(move || {
        let spec = common::spec(&script);
        let mut engine = common::engine(&spec, 44_100.0);
        let _ = tx.send(engine.modes(None));
    });
    let analysis = rx
        .recv_timeout(std::time::Duration::from_secs(120))
        .expect("the modal analysis ends");
    assert!(analysis.skipped.is_none(), "{:?}", analysis.skipped);
    assert!(analysis.modes.len() > 30, "{} modes", analysis.modes.len());
    assert!(analysis
        .modes
        .iter()
        .all(|m| m.frequency_hz.is_finite() && m.frequency_hz > 0.0));
}
