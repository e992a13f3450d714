//! Model preparation in the plugin: every built-in preset compiles at the common rates, the
//! stability clamp holds exploding gains back, macro slots bind and map, and a bad script
//! never replaces the running model.

use ressort_engine::instrument::{prepare, CHUNK, STABILITY_HEADROOM};
use ressort_engine::ScaleClass;
use ressort_plugin::model::{ModelState, ModelStore};
use ressort_plugin::presets::{Preset, PRESETS};

#[test]
fn every_preset_prepares_at_every_common_rate() {
    for preset in PRESETS {
        for sr in [44_100.0, 48_000.0, 96_000.0] {
            let p = prepare(preset.id, preset.text, sr)
                .unwrap_or_else(|e| panic!("{} at {sr}: {e}", preset.id));
            assert_eq!(p.inputs.len(), p.facts().roles.len() * CHUNK);
            assert!(p.outputs.len() >= CHUNK);
            assert!(
                !p.facts().envelope.lines.is_empty(),
                "{}: no stability lines",
                preset.id
            );
            // The clamp accepts every preset as written.
            let (gk, gz, clamped) = p.facts().envelope.clamp(1.0, 1.0, 1.0);
            assert!(
                !clamped && gk == 1.0 && gz == 1.0,
                "{} clamped at unit gains",
                preset.id
            );
            for key in ["What:", "How to play:", "Source:"] {
                assert!(
                    !preset.header_field(key).is_empty(),
                    "{} lacks {key}",
                    preset.id
                );
            }
        }
    }
}

/// The clamp's limit: the exact stability limit of the linear network (issue 14) with the
/// headroom, where it applies — never below the coupled (Gershgorin) bound it replaces (on
/// networks of positive springs), and
/// stable there by the exact criterion; elsewhere the Gershgorin bound, where the worst mass
/// reaches the headroom.
#[test]
fn the_stiffness_limit_matches_the_stability_analysis() {
    for preset in PRESETS {
        let mut p = prepare(preset.id, preset.text, 48_000.0).unwrap();
        let limit = p.facts().envelope.max_stiffness(1.0);
        assert!(limit.is_finite() && limit > 0.0, "{}: {limit}", preset.id);
        // The limits hold for a key held down: a bow's friction at its pressed value.
        let exciters = p.facts().exciters.clone();
        ressort_engine::instrument::prepare::press_audio_params(&mut p.engine, &exciters);
        let gershgorin = ressort_engine::analysis::envelope::envelope(&mut p.engine);
        let bound = gershgorin.max_stiffness(1.0);
        let exact = p.engine.exact_stability();
        match exact.max_stiffness(1.0) {
            Some(e) if exact.is_stable(1.0, 1.0) == Some(true) => {
                assert!(
                    limit <= STABILITY_HEADROOM * e * (1.0 + 1e-9),
                    "{}: clamp ×{limit} beyond the headroom of the exact limit ×{e}",
                    preset.id
                );
                // The per-mass rule sums signed stiffnesses, so with negative springs (Felt
                // Piano's or Steel Pan's bending) its figure is no bound from below.
                if !exact.has_negative_links() {
                    assert!(
                        limit >= bound * (1.0 - 1e-9),
                        "{}: ×{limit} < bound ×{bound}",
                        preset.id
                    );
                }
                assert_eq!(exact.is_stable(limit, 1.0), Some(true), "{}", preset.id);
                println!(
                    "{:<22} stiffness limit ×{limit:9.3} (exact ×{e:9.3}, Gershgorin ×{bound:9.3})",
                    preset.id
                );
            }
            _ => {
                p.engine.set_class_gain(ScaleClass::Stiffness, limit);
                let at = p.engine.stability();
                let worst = at
                    .masses
                    .iter()
                    .map(|m| m.coupled_load())
                    .fold(0.0, f64::max);
                assert!(
                    (worst - STABILITY_HEADROOM).abs() < 1e-9
                        || (limit <= 1.0 + 1e-9 && worst <= p.facts().worst_load.0 + 1e-9),
                    "{} at ×{limit}: worst coupled load {worst}",
                    preset.id
                );
                assert!(at.is_stable(), "{} at its limit ×{limit}", preset.id);
                println!(
                    "{:<22} stiffness limit ×{limit:9.3} (Gershgorin)",
                    preset.id
                );
            }
        }
    }
}

/// Asking for ×16 stiffness and ×16 damping on every preset gives clamped gains under which
/// the model runs for a second, struck, without the guard tripping and with finite outputs.
#[test]
fn clamped_gains_keep_every_preset_running() {
    for preset in PRESETS {
        let mut p = prepare(preset.id, preset.text, 48_000.0).unwrap();
        let (gk, gz, clamped) = p.facts().envelope.clamp(16.0, 16.0, 1.0);
        println!(
            "{:<20} ×16/×16 requested → stiffness ×{gk:.3}, damping ×{gz:.3} (clamped {clamped})",
            preset.id
        );
        p.engine.set_class_gain(ScaleClass::Stiffness, gk);
        p.engine.set_class_gain(ScaleClass::Damping, gz);
        let n_in = p.facts().roles.len();
        let n_out = p.outputs.len() / CHUNK;
        let mut peak: f64 = 0.0;
        for block in 0..(48_000 / CHUNK) {
            p.inputs.fill(0.0);
            if block == 0 {
                if let Some(k) = p.facts().note_input {
                    p.inputs[k * CHUNK] = -0.05;
                }
            }
            let report = p.engine.process(
                CHUNK,
                &p.inputs[..n_in * CHUNK],
                &mut p.outputs[..n_out * CHUNK],
            );
            assert!(!report.tripped, "{} exploded at ×{gk}", preset.id);
            // Every sample, before the peak: `f64::max` drops a NaN, so a peak never sees one.
            let outs = &p.outputs[..n_out * CHUNK];
            if let Some(i) = outs.iter().position(|x| !x.is_finite()) {
                panic!(
                    "{} at ×{gk}/×{gz}: output {} is {} in block {block}",
                    preset.id,
                    i / CHUNK + 1,
                    outs[i]
                );
            }
            peak = outs.iter().fold(peak, |a, x| a.max(x.abs()));
        }
        println!("{:<20} output peak {peak:.3e}", "");
    }
}

#[test]
fn macro_slots_bind_params_in_declaration_order() {
    let text = "@K param 0.1\n@Z param 0.001\n@m mass 1 0 0\n@g ground 0\n\
                @s springDamper @m @g K Z\n@in1 frcInput @m\n@out1 posOutput @m\n";
    let p = prepare("test", text, 48_000.0).unwrap();
    let k = p.facts().macros[0].as_ref().expect("slot 1 bound");
    let z = p.facts().macros[1].as_ref().expect("slot 2 bound");
    assert!(p.facts().macros[2..].iter().all(Option::is_none));
    assert_eq!((k.name.as_str(), z.name.as_str()), ("K", "Z"));
    // The declared value sits in the middle; the ends are the range.
    assert!((k.value_at(0.5) - 0.1).abs() < 1e-12);
    assert!((k.value_at(0.0) - k.min).abs() < 1e-12);
    assert!((k.value_at(1.0) - k.max).abs() < 1e-12);
    assert!(k.min < 0.1 && k.max > 0.1);
    // ×4 of K = 0.4 at M = 1 is stable (0.4 + 0.002 < 4), so the full default range stays.
    assert!((k.max - 0.4).abs() < 1e-9, "{}", k.max);
    println!("K range {}..{}, Z range {}..{}", k.min, k.max, z.min, z.max);
}

#[test]
fn macro_ranges_stop_where_the_model_would_explode() {
    // K = 3 on M = 1: ×4 would be 12 > 4M, so the range stops below 4 (at the headroom).
    let text = "@K param 3\n@m mass 1 0 0\n@g ground 0\n@s spring @m @g K\n\
                @in1 frcInput @m\n@out1 posOutput @m\n";
    let p = prepare("test", text, 44_100.0).unwrap();
    let k = p.facts().macros[0].as_ref().unwrap();
    assert!(k.max < 4.0 && k.max > 3.0, "max {}", k.max);
    println!("K = 3 on M = 1: macro range {}..{}", k.min, k.max);
}

#[test]
fn a_bad_script_keeps_the_running_model_and_reports_where() {
    let store = std::sync::Arc::new(ModelStore::default());
    let before = store.running();
    let err = store
        .submit(ModelState::new(
            "broken",
            "@m mass 1 0 0\n@s spring @m @nowhere 0.1\n",
        ))
        .unwrap_err();
    assert_eq!(store.running(), before);
    let status = store.status();
    assert_eq!(status.diagnostics, err.0);
    assert!(err.0[0].starts_with("2:"), "{:?}", err.0);
    assert_eq!(status.rejected.unwrap().name, "broken");

    let good = Preset::find("string-1000").unwrap();
    store.submit(ModelState::new(good.id, good.text)).unwrap();
    assert_eq!(store.running().name, "string-1000");
    assert!(store.status().diagnostics.is_empty());
}

/// The reference pitch found by rendering an impulse response equals the closed form of the
/// oscillator it is made of: sin²(πf/SR) = K'/4M with K' = K·(44100/SR)² (spec §1.7, §5.3).
#[test]
fn the_estimated_reference_pitch_of_an_oscillator_matches_the_closed_form() {
    let text = "@o osc 1 0.01 0.00001 0 0\n@in1 frcInput @o\n@out1 posOutput @o\n";
    for sr in [44_100.0, 48_000.0, 96_000.0] {
        let p = prepare("osc", text, sr).unwrap();
        let k = 0.01 * (44_100.0 / sr) * (44_100.0f64 / sr);
        let exact = (k / 4.0).sqrt().asin() * sr / std::f64::consts::PI;
        let got = p.facts().settings.reference_pitch_hz.expect("a pitch");
        let cents = 1200.0 * (got / exact).log2();
        println!(
            "osc K=0.01 at {sr} Hz: estimated {got:.3} Hz, exact {exact:.3} Hz ({cents:+.2} cents)"
        );
        assert!(cents.abs() < 1.0, "{cents} cents");
    }
}

#[test]
fn the_plugin_ships_every_script_in_models() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            e.file_name()
                .to_str()?
                .strip_suffix(".mdl")
                .map(str::to_string)
        })
        .collect();
    files.sort();
    let mut ids: Vec<String> = PRESETS.iter().map(|p| p.id.to_string()).collect();
    ids.sort();
    assert_eq!(files, ids);
}

/// Host directives reach the plugin: routing, note input and force, pitch, key and macro
/// ranges; a `~note` on an input that is not a force input is an error at its line.
#[test]
fn host_directives_configure_the_plugin() {
    let text = "@K param 0.1\n@o osc 1 K 0.001 0 0\n@in1 frcInput @o\n@in2 frcInput @o\n\
                @in3 posInput 0.5\n@c contact @in3 @o 0.01 0 0\n@out1 posOutput @o\n\
                ~pitch 440\n~key 69\n~note in2 -0.1\n~route in1 sidechain_right\n~macro K 0.05 0.2\n";
    let p = prepare("t", text, 48_000.0).unwrap();
    assert_eq!(p.facts().note_input, Some(1));
    assert_eq!(p.facts().settings.note_force, -0.1);
    assert_eq!(p.facts().settings.reference_pitch_hz, Some(440.0));
    assert_eq!(p.facts().settings.reference_key, 69.0);
    assert_eq!(
        p.facts().routing,
        vec![
            Some(ressort_engine::RouteSource::SidechainRight),
            None,
            None
        ]
    );
    assert_eq!(p.facts().rest, vec![0.0, 0.0, 0.5]);
    let k = p.facts().macros[0].as_ref().unwrap();
    assert_eq!((k.min, k.max), (0.05, 0.2));

    let bad = text.replace("~note in2 -0.1", "~note in3");
    let err = prepare("t", &bad, 48_000.0).unwrap_err();
    assert!(
        err.0[0].starts_with("10:1: error: `~note in3`"),
        "{:?}",
        err.0
    );
}

/// Every preset, played in the instrument layout as its header says, moves its first output
/// clearly: a full-velocity MIDI note held down (its strike and its exciters: bows, plucks,
/// presses), or, for a preset a key does not play, a steady sidechain ramp down at 3e-5 units
/// per sample (the bow speed the headers give) on `@in1` and `@in2`. The inputs the
/// instrument layout does not feed (`@in3` on) stay silent, so an audio-rate parameter there
/// holds its default.
#[test]
fn every_preset_moves_its_first_output_when_played() {
    use ressort_engine::instrument::{Controls, Event, Instrument, Timed, MAX_HOST_INPUTS};
    const SR: f64 = 48_000.0;
    const FRAMES: usize = 48_000;
    const BLOCK: usize = 256;
    let mut silent = Vec::new();
    for preset in PRESETS {
        let p = prepare(preset.id, preset.text, SR).unwrap();
        let played = p.facts().note_input.is_some() || !p.facts().exciters.is_empty();
        // The output stage's own gain, so that the peak reads in the model's units.
        let trim = p.facts().output_trim;
        let controls = Controls {
            dc_filter: false,
            output_db: -60.0,
            ..Controls::DEFAULT
        };
        let mut inst = Instrument::new(SR, controls);
        inst.set_model(Box::new(p));
        let (mut l, mut r) = ([0.0f32; BLOCK], [0.0f32; BLOCK]);
        let mut ramp = vec![0.0f32; BLOCK];
        let mut peak = 0.0f64;
        for block in 0..FRAMES / BLOCK {
            let note = (block == 0 && played).then(|| Timed::new(0, Event::note_on(60, 1.0)));
            let mut host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
            if !played {
                for (i, s) in ramp.iter_mut().enumerate() {
                    *s = (-3e-5 * (block * BLOCK + i) as f64) as f32;
                }
                host[2] = Some(&ramp);
                host[3] = Some(&ramp);
            }
            let mut out: [&mut [f32]; 2] = [&mut l, &mut r];
            let report = inst.process(
                BLOCK,
                &host,
                false,
                &mut note.into_iter(),
                &controls,
                &mut out,
            );
            assert_eq!(report.trips, 0, "{} exploded", preset.id);
            peak = l.iter().fold(peak, |m, v| m.max(v.abs() as f64));
        }
        // In the model's units: the output gain and the trim taken back off.
        let peak = peak / (1e-3 * trim);
        // A hundredth of the level every preset is trimmed to would be a faint sound; these
        // move by far more.
        let bar = 1e-6;
        println!(
            "{:<24} out1 peak excursion {peak:.3e} (played by a key: {played})",
            preset.id
        );
        if !(peak > bar) {
            silent.push(format!(
                "{}: out1 peak excursion {peak:e} is not above {bar:e}",
                preset.id
            ));
        }
    }
    assert!(silent.is_empty(), "{}", silent.join("\n"));
}

/// Chladni's listening point is two knobs: the `audioParam`s `lX` and `lY` take Macro slots in
/// declaration order (after the six `param`s above them), range 0 … 1 as coordinates, and
/// moving the `lX` slot moves where out1 listens, while `in3` stays unfed.
#[test]
fn chladni_listening_point_is_a_macro_knob() {
    const FRAMES: usize = 6000;
    let preset = Preset::find("chladni-150x150").unwrap();
    let render = |lx_slot: Option<f64>| {
        let mut p = prepare(preset.id, preset.text, 48_000.0).unwrap();
        let names: Vec<&str> = p
            .facts()
            .macros
            .iter()
            .map(|b| b.as_ref().map_or("", |b| b.name.as_str()))
            .collect();
        assert_eq!(
            names[..11],
            [
                "meshK",
                "meshZ",
                "meshZo",
                "eX",
                "eY",
                "contactStiffness",
                "lX",
                "lY",
                "cX",
                "cY",
                "pM"
            ]
        );
        let lx = p.facts().macros[6].clone().unwrap();
        let ly = p.facts().macros[7].as_ref().unwrap();
        assert_eq!((lx.min, lx.default, lx.max), (0.0, 0.3, 1.0));
        assert_eq!((ly.min, ly.default, ly.max), (0.0, 0.6, 1.0));
        if let Some(n) = lx_slot {
            p.engine.set_param(lx.param, lx.value_at(n)).unwrap();
        }
        let n_in = p.facts().roles.len();
        let n_out = p.outputs.len() / CHUNK;
        let k = p.facts().note_input.expect("a note input");
        let strike = p.facts().settings.note_force * p.facts().strike_scale;
        let mut out1 = Vec::with_capacity(FRAMES);
        for block in 0..FRAMES / CHUNK {
            p.inputs.fill(0.0);
            if block == 0 {
                p.inputs[k * CHUNK] = strike;
            }
            let report = p.engine.process(
                CHUNK,
                &p.inputs[..n_in * CHUNK],
                &mut p.outputs[..n_out * CHUNK],
            );
            assert!(!report.tripped);
            out1.extend_from_slice(&p.outputs[..CHUNK]);
        }
        out1
    };
    let centre = render(None);
    let peak = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(
        peak(&centre) > 0.0,
        "the strike does not reach the listening point"
    );
    // The slot's centre is the declared default: nothing changes.
    assert_eq!(render(Some(0.5)), centre);
    let moved = render(Some(0.9));
    let diff: Vec<f64> = moved.iter().zip(&centre).map(|(a, b)| a - b).collect();
    println!(
        "out1 peak {:.3e} at lX = 0.3, {:.3e} at the slot's 0.9; difference {:.3e}",
        peak(&centre),
        peak(&moved),
        peak(&diff)
    );
    assert!(peak(&diff) > 0.1 * peak(&centre));
}

#[test]
fn ab_compare_switches_between_two_scripts() {
    let store = std::sync::Arc::new(ModelStore::default());
    let a = ModelState::new("a", "@o osc 1. 0.1 0.001 0. 0.\n@out1 posOutput @o\n");
    let b = ModelState::new("b", "@o osc 1. 0.2 0.001 0. 0.\n@out1 posOutput @o\n");
    store
        .activate(48_000.0, true)
        .expect("the default preset runs");
    store.submit(a.clone()).unwrap();
    assert_eq!(store.compare().active, 0);
    // B starts as a copy of A.
    store.switch_compare().unwrap();
    assert_eq!(store.compare().active, 1);
    assert_eq!(store.running(), a);
    // An edit goes into B; A keeps its script.
    store.submit(b.clone()).unwrap();
    let c = store.compare();
    assert_eq!(c.slots, [Some(a.clone()), Some(b.clone())]);
    store.switch_compare().unwrap();
    assert_eq!(store.running(), a);
    store.switch_compare().unwrap();
    assert_eq!(store.running(), b);
    // A script with errors changes neither the running model nor the slots.
    let broken = ModelState::new("broken", "@o osc 1. 0.1\n");
    assert!(store.submit(broken).is_err());
    assert_eq!(store.compare().slots, [Some(a.clone()), Some(b.clone())]);
    // Copying the running script over the other slot.
    store.copy_to_other_slot();
    assert_eq!(store.compare().slots, [Some(b.clone()), Some(b)]);
    store.deactivate();
}

/// The summary's stability lines are written at the first look after a load, from the model
/// that runs: the mass closest to its limit and its load, as the engine's report has them,
/// for each of two models loaded one after the other without a look in between.
#[test]
fn the_stability_lines_follow_the_running_model() {
    let store = std::sync::Arc::new(ModelStore::default());
    store
        .activate(48_000.0, true)
        .expect("the default preset runs");
    for (name, mass) in [("mesh-15x15", "@mesh["), ("string-1000", "@s[")] {
        let preset = Preset::find(name).unwrap();
        store
            .submit(ModelState::new(preset.id, preset.text))
            .unwrap();
        if name == "mesh-15x15" {
            continue; // not looked at: the string's lines must not be the mesh's
        }
        let lines = store.status().summary.stability;
        let p = prepare(preset.id, preset.text, 48_000.0).unwrap();
        let mut engine = p.engine.clone();
        let worst = engine.stability_numbers().worst().expect("a mass").load();
        let expected = format!("({:.1} % of 4M used)", 100.0 * worst);
        assert!(
            lines[0].starts_with(&format!("closest to the limit: {mass}"))
                && lines[0].ends_with(&expected),
            "{name}: {lines:?}, expected {expected}"
        );
        // Asked again, the same lines.
        assert_eq!(store.status().summary.stability, lines);
    }
    store.deactivate();
}
