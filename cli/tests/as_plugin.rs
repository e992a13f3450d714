//! `ressort render --as-plugin`: the WAV file is what `ressort_engine::instrument` plays (the
//! plugin's own signal path; tests/tests/instrument.rs checks the plugin against it), MIDI
//! files play at their times, bad options are clear errors, and the scripts that once froze a
//! host end.

use midly::num::{u15, u28, u4, u7};
use midly::{Format, Header, MidiMessage, Smf, Timing, TrackEvent, TrackEventKind};
use ressort_engine::instrument::{self, Controls, Event, Instrument, Timed, MAX_HOST_INPUTS};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// An oscillator with a hammer, a `param` on Macro 1 and a sidechain force input.
const MODEL: &str = "\
@K param 0.02
@o osc 1. K 0.0001 0. 0.
@g ground 0.1
@h mass 1. 0.1 0.
@hs springDamper @g @h 0.0001 0.01
@hit contact @o @h 0.1 0.001
@in1 frcInput @h
@out1 posOutput @o
";

const SR: u32 = 48_000;

fn ressort(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ressort"))
        .args(args)
        .output()
        .expect("run ressort")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn write_wav(path: &Path, channels: &[Vec<f32>]) {
    let spec = hound::WavSpec {
        channels: channels.len() as u16,
        sample_rate: SR,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let mut w = hound::WavWriter::create(path, spec).unwrap();
    for i in 0..channels[0].len() {
        for c in channels {
            w.write_sample(c[i]).unwrap();
        }
    }
    w.finalize().unwrap();
}

/// The WAV's channels.
fn read_wav(path: &Path) -> Vec<Vec<f32>> {
    let mut r = hound::WavReader::open(path).unwrap();
    let n = r.spec().channels as usize;
    let all: Vec<f32> = r.samples::<f32>().map(Result::unwrap).collect();
    (0..n)
        .map(|c| all.iter().skip(c).step_by(n).copied().collect())
        .collect()
}

/// A one-track MIDI file at 480 ticks per beat, 120 bpm: (delta ticks, key, velocity).
fn midi_file(path: &Path, notes: &[(u32, u8, u8)]) {
    let track = notes
        .iter()
        .map(|&(delta, key, vel)| TrackEvent {
            delta: u28::new(delta),
            kind: TrackEventKind::Midi {
                channel: u4::new(0),
                message: MidiMessage::NoteOn {
                    key: u7::new(key),
                    vel: u7::new(vel),
                },
            },
        })
        .collect();
    let smf = Smf {
        header: Header::new(Format::SingleTrack, Timing::Metrical(u15::new(480))),
        tracks: vec![track],
    };
    smf.save(path).unwrap();
}

/// The instrument run directly on the same score.
fn instrument_render(
    controls: &Controls,
    events: &[(u32, Event)],
    sidechain: &[Vec<f32>],
    frames: usize,
) -> [Vec<f32>; 2] {
    let model = instrument::prepare("m", MODEL, SR as f64).unwrap();
    let mut inst = Instrument::new(SR as f64, *controls);
    inst.set_model(Box::new(model));
    let (mut l, mut r) = (vec![0.0f32; frames], vec![0.0f32; frames]);
    let mut host_in: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
    for (c, ch) in sidechain.iter().enumerate() {
        host_in[2 + c] = Some(ch);
    }
    let mut ev = events.iter().map(|&(t, e)| Timed::new(t, e));
    let mut out: [&mut [f32]; 2] = [&mut l, &mut r];
    inst.process(frames, &host_in, false, &mut ev, controls, &mut out);
    [l, r]
}

fn paths(dir: &Path) -> (PathBuf, PathBuf) {
    let model = dir.join("m.mdl");
    std::fs::write(&model, MODEL).unwrap();
    (model, dir.join("out.wav"))
}

#[test]
fn render_as_plugin_writes_what_the_instrument_plays() {
    let dir = tempfile::tempdir().unwrap();
    let (model, out) = paths(dir.path());
    let frames = 24_000;
    let mut left = vec![0.0f32; frames];
    left[7_001] = -0.2;
    let right = vec![0.0f32; frames];
    let sc = dir.path().join("sc.wav");
    write_wav(&sc, &[left.clone(), right.clone()]);
    let run = ressort(&[
        "render",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--sample-rate",
        "48000",
        "--samples",
        "24000",
        "--note",
        "60:0.9",
        "--note",
        "67:0.5@0.25",
        "--sidechain",
        sc.to_str().unwrap(),
        "--control",
        "stiffness=2",
        "--control",
        "output-gain=-6",
        "--set",
        "K=0.03",
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    let wav = read_wav(&out);
    assert_eq!(wav.len(), 2, "stereo, as the plugin's main output");

    let mut controls = Controls::DEFAULT;
    controls.stiffness_octaves = 1.0;
    controls.output_db = -6.0;
    let prepared = instrument::prepare("m", MODEL, SR as f64).unwrap();
    let binding = prepared.facts().macros[0].clone().expect("K is on Macro 1");
    controls.macros[0] = binding.normalized_of(0.03);
    let events = [
        (
            0,
            Event::NoteOn {
                channel: 0,
                voice_id: None,
                note: 60,
                velocity: 0.9,
            },
        ),
        (
            12_000,
            Event::NoteOn {
                channel: 0,
                voice_id: None,
                note: 67,
                velocity: 0.5,
            },
        ),
    ];
    let direct = instrument_render(&controls, &events, &[left, right], frames);
    let peak = direct[0].iter().fold(0.0f32, |m, x| m.max(x.abs()));
    println!("peak {peak}");
    assert!(peak > 1e-3, "the score must sound");
    assert_eq!(wav[0], direct[0], "left differs from the instrument");
    assert_eq!(wav[1], direct[1], "right differs from the instrument");
}

#[test]
fn render_midi_plays_each_note_at_its_time() {
    let dir = tempfile::tempdir().unwrap();
    let (model, out) = paths(dir.path());
    let mid = dir.path().join("phrase.mid");
    // Beat 1 (0.5 s at 120 bpm): note 60; beat 2: note 72, softer.
    midi_file(&mid, &[(480, 60, 100), (480, 72, 60)]);
    let run = ressort(&[
        "render",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--sample-rate",
        "48000",
        "--midi",
        mid.to_str().unwrap(),
        "--control",
        "output-gain=-12",
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    let wav = read_wav(&out);
    // Until 2 s after the last event.
    assert_eq!(wav[0].len(), 48_000 + 2 * 48_000);
    let before = wav[0][..24_000].iter().fold(0.0f32, |m, x| m.max(x.abs()));
    let after = wav[0][24_000..26_000]
        .iter()
        .fold(0.0f32, |m, x| m.max(x.abs()));
    println!("peak before the first note {before:e}, after {after:e}");
    assert_eq!(before, 0.0, "nothing sounds before the first note");
    assert!(after > 1e-3, "the first note must sound at 0.5 s");

    let direct = instrument_render(
        &Controls {
            output_db: -12.0,
            ..Controls::DEFAULT
        },
        &[
            (
                24_000,
                Event::NoteOn {
                    channel: 0,
                    voice_id: None,
                    note: 60,
                    velocity: 100.0 / 127.0,
                },
            ),
            (
                48_000,
                Event::NoteOn {
                    channel: 0,
                    voice_id: None,
                    note: 72,
                    velocity: 60.0 / 127.0,
                },
            ),
        ],
        &[],
        wav[0].len(),
    );
    assert_eq!(wav[0], direct[0]);
}

#[test]
fn bad_plugin_options_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let (model, out) = paths(dir.path());
    let garbage = dir.path().join("garbage.mid");
    std::fs::write(&garbage, b"MThd not really").unwrap();
    let m = model.to_str().unwrap();
    let o = out.to_str().unwrap();
    let g = garbage.to_str().unwrap();
    for (args, expected) in [
        (vec!["--note", "200"], "--note 200: expected KEY"),
        (vec!["--note", "60:2"], "--note 60:2"),
        (vec!["--control", "colour=3"], "unknown control `colour`"),
        (
            vec!["--control", "stiffness=-1"],
            "a factor must be positive",
        ),
        (vec!["--control", "macro17=0.5"], "macro slots are macro1"),
        (vec!["--midi", g], "not a readable MIDI file"),
        (
            vec!["--as-plugin", "--impulse", "in1=-0.1"],
            "--input and --impulse feed model inputs directly",
        ),
        (vec!["--as-plugin", "--set", "Q=1"], "unknown parameter `Q`"),
        (
            vec!["--cc", "200=macro1"],
            "--cc 200=macro1: expected CC=macroN",
        ),
        (vec!["--cc", "74=macro0"], "expected CC=macroN"),
    ] {
        let mut all = vec!["render", m, "-o", o];
        all.extend(args.iter().copied());
        let run = ressort(&all);
        let err = text(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
    }
}

#[test]
fn a_mapped_controller_in_a_midi_file_moves_its_macro() {
    let dir = tempfile::tempdir().unwrap();
    let (model, out) = paths(dir.path());
    let mid = dir.path().join("cc.mid");
    let track = vec![
        TrackEvent {
            delta: u28::new(0),
            kind: TrackEventKind::Midi {
                channel: u4::new(0),
                message: MidiMessage::Controller {
                    controller: u7::new(74),
                    value: u7::new(127),
                },
            },
        },
        TrackEvent {
            delta: u28::new(0),
            kind: TrackEventKind::Midi {
                channel: u4::new(0),
                message: MidiMessage::NoteOn {
                    key: u7::new(60),
                    vel: u7::new(100),
                },
            },
        },
    ];
    Smf {
        header: Header::new(Format::SingleTrack, Timing::Metrical(u15::new(480))),
        tracks: vec![track],
    }
    .save(&mid)
    .unwrap();
    let render = |extra: &[&str]| {
        let mut args = vec![
            "render",
            model.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--sample-rate",
            "48000",
            "--samples",
            "12000",
            "--midi",
            mid.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let run = ressort(&args);
        assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
        read_wav(&out)
    };
    let unmapped = render(&[]);
    let mapped = render(&["--cc", "74=macro1"]);
    let direct = instrument_render(
        &Controls::DEFAULT,
        &[
            (0, Event::Controller { cc: 74, value: 1.0 }),
            (
                0,
                Event::NoteOn {
                    channel: 0,
                    voice_id: None,
                    note: 60,
                    velocity: 100.0 / 127.0,
                },
            ),
        ],
        &[],
        12_000,
    );
    assert_ne!(
        mapped[0], unmapped[0],
        "CC 74 on Macro 1 must change the sound"
    );
    // The direct render has no map: it equals the unmapped file.
    assert_eq!(direct[0], unmapped[0]);
}

/// The two scripts that froze a host's state load and panicked inside faer (issue 40): Fretted
/// String with its osc's damping at 10³⁰⁸, and with a link's damping at 0 besides. `ressort
/// modes` and `render --as-plugin` end on both, each within [`EXTREME_LIMIT_S`], without a
/// panic, and the render is finite.
#[test]
fn the_scripts_that_froze_a_host_end_in_modes_and_render() {
    const EXTREME_LIMIT_S: f64 = 120.0;
    let preset = include_str!("../../models/fretted-string.mdl");
    let huge = preset.replace(
        "@low_m60 osc low_M 0 low_Zosc 0. 0.",
        "@low_m60 osc low_M 0 1e308 0. 0.",
    );
    let both = huge.replace(
        "@low_r37 springDamper @low_m35 @low_m36 low_K low_Z",
        "@low_r37 springDamper @low_m35 @low_m36 low_K 0",
    );
    assert!(
        huge != preset && both != huge,
        "the preset still has the lines this test edits"
    );
    let dir = tempfile::tempdir().unwrap();
    let mut longest = 0.0f64;
    for (i, script) in [huge, both].iter().enumerate() {
        let model = dir.path().join(format!("fretted-{i}.mdl"));
        let out = dir.path().join(format!("fretted-{i}.wav"));
        std::fs::write(&model, script).unwrap();
        let m = model.to_str().unwrap();
        for args in [
            vec!["modes", m, "--count", "10"],
            vec![
                "render",
                m,
                "--as-plugin",
                "--seconds",
                "0.3",
                "--note",
                "60",
                "-o",
                out.to_str().unwrap(),
            ],
        ] {
            let start = std::time::Instant::now();
            let mut child = Command::new(env!("CARGO_BIN_EXE_ressort"))
                .args(&args)
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("run ressort");
            let status = loop {
                if let Some(status) = child.try_wait().unwrap() {
                    break status;
                }
                if start.elapsed().as_secs_f64() > EXTREME_LIMIT_S {
                    let _ = child.kill();
                    panic!(
                        "`ressort {}` on variant {i} still runs after {EXTREME_LIMIT_S} s",
                        args[0]
                    );
                }
                std::thread::sleep(std::time::Duration::from_millis(20));
            };
            let output = child.wait_with_output().unwrap();
            let stderr = text(&output.stderr);
            assert!(
                !stderr.contains("panicked"),
                "`ressort {}` panicked: {stderr}",
                args[0]
            );
            assert!(
                status.success(),
                "`ressort {}` on variant {i}: {stderr}",
                args[0]
            );
            longest = longest.max(start.elapsed().as_secs_f64());
        }
        let wav = read_wav(&out);
        assert!(
            wav.iter().flatten().all(|s| s.is_finite()),
            "variant {i} renders finite"
        );
    }
    println!("both variants end in `modes` and `render --as-plugin`; longest {longest:.2} s");
}
