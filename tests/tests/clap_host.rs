//! End-to-end tests: the bundled Ressort plugin (built with `assert_process_allocs`, so any heap
//! allocation inside `process()` aborts the test binary) loaded in a CLAP host.
//!
//! Run with `-- --nocapture` to see the measured figures.
//!
//! Parameter values on the CLAP side are nice-plug's normalized values (0..1); the helpers
//! below convert the plain values of the plugin's documentation (octaves, semitones, dB).

use ressort_tests::presets::presets;
use ressort_tests::state;
use ressort_tests::{
    band_energy_share, cents, oscillator_frequency, peak_frequency, plugin_with_model,
    run_isolated, struck_default, Block, ClapId, ProcessStatus, Score, Stereo, TestPlugin,
};
use serde_json::json;

// ---------------------------------------------------------------------------------------------
// Models and helpers
// ---------------------------------------------------------------------------------------------

/// The preset of `models/hammer-oscillator.mdl`: an oscillator (M = 1, K = 0.1) struck by a
/// hammer that `@in1` pushes; out1 is the oscillator, out2 the hammer.
const HAMMER_OSCILLATOR: &str = include_str!("../../models/hammer-oscillator.mdl");
const HAMMER_OSC_M: f64 = 1.0;
const HAMMER_OSC_K: f64 = 0.1;

/// A single, lightly damped oscillator struck directly by `@in1` (and by MIDI notes): a linear
/// model whose pitch follows the exact law, low enough (≈ 222 Hz) that the law's bend is far
/// below a cent for an octave.
const LOW_OSCILLATOR: &str = include_str!("../models/low-oscillator.mdl");
const LOW_OSC_M: f64 = 1.0;
const LOW_OSC_K: f64 = 0.001;

/// A small membrane with two `param`s (bound to Macro 1 and 2): a non-default model for the
/// state tests.
const SMALL_MESH: &str = include_str!("../models/small-mesh.mdl");

/// The engine's chunk: controls change at multiples of this many samples from activation.
const CHUNK: usize = 16;

/// A sidechain impulse that strikes the default mesh without driving the output into the soft
/// ceiling (peak ≈ 0.3 at the default +24 dB output gain).
const STRIKE: f32 = -0.05;

/// A parameter's CLAP id and its plain range, as documented (the CLAP values are normalized).
#[derive(Clone, Copy, Debug)]
struct Param {
    id: ClapId,
    min: f64,
    max: f64,
}

impl Param {
    /// The CLAP (normalized) value of a plain value on a linear range.
    fn clap(&self, plain: f64) -> f64 {
        ((plain - self.min) / (self.max - self.min)).clamp(0.0, 1.0)
    }
}

/// The plugin's parameters by name, with their documented plain ranges.
#[derive(Clone, Copy, Debug)]
struct Params {
    stiffness: Param,
    damping: Param,
    tune: Param,
    output_gain: Param,
    force_gain: Param,
    dc_filter: Param,
    macro1: Param,
    macro2: Param,
}

impl Params {
    fn of(plugin: &mut TestPlugin) -> Params {
        let mut p = |name: &str, min: f64, max: f64| Param {
            id: plugin.param(name).id,
            min,
            max,
        };
        Params {
            stiffness: p("Stiffness", -4.0, 4.0),
            damping: p("Damping", -4.0, 4.0),
            tune: p("Tune", -24.0, 24.0),
            output_gain: p("Output Gain", -40.0, 60.0),
            force_gain: p("Force Gain", -60.0, 40.0),
            dc_filter: p("DC Filter", 0.0, 1.0),
            macro1: p("Macro 1", 0.0, 1.0),
            macro2: p("Macro 2", 0.0, 1.0),
        }
    }
}

/// A score of sidechain strikes (left channel) at the given frames.
fn strikes(frames: &[usize], value: f32) -> Score {
    frames
        .iter()
        .fold(Score::new(), |s, &f| s.impulse(f, value))
}

fn assert_finite_and_sounding(audio: &Stereo, what: &str) {
    assert!(audio.is_finite(), "{what}: non-finite output");
    assert!(
        audio.peak() > 1e-3,
        "{what}: silent output (peak {:e})",
        audio.peak()
    );
}

/// Drops an instance whose explosion guard may have tripped, after giving nice-plug's shared
/// background thread time to run the guard reports the instance queued. Destroying an instance
/// with reports still queued can abort the process (a nice-plug bug, asserted by
/// `destroying_instances_after_a_guard_trip_does_not_abort`); the tests about other things step
/// around it this way.
fn retire(mut plugin: TestPlugin) {
    plugin.deactivate();
    std::thread::sleep(std::time::Duration::from_millis(200));
    drop(plugin);
}

/// The measured pitch of the left channel over `range` (seconds).
fn pitch(audio: &Stereo, sr: f64, range: (f64, f64), band: (f64, f64)) -> f64 {
    let a = (range.0 * sr) as usize;
    let b = ((range.1 * sr) as usize).min(audio.left.len());
    peak_frequency(&audio.left[a..b], sr, band.0, band.1)
}

// ---------------------------------------------------------------------------------------------
// Description
// ---------------------------------------------------------------------------------------------

#[test]
fn bundle_is_built_with_the_allocation_check() {
    // `assert_process_allocs` links nice-assert-no-alloc, whose abort message is in the binary.
    // Without it these tests would not prove that process() never allocates.
    let path = ressort_tests::bundle_path();
    let bytes = std::fs::read(&path).unwrap_or_else(|e| {
        panic!(
            "cannot read {}: {e}\nBuild it with:\n    {}",
            path.display(),
            ressort_tests::BUILD_COMMAND
        )
    });
    let marker = b"Memory allocation of ";
    let found = bytes.windows(marker.len()).any(|w| w == marker);
    println!("bundle {} ({} bytes)", path.display(), bytes.len());
    assert!(
        found,
        "{} was not built with assert_process_allocs (debug). Build it with:\n    {}",
        path.display(),
        ressort_tests::BUILD_COMMAND
    );
}

#[test]
fn plugin_describes_its_ports_and_parameters() {
    let mut plugin = TestPlugin::new();
    assert_eq!(plugin.descriptor_name(), "Ressort");

    let params = plugin.params();
    println!("parameters (CLAP values are normalized 0..1):");
    for p in &params {
        let text = |plugin: &mut TestPlugin, v| plugin.param_text(p.id, v).unwrap_or_default();
        println!(
            "  {:>10}  {:<14} module {:<10?} min {} max {} default {:.4} ({}) flags {:#x}  \
             [0 = {}, 1 = {}]",
            p.id.get(),
            p.name,
            p.module,
            p.min,
            p.max,
            p.default,
            text(&mut plugin, p.default),
            p.flags,
            text(&mut plugin, p.min),
            text(&mut plugin, p.max),
        );
    }
    let mut names: Vec<String> = [
        "Stiffness",
        "Damping",
        "Tune",
        "Output Gain",
        "Force Gain",
        "Position Gain",
        "DC Filter",
        "Guard Tripped",
        "Bend Range",
        "Velocity Curve",
        "A4",
        "Sidechain Trigger",
        "Trigger Sensitivity",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    names.extend((1..=16).map(|i| format!("Macro {i}")));
    for name in &names {
        assert!(
            params.iter().any(|p| &p.name == name),
            "missing parameter {name}"
        );
    }
    let mut ids: Vec<u32> = params.iter().map(|p| p.id.get()).collect();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), params.len(), "duplicate parameter ids");
    // The guard flag is the plugin's to set: visible, not automatable.
    const CLAP_PARAM_IS_AUTOMATABLE: u32 = 1 << 5;
    const CLAP_PARAM_IS_HIDDEN: u32 = 1 << 2;
    let guard = plugin.param("Guard Tripped");
    assert_eq!(
        guard.flags & (CLAP_PARAM_IS_AUTOMATABLE | CLAP_PARAM_IS_HIDDEN),
        0
    );
    assert_eq!(plugin.param_text(guard.id, 0.0).as_deref(), Some("Clear"));
    // The editor's model-change counter: hidden and not automatable, it only makes hosts
    // record an edit of the project.
    let edits = plugin.param("Model Edits");
    assert_eq!(edits.flags & CLAP_PARAM_IS_AUTOMATABLE, 0);
    assert_ne!(edits.flags & CLAP_PARAM_IS_HIDDEN, 0);

    // The documented plain ranges, through the plugin's own value texts.
    let p = Params::of(&mut plugin);
    let stiffness_x4 = plugin.param_text(p.stiffness.id, p.stiffness.clap(2.0));
    assert_eq!(stiffness_x4.as_deref(), Some("4.00 ×"));
    let tune = plugin.param_text(p.tune.id, p.tune.clap(12.0));
    assert_eq!(tune.as_deref(), Some("+12.00 st"));
    let gain = plugin.param("Output Gain");
    let default_text = plugin.param_text(gain.id, gain.default);
    // The automatic level trim sets a new model's level; Output Gain adds to it.
    assert_eq!(default_text.as_deref(), Some("0.0 dB"));
    let a4 = plugin.param("A4");
    assert_eq!(
        plugin.param_text(a4.id, a4.default).as_deref(),
        Some("440.0 Hz")
    );
    assert_eq!(plugin.param_value(p.stiffness.id), Some(0.5));

    let inputs = plugin.audio_ports(true);
    let outputs = plugin.audio_ports(false);
    let configs = plugin.audio_port_configs();
    let notes = plugin.note_ports(true);
    println!("audio inputs {inputs:?}\naudio outputs {outputs:?}\nconfigurations {configs:?}");
    println!("note inputs {notes:?}");
    assert_eq!(inputs.len(), 1, "default layout: the sidechain only");
    assert_eq!(inputs[0].name, "Sidechain");
    assert_eq!(inputs[0].channels, 2);
    assert!(!inputs[0].is_main);
    assert_eq!(outputs.len(), 1);
    assert!(outputs[0].is_main);
    assert_eq!(outputs[0].channels, 2);
    assert_eq!(configs.len(), 4);
    assert!(configs.iter().any(|c| c == "Effect with sidechain"));
    assert!(configs.iter().any(|c| c == "Multichannel instrument"));
    assert!(configs.iter().any(|c| c == "Effect"));
    assert_eq!(notes.len(), 1, "one note input");
    assert!(notes[0].dialects & 1 != 0, "note input accepts CLAP notes");
    assert!(notes[0].dialects & 2 != 0, "note input accepts MIDI");

    let saved = plugin.save_state();
    let (model, _) = state::model(&saved).expect("model field in the state");
    println!("default model in the state: {model}");
    assert_eq!(model, "mesh-15x15");
}

// ---------------------------------------------------------------------------------------------
// Activation and audio
// ---------------------------------------------------------------------------------------------

/// The remote-control pages a controller or a host's device panel shows, as a CLAP host reads
/// them: the running model's own macros first on a page named after it, filled up with the
/// physics, then the rest; each slot a parameter the plugin has, none twice. They follow the
/// model: a state load with another model changes them, and the host is told
/// (`clap_host_remote_controls.changed`).
#[test]
fn remote_control_pages_follow_the_running_model() {
    let mut plugin = TestPlugin::new();
    plugin.activate(48_000.0, 1, 512);
    plugin.render(0.05, 512, &Score::new());
    plugin.idle();
    let read = |plugin: &mut TestPlugin| -> Vec<(String, String, Vec<String>)> {
        let params = plugin.params();
        let name = |id: Option<ClapId>| {
            id.map(|id| {
                params
                    .iter()
                    .find(|p| p.id == id)
                    .unwrap_or_else(|| panic!("page slot {id:?} is no parameter"))
                    .name
                    .clone()
            })
            .unwrap_or_default()
        };
        let mut seen = Vec::new();
        let mut out = Vec::new();
        for page in plugin.remote_control_pages() {
            let names: Vec<String> = page.params.iter().map(|&id| name(id)).collect();
            println!("  {} / {}: {}", page.section, page.name, names.join(", "));
            for id in page.params.iter().flatten() {
                assert!(!seen.contains(id), "{id:?} on two pages");
                seen.push(*id);
            }
            out.push((page.section, page.name, names));
        }
        out
    };
    let expect = |list: &[&str]| list.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    println!("remote-control pages of the default model:");
    let mesh = read(&mut plugin);
    assert_eq!(mesh.len(), 3, "{mesh:?}");
    assert_eq!(
        mesh[0],
        (
            "Model".to_string(),
            "mesh-15x15: K, Z".to_string(),
            expect(&[
                "Macro 1",
                "Macro 2",
                "Stiffness",
                "Damping",
                "Release",
                "Output Gain",
                "Tune",
                "Force Gain"
            ])
        )
    );
    assert_eq!(
        mesh[1],
        (
            "Instrument".to_string(),
            "Physics".to_string(),
            expect(&["Position Gain", "Velocity Curve", "", "", "", "", "", ""])
        )
    );
    assert_eq!(
        (mesh[2].0.as_str(), mesh[2].1.as_str()),
        ("Playing", "Playing")
    );
    assert_eq!(mesh[2].2[0], "A4");
    let changed = plugin.counters().remote_controls_changed;

    let felt = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/felt-piano.mdl"),
    )
    .unwrap();
    let blob = state::with_musical_model(&plugin.save_state(), "felt-piano", &felt);
    plugin.load_state(&blob).expect("the state loads");
    plugin.render(0.05, 512, &Score::new());
    plugin.idle();
    println!("after loading felt-piano:");
    let piano = read(&mut plugin);
    assert_eq!(piano[0].1, "felt-piano: K, K2, Z");
    assert_eq!(
        piano[0].2,
        expect(&[
            "Macro 1",
            "Macro 2",
            "Macro 3",
            "Stiffness",
            "Damping",
            "Release",
            "Output Gain",
            "Tune"
        ])
    );
    assert_eq!(
        piano[1].2[..3],
        expect(&["Force Gain", "Position Gain", "Velocity Curve"])
    );
    let told = plugin.counters().remote_controls_changed - changed;
    println!("clap_host_remote_controls.changed calls after the load: {told}");
    assert!(told >= 1, "the host was not told the pages changed");
}

#[test]
fn renders_at_every_sample_rate_and_block_size() {
    let mut plugin = struck_default();
    for sr in [44_100.0, 48_000.0, 96_000.0] {
        let mut reference: Option<(usize, Stereo)> = None;
        for block in [1usize, 64, 333, 4096] {
            plugin.activate(sr, 1, block as u32);
            let quarter = (0.25 * sr) as usize;
            let out = plugin.render(0.5, block, &strikes(&[0, quarter], STRIKE));
            let what = format!("{sr} Hz, blocks of {block}");
            assert_finite_and_sounding(&out.audio, &what);
            println!(
                "{what:>24}: {} frames, peak {:.4}, rms {:.5}, last status {:?}",
                out.audio.len(),
                out.audio.peak(),
                out.audio.rms(),
                out.last_status()
            );
            assert!(out.audio.peak() <= 1.0);
            // The engine runs in chunks counted from activation: the block size must not
            // change a single bit.
            match &reference {
                None => reference = Some((block, out.audio)),
                Some((b0, r)) => {
                    assert!(
                        r.bit_identical(&out.audio),
                        "{sr} Hz: blocks of {block} differ from blocks of {b0} from frame {:?}",
                        r.first_difference(&out.audio)
                    );
                }
            }
            plugin.deactivate();
        }
        println!("{sr} Hz: identical output for every block size");
    }
}

#[test]
fn sidechain_strikes_sound_and_silence_stays_silent() {
    let sr = 48_000.0;
    let mut plugin = struck_default();
    plugin.activate(sr, 1, 512);

    // At rest, silence in gives exact silence out.
    let quiet = plugin.render(1.0, 512, &Score::new());
    println!("silence: peak {:e}", quiet.audio.peak());
    assert!(quiet.audio.is_finite());
    assert_eq!(
        quiet.audio.peak(),
        0.0,
        "the model at rest must output zeros"
    );

    // A few strikes on @in1 (sidechain left).
    let at = |s: f64| (s * sr) as usize;
    let out = plugin.render(
        1.5,
        512,
        &strikes(&[at(0.0), at(0.4), at(0.8), at(1.2)], STRIKE),
    );
    assert_finite_and_sounding(&out.audio, "strikes");
    for (i, seg) in [(0.0, 0.4), (0.4, 0.8), (0.8, 1.2), (1.2, 1.5)]
        .iter()
        .enumerate()
    {
        let s = out.audio.slice(at(seg.0)..at(seg.1));
        println!("strike {}: peak {:.4}, rms {:.5}", i + 1, s.peak(), s.rms());
        assert!(s.peak() > 1e-3, "strike {} is silent", i + 1);
    }
    assert!(out.audio.peak() <= 1.0);

    // The sidechain's right channel feeds @in2, which the default mesh does not declare.
    plugin.activate(sr, 1, 512);
    let right = Score::new().sidechain_sample(0, 0.0, STRIKE);
    let out = plugin.render(0.5, 512, &right);
    println!(
        "impulse on the right channel (@in2, unused): peak {:e}",
        out.audio.peak()
    );
    assert_eq!(out.audio.peak(), 0.0);
}

#[test]
fn effect_layout_routes_the_main_input_to_in1() {
    let sr = 48_000.0;
    let mut plugin = struck_default();
    plugin
        .select_audio_config("Effect with sidechain")
        .expect("select the effect layout");
    let inputs = plugin.audio_ports(true);
    println!("effect layout inputs: {inputs:?}");
    assert_eq!(inputs.len(), 2);
    assert!(inputs.iter().any(|p| p.is_main && p.channels == 2));
    plugin.activate(sr, 1, 256);

    let main = Stereo {
        left: vec![STRIKE],
        right: vec![0.0],
    };
    let out = plugin.render(0.5, 256, &Score::new().with_main_input(main));
    println!("main-left impulse: peak {:.4}", out.audio.peak());
    assert_finite_and_sounding(&out.audio, "main input left → @in1");

    // With a main input the sidechain moves to @in3/@in4, which the mesh does not declare.
    plugin.activate(sr, 1, 256);
    let out = plugin.render(0.5, 256, &strikes(&[0], STRIKE));
    println!(
        "sidechain-left impulse in the effect layout: peak {:e}",
        out.audio.peak()
    );
    assert_eq!(out.audio.peak(), 0.0);
}

#[test]
fn non_finite_sidechain_input_gives_finite_output() {
    let sr = 48_000.0;
    let frames = (0.5 * sr) as usize;
    let mut dirty = Stereo::silence(frames);
    dirty.left[0] = STRIKE;
    dirty.left[100] = f32::NAN;
    dirty.left[200] = f32::INFINITY;
    dirty.right[250] = f32::NEG_INFINITY;
    dirty.left[300] = f32::NEG_INFINITY;
    dirty.right[400] = f32::NAN;
    for s in &mut dirty.left[4096..8192] {
        *s = f32::NAN;
    }
    for s in &mut dirty.right[6000..7000] {
        *s = f32::INFINITY;
    }
    dirty.left[10_000] = STRIKE;
    let mut clean = dirty.clone();
    for s in clean.left.iter_mut().chain(clean.right.iter_mut()) {
        if !s.is_finite() {
            *s = 0.0;
        }
    }

    let mut plugin = struck_default();
    plugin.activate(sr, 1, 333);
    let out = plugin.render(0.5, 333, &Score::new().with_sidechain(dirty));
    assert_finite_and_sounding(&out.audio, "NaN/Inf in the sidechain");
    println!("NaN/Inf input: peak {:.4}", out.audio.peak());

    plugin.activate(sr, 1, 333);
    let reference = plugin.render(0.5, 333, &Score::new().with_sidechain(clean));
    // Non-finite input samples count as silence: the output matches the cleaned input's.
    assert!(
        out.audio.bit_identical(&reference.audio),
        "differs from the render with the non-finite samples zeroed, from frame {:?}",
        out.audio.first_difference(&reference.audio)
    );
}

#[test]
fn extreme_parameter_values_stay_finite_and_bounded() {
    // The loudest cases trip the plugin's explosion guard, whose reports go through nice-plug's
    // shared background thread; see `destroying_instances_after_a_guard_trip_does_not_abort`
    // for why that must not share a process with the other tests.
    if !run_isolated("extreme_parameter_values_stay_finite_and_bounded") {
        return;
    }
    let sr = 48_000.0;
    let mut cases_run = 0;
    for (model, script) in [
        ("mesh-15x15 (default)", None),
        ("hammer-oscillator", Some(HAMMER_OSCILLATOR)),
    ] {
        let mut plugin = match script {
            Some(s) => plugin_with_model(model, s, &[]),
            None => struck_default(),
        };
        let p = Params::of(&mut plugin);
        let cases: [(&str, Vec<(Param, f64)>); 7] = [
            ("Stiffness max (×16)", vec![(p.stiffness, 4.0)]),
            ("Damping min (×1/16)", vec![(p.damping, -4.0)]),
            ("Damping max (×16)", vec![(p.damping, 4.0)]),
            (
                "Stiffness max, Damping max",
                vec![(p.stiffness, 4.0), (p.damping, 4.0)],
            ),
            (
                "Stiffness max, Damping min",
                vec![(p.stiffness, 4.0), (p.damping, -4.0)],
            ),
            (
                "Stiffness max, Tune +24 st",
                vec![(p.stiffness, 4.0), (p.tune, 24.0)],
            ),
            (
                "Output +60 dB, Force +40 dB, DC off",
                vec![
                    (p.output_gain, 60.0),
                    (p.force_gain, 40.0),
                    (p.dc_filter, 0.0),
                ],
            ),
        ];
        for (name, values) in cases {
            plugin.activate(sr, 1, 256);
            // Set at the start of the render, then strike hard and repeatedly; finally move
            // every control back and forth in the middle of the ringing.
            let mut score = strikes(&[0, 4_800, 9_600, 24_000], -0.5);
            for (param, plain) in &values {
                score = score.param(0, param.id, param.clap(*plain));
                score = score.param(30_000, param.id, param.clap(0.0_f64.max(param.min)));
                score = score.param(30_101, param.id, param.clap(*plain));
            }
            let out = plugin.render(1.0, 256, &score);
            let what = format!("{model}, {name}");
            assert!(out.audio.is_finite(), "{what}: non-finite output");
            let peak = out.audio.peak();
            let rms = out.audio.rms();
            println!("{what:>58}: peak {peak:.6}, rms {rms:.4}");
            assert!(peak <= 1.0, "{what}: sample beyond ±1 ({peak})");
            // The clamp and the guard keep a struck model playing at the extremes: it is
            // neither muted nor reduced to a click (the quietest case is about 0.12 rms).
            assert!(
                rms > 0.01,
                "{what}: the struck model is (nearly) silent, rms {rms:.2e}"
            );
            cases_run += 1;
        }
        retire(plugin);
    }
    assert_eq!(cases_run, 14);

    // A model that explodes by itself: the guard keeps the output finite and bounded.
    let mut plugin = plugin_with_model("exploding", EXPLODING, &[]);
    for block in [1usize, 333, 4096] {
        plugin.activate(sr, 1, block as u32);
        let out = plugin.render(0.25, block, &strikes(&[0, 100], -0.5));
        println!(
            "{:>58}: peak {:.6}, rms {:.4}",
            format!("exploding model, blocks of {block}"),
            out.audio.peak(),
            out.audio.rms()
        );
        assert!(out.audio.is_finite(), "exploding model: non-finite output");
        assert!(out.audio.peak() <= 1.0, "exploding model: beyond ±1");
    }
    retire(plugin);
}

// ---------------------------------------------------------------------------------------------
// Pitch: Stiffness, MIDI notes, pitch bend
// ---------------------------------------------------------------------------------------------

#[test]
fn stiffness_automation_raises_the_pitch_sample_accurately() {
    let sr = 48_000.0;
    let gain = [("output_gain", json!({ "f32": -12.0 }))];
    let mut plugin = plugin_with_model("low-oscillator", LOW_OSCILLATOR, &gain);
    let p = Params::of(&mut plugin);

    // Stiffness ×2 (+1 octave) at a sample in the middle of a 4096-frame block.
    let event_at: usize = 24_077;
    assert!(!event_at.is_multiple_of(4096) && !event_at.is_multiple_of(CHUNK));
    let score = strikes(&[0], STRIKE);
    let automated = score
        .clone()
        .param(event_at as u32, p.stiffness.id, p.stiffness.clap(1.0));

    plugin.activate(sr, 1, 4096);
    let plain = plugin.render(1.2, 4096, &score);
    plugin.activate(sr, 1, 4096);
    let moved = plugin.render(1.2, 4096, &automated);
    assert!(moved.audio.is_finite());

    // Sample accuracy: nothing changes before the event; the new stiffness acts from the
    // event's own sample (not the next 16-sample chunk of the control grid), and the moved
    // mass reaches the output one step later (spec §1.6).
    let first = moved
        .audio
        .first_difference(&plain.audio)
        .expect("the automation changed nothing");
    let boundary = event_at.div_ceil(CHUNK) * CHUNK;
    println!(
        "Stiffness event at frame {event_at}: first changed output frame {first} \
         ({} after the event; the control grid's next point is {boundary})",
        first - event_at
    );
    assert!(
        first >= event_at && first <= event_at + 1,
        "the change starts at frame {first}, the event is at {event_at}"
    );
    // The same automation in other block sizes renders the same samples.
    // (Fresh instances: parameter values outlive a reactivation.)
    for block in [1u32, 64, 333] {
        let mut other = plugin_with_model("low-oscillator", LOW_OSCILLATOR, &gain);
        other.activate(sr, 1, block);
        let other = other.render(0.6, block as usize, &automated);
        let n = other.audio.len();
        assert_eq!(
            other.audio.first_difference(&moved.audio.slice(0..n)),
            None,
            "blocks of {block} render the automation differently from blocks of 4096"
        );
    }

    let band = (50.0, 2_000.0);
    let t_event = event_at as f64 / sr;
    let before = pitch(&moved.audio, sr, (0.05, t_event), band);
    let after = pitch(&moved.audio, sr, (t_event + 0.1, 1.2), band);
    let unmoved = pitch(&plain.audio, sr, (t_event + 0.1, 1.2), band);
    let expected_before = oscillator_frequency(LOW_OSC_M, LOW_OSC_K, 1.0, sr);
    let expected_after = oscillator_frequency(LOW_OSC_M, LOW_OSC_K, 2.0, sr);
    println!(
        "pitch before {before:.3} Hz (law {expected_before:.3}), after Stiffness ×2 \
         {after:.3} Hz (law {expected_after:.3}), without automation {unmoved:.3} Hz; \
         ratio {:.5} ({:+.2} cents from √2)",
        after / before,
        cents(after / before, 2f64.sqrt())
    );
    assert!(after > before * 1.3, "Stiffness up did not raise the pitch");
    assert!(cents(before, expected_before).abs() < 2.0);
    assert!(cents(after, expected_after).abs() < 2.0);
    assert!(cents(unmoved, expected_before).abs() < 2.0);
}

#[test]
fn force_inputs_and_strikes_sound_the_same_at_every_sample_rate() {
    // Script parameters are "as at 44.1 kHz" (spec §1.7); the plugin reads force signals the
    // same way: a force input is scaled by (44100/SR)² like gravity, a one-sample strike by
    // 44100/SR (the same momentum). The same sidechain signal and the same note then move
    // the model by the same amount at any rate.
    let rates = [44_100.0, 48_000.0, 96_000.0];
    let measure = |sr: f64, score: &dyn Fn(f64) -> Score| -> f32 {
        // −12 dB keeps both responses below the soft ceiling's knee.
        let gain = [("output_gain", json!({ "f32": -12.0 }))];
        let mut plugin = plugin_with_model("low-oscillator", LOW_OSCILLATOR, &gain);
        plugin.activate(sr, 1, 512);
        let out = plugin.render(0.3, 512, &score(sr));
        assert_finite_and_sounding(&out.audio, "low-oscillator");
        retire(plugin);
        out.audio.peak()
    };
    // A 2 ms raised-cosine push on the sidechain: the same continuous signal at every rate.
    let push = |sr: f64| {
        let n = (0.002 * sr).round() as usize;
        let mut signal = Stereo::silence(n);
        for (i, x) in signal.left.iter_mut().enumerate() {
            *x = -1e-4 * (std::f64::consts::PI * i as f64 / n as f64).sin().powi(2) as f32;
        }
        Score::new().with_sidechain(signal)
    };
    let note = |_sr: f64| Score::new().note_on(0, 60, 1.0);
    let mut spread = Vec::new();
    for (what, score) in [
        ("sidechain push", &push as &dyn Fn(f64) -> Score),
        ("MIDI note", &note),
    ] {
        let peaks: Vec<f32> = rates.iter().map(|&sr| measure(sr, score)).collect();
        let ratios: Vec<f64> = peaks.iter().map(|p| (p / peaks[0]) as f64).collect();
        println!(
            "{what}: peak {:.4} at 44.1 kHz, {:.4} at 48 kHz (×{:.4}), {:.4} at 96 kHz (×{:.4})",
            peaks[0], peaks[1], ratios[1], peaks[2], ratios[2]
        );
        spread.extend(ratios.iter().map(|r| (r - 1.0).abs()));
    }
    let worst = spread.iter().cloned().fold(0.0, f64::max);
    // The README's figure: within 0.4 % (the sidechain push at 96 kHz measures 0.32 %).
    assert!(
        worst < 0.004,
        "the response to the same force moves by {:.2} % across sample rates",
        worst * 100.0
    );
}

/// The low oscillator (as mass, ground and spring) heard through the force on its mass
/// (`frcOutput`, spec §2.2.4): the spring's force −K·x follows
/// every change of K at once, so steps in the stiffness are steps in the output.
const LOW_OSCILLATOR_FORCE: &str = "\
# The low oscillator, heard through the force on its mass (zipper-noise test).
@g ground 0.
@m mass 1. 0. 0.
@s springDamper @m @g 0.001 0.00001
@in1 frcInput @m
@out1 frcOutput @m
";

#[test]
fn a_stiffness_sweep_has_no_zipper_noise() {
    // A sounding oscillator (a pure tone of 157 to 444 Hz here) while a host automates
    // Stiffness from -1 to +1 octave over a second, one automation point every 512 samples.
    // Heard through its force, a stepped stiffness is a stepped output: energy far above the
    // tone, at the step rate's harmonics. A model of this loop (numpy, same law) puts -63 dB
    // of the energy above 2 kHz when each point is applied at once, -77 dB with the plugin's
    // 15 ms smoothing (what remains is the 16-sample control grid).
    let sr = 48_000.0;
    let (start, seconds) = (0.25, 1.0);
    let render = |sweep: bool| {
        let mut plugin = plugin_with_model("low-oscillator-force", LOW_OSCILLATOR_FORCE, &[]);
        let p = Params::of(&mut plugin);
        let mut score = strikes(&[0], STRIKE).param(0, p.stiffness.id, p.stiffness.clap(-1.0));
        if sweep {
            let (a, n) = ((start * sr) as usize, (seconds * sr) as usize);
            for t in (0..=n).step_by(512) {
                let octaves = -1.0 + 2.0 * t as f64 / n as f64;
                score = score.param((a + t) as u32, p.stiffness.id, p.stiffness.clap(octaves));
            }
        }
        plugin.activate(sr, 1, 512);
        let out = plugin.render(start + seconds + 0.05, 512, &score);
        assert_finite_and_sounding(&out.audio, "low-oscillator-force");
        let segment = &out.audio.left[(start * sr) as usize..((start + seconds) * sr) as usize];
        let peak = segment.iter().fold(0.0f32, |m, x| m.max(x.abs()));
        assert!(
            peak < 0.5,
            "the soft ceiling would add harmonics (peak {peak})"
        );
        band_energy_share(segment, sr, 2_000.0, 20_000.0)
    };
    let db = |share: f64| 10.0 * share.max(1e-30).log10();
    let steady = db(render(false));
    let swept = db(render(true));
    println!(
        "energy above 2 kHz: {steady:.1} dB of the total for the steady tone, {swept:.1} dB \
         during the sweep"
    );
    assert!(
        swept < -72.0,
        "the Stiffness sweep puts {swept:.1} dB of the energy above 2 kHz"
    );
}

#[test]
fn stiffness_plus_two_octaves_raises_a_linear_model_by_an_octave() {
    // Stiffness multiplies every K; for a mass-spring oscillator sin²(πf/SR) = K/4M, so ×4
    // is an octave up to the law's bend: +0.2 cent at 222 Hz, +19 cents at 2.2 kHz (48 kHz).
    // Tolerance: each pitch is measured on a 1 s (low) or 0.5 s (high) steady segment, where
    // the parabolic peak interpolation is accurate to a few hundredths of a bin (< 0.2 cent
    // here); 2 cents against the law leaves room for the decay, while any wrong gain law
    // (e.g. ×4 on the frequency, or ×2 on K) would be off by 600 cents or more.
    let sr = 48_000.0;
    let gain = [("output_gain", json!({ "f32": -12.0 }))];
    // The hammer needs a kick above 0.05 to reach the oscillator (its suspension's damping,
    // models/hammer-oscillator.mdl): -0.1 is the model's own example.
    for (name, script, m, k, band, segment, strike) in [
        (
            "low-oscillator",
            LOW_OSCILLATOR,
            LOW_OSC_M,
            LOW_OSC_K,
            (50.0, 2_000.0),
            (0.1, 1.1),
            STRIKE,
        ),
        (
            "hammer-oscillator",
            HAMMER_OSCILLATOR,
            HAMMER_OSC_M,
            HAMMER_OSC_K,
            (500.0, 10_000.0),
            (0.1, 0.6),
            -0.1,
        ),
    ] {
        let mut plugin = plugin_with_model(name, script, &gain);
        let p = Params::of(&mut plugin);
        let mut measure = |octaves: f64| {
            plugin.activate(sr, 1, 512);
            let score = strikes(&[0], strike).param(0, p.stiffness.id, p.stiffness.clap(octaves));
            let out = plugin.render(segment.1 + 0.05, 512, &score);
            assert_finite_and_sounding(&out.audio, name);
            pitch(&out.audio, sr, segment, band)
        };
        let f1 = measure(0.0);
        let f4 = measure(2.0);
        let law1 = oscillator_frequency(m, k, 1.0, sr);
        let law4 = oscillator_frequency(m, k, 4.0, sr);
        let ratio = f4 / f1;
        println!(
            "{name}: ×1 {f1:.3} Hz (law {law1:.3}), ×4 {f4:.3} Hz (law {law4:.3}); ratio \
             {ratio:.5} = octave {:+.2} cents (law predicts {:+.2} cents)",
            cents(ratio, 2.0),
            cents(law4 / law1, 2.0)
        );
        assert!(cents(f1, law1).abs() < 2.0, "{name}: ×1 pitch off the law");
        assert!(cents(f4, law4).abs() < 2.0, "{name}: ×4 pitch off the law");
        if name == "low-oscillator" {
            assert!(
                cents(ratio, 2.0).abs() < 2.0,
                "Stiffness ×4 is not an octave on a linear low model"
            );
        }
    }
}

#[test]
fn midi_notes_play_at_the_expected_pitch() {
    let sr = 48_000.0;
    let gain = [("output_gain", json!({ "f32": -12.0 }))];

    // A low, linear oscillator: both the exact law and its low-frequency limit give an
    // octave for 12 semitones (they differ by 0.2 cent here).
    let mut plugin = plugin_with_model("low-oscillator", LOW_OSCILLATOR, &gain);
    let band = (50.0, 2_000.0);
    let mut play = |score: Score| {
        plugin.activate(sr, 1, 512);
        let out = plugin.render(1.15, 512, &score);
        assert_finite_and_sounding(&out.audio, "MIDI note");
        pitch(&out.audio, sr, (0.1, 1.1), band)
    };
    let f60 = play(Score::new().note_on(0, 60, 1.0));
    let f72 = play(Score::new().note_on(0, 72, 1.0));
    let f48 = play(Score::new().note_on(0, 48, 1.0));
    let f67 = play(Score::new().note_on(0, 67, 0.5));
    let bent = play(Score::new().pitch_bend(0, 1.0).note_on(0, 60, 1.0));
    let reference = oscillator_frequency(LOW_OSC_M, LOW_OSC_K, 1.0, sr);
    println!(
        "low oscillator: note 60 {f60:.3} Hz (model {reference:.3} Hz, {:+.3} cents); \
         72/60 = {:.5} ({:+.3} cents from 2); 48/60 = {:.5} ({:+.3} cents from 1/2); \
         67/60 {:+.3} cents from 700; bend +1 {:+.3} cents from 200",
        cents(f60, reference),
        f72 / f60,
        cents(f72 / f60, 2.0),
        f48 / f60,
        cents(f48 / f60, 0.5),
        cents(f67, f60) - 700.0,
        cents(bent, f60) - 200.0
    );
    assert!(
        cents(f60, reference).abs() < 1.0,
        "note 60 must play the model as written"
    );
    assert!(
        cents(f72 / f60, 2.0).abs() < 2.0,
        "note 72 is not an octave above 60"
    );
    assert!(
        cents(f48 / f60, 0.5).abs() < 2.0,
        "note 48 is not an octave below 60"
    );
    assert!(
        (cents(f67, f60) - 700.0).abs() < 2.0,
        "note 67 is not a fifth above 60"
    );
    assert!(
        (cents(bent, f60) - 200.0).abs() < 2.0,
        "a full pitch bend up is not +2 semitones"
    );

    // The hammer oscillator at ≈ 2.2 kHz, where the exact law and its low-frequency limit
    // 2^(st/6) part by 19 cents per octave at 48 kHz. A note's force (0.02)
    // does not throw this preset's damped hammer onto the oscillator (see
    // `every_preset_sounds_on_a_midi_note`): Force Gain +12 dB makes it 0.08.
    let gain = [
        ("output_gain", json!({ "f32": -12.0 })),
        ("force_gain", json!({ "f32": 12.0 })),
    ];
    let mut plugin = plugin_with_model("hammer-oscillator", HAMMER_OSCILLATOR, &gain);
    let band = (500.0, 10_000.0);
    let mut play = |key: u8| {
        plugin.activate(sr, 1, 512);
        let out = plugin.render(0.65, 512, &Score::new().note_on(0, key, 1.0));
        assert_finite_and_sounding(&out.audio, "MIDI note on the hammer oscillator");
        pitch(&out.audio, sr, (0.1, 0.6), band)
    };
    let h60 = play(60);
    let h72 = play(72);
    let model = oscillator_frequency(HAMMER_OSC_M, HAMMER_OSC_K, 1.0, sr);
    let low_frequency_law = oscillator_frequency(HAMMER_OSC_M, HAMMER_OSC_K, 4.0, sr) / model;
    let ratio = h72 / h60;
    println!(
        "hammer oscillator: note 60 {h60:.3} Hz (model by the exact law {model:.3} Hz, \
         {:+.3} cents); note 72 {h72:.3} Hz; ratio {ratio:.5} = octave {:+.2} cents \
         (the 2^(st/6) stiffness law predicts {low_frequency_law:.5}, {:+.2} cents)",
        cents(h60, model),
        cents(ratio, 2.0),
        cents(low_frequency_law, 2.0)
    );
    assert!(
        cents(h60, model).abs() < 1.0,
        "note 60 must play the model as written"
    );
    // The plugin measures this model's reference pitch and tunes by the exact law
    // (`dsp::tuning_gain`): note 72 is an octave. The 3-cent tolerance is far inside the
    // 19 cents by which the low-frequency law 2^(st/6) would miss it.
    assert!(
        cents(low_frequency_law, 2.0).abs() > 3.0 * 3.0,
        "the two laws are too close here to tell apart"
    );
    assert!(
        cents(ratio, 2.0).abs() < 3.0,
        "note 72 / note 60 = {ratio:.5} ({:+.2} cents from an octave) does not follow the \
         exact law; the low-frequency law 2^(st/6) gives {low_frequency_law:.5}",
        cents(ratio, 2.0)
    );
}

// ---------------------------------------------------------------------------------------------
// State
// ---------------------------------------------------------------------------------------------

#[test]
fn state_round_trip_renders_bit_identically() {
    let sr = 48_000.0;
    let block = 256;
    let mut first = TestPlugin::new();
    let p = Params::of(&mut first);
    first.activate(sr, 1, block);

    // Change parameters through automation, as a host would.
    let changes = [
        (p.stiffness, 0.25),
        (p.damping, -1.0),
        (p.tune, -2.0),
        (p.output_gain, 0.0),
        (p.dc_filter, 0.0),
        (p.macro1, 0.7),
        (p.macro2, 0.3),
    ];
    let score = changes.iter().fold(Score::new(), |s, (param, plain)| {
        s.param(0, param.id, param.clap(*plain))
    });
    first.render(0.1, block as usize, &score);

    // Load a non-default model through the state, while active.
    let with_model = state::with_model(&first.save_state(), "small-mesh", SMALL_MESH);
    first.load_state(&with_model).expect("load a valid state");
    first.render(0.2, block as usize, &strikes(&[0], STRIKE));
    let saved = first.save_state();
    let (name, script) = state::model(&saved).expect("model in the saved state");
    assert_eq!(name, "small-mesh");
    assert_eq!(script, SMALL_MESH);
    println!(
        "saved state: {} bytes; stiffness {:?}, output_gain {:?}, dc_filter {:?}, macro_1 {:?}",
        saved.len(),
        state::param(&saved, "stiffness"),
        state::param(&saved, "output_gain"),
        state::param(&saved, "dc_filter"),
        state::param(&saved, "macro_1"),
    );
    assert_eq!(
        state::param(&saved, "output_gain"),
        Some(json!({ "f32": 0.0 }))
    );
    assert_eq!(
        state::param(&saved, "dc_filter"),
        Some(json!({ "bool": false }))
    );

    let at = |s: f64| (s * sr) as usize;
    let score = strikes(&[at(0.0), at(0.5), at(0.9)], STRIKE)
        .note_on(at(0.3) as u32, 55, 0.7)
        .pitch_bend(at(0.6) as u32, 0.25);
    first.deactivate();
    first.activate(sr, 1, block);
    let a = first.render(1.2, block as usize, &score);
    assert_finite_and_sounding(&a.audio, "instance 1");

    let mut second = TestPlugin::new();
    second.load_state(&saved).expect("load the saved state");
    second.activate(sr, 1, block);
    let b = second.render(1.2, block as usize, &score);
    println!(
        "render A peak {:.5} rms {:.5}; render B peak {:.5} rms {:.5}",
        a.audio.peak(),
        a.audio.rms(),
        b.audio.peak(),
        b.audio.rms()
    );
    assert!(
        a.audio.bit_identical(&b.audio),
        "the restored instance differs from frame {:?}",
        a.audio.first_difference(&b.audio)
    );
    for param in first.params() {
        assert_eq!(
            first.param_value(param.id),
            second.param_value(param.id),
            "{} differs after the round trip",
            param.name
        );
    }
    assert_eq!(
        state::json(&second.save_state()),
        state::json(&saved),
        "the restored instance saves a different state"
    );

    // The state really changed the sound: the default model with default parameters differs.
    let mut fresh = TestPlugin::new();
    fresh.activate(sr, 1, block);
    let c = fresh.render(1.2, block as usize, &score);
    assert!(!c.audio.bit_identical(&a.audio));
}

/// A deterministic pseudo-random byte string.
fn noise_bytes(len: usize, mut seed: u64) -> Vec<u8> {
    (0..len)
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 24) as u8
        })
        .collect()
}

#[test]
fn corrupted_states_are_rejected_and_the_model_keeps_playing() {
    let sr = 48_000.0;
    let block = 256usize;
    // Two instances running the same non-default model: one gets the corrupted states, the
    // other is the reference it must keep matching bit for bit.
    let mut victim = plugin_with_model("small-mesh", SMALL_MESH, &[]);
    let mut twin = plugin_with_model("small-mesh", SMALL_MESH, &[]);
    let good = victim.save_state();

    victim.activate(sr, 1, block as u32);
    let reference = victim.render(0.5, block, &strikes(&[0], STRIKE));
    assert_finite_and_sounding(&reference.audio, "reference");
    victim.activate(sr, 1, block as u32);
    twin.activate(sr, 1, block as u32);

    let mut json_garbage = b"{\"params\": {\"stiffness\": ".to_vec();
    json_garbage.extend(noise_bytes(300, 7));
    let mut long_claim = (1u64 << 20).to_le_bytes().to_vec();
    long_claim.extend_from_slice(&good[8..200]);
    let blobs: Vec<(&str, Vec<u8>)> = vec![
        ("truncated to half", good[..good.len() / 2].to_vec()),
        ("truncated inside the length", good[..5].to_vec()),
        ("empty", Vec::new()),
        ("random bytes", noise_bytes(4096, 0x9e37_79b9_7f4a_7c15)),
        (
            "random bytes with a valid length",
            state::blob(&noise_bytes(2000, 42)),
        ),
        ("JSON cut short", state::blob(&json_garbage)),
        ("length beyond the data", long_claim),
        (
            "valid JSON, not a state",
            state::blob(br#"{"hello": [1, 2, 3]}"#),
        ),
        (
            "script with a syntax error",
            state::with_model(
                &good,
                "broken",
                "@o osc 1. 0.1 0.0003 0. 0.\n@in1 frcInput @nowhere\n@@ ) garbage\n",
            ),
        ),
        (
            "script with a bad argument count",
            state::with_model(&good, "short", "@m mass\n@out1 posOutput @m\n"),
        ),
    ];

    let mut t = 0.0;
    for (what, blob) in &blobs {
        let result = victim.load_state(blob);
        println!("{what:>34}: load → {result:?}");
        // Keep playing: strike both and compare.
        let score = strikes(&[0, 5_000], STRIKE);
        let a = victim.render(0.25, block, &score);
        let b = twin.render(0.25, block, &score);
        t += 0.25;
        assert!(
            a.audio.bit_identical(&b.audio),
            "after the {what} state the output differs from the untouched instance from frame \
             {:?} (at {t:.2} s)",
            a.audio.first_difference(&b.audio)
        );
        assert_finite_and_sounding(&a.audio, what);
        let (name, script) = state::model(&victim.save_state()).expect("model in the state");
        assert_eq!(
            name, "small-mesh",
            "{what}: the running model's name changed"
        );
        assert_eq!(
            script, SMALL_MESH,
            "{what}: the running model's script changed"
        );
    }
    assert_eq!(
        state::json(&victim.save_state()),
        state::json(&twin.save_state()),
        "the corrupted loads changed the state"
    );

    // A fresh activation plays the previous model exactly as before.
    victim.activate(sr, 1, block as u32);
    let again = victim.render(0.5, block, &strikes(&[0], STRIKE));
    assert!(
        again.audio.bit_identical(&reference.audio),
        "after the corrupted loads a fresh render differs from frame {:?}",
        again.audio.first_difference(&reference.audio)
    );

    // Corrupted states while inactive leave the model too.
    victim.deactivate();
    for (what, blob) in &blobs {
        let result = victim.load_state(blob);
        println!("{what:>34} (inactive): load → {result:?}");
    }
    victim.activate(sr, 1, block as u32);
    let after = victim.render(0.5, block, &strikes(&[0], STRIKE));
    assert!(
        after.audio.bit_identical(&reference.audio),
        "after corrupted loads while inactive the render differs from frame {:?}",
        after.audio.first_difference(&reference.audio)
    );
}

// ---------------------------------------------------------------------------------------------
// Process status
// ---------------------------------------------------------------------------------------------

#[test]
fn process_status_lets_the_host_sleep_only_when_quiet() {
    let sr = 48_000.0;
    let block = 512usize;
    let mut plugin = struck_default();
    plugin.activate(sr, 1, block as u32);

    // Long silence: the plugin may be put to sleep.
    let quiet = plugin.render(2.0, block, &Score::new());
    let switch = quiet
        .statuses
        .iter()
        .find(|(_, s)| *s == ProcessStatus::ContinueIfNotQuiet)
        .map(|(f, _)| *f as f64 / sr);
    println!(
        "silence: first status {:?}, ContinueIfNotQuiet from {switch:?} s, last {:?}",
        quiet.statuses[0].1,
        quiet.last_status()
    );
    assert_eq!(quiet.last_status(), Some(ProcessStatus::ContinueIfNotQuiet));

    // Ringing: the plugin must keep being processed.
    let ring = plugin.render(0.5, block, &strikes(&[0], STRIKE));
    assert_finite_and_sounding(&ring.audio, "strike");
    for (frame, status) in &ring.statuses {
        assert_eq!(
            *status,
            ProcessStatus::Continue,
            "status while ringing at {:.3} s",
            *frame as f64 / sr
        );
    }

    // It asks to continue until the tail is below −120 dBFS for a second, then lets go.
    let mut elapsed = 0.5;
    let mut quiet_from = None;
    while elapsed < 60.0 {
        let out = plugin.render(1.0, block, &Score::new());
        let peak = out.audio.peak();
        if out.last_status() == Some(ProcessStatus::ContinueIfNotQuiet) {
            let (f, _) = out
                .statuses
                .iter()
                .find(|(_, s)| *s == ProcessStatus::ContinueIfNotQuiet)
                .expect("status");
            quiet_from = Some(elapsed + *f as f64 / sr);
            println!("second {elapsed:.1}: peak {peak:e}, quiet status");
            break;
        }
        if (elapsed as usize).is_multiple_of(5) {
            println!(
                "second {elapsed:.1}: peak {peak:e}, status {:?}",
                out.last_status()
            );
        }
        elapsed += 1.0;
    }
    let quiet_from = quiet_from.expect("the plugin never reported CONTINUE_IF_NOT_QUIET");
    println!("after a strike: ContinueIfNotQuiet from {quiet_from:.2} s");

    // A single block after a strike reports CONTINUE at once.
    let impulse = [STRIKE];
    let out = plugin.process(&Block {
        frames: 1,
        sidechain: &[&impulse, &[0.0]],
        ..Block::default()
    });
    assert_eq!(out.status, ProcessStatus::Continue);
    let status = plugin.process(&Block::silent(block)).status;
    assert_eq!(
        status,
        ProcessStatus::Continue,
        "ringing again after the strike"
    );
}

/// The largest difference between the left channels of two renders.
fn left_difference(a: &Stereo, b: &Stereo) -> f32 {
    a.left
        .iter()
        .zip(&b.left)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

/// Every preset compiles in the plugin (see [`plugin_with_model`]) and, played in the
/// instrument layout as its header says, moves out1 (the left channel) through the whole
/// plugin: the rule and the bars of `every_preset_moves_its_first_output_when_played`
/// (plugin/tests/models.rs), which checks the same on the engine the plugin prepares. A
/// full-velocity note held down for presets with a force input or exciters (a key bows or
/// plucks them), else a sidechain ramp down at 3e-5 per sample on both channels. The bar is the engine test's 1e-6
/// raised by the default +24 dB output gain and rounded down: 1e-5.
#[test]
fn every_preset_compiles_and_moves_out1_when_played() {
    // Some presets are loud enough to trip the explosion guard: run in a process of its own.
    if !run_isolated("every_preset_compiles_and_moves_out1_when_played") {
        return;
    }
    let sr = 48_000.0;
    let presets = presets();
    assert!(presets.len() >= 4, "presets: {presets:?}");
    let mut still = Vec::new();
    for (name, script) in &presets {
        // As a project saved before the automatic levels (Output Gain +24 dB): the bar is in
        // the model's units.
        let mut plugin =
            plugin_with_model(name, script, &[("output_gain", json!({ "f32": 24.0 }))]);
        // A key plays a preset with a force input or exciters (a bow, a pluck): held down.
        let struck = script.lines().any(|l| {
            !l.trim_start().starts_with('#')
                && (l.contains("frcInput") || l.trim_start().starts_with("~exciter"))
        });
        let score = if struck {
            Score::new().note_on(0, 60, 1.0)
        } else {
            (0..sr as usize).fold(Score::new(), |s, i| {
                let x = -3e-5 * i as f32;
                s.sidechain_sample(i, x, x)
            })
        };
        plugin.activate(sr, 1, 512);
        let out = plugin.render(1.0, 512, &score);
        assert!(out.audio.is_finite(), "{name}: non-finite output");
        let first = out.audio.left[0];
        let excursion = out
            .audio
            .left
            .iter()
            .fold(0.0f32, |m, x| m.max((x - first).abs()));
        println!(
            "{name:>22}: {} out1 excursion {excursion:.3e}, peak {:.5}, rms {:.5}",
            if struck { "note 60:" } else { "ramp:   " },
            out.audio.peak(),
            out.audio.rms(),
        );
        if !(excursion > 1e-5) {
            still.push(format!("{name}: out1 excursion {excursion:e}"));
        }
        retire(plugin);
    }
    assert!(
        still.is_empty(),
        "out1 does not move when played:\n{}",
        still.join("\n")
    );
}

#[test]
fn struck_presets_sound_on_a_midi_note() {
    // A note-on strikes the model's first force input with force 0.02 × velocity. The presets
    // whose in1 pushes a hammer onto the resonator must answer a full-velocity note at default
    // settings on out1 (the left channel, the resonator): compared with the same render
    // without the note.
    if !run_isolated("struck_presets_sound_on_a_midi_note") {
        return;
    }
    let sr = 48_000.0;
    let struck = [
        "string-1000",
        "mesh-15x15",
        "mesh-25x20",
        "hammer-oscillator",
    ];
    let mut silent = Vec::new();
    for (name, script) in presets()
        .iter()
        .filter(|(n, _)| struck.contains(&n.as_str()))
    {
        let mut plugin = plugin_with_model(name, script, &[]);
        plugin.activate(sr, 1, 512);
        let without = plugin.render(0.5, 512, &Score::new());
        plugin.activate(sr, 1, 512);
        let with = plugin.render(0.5, 512, &Score::new().note_on(0, 60, 1.0));
        assert!(with.audio.is_finite(), "{name}: non-finite output");
        let difference = left_difference(&with.audio, &without.audio);
        println!("{name:>18}: note 60 changes out1 by up to {difference:.5}");
        if !(difference > 1e-3) {
            silent.push(name.clone());
        }
        retire(plugin);
    }
    assert!(
        silent.is_empty(),
        "a full-velocity MIDI note does not sound on {silent:?}"
    );
}

/// An unstable model: an oscillator with a negative stiffness, displaced at rest, runs away at
/// once and again after every reset. No stiffness gain makes it stable (the exact limit, which
/// holds a too-stiff model below its own stiffness, does not apply to a negative one), so only
/// the explosion guard can catch it.
const EXPLODING: &str = "\
# An oscillator with a negative stiffness, displaced at rest (end-to-end guard tests).
@o osc 1. -2. 0. 1. 0.
@out1 posOutput @o
";

#[test]
fn destroying_instances_after_a_guard_trip_does_not_abort() {
    // Two instances in one host. Instance A runs an exploding model, so its guard trips and
    // queues a report on nice-plug's background thread, which every instance in the process
    // shares; A is destroyed, possibly with reports still queued; later B is destroyed. A host
    // must survive this. Whether a report is still queued when A goes away is a race, so A is
    // created, tripped and destroyed many times while B lives.
    if !run_isolated("destroying_instances_after_a_guard_trip_does_not_abort") {
        return;
    }
    let sr = 48_000.0;
    let mut b = struck_default();
    b.activate(sr, 1, 256);
    let before = b.render(0.2, 256, &strikes(&[0], STRIKE));
    assert_finite_and_sounding(&before.audio, "instance B");
    let cycles = 40;
    for cycle in 0..cycles {
        let mut a = plugin_with_model("exploding", EXPLODING, &[]);
        // Large blocks: each process() call queues a report per 16-sample chunk.
        a.activate(sr, 1, 4096);
        let out = a.render(0.2, 4096, &Score::new());
        assert!(out.audio.is_finite());
        // The guard mutes the rest of every chunk it trips in: mostly exact zeros.
        let zeros = out.audio.left.iter().filter(|x| **x == 0.0).count();
        if cycle == 0 {
            println!(
                "instance A (exploding model): {zeros} of {} samples muted by the guard",
                out.audio.left.len()
            );
        }
        assert!(
            zeros > out.audio.left.len() / 2,
            "the exploding model did not trip the guard ({zeros} zeros)"
        );
        // A is destroyed here, right after its last trips.
    }
    println!("{cycles} instances tripped the guard and were destroyed while B lived");
    let after = b.render(0.2, 256, &strikes(&[0], STRIKE));
    assert_finite_and_sounding(&after.audio, "instance B after the others are gone");
    b.deactivate();
    println!("destroying instance B");
    drop(b);
    println!("all instances destroyed without aborting");
}

/// The first frame of a run of at least `run` frames of exact digital silence (both channels)
/// after the output has started sounding. A struck membrane decays for tens of seconds; exact
/// zeros after the strike mean the explosion guard muted and reset it.
fn muted_after_sound(audio: &Stereo, run: usize) -> Option<usize> {
    let start = audio
        .left
        .iter()
        .zip(&audio.right)
        .position(|(l, r)| *l != 0.0 || *r != 0.0)?;
    let mut zeros = 0;
    for i in start..audio.len() {
        if audio.left[i] == 0.0 && audio.right[i] == 0.0 {
            zeros += 1;
            if zeros == run {
                return Some(i + 1 - run);
            }
        } else {
            zeros = 0;
        }
    }
    None
}

#[test]
fn combined_controls_keep_the_model_stable() {
    // The plugin clamps Stiffness and Damping to what the model's stability analysis allows,
    // and binds the macros to the model's params within stable ranges. Every combination of
    // controls must then stay stable: the explosion guard must never have to step in.
    if !run_isolated("combined_controls_keep_the_model_stable") {
        return;
    }
    let sr = 48_000.0;
    let probe = TestPlugin::new().params();
    let id = |name: &str| probe.iter().find(|p| p.name == name).expect(name).id;
    let (stiffness, tune, macro1) = (id("Stiffness"), id("Tune"), id("Macro 1"));
    // CLAP values: Stiffness +1 octave = 0.625, +0.5 = 0.5625; Tune +12 = 0.75, +3 = 0.5625.
    /// A name, CLAP parameter values set before activation, and an optional note.
    type Case = (&'static str, Vec<(ClapId, f64)>, Option<u8>);
    let cases: [Case; 4] = [
        ("Macro 1 (K) max", vec![(macro1, 1.0)], None),
        (
            "Macro 1 (K) max, Stiffness ×2",
            vec![(macro1, 1.0), (stiffness, 0.625)],
            None,
        ),
        (
            "Macro 1 (K) max, Tune +12 st",
            vec![(macro1, 1.0), (tune, 0.75)],
            None,
        ),
        (
            "Macro 1 0.8, Stiffness ×1.41, Tune +3 st, note 64",
            vec![(macro1, 0.8), (stiffness, 0.5625), (tune, 0.5625)],
            Some(64),
        ),
    ];
    let mut exploded = Vec::new();
    for (what, values, note) in cases {
        let mut plugin = struck_default();
        plugin.flush_params(&values);
        plugin.activate(sr, 1, 512);
        let mut score = strikes(&[0], STRIKE);
        if let Some(key) = note {
            score = score.note_on(2_400, key, 0.7);
        }
        let out = plugin.render(1.0, 512, &score);
        assert!(out.audio.is_finite(), "{what}: non-finite output");
        assert!(out.audio.peak() <= 1.0, "{what}: beyond ±1");
        let muted = muted_after_sound(&out.audio, 64);
        println!(
            "mesh-15x15, {what}: peak {:.4}, rms {:.5}, muted from {}",
            out.audio.peak(),
            out.audio.rms(),
            muted.map_or("never".to_string(), |f| format!("{:.4} s", f as f64 / sr))
        );
        if let Some(f) = muted {
            exploded.push(format!("{what} (muted at frame {f})"));
        } else if !(out.audio.peak() > 1e-3) {
            exploded.push(format!("{what} (silent from the start)"));
        }
        retire(plugin);
    }
    assert!(
        exploded.is_empty(),
        "the guard had to reset the model: {exploded:?}"
    );
}

#[test]
fn a_loud_but_stable_model_is_not_muted() {
    // Output Gain goes to +60 dB and the soft ceiling keeps the output below ±1. A stable model
    // struck within its documented range must sound at the default +24 dB, and raising the
    // gain must never make it quieter.
    if !run_isolated("a_loud_but_stable_model_is_not_muted") {
        return;
    }
    let sr = 48_000.0;
    // The hammer oscillator's out2 is the hammer, which rests at position 1: 15.85 at
    // +24 dB, just under the blast level (16). The model's example strike (-0.1) and one
    // twice as hard throw the hammer back up past it.
    let cases = [
        ("hammer-oscillator", HAMMER_OSCILLATOR, 30.0, -0.1f32),
        ("hammer-oscillator", HAMMER_OSCILLATOR, 30.0, -0.2),
        (
            "mesh-15x15",
            include_str!("../../models/mesh-15x15.mdl"),
            60.0,
            STRIKE,
        ),
    ];
    let mut muted = Vec::new();
    for (name, script, loud_db, strike) in cases {
        let at = (0.1 * sr) as usize;
        let out1_rms = |gain_db: f64| {
            let gain = [("output_gain", json!({ "f32": gain_db }))];
            let mut plugin = plugin_with_model(name, script, &gain);
            plugin.activate(sr, 1, 512);
            let out = plugin.render(0.6, 512, &strikes(&[at], strike));
            assert!(out.audio.is_finite());
            assert!(out.audio.peak() <= 1.0);
            let left = &out.audio.left[at..];
            let rms =
                (left.iter().map(|x| (*x as f64).powi(2)).sum::<f64>() / left.len() as f64).sqrt();
            let peak = left.iter().fold(0.0f32, |m, x| m.max(x.abs()));
            println!(
                "{name} at {gain_db:+} dB, strike {strike}: out1 after the strike peak \
                 {peak:.4}, rms {rms:.5}"
            );
            retire(plugin);
            rms
        };
        let normal = out1_rms(24.0);
        let loud = out1_rms(loud_db);
        if !(normal > 1e-3) {
            muted.push(format!(
                "{name}: out1 silent at +24 dB after a {strike} strike"
            ));
        } else if !(loud >= normal) {
            muted.push(format!(
                "{name}: out1 rms {loud:.5} at {loud_db:+} dB < {normal:.5} at +24 dB"
            ));
        }
    }
    assert!(muted.is_empty(), "stable models muted: {muted:?}");
}
