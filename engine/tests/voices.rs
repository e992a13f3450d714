//! Polyphony in the instrument: every note its own copy of the model. A chord is the sum of
//! its notes, a bank of one voice is the monophonic engine, voices free themselves at rest,
//! stealing does not click, the sustain pedal holds notes, and the motion view shows the
//! most recently struck voice.

use ressort_engine::instrument::{
    self, Controls, Conventions, Event, Instrument, Timed, MAX_HOST_INPUTS,
};

const SR: f64 = 48_000.0;

/// An oscillator struck through a hammer (a contact: each voice is nonlinear on its own),
/// shared with the plugin's polyphony tests.
const STRUCK: &str = include_str!("../../tests/models/struck-oscillator.mdl");

/// A strongly damped oscillator struck directly: it comes to rest within a second.
const DAMPED: &str = "\
@o osc 1. 0.02 0.002 0. 0.
@in1 frcInput @o
@out1 posOutput @o
";

struct Render {
    left: Vec<f32>,
    ended: Vec<u8>,
    sounding: Vec<usize>,
}

fn render(
    script: &str,
    voices: usize,
    controls: Controls,
    events: &[(u32, Event)],
    frames: usize,
) -> Render {
    render_with(script, voices, controls, events, frames, None)
}

/// With `sidechain`, a signal on the sidechain's first channel (`@in1` in the instrument
/// layout).
fn render_with(
    script: &str,
    voices: usize,
    controls: Controls,
    events: &[(u32, Event)],
    frames: usize,
    sidechain: Option<&[f32]>,
) -> Render {
    render_as(
        Conventions::Musical,
        script,
        voices,
        controls,
        events,
        frames,
        sidechain,
    )
}

/// [`render_with`] under the given conventions: the legacy ones play the model's own units,
/// without the automatic trims (the tests that read a force's displacement need them).
fn render_as(
    conventions: Conventions,
    script: &str,
    voices: usize,
    controls: Controls,
    events: &[(u32, Event)],
    frames: usize,
    sidechain: Option<&[f32]>,
) -> Render {
    let mut model = instrument::prepare_with("test", script, SR, conventions).unwrap();
    model.set_voices(voices);
    let mut inst = Instrument::new(SR, controls);
    inst.set_model(Box::new(model));
    play(&mut inst, controls, events, frames, sidechain)
}

/// Plays `events` on `inst` in blocks of 256 frames, noting the notes whose voices ended and
/// the voices sounding after each block.
fn play(
    inst: &mut Instrument,
    controls: Controls,
    events: &[(u32, Event)],
    frames: usize,
    sidechain: Option<&[f32]>,
) -> Render {
    let block = 256;
    let mut left = vec![0.0f32; frames];
    let mut right = vec![0.0f32; frames];
    let mut ended = Vec::new();
    let mut sounding = Vec::new();
    let mut start = 0;
    while start < frames {
        let n = block.min(frames - start);
        let mut ev = events
            .iter()
            .filter(|(t, _)| (*t as usize) >= start && (*t as usize) < start + n)
            .map(|&(t, e)| Timed::new(t - start as u32, e));
        let mut host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
        host[2] = sidechain.map(|s| &s[start..start + n]);
        let mut out: [&mut [f32]; 2] = [&mut left[start..start + n], &mut right[start..start + n]];
        inst.process(n, &host, false, &mut ev, &controls, &mut out);
        inst.drain_ended(|e| ended.push(e.note));
        sounding.push(inst.voice_count().0);
        start += n;
    }
    Render {
        left,
        ended,
        sounding,
    }
}

/// Below the soft ceiling and the DC filter's reach: the output stage is linear.
fn quiet() -> Controls {
    Controls {
        output_db: -12.0,
        ..Controls::DEFAULT
    }
}

fn peak(x: &[f32]) -> f32 {
    x.iter().fold(0.0f32, |m, v| m.max(v.abs()))
}

/// A string macro struck directly through connection points: its voices run in lanes.
const STRING: &str = "\
@s string 24 1. 0.1 0.0005 0. 0.
@in1 frcInput [@s 0.3]
@out1 posOutput [@s 0.7]
";

/// A string macro of 400 nodes: one voice fills the vectors, so its voices are whole engines
/// (`MAX_LANE_POINTS`).
const LONG_STRING: &str = "\
@s string 400 1. 0.1 0.0005 0. 0.
@in1 frcInput [@s 0.3]
@out1 posOutput [@s 0.7]
";

/// A pre-tensioned string in space (3-D spec §4.1), struck across its length through a
/// connection point and heard transversally: its voices run in 3-D lanes.
const STRING_3D: &str = "\
~dim 3
@s string3 24 1. 0.1 0.0005 [0 0 0] [24 0 0] [0.95*auto] 'Zo=1e-5'
@in1 frcInput [@s 0.3] [0 0.6 0.8]
@out1 posOutput [@s 0.7] [0 0 1]
";

#[test]
fn small_models_run_in_voice_lanes_and_large_ones_on_engines() {
    use ressort_engine::instrument::voices::Copies;
    let bank_of = |script: &str| {
        let mut m = instrument::prepare("test", script, SR).unwrap();
        m.set_voices(8);
        m.bank.unwrap().copies
    };
    assert!(matches!(bank_of(STRUCK), Copies::Lanes(_)));
    assert!(matches!(bank_of(DAMPED), Copies::Lanes(_)));
    assert!(matches!(bank_of(STRING), Copies::Lanes(_)));
    assert!(matches!(bank_of(LONG_STRING), Copies::Engines(_)));
    assert!(matches!(bank_of(STRING_3D), Copies::Lanes(_)));
}

#[test]
fn a_chord_is_the_sum_of_its_notes() {
    chord_is_the_sum_of_its_notes(STRUCK);
    chord_is_the_sum_of_its_notes(STRING);
    chord_is_the_sum_of_its_notes(LONG_STRING);
    chord_is_the_sum_of_its_notes(STRING_3D);
}

fn chord_is_the_sum_of_its_notes(script: &str) {
    let notes = [(0u32, 60u8), (12_000, 64), (24_001, 67)];
    let frames = 48_000;
    let chord: Vec<(u32, Event)> = notes
        .iter()
        .map(|&(t, n)| (t, Event::note_on(n, 0.9)))
        .collect();
    let together = render(script, 8, quiet(), &chord, frames).left;
    let mut sum = vec![0.0f64; frames];
    for &(t, n) in &notes {
        let alone = render(script, 8, quiet(), &[(t, Event::note_on(n, 0.9))], frames).left;
        for (s, x) in sum.iter_mut().zip(&alone) {
            *s += *x as f64;
        }
    }
    let p = peak(&together) as f64;
    let err = together
        .iter()
        .zip(&sum)
        .fold(0.0f64, |m, (a, b)| m.max((*a as f64 - b).abs()));
    println!(
        "chord peak {p:.4}, largest difference from the sum {err:.3e} ({:.2e} of the peak)",
        err / p
    );
    assert!(
        p > 1e-3 && p < 0.5,
        "the chord must sound below the ceiling's knee ({p})"
    );
    assert!(err <= 1e-6 * p, "{err} > 1e-6 × {p}");
}

#[test]
fn a_bank_of_one_note_plays_the_monophonic_engine() {
    // One note from rest: a voice of the bank is the engine itself, to the bit.
    let note = [(100u32, Event::note_on(60, 0.8))];
    for script in [STRUCK, STRING, LONG_STRING, STRING_3D] {
        let mono = render(script, 1, quiet(), &note, 24_000).left;
        let poly = render(script, 4, quiet(), &note, 24_000).left;
        assert!(peak(&mono) > 1e-3);
        assert_eq!(mono, poly);
    }
}

#[test]
fn voices_free_themselves_once_at_rest() {
    let events: Vec<(u32, Event)> = (0..6)
        .map(|i| (i * 2_400, Event::note_on(55 + i as u8, 1.0)))
        .collect();
    let r = render(DAMPED, 8, quiet(), &events, 3 * 48_000);
    let most = r.sounding.iter().copied().max().unwrap();
    println!(
        "most voices sounding {most}; at the end {}; ended {:?}",
        r.sounding.last().unwrap(),
        r.ended
    );
    assert_eq!(most, 6);
    assert_eq!(
        *r.sounding.last().unwrap(),
        0,
        "every voice must free itself"
    );
    let mut ended = r.ended.clone();
    ended.sort_unstable();
    assert_eq!(ended, [55, 56, 57, 58, 59, 60], "each voice ends once");
}

#[test]
fn stealing_a_voice_makes_no_click() {
    // Two voices, three notes: the third steals the quieter of the first two, which fades out
    // over 5 ms instead of stopping. The difference from a bank with room for all three is
    // minus the stolen voice times (1 − its fade gain): it must change smoothly, where a cut
    // would jump by the voice's whole value.
    let events = [
        (0u32, Event::note_on(60, 1.0)),
        (4_800, Event::note_on(64, 1.0)),
        (9_600, Event::note_on(67, 1.0)),
    ];
    let frames = 24_000;
    let stolen = render(STRUCK, 2, quiet(), &events, frames);
    let roomy = render(STRUCK, 3, quiet(), &events, frames);
    assert_eq!(stolen.ended.len(), 1, "one voice was stolen");
    assert!(stolen.sounding.iter().all(|&n| n <= 2));
    let victim = stolen.ended[0];
    let at = events
        .iter()
        .find(|(_, e)| *e == Event::note_on(victim, 1.0))
        .unwrap()
        .0;
    let alone = render(
        STRUCK,
        3,
        quiet(),
        &[(at, Event::note_on(victim, 1.0))],
        frames,
    )
    .left;
    let d: Vec<f32> = stolen
        .left
        .iter()
        .zip(&roomy.left)
        .map(|(a, b)| a - b)
        .collect();
    let step = d.windows(2).fold(0.0f32, |m, w| m.max((w[1] - w[0]).abs()));
    let level = peak(&alone[9_000..10_200]);
    println!(
        "note {victim} stolen; its level there {level:.3e}; largest step of the difference \
         {step:.3e} ({:.1} % of it)",
        100.0 * step / level
    );
    assert!(
        level > 1e-3,
        "the stolen voice must still sound when it is stolen"
    );
    assert!(step < 0.2 * level, "the stolen voice was cut, not faded");
}

#[test]
fn release_damps_only_released_voices_and_the_pedal_holds_them() {
    let controls = Controls {
        release: 1.0,
        ..quiet()
    };
    let held = render(STRUCK, 4, controls, &[(0, Event::note_on(60, 1.0))], 24_000).left;
    let released = render(
        STRUCK,
        4,
        controls,
        &[(0, Event::note_on(60, 1.0)), (2_400, Event::note_off(60))],
        24_000,
    )
    .left;
    let pedalled = render(
        STRUCK,
        4,
        controls,
        &[
            (0, Event::Controller { cc: 64, value: 1.0 }),
            (0, Event::note_on(60, 1.0)),
            (2_400, Event::note_off(60)),
        ],
        24_000,
    )
    .left;
    let tail = |x: &[f32]| peak(&x[18_000..]);
    println!(
        "tail peak: held {:.3e}, released {:.3e}, released under the pedal {:.3e}",
        tail(&held),
        tail(&released),
        tail(&pedalled)
    );
    assert!(
        tail(&released) < 0.5 * tail(&held),
        "Release must damp the released note"
    );
    assert_eq!(
        held, pedalled,
        "the pedal holds the note: nothing is released"
    );
}

#[test]
fn host_audio_still_strikes_the_model_without_notes() {
    // With voices, the model itself keeps playing what the sidechain feeds it, exactly as the
    // monophonic instrument does; notes add voices of their own.
    let mut side = vec![0.0f32; 24_000];
    side[10] = -0.05;
    // The knobs act on it too.
    let controls = Controls {
        stiffness_octaves: 1.0,
        damping_octaves: -1.0,
        ..quiet()
    };
    let legacy = Conventions::Legacy;
    let poly = render_as(legacy, DAMPED, 8, controls, &[], 24_000, Some(&side)).left;
    let mono = render_as(legacy, DAMPED, 1, controls, &[], 24_000, Some(&side)).left;
    let plain = render_as(legacy, DAMPED, 1, quiet(), &[], 24_000, Some(&side)).left;
    assert_ne!(mono, plain, "Stiffness and Damping must change the sound");
    assert!(peak(&mono) > 1e-3, "the sidechain strikes");
    assert_eq!(poly, mono);
    // Today's conventions: the same, at the model's home key and through its trims.
    let poly = render_with(DAMPED, 8, controls, &[], 24_000, Some(&side)).left;
    let mono = render_with(DAMPED, 1, controls, &[], 24_000, Some(&side)).left;
    assert!(peak(&mono) > 1e-6, "the sidechain strikes");
    assert_eq!(poly, mono);
}

#[test]
fn drunk_triangles_play_100_overlapping_notes_and_free_their_voices() {
    // The paper's instrument: every note drops a mass on its own triangle, tuned to the note;
    // a voice frees itself once its mass rests on the triangle (away from where it started).
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../models/drunk-triangles.mdl"
    ))
    .unwrap();
    let settings = instrument::prepare("dt", &text, SR)
        .unwrap()
        .facts()
        .settings
        .clone();
    assert_eq!(settings.voices, Some(100));
    // Forty keys around C4, where the unpitched triangle sounds as written.
    let low = settings.reference_key.round() as u32 - 20;
    let events: Vec<(u32, Event)> = (0..100u32)
        .map(|i| (i * 960, Event::note_on((low + i % 40) as u8, 0.8)))
        .collect();
    let r = render(&text, 100, Controls::DEFAULT, &events, 20 * 48_000);
    let most = r.sounding.iter().copied().max().unwrap();
    let last = *r.sounding.last().unwrap();
    println!(
        "100 notes over 2 s: {most} voices at most, {last} still sounding at 20 s, {} ended",
        r.ended.len()
    );
    assert!(r.left.iter().all(|x| x.is_finite() && x.abs() <= 1.0));
    assert_eq!(most, 100, "every note gets a voice");
    assert_eq!(r.ended.len() + last, 100, "a voice ends at most once");
    assert!(
        r.ended.len() >= 50,
        "the voices whose masses rest must free themselves"
    );
}

fn on(note: u8, channel: u8, voice_id: Option<i32>) -> Event {
    Event::NoteOn {
        note,
        velocity: 0.9,
        channel,
        voice_id,
    }
}

#[test]
fn an_mpe_bend_moves_only_its_channels_voice() {
    let mpe = Controls {
        mpe: true,
        ..quiet()
    };
    // +12 semitones of the ±48 member range, sent before the note as MPE controllers do.
    let up = Event::PitchBend {
        value: 0.5 + 12.0 / 96.0,
        channel: 2,
    };
    let bent = render(
        STRUCK,
        8,
        mpe,
        &[(0, on(60, 1, None)), (0, up), (0, on(67, 2, None))],
        24_000,
    )
    .left;
    let played = render(
        STRUCK,
        8,
        mpe,
        &[(0, on(60, 1, None)), (0, on(79, 2, None))],
        24_000,
    )
    .left;
    assert_eq!(bent, played, "bend +12 on channel 2 plays note 67 as 79");
    // The other channel's voice does not move.
    let alone = render(STRUCK, 8, mpe, &[(0, on(60, 1, None))], 24_000).left;
    let with_other_bend = render(STRUCK, 8, mpe, &[(0, on(60, 1, None)), (100, up)], 24_000).left;
    assert_eq!(
        alone, with_other_bend,
        "a bend on channel 2 must not move channel 1"
    );
    // Without MPE the same bend is global: ±2 semitones over the whole instrument.
    let global = render(
        STRUCK,
        8,
        quiet(),
        &[(0, on(60, 1, None)), (100, up)],
        24_000,
    )
    .left;
    assert_ne!(alone, global);
}

#[test]
fn note_expressions_retune_and_modulate_one_voice() {
    let tune = |v: i32, st: f32| Event::Tuning {
        semitones: st,
        channel: 0,
        note: None,
        voice_id: Some(v),
    };
    // The CLAP tuning expression: +12 on voice 7 is note 72; voice 8 stays.
    let tuned = render(
        STRUCK,
        8,
        quiet(),
        &[
            (0, on(60, 0, Some(7))),
            (0, tune(7, 12.0)),
            (0, on(55, 0, Some(8))),
        ],
        24_000,
    )
    .left;
    let played = render(
        STRUCK,
        8,
        quiet(),
        &[(0, on(72, 0, Some(7))), (0, on(55, 0, Some(8)))],
        24_000,
    )
    .left;
    assert_eq!(tuned, played);
    // Polyphonic modulation: Stiffness +2 octaves on one voice is that voice at ×4.
    let modulated = render(
        DAMPED,
        8,
        quiet(),
        &[
            (0, on(60, 0, Some(3))),
            (
                0,
                Event::Modulation {
                    target: ressort_engine::instrument::events::Modulated::Stiffness,
                    octaves: 2.0,
                    voice_id: 3,
                },
            ),
        ],
        24_000,
    )
    .left;
    let stiffer = render(
        DAMPED,
        8,
        Controls {
            stiffness_octaves: 2.0,
            ..quiet()
        },
        &[(0, on(60, 0, Some(3)))],
        24_000,
    )
    .left;
    assert_eq!(modulated, stiffer);
}

#[test]
fn pressure_pushes_the_scripts_pressure_input() {
    // `~pressure in1 0.001`: full pressure is a sustained force of 0.001 on the oscillator,
    // which settles at F/K = 0.05 units (× the output gain).
    let script = format!("{DAMPED}~pressure in1 0.001\n");
    let controls = Controls {
        dc_filter: false,
        ..quiet()
    };
    let press = Event::Pressure {
        value: 1.0,
        channel: 0,
        note: Some(60),
        voice_id: None,
    };
    // In the model's own units: a legacy project's, without the automatic trim.
    let pressed = render_as(
        Conventions::Legacy,
        &script,
        8,
        controls,
        &[(0, Event::note_on(60, 0.0)), (0, press)],
        96_000,
        None,
    )
    .left;
    let gain = 10f64.powf(-12.0 / 20.0);
    let settled = *pressed.last().unwrap() as f64 / gain;
    println!("settled at {settled:.5} units (F/K = 0.05)");
    assert!((settled - 0.05).abs() < 0.05 * 0.02, "{settled}");
    // Channel pressure without MPE reaches the model itself too (no note needed).
    let channel = Event::Pressure {
        value: 0.5,
        channel: 0,
        note: None,
        voice_id: None,
    };
    let mono = render_as(
        Conventions::Legacy,
        &script,
        1,
        controls,
        &[(0, channel)],
        96_000,
        None,
    )
    .left;
    let settled = *mono.last().unwrap() as f64 / gain;
    assert!((settled - 0.025).abs() < 0.025 * 0.02, "{settled}");
}

#[test]
fn the_editors_strike_plays_a_voice() {
    // Strike and Audition send a strike without a note: with voices it plays the reference key
    // on a voice of its own, as a note at that key does.
    let struck = render(
        STRUCK,
        8,
        quiet(),
        &[(0, Event::Strike { velocity: 0.8 })],
        12_000,
    );
    let played = render(STRUCK, 8, quiet(), &[(0, Event::note_on(60, 0.8))], 12_000);
    assert!(peak(&struck.left) > 1e-3);
    assert_eq!(struck.sounding[0], 1);
    assert_eq!(struck.left, played.left);
}

/// Renders `events` with the Stiffness control swept every block (×0.5 … ×1), so that every
/// voice is re-tuned every chunk.
fn render_swept(script: &str, events: &[(u32, Event)], frames: usize) -> Vec<f32> {
    let mut model = instrument::prepare("test", script, SR).unwrap();
    model.set_voices(8);
    let mut controls = quiet();
    let mut inst = Instrument::new(SR, controls);
    inst.set_model(Box::new(model));
    let block = 64;
    let mut left = vec![0.0f32; frames];
    let mut right = vec![0.0f32; frames];
    let mut start = 0;
    while start < frames {
        let n = block.min(frames - start);
        controls.stiffness_octaves = -0.5 + 0.5 * (start as f64 * 20.0 / SR).cos();
        let mut ev = events
            .iter()
            .filter(|(t, _)| (*t as usize) >= start && (*t as usize) < start + n)
            .map(|&(t, e)| Timed::new(t - start as u32, e));
        let host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
        let mut out: [&mut [f32]; 2] = [&mut left[start..start + n], &mut right[start..start + n]];
        inst.process(n, &host, false, &mut ev, &controls, &mut out);
        start += n;
    }
    left
}

/// Voices on one note share the gains worked out for the first of them each chunk, but only
/// with the same modulation: three voices on note 60, two of them with Stiffness +1 octave,
/// under a Stiffness sweep, sum to the three played alone.
#[test]
fn voices_on_one_note_share_gains_only_with_the_same_modulation() {
    let stiffer = |v: i32| Event::Modulation {
        target: ressort_engine::instrument::events::Modulated::Stiffness,
        octaves: 1.0,
        voice_id: v,
    };
    let voices: [Vec<(u32, Event)>; 3] = [
        vec![(0, on(60, 0, Some(1)))],
        vec![(0, on(60, 0, Some(2))), (0, stiffer(2))],
        vec![(4_000, on(60, 0, Some(3))), (4_000, stiffer(3))],
    ];
    let frames = 24_000;
    let together = render_swept(STRUCK, &voices.concat(), frames);
    let mut sum = vec![0.0f64; frames];
    for v in &voices {
        for (s, x) in sum.iter_mut().zip(render_swept(STRUCK, v, frames)) {
            *s += x as f64;
        }
    }
    let p = peak(&together) as f64;
    let err = together
        .iter()
        .zip(&sum)
        .fold(0.0f64, |m, (a, b)| m.max((*a as f64 - b).abs()));
    println!("peak {p:.4}, largest difference from the sum {err:.3e}");
    assert!(
        p > 1e-3 && p < 0.5,
        "the voices must sound below the knee ({p})"
    );
    assert!(err <= 1e-6 * p, "{err} > 1e-6 × {p}");
}

/// Records every position snapshot the instrument hands its watcher (the editor's motion
/// view), one per chunk.
#[derive(Debug, Default, Clone)]
struct Recorder(std::sync::Arc<std::sync::Mutex<Vec<Vec<f64>>>>);

impl instrument::Watcher for Recorder {
    fn tick(&mut self, _frames: usize, axes: [&[f64]; 3], _watching: bool) {
        // x, then y, then z: a 1-D model's x and y are empty (it moves along z).
        self.0.lock().unwrap().push(axes.concat());
    }
}

/// The positions the motion view is shown, chunk by chunk, while `events` play on 8 voices.
fn watched(script: &str, events: &[(u32, Event)], frames: usize) -> Vec<Vec<f64>> {
    watched_on(script, 8, events, frames)
}

/// [`watched`] on `voices` voices (1: the monophonic engine, no bank).
fn watched_on(
    script: &str,
    voices: usize,
    events: &[(u32, Event)],
    frames: usize,
) -> Vec<Vec<f64>> {
    let mut model = instrument::prepare("test", script, SR).unwrap();
    model.set_voices(voices);
    let recorder = Recorder::default();
    model.watcher = Some(Box::new(recorder.clone()));
    let mut inst = Instrument::new(SR, quiet());
    inst.set_model(Box::new(model));
    inst.set_watching(true);
    play(&mut inst, quiet(), events, frames, None);
    let ticks = recorder.0.lock().unwrap().clone();
    ticks
}

#[test]
fn the_motion_view_shows_the_most_recently_struck_voice() {
    // Note 60 at 0, note 67 at 4,800 (a chunk boundary): from then on the view shows note
    // 67's voice, which moves exactly as note 67 played alone; before, note 60's.
    let (first, second) = (on(60, 0, None), on(67, 0, None));
    let frames = 9_600;
    let both = watched(STRING, &[(0, first), (4_800, second)], frames);
    let only_first = watched(STRING, &[(0, first)], frames);
    let only_second = watched(STRING, &[(4_800, second)], frames);
    assert_eq!(both.len(), only_second.len());
    let chunk = frames / both.len();
    let switch = 4_800 / chunk;
    let moving = |ticks: &[Vec<f64>]| ticks.iter().flatten().any(|x| *x != 0.0);
    assert!(moving(&both[..switch]) && moving(&both[switch..]));
    assert_eq!(
        both[..switch],
        only_first[..switch],
        "before the second note the view shows the first note's voice"
    );
    assert_eq!(
        both[switch..],
        only_second[switch..],
        "after it, the view shows the second note's voice"
    );
    assert_ne!(
        both[switch..],
        only_first[switch..],
        "the view must leave the first voice"
    );
}

/// A 3-D model's voice in a lane group shows the motion view all three axes, exactly as the
/// monophonic engine shows them: the strike, across the string, moves it on y and z.
#[test]
fn the_motion_view_of_a_3d_voice_in_lanes_shows_every_axis() {
    let note = [(0u32, on(60, 0, None))];
    let frames = 9_600;
    let lanes = watched_on(STRING_3D, 8, &note, frames);
    let mono = watched_on(STRING_3D, 1, &note, frames);
    let points = mono[0].len() / 3;
    assert!(
        points >= 24 && mono[0].len() == 3 * points,
        "x, y and z of each point"
    );
    let moved = |axis: usize| {
        let first = &lanes[0][axis * points..(axis + 1) * points];
        lanes
            .iter()
            .any(|t| t[axis * points..(axis + 1) * points] != *first)
    };
    assert!(
        moved(1) && moved(2),
        "the strike moves the string on y and z"
    );
    assert_eq!(lanes, mono, "a lane shows what the engine alone shows");
}
