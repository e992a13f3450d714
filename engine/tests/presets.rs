//! The preset library in `models/`: every file documents itself, parses without errors, passes
//! the stability check, has the counts spec §7 gives, and renders finite, non-silent audio when
//! played the way its header says.

mod common;

use common::{engine, render};
use ressort_engine::lang::{folder_files, parse_with_files};
use ressort_engine::spec::REFERENCE_SAMPLE_RATE_HZ;
use ressort_engine::{
    reference, ElementKind, Endpoint, ExciterKind, InputUse, LawKind, ModelSpec, OutputUse,
    ParamKind,
};
use std::path::PathBuf;

fn presets() -> Vec<(String, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../models");
    let mut files: Vec<(String, String)> = std::fs::read_dir(&dir)
        .expect("models/ exists")
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "mdl"))
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&p).unwrap())
        })
        .collect();
    files.sort();
    assert!(!files.is_empty());
    files
}

fn preset(name: &str) -> ModelSpec {
    let files = presets();
    let (_, text) = files
        .iter()
        .find(|f| f.0 == name)
        .unwrap_or_else(|| panic!("models/{name} is missing"));
    // A preset in space may import a mesh of models/ (Mesh Bell's bell-coarse.obj).
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../models");
    let parsed = parse_with_files(text, &folder_files(&dir));
    let errors: Vec<String> = parsed.errors().map(|d| d.to_string()).collect();
    parsed
        .spec
        .unwrap_or_else(|| panic!("{name} does not parse: {errors:?}"))
}

/// Points / interactions of every preset, as spec §7 states them (§7.0 conventions: avatars and
/// macro nodes count, connection points and force inputs do not). `None` for the tutorial
/// models whose section gives no count. Every file in `models/` must be listed here, so a
/// preset cannot be added or lost without this table noticing.
const COUNTS: &[(&str, Option<(usize, usize)>)] = &[
    // §7.10, canonical definitions.
    ("string-1000.mdl", Some((1004, 1003))),
    ("mesh-15x15.mdl", Some((227, 422))),
    ("mesh-25x20.mdl", Some((502, 957))),
    // §7.2 basics.
    ("oscillator-bank.mdl", Some((8, 0))),
    ("bowed-string.mdl", Some((156, 158))),
    ("plucked-harmonics.mdl", Some((156, 158))),
    // §7.3 intermediate.
    ("fretted-string.mdl", Some((169, 203))),
    ("drunk-triangles-xl.mdl", Some((68, 149))),
    ("drunk-triangles.mdl", Some((5, 5))),
    // §7.4 advanced.
    ("brokendown-string.mdl", Some((401, 401))),
    ("chladni-150x150.mdl", Some((22_503, 44_703))),
    ("coupled-strings-bowed.mdl", Some((285, 572))),
    ("nofx-drone.mdl", Some((463, 463))),
    ("resonant-strings.mdl", Some((804, 968))),
    ("rolling-mesh.mdl", Some((101, 181))),
    ("two-fingers-string.mdl", Some((127, 258))),
    // Ressort's own: the counts its header gives.
    ("struck-string.mdl", Some((20, 19))),
    ("felt-piano.mdl", Some((32, 61))),
    // §7.6 Oscillator tutorial series: no counts given.
    ("harmonic-oscillator.mdl", None),
    ("hammer-oscillator.mdl", None),
    ("gravity-oscillator.mdl", None),
    ("plucked-oscillator.mdl", None),
    ("bowed-oscillator.mdl", None),
    ("nonlinear-oscillator.mdl", None),
    // The sound library (issue 37): Ressort's own designs; their headers give no counts.
    ("hammered-dulcimer.mdl", None),
    ("harp.mdl", None),
    ("koto.mdl", None),
    ("cello.mdl", None),
    ("erhu.mdl", None),
    ("glockenspiel.mdl", None),
    ("marimba.mdl", None),
    ("xylophone.mdl", None),
    ("bowed-plate.mdl", None),
    ("crotales.mdl", None),
    ("gong.mdl", None),
    ("frame-drum.mdl", None),
    ("snare.mdl", None),
    ("steel-pan.mdl", None),
    ("timpani.mdl", None),
    ("tom.mdl", None),
    ("bowed-pad.mdl", None),
    ("glass-harmonica.mdl", None),
    ("organ-pipes.mdl", None),
    ("singing-bowl.mdl", None),
    ("kick-resonator.mdl", None),
    ("metal-sheet.mdl", None),
    ("sympathetic-strings.mdl", None),
    ("wood-box.mdl", None),
    ("bright-grand.mdl", None),
    ("electric-tine.mdl", None),
    ("harpsichord.mdl", None),
    ("bouncing-ball.mdl", None),
    ("duffing.mdl", None),
    ("friction-squeal.mdl", None),
    ("rattle.mdl", None),
    ("bolted-piano-string.mdl", None),
    ("tangent-clavinet.mdl", None),
    ("jawari-sitar.mdl", None),
    ("open-back-banjo.mdl", None),
    ("kalimba-tine.mdl", None),
    ("slit-drum.mdl", None),
    ("chime-tube.mdl", None),
    ("musical-saw.mdl", None),
    ("talking-drum.mdl", None),
    ("aeolian-harp.mdl", None),
    ("celesta.mdl", None),
    // Models in space (issue 39): (points, interactions) as `ressort check` counts them.
    ("glide-string.mdl", Some((16, 30))),
    ("plucked-string-3d.mdl", Some((35, 67))),
    ("bowed-string-3d.mdl", Some((35, 67))),
    ("mesh-bell.mdl", Some((61, 324))),
    ("ball-on-drum.mdl", Some((170, 625))),
    ("rope-and-plate.mdl", Some((88, 375))),
    ("pendulum-chain.mdl", Some((7, 12))),
    ("newtons-cradle.mdl", Some((20, 24))),
];

#[test]
fn every_preset_starts_with_a_description() {
    for (name, text) in presets() {
        let header: Vec<&str> = text.lines().take_while(|l| l.starts_with('#')).collect();
        let joined = header.join("\n");
        for word in ["What:", "How to play:", "Source:"] {
            assert!(joined.contains(word), "{name}: header lacks `{word}`");
        }
    }
}

#[test]
fn every_preset_has_the_counts_of_the_specification() {
    let files = presets();
    for (name, _) in &files {
        assert!(
            COUNTS.iter().any(|(n, _)| n == name),
            "models/{name} is not in the COUNTS table"
        );
    }
    for (name, counts) in COUNTS {
        let spec = preset(name);
        let Some(expected) = counts else { continue };
        let e = engine(&spec, 44_100.0);
        let found = (e.info().num_points, e.info().num_interactions);
        assert_eq!(found, *expected, "{name}: points / interactions");
    }
}

/// A parameter's declared value; audio-rate parameters read as their default, their value
/// with a silent input (the test leaves their inputs unfed, as the plugin and `ressort render`
/// do).
fn lookup(spec: &ModelSpec) -> impl Fn(&str) -> Option<f64> + '_ {
    move |name| {
        spec.param(name).map(|p| match p.kind {
            ParamKind::Control { value } => value,
            ParamKind::Audio { default, .. } => default,
        })
    }
}

/// Strong enough for every hanging hammer: a suspension of damping Z stops a kick of I after
/// |I|/Z units, and the hammer oscillators hang 1 unit above with Z = 0.05.
const FORCE_IMPULSE: f64 = -0.1;

/// What an avatar does, read from the interactions it drives.
enum Role {
    /// It bows through `nlBow` with this Vscale (script value).
    Bow { vscale: f64 },
    /// It plucks through `nlPluck` with this Pscale.
    Pluck { pscale: f64 },
    /// A damper, jaw, finger or contact: it stays where it was declared.
    Hold,
}

fn role(spec: &ModelSpec, avatar: &str) -> Role {
    let value = lookup(spec);
    let me = Endpoint::label(avatar);
    for e in &spec.elements {
        if let ElementKind::Interaction { law, a, b } = &e.kind {
            if *a != me && *b != me {
                continue;
            }
            match law.kind() {
                LawKind::Bow => {
                    return Role::Bow {
                        vscale: law.arg("Vscale").unwrap().eval(&value),
                    }
                }
                LawKind::Pluck => {
                    return Role::Pluck {
                        pscale: law.arg("Pscale").unwrap().eval(&value),
                    }
                }
                _ => {}
            }
        }
    }
    Role::Hold
}

/// The input signals that play a preset, following the headers' "How to play": a downward
/// force impulse on force inputs; bows moved from their start at half their Vscale (inside the
/// slip band Vscale/3…Vscale, where the bow self-oscillates); plectra swept smoothly through
/// the string (from p to −p, or 4·Pscale down when they start on it); every other avatar held
/// at its declared position (an input at 0 would make it jump there in one sample); the inputs
/// of audio-rate parameters unfed (silent), as in the plugin's instrument layout, which feeds
/// only `@in1` and `@in2`, and in `ressort render` without `--input`, but for those a key
/// presses (`~exciter inK press`), held at the press's depth.
fn excitation(spec: &ModelSpec, inputs: &[Vec<InputUse>], sr: f64, frames: usize) -> Vec<Vec<f64>> {
    let value = lookup(spec);
    let z_scale = REFERENCE_SAMPLE_RATE_HZ / sr;
    inputs
        .iter()
        .map(|uses| match uses.first() {
            Some(InputUse::Force(_)) => {
                let mut v = vec![0.0; frames];
                v[0] = FORCE_IMPULSE;
                v
            }
            Some(InputUse::Position(label)) => {
                let start = match &spec.element(label).expect("avatar").kind {
                    ElementKind::PosInput { pos, .. } => pos.z().eval(&value),
                    other => panic!("@{label} is a {}", other.keyword()),
                };
                match role(spec, label) {
                    Role::Bow { vscale } => {
                        // Speed rising over 50 ms to 0.5·Vscale per step at this rate.
                        let speed = 0.5 * vscale * z_scale;
                        let attack = 0.05 * sr;
                        let mut x = start;
                        (0..frames)
                            .map(|n| {
                                let v = x;
                                x += speed * (n as f64 / attack).min(1.0);
                                v
                            })
                            .collect()
                    }
                    Role::Pluck { pscale } => {
                        let end = if start.abs() > pscale {
                            -start
                        } else {
                            start - 4.0 * pscale
                        };
                        // A raised-cosine sweep over 100 ms, starting after 10 ms.
                        (0..frames)
                            .map(|n| {
                                let s = ((n as f64 / sr - 0.01) / 0.1).clamp(0.0, 1.0);
                                let w = 0.5 - 0.5 * (std::f64::consts::PI * s).cos();
                                start + (end - start) * w
                            })
                            .collect()
                    }
                    Role::Hold => vec![start; frames],
                }
            }
            Some(InputUse::Param(_)) => vec![0.0; frames],
            None => vec![0.0; frames],
        })
        .enumerate()
        .map(|(k, signal)| {
            // A key presses the input of an `audioParam` (a bow's friction, a plectrum's
            // stiffness) to its exciter's depth: hold it there, as a held key does.
            let press = spec
                .host
                .exciters
                .iter()
                .find(|x| x.input as usize == k + 1 && x.kind == ExciterKind::Press);
            match (press, inputs[k].first()) {
                (Some(x), Some(InputUse::Param(_))) => vec![x.amount.unwrap_or(0.0); frames],
                _ => signal,
            }
        })
        .collect()
}

/// The smallest excursion that counts as sound on an output that reads the model (not an
/// avatar). A disconnected output or an excitation that never reaches the structure gives 0.
const SILENCE: f64 = 1e-7;

/// The smallest peak excursion of `@out1` from its value at rest, relative to the strike
/// |FORCE_IMPULSE|, for a preset struck through a force input as its header says: a hundred
/// times [`SILENCE`] (a listening point or strike pinned at a corner gives exactly 0) and
/// about 5 times below the quietest struck preset, NoFx Drone, whose listening chain only a
/// 1e-5 damper couples to the struck one (4.7e-5); the others move by 0.04 or more.
const FIRST_OUTPUT_MOVES: f64 = 1e-4;

/// The same for presets played only by position gestures (bows, plectra) or by themselves: the
/// bowed ones with their published bow friction are quiet by design (their headers say to add
/// gain; Resonant Strings gives a few 1e-6), so the bar is ten times [`SILENCE`].
const FIRST_OUTPUT_MOVES_UNSTRUCK: f64 = 1e-6;

#[test]
fn every_preset_is_stable_and_sounds() {
    const SR: f64 = 48_000.0;
    const FRAMES: usize = 48_000;
    // Silent outputs are collected, so that one run names every preset that does not play.
    let mut silent = Vec::new();
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../models");
    for (name, text) in presets() {
        let parsed = parse_with_files(&text, &folder_files(&dir));
        let errors: Vec<String> = parsed.errors().map(|d| d.to_string()).collect();
        assert!(errors.is_empty(), "{name}: {errors:?}");
        let warnings: Vec<String> = parsed.warnings().map(|d| d.to_string()).collect();
        assert!(warnings.is_empty(), "{name}: {warnings:?}");
        let spec = parsed.spec.unwrap();
        // The presets in space are played through the instrument's exciters, as a key plays
        // them, by `playing.rs` (level band, tuning, the kick, 22.05 and 192 kHz); this
        // bare-engine harness reads the avatars and laws of 1-D scripts only.
        if spec.is_3d() {
            continue;
        }
        let mut e = engine(&spec, SR);
        let report = e.stability();
        assert!(report.is_stable(), "{name}: {:?}", report.warnings);

        let inputs = excitation(&spec, &e.info().inputs, SR, FRAMES);
        let out = render(&mut e, FRAMES, 512, &inputs);
        assert!(
            !e.is_tripped(),
            "{name}: guard tripped {:?}",
            e.guard_event()
        );
        // Audio-rate parameters now hold their driven values: check again with them.
        let report = e.stability();
        assert!(
            report.is_stable(),
            "{name} (as played): {:?}",
            report.warnings
        );

        let info = e.info().clone();
        let mut loudest = (0.0f64, 0.0f64);
        for (c, ch) in out.iter().enumerate() {
            assert!(
                ch.iter().all(|v| v.is_finite()),
                "{name}: out{} not finite",
                c + 1
            );
            // Outputs that read an avatar only echo their input.
            if let OutputUse::Position(target) = &info.outputs[c] {
                let avatar = spec
                    .element(target.trim_start_matches('@'))
                    .is_some_and(|el| matches!(el.kind, ElementKind::PosInput { .. }));
                if avatar {
                    continue;
                }
            }
            let peak = ch.iter().fold(0.0f64, |m, v| m.max((v - ch[0]).abs()));
            let mean = ch.iter().sum::<f64>() / ch.len() as f64;
            let rms = (ch.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / ch.len() as f64).sqrt();
            if !(peak > SILENCE) {
                silent.push(format!(
                    "{name}: out{} is silent (peak excursion {peak:e})",
                    c + 1
                ));
            }
            if peak > loudest.0 {
                loudest = (peak, rms);
            }
        }
        // The first output is what a host hears first: it must move clearly.
        let first = out
            .first()
            .map(|ch| ch.iter().fold(0.0f64, |m, v| m.max((v - ch[0]).abs())))
            .unwrap_or(0.0);
        println!(
            "{name:<28} out1 peak excursion {first:.3e} ({:.1e} × strike); loudest output: \
             peak excursion {:.3e}, AC RMS {:.3e}",
            first / FORCE_IMPULSE.abs(),
            loudest.0,
            loudest.1
        );
        let struck = info
            .inputs
            .iter()
            .any(|uses| matches!(uses.first(), Some(InputUse::Force(_))));
        // A force output (a velocity pickup: a damper read against a ground) gives a force
        // per step, orders of magnitude below a position's excursion; the plugin's automatic
        // trim levels it, and it must only be heard at all.
        let force_pickup = matches!(info.outputs.first(), Some(OutputUse::Force(_)));
        let bar = if force_pickup {
            SILENCE
        } else if struck {
            FIRST_OUTPUT_MOVES * FORCE_IMPULSE.abs()
        } else {
            FIRST_OUTPUT_MOVES_UNSTRUCK
        };
        if !(first > bar) {
            silent.push(format!(
                "{name}: out1 barely moves when played as its header says: peak excursion \
                 {first:e} from its rest value {:e}, not above {bar:e}{}",
                out.first().map_or(0.0, |ch| ch[0]),
                if struck {
                    format!(
                        " ({FIRST_OUTPUT_MOVES:e} × the strike {:e})",
                        FORCE_IMPULSE.abs()
                    )
                } else {
                    String::new()
                }
            ));
        }
    }
    assert!(silent.is_empty(), "{}", silent.join("\n"));
}

#[test]
fn canonical_scripts_equal_the_builder_reference_models() {
    for (file, spec) in [
        ("string-1000.mdl", reference::string_1000()),
        ("mesh-15x15.mdl", reference::mesh_15x15()),
        ("mesh-25x20.mdl", reference::mesh_25x20()),
        ("hammer-oscillator.mdl", reference::hammer_oscillator()),
    ] {
        // Host directives (`~pitch`, `~note`, …) tell the plugin how to play a preset; the
        // physics must be the builder's.
        let mut parsed = preset(file);
        parsed.host = Default::default();
        let mut spec = spec;
        if file == "hammer-oscillator.mdl" {
            // The preset leaves out the tutorial's second output, the hammer's height (an
            // instrument listens to what sounds), and adds a force on the oscillator for the
            // sidechain.
            spec.elements.retain(|e| e.label != "out2");
            parsed.elements.retain(|e| e.label != "in2");
        }
        assert_eq!(parsed, spec, "{file} differs from the builder model");
    }
}

/// The inputs a preset adds to its gallery model for the plugin's sidechain (a force on the
/// structure where the hammer strikes: the hammers rest in a catch that an oscillating push
/// mostly lifts).
const SIDECHAIN_INPUTS: &[(&str, &str)] = &[
    ("fretted-string.mdl", "in16"),
    ("chladni-150x150.mdl", "in7"),
];

#[test]
fn gallery_scripts_equal_the_builder_reference_models() {
    for (file, spec) in [
        ("fretted-string.mdl", reference::fretted_string()),
        ("chladni-150x150.mdl", reference::chladni_150()),
    ] {
        let mut parsed = preset(file);
        // The host directives (`~voices`, …) are the plugin's; the physics is the builder's.
        parsed.host = Default::default();
        for (f, label) in SIDECHAIN_INPUTS {
            if f == &file {
                parsed.elements.retain(|e| e.label != *label);
            }
        }
        // Element by element first, for a readable failure on a 200-line model.
        for (i, (a, b)) in parsed.elements.iter().zip(&spec.elements).enumerate() {
            assert_eq!(a, b, "{file}: element {i} differs from the builder model");
        }
        assert_eq!(parsed, spec, "{file} differs from the builder model");
    }
}
