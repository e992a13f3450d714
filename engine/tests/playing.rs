//! Every preset as a musician plays it, through the instrument the plugin runs: a note lands
//! in the level band and in tune, softer notes are softer, every exciter kind sounds and stops
//! as docs/LANGUAGE.md §12.4 says, a bowed chord is the sum of its notes, a kick on the
//! sidechain strikes like a medium note, and trigger mode turns a drum loop into strikes.

mod common;

use common::{cents, peak_frequency, presets};
use ressort_engine::instrument::dsp::CEILING_KNEE;
use ressort_engine::instrument::{
    self, Controls, Event, Gains, Instrument, Prepared, Timed, MAX_HOST_INPUTS, MAX_HOST_OUTPUTS,
};
use ressort_engine::{ExciterKind, ScaleClass};

fn preset(name: &str) -> String {
    presets()
        .into_iter()
        .find(|p| p.0 == name)
        .unwrap_or_else(|| panic!("models/{name}.mdl"))
        .1
}

/// A preset prepared once at one rate, played from rest as often as a test asks.
struct Player {
    model: Option<Box<Prepared>>,
    sample_rate: f64,
    /// The model's engine as prepared: at rest, every parameter as declared (a played copy
    /// holds the values its exciters last pressed).
    template: ressort_engine::Engine,
}

/// What one performance gave: every host output channel, and the strikes the sidechain
/// trigger played.
struct Take {
    channels: Vec<Vec<f32>>,
    triggered: u32,
    /// Guard trips: the model exploded and was reset.
    trips: u32,
    /// The Stiffness and Damping gains the instrument played the last note with.
    gains: Gains,
}

impl Take {
    fn peak(&self) -> f64 {
        self.channels
            .iter()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs() as f64))
    }

    fn peak_db(&self) -> f64 {
        db(self.peak())
    }

    /// The peak of the main channels between `from` and `to` seconds.
    fn peak_between(&self, sr: f64, from: f64, to: f64) -> f64 {
        let (a, b) = ((from * sr) as usize, (to * sr) as usize);
        self.channels[..2]
            .iter()
            .flat_map(|c| &c[a.min(c.len())..b.min(c.len())])
            .fold(0.0f64, |m, v| m.max(v.abs() as f64))
    }

    fn left(&self) -> Vec<f64> {
        self.channels[0].iter().map(|&v| v as f64).collect()
    }
}

fn db(x: f64) -> f64 {
    if x > 0.0 {
        20.0 * x.log10()
    } else {
        -240.0
    }
}

impl Player {
    fn new(script: &str, sample_rate: f64) -> Player {
        let mut model = instrument::prepare("test", script, sample_rate).expect("it prepares");
        if let Some(v) = model.facts().settings.voices {
            model.set_voices(v as usize);
        }
        Player {
            template: model.engine.clone(),
            model: Some(Box::new(model)),
            sample_rate,
        }
    }

    fn model(&self) -> &Prepared {
        self.model.as_deref().unwrap()
    }

    /// Plays `events` (sample, event) and `sidechain` (both channels) for `seconds` with
    /// `controls`, from rest.
    fn play(
        &mut self,
        controls: Controls,
        events: &[(usize, Event)],
        sidechain: Option<&[f32]>,
        seconds: f64,
    ) -> Take {
        let sr = self.sample_rate;
        let mut model = self.model.take().expect("a model");
        model.engine.reset();
        model.rest_gestures();
        if let Some(b) = model.bank.as_mut() {
            b.clear();
        }
        let channels = match model.facts().num_outputs {
            0..=2 => 2,
            n => n.min(MAX_HOST_OUTPUTS).div_ceil(2) * 2,
        };
        let mut inst = Instrument::new(sr, controls);
        inst.set_model(model);
        let frames = (seconds * sr) as usize;
        let mut out = vec![vec![0.0f32; frames]; channels];
        let block = 480;
        let mut done = 0;
        let mut triggered = 0;
        let mut trips = 0;
        while done < frames {
            let len = block.min(frames - done);
            let mut evs = events
                .iter()
                .filter(|(t, _)| *t >= done && *t < done + len)
                .map(|&(t, e)| Timed::new((t - done) as u32, e));
            let mut host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
            if let Some(s) = sidechain {
                host[2] = s.get(done..);
                host[3] = s.get(done..);
            }
            let mut slices: Vec<&mut [f32]> =
                out.iter_mut().map(|c| &mut c[done..done + len]).collect();
            let report = inst.process(len, &host, false, &mut evs, &controls, &mut slices);
            triggered += report.triggered;
            trips += report.trips;
            done += len;
        }
        let gains = inst.gains();
        let [model, _, _] = inst.take_models();
        self.model = model;
        Take {
            channels: out,
            triggered,
            trips,
            gains,
        }
    }

    /// One note held for `seconds`.
    fn note(&mut self, key: u8, velocity: f32, seconds: f64) -> Take {
        self.play(
            Controls::DEFAULT,
            &[(0, Event::note_on(key, velocity))],
            None,
            seconds,
        )
    }
}

/// The level band of a C4 note at velocity 0.8, dBFS.
const BAND: (f64, f64) = (-18.0, -6.0);
/// The widest spread of those levels over every preset.
const SPREAD_DB: f64 = 12.0;
/// How much quieter a note at velocity 0.2 is than one at 0.8, at least.
const SOFTER_DB: f64 = 3.0;

#[test]
fn every_preset_lands_in_the_level_band_and_velocity_is_loudness() {
    const SR: f64 = 48_000.0;
    let mut wrong = Vec::new();
    let (mut lowest, mut highest) = (f64::INFINITY, f64::NEG_INFINITY);
    println!("preset                     v0.8 dBFS  v1.0 dBFS  v0.2 dBFS");
    for (name, script) in presets() {
        let mut p = Player::new(&script, SR);
        let medium = p.note(60, 0.8, 2.0).peak_db();
        let loud = p.note(60, 1.0, 2.0).peak_db();
        let soft = p.note(60, 0.2, 2.0).peak_db();
        println!("{name:<26} {medium:9.1} {loud:10.1} {soft:10.1}");
        lowest = lowest.min(medium);
        highest = highest.max(medium);
        if !(BAND.0..=BAND.1).contains(&medium) {
            wrong.push(format!("{name}: C4 at 0.8 peaks at {medium:.1} dBFS"));
        }
        if loud > db(CEILING_KNEE) {
            wrong.push(format!(
                "{name}: C4 at 1.0 reaches the ceiling ({loud:.1} dBFS)"
            ));
        }
        if soft > medium - SOFTER_DB {
            wrong.push(format!(
                "{name}: velocity 0.2 ({soft:.1} dBFS) is not softer than 0.8 ({medium:.1})"
            ));
        }
    }
    println!("spread {:.1} dB", highest - lowest);
    if highest - lowest > SPREAD_DB {
        wrong.push(format!("the levels spread over {:.1} dB", highest - lowest));
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// The corners of the macro slots a test plays at: every slot at its bottom, every slot at
/// its top, and the two alternations (a lighter mass with a stiffer spring, and so on).
fn macro_corners() -> [(&'static str, [f64; instrument::NUM_MACROS]); 4] {
    let alternate =
        |first: f64| std::array::from_fn(|i| if i % 2 == 0 { first } else { 1.0 - first });
    [
        ("all at 0", [0.0; instrument::NUM_MACROS]),
        ("all at 1", [1.0; instrument::NUM_MACROS]),
        ("0, 1, 0, …", alternate(0.0)),
        ("1, 0, 1, …", alternate(1.0)),
    ]
}

#[test]
fn every_preset_stays_stable_with_its_macros_at_the_corners() {
    const SR: f64 = 48_000.0;
    let mut wrong = Vec::new();
    let mut played = 0;
    for (name, script) in presets() {
        let mut p = Player::new(&script, SR);
        for (corner, macros) in macro_corners() {
            let controls = Controls {
                macros,
                ..Controls::DEFAULT
            };
            let take = p.play(controls, &[(0, Event::note_on(60, 1.0))], None, 1.0);
            played += 1;
            let finite = take.channels.iter().flatten().all(|v| v.is_finite());
            if take.trips > 0 || !finite || take.peak() > 1.0 {
                wrong.push(format!(
                    "{name}, macros {corner}: {} guard trip(s), finite {finite}, peak {:.3}",
                    take.trips,
                    take.peak()
                ));
            }
        }
    }
    println!(
        "{played} performances at the macro corners, {} wrong",
        wrong.len()
    );
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// Keys to check a pitched preset at: C3, C4, A4 and its own key where they are in tune (at
/// most three octaves below its pitch, not above its highest key), then its own key and the
/// fifth and octave below it.
fn keys_of(m: &Prepared) -> Vec<u8> {
    let own = m.facts().settings.reference_key;
    let top = m.highest_key().unwrap_or(own + 12.0).floor();
    let mut keys: Vec<u8> = [48.0, 60.0, 69.0, own.round()]
        .into_iter()
        .filter(|&k| k <= top && k >= own - 36.0)
        .map(|k| k as u8)
        .collect();
    for k in [
        own.round().min(top),
        own.round().min(top) - 7.0,
        own.round().min(top) - 12.0,
    ] {
        if keys.len() < 3 && !keys.contains(&(k as u8)) {
            keys.push(k as u8);
        }
    }
    keys.sort();
    keys.dedup();
    keys.truncate(3);
    keys
}

/// The pitch closest to `expected_hz` in the held part of a note (from 0.3 s to its end): the
/// strongest peak within half a semitone of it, interpolated.
fn pitch_near(take: &Take, sr: f64, expected_hz: f64) -> f64 {
    let left = take.left();
    let part = &left[(0.3 * sr) as usize..];
    let ratio = 2f64.powf(0.5 / 12.0);
    peak_frequency(part, sr, expected_hz / ratio, expected_hz * ratio)
}

/// The reference mode as the instrument tuned it for a note: the mode of the model as
/// prepared, at the gains it played the note with, closest to `expected_hz`.
fn tuned_mode(template: &ressort_engine::Engine, gains: &Gains, expected_hz: f64) -> f64 {
    let mut e = template.clone();
    e.set_class_gain(ScaleClass::Stiffness, gains.stiffness);
    e.set_class_gain(ScaleClass::Damping, gains.damping);
    let a = e.modes(None);
    a.modes
        .iter()
        .map(|m| m.frequency_hz)
        .min_by(|a, b| {
            cents(*a, expected_hz)
                .abs()
                .total_cmp(&cents(*b, expected_hz).abs())
        })
        .unwrap_or(0.0)
}

/// How far a bow's stick and slip moves a string's pitch from its mode: with the bowing
/// point near the string's end, the presets' bows sound up to about ten cents off, sharp or
/// flat with the bow's force (measured; the mode itself is tuned exactly).
const BOWED_CENTS: f64 = 12.0;
/// How far a bowed preset's `~pitch` may place its mode from the key so that the bowed
/// sound is heard on it.
const MODE_OFFSET_BOWED_CENTS: f64 = 20.0;

#[test]
fn pitched_presets_play_in_tune_at_three_keys_and_three_rates() {
    let mut wrong = Vec::new();
    let mut checked = 0;
    for (name, script) in presets() {
        for sr in [44_100.0, 48_000.0, 96_000.0] {
            let mut p = Player::new(&script, sr);
            if p.model().facts().settings.unpitched {
                break;
            }
            let bowed = p
                .model()
                .facts()
                .exciters
                .iter()
                .any(|x| x.kind == ExciterKind::Bow);
            let heard_within = if bowed { BOWED_CENTS } else { 5.0 };
            // A bow pulls its string flat by up to 16 cents with its force (Cello, Erhu): a
            // bowed preset may place its mode sharp by `~pitch` so that what is heard is
            // centred on the key.
            let mode_within = if bowed { MODE_OFFSET_BOWED_CENTS } else { 5.0 };
            for key in keys_of(p.model()) {
                let expected = 440.0 * 2f64.powf((key as f64 - 69.0) / 12.0);
                let take = p.note(key, 0.8, 1.5);
                // The reference mode sits on the key; the note sounds there.
                let mode = cents(tuned_mode(&p.template, &take.gains, expected), expected);
                let heard = cents(pitch_near(&take, sr, expected), expected);
                checked += 1;
                println!(
                    "{name:<26} {sr:>6} Hz  key {key:>3}  mode {mode:+6.2} cents  heard \
                     {heard:+6.2} cents"
                );
                if mode.abs() > mode_within || heard.abs() > heard_within {
                    wrong.push(format!(
                        "{name} at {sr} Hz, key {key}: mode {mode:+.1} cents, heard \
                         {heard:+.1} cents"
                    ));
                }
            }
        }
    }
    assert!(checked >= 3 * 3 * 10, "only {checked} notes checked");
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// Controls for a linear output stage: far below the ceiling's knee, no DC filter.
fn quiet() -> Controls {
    Controls {
        output_db: -30.0,
        dc_filter: false,
        ..Controls::DEFAULT
    }
}

/// The peak of `take`'s main channels in every `step` seconds.
fn envelope(take: &Take, sr: f64, step: f64) -> Vec<f64> {
    let n = (step * sr) as usize;
    let left = &take.channels[0];
    left.chunks(n)
        .map(|c| c.iter().fold(0.0f64, |m, v| m.max(v.abs() as f64)))
        .collect()
}

#[test]
fn a_bow_sounds_while_its_key_is_held_and_leaves_at_note_off() {
    const SR: f64 = 48_000.0;
    let script = preset("bowed-string");
    let mut p = Player::new(&script, SR);
    let off = (1.5 * SR) as usize;
    let events = [(0, Event::note_on(45, 0.8)), (off, Event::note_off(45))];
    let take = p.play(Controls::DEFAULT, &events, None, 3.0);
    let env = envelope(&take, SR, 0.1);
    println!(
        "bowed, held 1.5 s: {:?}",
        env.iter().map(|&v| db(v).round()).collect::<Vec<_>>()
    );
    // It speaks, and holds: the last half second of the key is as loud as the note gets.
    let held = take.peak_between(SR, 1.0, 1.5);
    assert!(db(held) > -20.0, "the bow sustains ({:.1} dBFS)", db(held));
    assert!(held > 0.5 * take.peak(), "the bow keeps the string going");
    // At note-off the bow stops: nothing drives the string any more, which only dies away.
    for w in env[16..].windows(2) {
        assert!(w[1] <= w[0] * 1.02, "driven after note-off: {env:?}");
    }
    // And it leaves: the string rings on as a free string does. A bow that stopped on the
    // string (its friction not lifted) would damp it: compare with the same bow whose
    // friction stays at the pressed value.
    let resting = script
        .replace("@nlZ audioParam @in5", "@nlZ param 0.2")
        .replace("~exciter in5 press 0.25\n", "");
    let mut r = Player::new(&resting, SR);
    let stays = r.play(Controls::DEFAULT, &events, None, 3.0);
    let ring = |t: &Take| db(t.peak_between(SR, 2.5, 3.0)) - db(t.peak_between(SR, 1.4, 1.5));
    println!(
        "one second after note-off: bow left {:.1} dB, bow resting {:.1} dB",
        ring(&take),
        ring(&stays)
    );
    assert!(
        ring(&take) > ring(&stays) + 10.0,
        "the lifted bow lets the string ring"
    );
    // Release damps a released string.
    let damped = p.play(
        Controls {
            release: 1.0,
            ..Controls::DEFAULT
        },
        &events,
        None,
        3.0,
    );
    assert!(
        ring(&damped) < ring(&take) - 3.0,
        "Release damps the released string"
    );
    // Held all along, the same note keeps sounding.
    let sustained = p.play(Controls::DEFAULT, &events[..1], None, 3.0);
    assert!(sustained.peak_between(SR, 2.5, 3.0) > 0.5 * held);
}

/// Pressure while a key is held (polyphonic aftertouch here; channel pressure and the CLAP
/// pressure expression arrive as the same event) drives the bow faster, and the string louder.
#[test]
fn pressure_on_a_held_bow_drives_it_harder() {
    const SR: f64 = 48_000.0;
    let mut p = Player::new(&preset("bowed-string"), SR);
    let soft = [(0, Event::note_on(45, 0.3))];
    let press = Event::Pressure {
        value: 1.0,
        channel: 0,
        note: Some(45),
        voice_id: None,
    };
    let pressed = [soft[0], ((0.8 * SR) as usize, press)];
    let plain = p.play(Controls::DEFAULT, &soft, None, 1.6);
    let harder = p.play(Controls::DEFAULT, &pressed, None, 1.6);
    let before = |t: &Take| db(t.peak_between(SR, 0.5, 0.8));
    let after = |t: &Take| db(t.peak_between(SR, 1.3, 1.6));
    println!(
        "bow at velocity 0.3: {:.1} → {:.1} dBFS alone, {:.1} → {:.1} dBFS with full pressure",
        before(&plain),
        after(&plain),
        before(&harder),
        after(&harder)
    );
    assert_eq!(
        before(&plain),
        before(&harder),
        "nothing changes before the pressure"
    );
    assert!(
        after(&harder) > after(&plain) + 2.0,
        "full pressure bows louder than velocity 0.3 alone"
    );
}

#[test]
fn a_pluck_plucks_once_per_key() {
    const SR: f64 = 48_000.0;
    let mut p = Player::new(&preset("plucked-harmonics"), SR);
    let take = p.play(quiet(), &[(0, Event::note_on(44, 0.8))], None, 1.5);
    let env = envelope(&take, SR, 0.02);
    let loudest = env.iter().cloned().fold(0.0, f64::max);
    let at = env.iter().position(|&v| v == loudest).unwrap();
    // It sounds at once (within the first 40 ms: the sweep crosses the string in 3 ms) …
    assert!(at <= 2 && loudest > 0.0, "peak in frame {at}");
    // … then only dies away: no second pluck while the key is held.
    for w in env[at..].windows(10) {
        assert!(w[9] <= w[0] * 1.05, "a second attack: {w:?}");
    }
    // Two keys, two plucks (each voice from the first side).
    let two = p.play(
        quiet(),
        &[
            (0, Event::note_on(44, 0.8)),
            ((0.5 * SR) as usize, Event::note_on(48, 0.8)),
        ],
        None,
        1.0,
    );
    let before = two.peak_between(SR, 0.4, 0.5);
    let after = two.peak_between(SR, 0.5, 0.55);
    assert!(
        after > 1.5 * before,
        "the second key plucks ({before:e} -> {after:e})"
    );
}

/// An oscillator that a finger presses through a stiff spring: a press moves its rest.
const PRESSED: &str = "\
@o osc 1. 0.01 0.002 0. 0.
@in1 posInput 0.
@f spring @in1 @o 0.01
@out1 posOutput @o
~exciter in1 press 0.5 10
";

#[test]
fn a_press_holds_its_depth_while_the_key_is_down_and_lets_go() {
    const SR: f64 = 48_000.0;
    let mut p = Player::new(PRESSED, SR);
    let off = (1.0 * SR) as usize;
    let take = p.play(
        quiet(),
        &[(0, Event::note_on(60, 1.0)), (off, Event::note_off(60))],
        None,
        2.0,
    );
    let left = take.left();
    let gain = 10f64.powf(-30.0 / 20.0) * p.model().facts().output_trim;
    // Pressed by 0.5 through an equal spring, the oscillator settles halfway, at 0.25.
    let held = left[off - 1] / gain;
    assert!((held - 0.25).abs() < 0.01, "held at {held}");
    let released = left[left.len() - 1] / gain;
    assert!(released.abs() < 0.01, "let go: {released}");
    // Softer keys press less deep.
    let soft = p.play(quiet(), &[(0, Event::note_on(60, 0.5))], None, 1.0);
    let half = soft.left()[(SR as usize) - 1] / gain;
    assert!((half - 0.125).abs() < 0.01, "half velocity: {half}");
}

#[test]
fn a_chord_of_three_bowed_notes_is_the_sum_of_the_notes() {
    const SR: f64 = 48_000.0;
    let mut p = Player::new(&preset("bowed-string"), SR);
    let keys = [40u8, 43, 47];
    let chord: Vec<(usize, Event)> = keys.iter().map(|&k| (0, Event::note_on(k, 0.8))).collect();
    let together = p.play(quiet(), &chord, None, 1.5).left();
    let mut sum = vec![0.0f64; together.len()];
    for &k in &keys {
        let alone = p
            .play(quiet(), &[(0, Event::note_on(k, 0.8))], None, 1.5)
            .left();
        for (s, a) in sum.iter_mut().zip(alone) {
            *s += a;
        }
    }
    let peak = together.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = together
        .iter()
        .zip(&sum)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    println!("chord peak {peak:e}, largest difference from the sum {worst:e}");
    assert!(peak > 1e-3, "the chord sounds");
    assert!(worst <= 1e-5 * peak, "{worst:e} of {peak:e}");
}

/// The kick of issue 36: a sine gliding 120 → 50 Hz under a 60 ms decay, twice a second,
/// peaking at −6 dBFS.
fn kick_loop(seconds: f64, sr: f64, hits: &[f64]) -> Vec<f32> {
    let frames = (seconds * sr) as usize;
    let mut x = vec![0.0f64; frames];
    for &start in hits {
        let mut phase = 0.0f64;
        for n in 0..(0.4 * sr) as usize {
            let t = n as f64 / sr;
            let f = 50.0 + 70.0 * (-t / 0.03).exp();
            phase += std::f64::consts::TAU * f / sr;
            if let Some(s) = x.get_mut((start * sr) as usize + n) {
                *s += (-t / 0.06).exp() * phase.sin();
            }
        }
    }
    let peak = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scale = 10f64.powf(-6.0 / 20.0) / peak;
    x.iter().map(|v| (v * scale) as f32).collect()
}

#[test]
fn a_kick_on_the_sidechain_strikes_like_a_medium_note() {
    const SR: f64 = 48_000.0;
    let mut p = Player::new(&preset("mesh-15x15"), SR);
    let note = p.note(60, 0.8, 2.0).peak_db();
    let hits: Vec<f64> = (0..8).map(|i| 0.5 * i as f64).collect();
    let kick = kick_loop(4.0, SR, &hits);
    let take = p.play(Controls::DEFAULT, &[], Some(&kick), 4.0);
    let struck = take.peak_db();
    println!("mesh-15x15: note {note:.1} dBFS, kick {struck:.1} dBFS");
    assert!(
        (struck - note).abs() <= 6.0,
        "kick {struck:.1} vs note {note:.1} dBFS"
    );
    assert!(
        struck < db(CEILING_KNEE),
        "the kick reaches the ceiling: {struck:.1} dBFS"
    );
    // The same kick through every preset: where the sidechain pushes the model it strikes,
    // and nowhere does it reach the ceiling.
    let mut hot = Vec::new();
    for (name, script) in presets() {
        let mut p = Player::new(&script, SR);
        let note = p.note(60, 0.8, 2.0).peak_db();
        let struck = p
            .play(Controls::DEFAULT, &[], Some(&kick[..96_000]), 2.0)
            .peak_db();
        println!("{name:<26} note {note:6.1} dBFS, kick {struck:6.1} dBFS");
        if struck >= db(CEILING_KNEE) {
            hot.push(format!("{name}: {struck:.1} dBFS"));
        }
    }
    assert!(hot.is_empty(), "a kick reaches the ceiling: {hot:?}");
}

#[test]
fn trigger_mode_turns_a_four_hit_drum_loop_into_four_strikes() {
    const SR: f64 = 48_000.0;
    let hits = [0.25, 0.75, 1.25, 1.75];
    let kick = kick_loop(2.2, SR, &hits);
    let trigger = Controls {
        trigger: true,
        ..Controls::DEFAULT
    };
    // A model without voices: each hit strikes it where the drum hits.
    let mut p = Player::new(&preset("mesh-15x15"), SR);
    let take = p.play(trigger, &[], Some(&kick), 2.2);
    assert_eq!(take.triggered, 4, "four hits, four strikes");
    let note = p.note(60, 0.8, 0.5).peak();
    for &t in &hits {
        let before = take.peak_between(SR, t - 0.1, t);
        let hit = take.peak_between(SR, t, t + 0.1);
        println!(
            "hit at {t} s: {:.1} dBFS (before {:.1})",
            db(hit),
            db(before)
        );
        assert!(hit > before, "a strike at {t} s");
        // A −6 dBFS hit plays velocity 0.8: a medium note, within 3 dB.
        assert!(
            (db(hit) - db(note)).abs() < 3.0,
            "{:.1} vs {:.1}",
            db(hit),
            db(note)
        );
    }
    // Without trigger mode the same loop pushes the model as a force: no strikes.
    let raw = p.play(Controls::DEFAULT, &[], Some(&kick), 2.2);
    assert_eq!(raw.triggered, 0);
    assert_ne!(raw.channels, take.channels);
    // With voices: each hit plays a voice of its own.
    let mut v = Player::new(&preset("struck-string"), SR);
    let take = v.play(trigger, &[], Some(&kick), 2.2);
    assert_eq!(take.triggered, 4);
    assert!(take.peak() > 1e-3);
}

/// The exciter examples of docs/LANGUAGE.md §12.4: each plays from a held key.
#[test]
fn the_guides_exciter_examples_play() {
    const SR: f64 = 48_000.0;
    let guide = include_str!("../../docs/LANGUAGE.md");
    let start = guide.find("### 12.4").expect("§12.4");
    let end = start + guide[start..].find("\n## ").expect("the next chapter");
    let section = &guide[start..end];
    let examples: Vec<&str> = section
        .split("```mims\n")
        .skip(1)
        .map(|b| &b[..b.find("```").unwrap()])
        .collect();
    assert_eq!(
        examples.len(),
        3,
        "a bow, a pluck and a strike with a press"
    );
    for script in examples {
        let mut p = Player::new(script, SR);
        let kinds: Vec<&str> = p
            .model()
            .facts()
            .exciters
            .iter()
            .map(|x| x.kind.name())
            .collect();
        let take = p.play(
            Controls::DEFAULT,
            &[
                (0, Event::note_on(60, 0.8)),
                ((0.8 * SR) as usize, Event::note_off(60)),
            ],
            None,
            1.5,
        );
        println!("{kinds:?}: {:.1} dBFS", take.peak_db());
        assert!(
            (BAND.0..=BAND.1).contains(&take.peak_db()),
            "{kinds:?}: {:.1}",
            take.peak_db()
        );
    }
}

#[test]
fn an_exciter_an_input_cannot_take_is_an_error_at_its_directive() {
    let bad = [
        (
            "@o osc 1. 0.1 0.001 0. 0.\n@in1 frcInput @o\n@out1 posOutput @o\n~exciter in1 bow 1\n",
            "4:10: error: `~exciter in1 bow`: in1 is not a position input (posInput); a bow \
             moves an avatar",
        ),
        (
            "@o osc 1. 0.1 0.001 0. 0.\n@in1 posInput 0.\n@s spring @in1 @o 0.1\n\
             @out1 posOutput @o\n~exciter in1 pluck\n",
            "5:10: error: `~exciter in1 pluck`: in1 plucks nothing (no nlPluck on @in1): give \
             the plectrum's travel",
        ),
        (
            "@o osc 1. 0.1 0.001 0. 0.\n@in1 posInput 0.\n@s spring @in1 @o 0.1\n\
             @out1 posOutput @o\n~exciter in3 press 0.1\n",
            "5:10: error: `~exciter in3 press`: the model has no input in3",
        ),
    ];
    for (script, expected) in bad {
        let err = instrument::prepare("bad", script, 48_000.0).unwrap_err();
        assert_eq!(err.0, vec![expected.to_string()]);
    }
    // The parser catches the rest where it reads them.
    for (script, expected) in [
        (
            "~exciter in1 scrape\n",
            "1:14: error: unknown exciter `scrape`",
        ),
        (
            "~exciter in1 bow -2\n",
            "1:18: error: `~exciter in1 bow`: bad value `-2`",
        ),
        (
            "~exciter in1 bow\n~exciter in1 press 1\n",
            "2:1: error: a second `~exciter` for in1",
        ),
        (
            "~note in1\n~exciter in2 strike\n",
            "2:1: error: a second strike",
        ),
    ] {
        let parsed = ressort_engine::parse(script);
        let first = parsed.errors().next().expect("an error").to_string();
        assert!(first.starts_with(expected), "{script:?}: {first}");
    }
}

/// Every preset plays at the lowest and highest rates a host offers without a guard trip:
/// scripts written at the edge for 44.1 kHz are unstable at 22.05 kHz as written (every
/// per-sample stiffness four times larger), and the exact limit holds them below it.
#[test]
fn every_preset_plays_at_22_05_and_192_khz_without_a_guard_trip() {
    let mut wrong = Vec::new();
    for sr in [22_050.0, 192_000.0] {
        for (name, script) in presets() {
            let mut p = Player::new(&script, sr);
            let take = p.note(60, 1.0, 1.0);
            let finite = take.channels.iter().flatten().all(|v| v.is_finite());
            println!(
                "{name:<26} {sr:>8} Hz: peak {:.3}, Stiffness ×{:.3}, {} trip(s)",
                take.peak(),
                take.gains.stiffness,
                take.trips
            );
            let silent = take.peak() < 1e-3;
            if take.trips > 0 || !finite || silent {
                wrong.push(format!(
                    "{name} at {sr} Hz: {} guard trip(s), finite {finite}, peak {:.3}",
                    take.trips,
                    take.peak()
                ));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// The editor's Vary at its default amount, pressed three times from the preset as loaded
/// (seeds 1, 2, 3): every press finds a variation, and each plays a C4 in the level band
/// without a guard trip, rendered as the instrument plays it (not by Vary's own measure).
#[test]
fn vary_keeps_every_preset_playable_and_in_the_level_band() {
    const SR: f64 = 48_000.0;
    const AMOUNT: f64 = 0.5;
    // Two Fingers String's variations are chaotic: Vary's own two-second measure and this
    // render of the same controls differ by up to 6 dB, and some seeds find nothing playable
    // (docs/NOTES.md). It is held to no trip and finite output only.
    const UNPREDICTABLE: [&str; 1] = ["two-fingers-string"];
    let mut wrong = Vec::new();
    println!("preset                     seed 1 dBFS  seed 2 dBFS  seed 3 dBFS");
    for (name, script) in presets() {
        let loose = UNPREDICTABLE.contains(&name.as_str());
        let mut p = Player::new(&script, SR);
        let mut controls = Controls::DEFAULT;
        let mut row = format!("{name:<26}");
        for seed in 1..=3 {
            let model = *p.model.take().expect("a model");
            let (back, variation) = instrument::vary_playable(model, &controls, AMOUNT, seed);
            p.model = Some(Box::new(back));
            let Some(v) = variation else {
                if !loose {
                    wrong.push(format!("{name}, seed {seed}: no playable variation"));
                }
                continue;
            };
            controls = v.controls;
            let take = p.play(controls, &[(0, Event::note_on(60, 0.8))], None, 2.0);
            let finite = take.channels.iter().flatten().all(|v| v.is_finite());
            let level = take.peak_db();
            row += &format!(" {level:12.1}");
            let in_band = loose || (BAND.0..=BAND.1).contains(&level);
            if take.trips > 0 || !finite || !in_band {
                wrong.push(format!(
                    "{name}, seed {seed} ({controls:?}): {} trip(s), finite {finite}, \
                     {level:.1} dBFS",
                    take.trips
                ));
            }
        }
        println!("{row}");
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// An empty script (a cleared editor, an empty file, comments only) is refused where it
/// starts: the language allows it, an instrument has nothing to play in it.
#[test]
fn an_empty_script_is_refused() {
    for script in ["", "\n\n", "# only a comment\n", "~voices 4\n"] {
        let err = instrument::prepare("empty", script, 48_000.0).unwrap_err();
        assert!(
            err.0[0].starts_with("1:1: error: the script is empty"),
            "{script:?}: {:?}",
            err.0
        );
    }
}

/// The spectral centroid of the first half second of `signal`, in Hz (Hann window).
fn attack_centroid(signal: &[f64], sr: f64) -> f64 {
    let n = (0.5 * sr) as usize;
    let mut frame: Vec<f64> = signal[..n]
        .iter()
        .enumerate()
        .map(|(i, v)| v * (0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / n as f64).cos()))
        .collect();
    let mut spectrum = realfft::RealFftPlanner::<f64>::new()
        .plan_fft_forward(n)
        .make_output_vec();
    realfft::RealFftPlanner::<f64>::new()
        .plan_fft_forward(n)
        .process(&mut frame, &mut spectrum)
        .unwrap();
    let (mut weighted, mut total) = (0.0, 0.0);
    for (k, c) in spectrum.iter().enumerate() {
        let f = k as f64 * sr / n as f64;
        weighted += f * c.norm();
        total += c.norm();
    }
    weighted / total
}

/// The felt of Felt Piano (`feltContact`, p = 2.5) hardens as it is pressed, so a harder key
/// is brighter, not only louder; a linear contact on the same wire is not.
#[test]
fn a_harder_key_on_the_felt_piano_is_brighter() {
    const SR: f64 = 48_000.0;
    let felt = preset("felt-piano");
    let linear = felt.replace(
        "@hit feltContact [@s 0.12] @h 0.003 2.5 0.0005",
        "@hit contact [@s 0.12] @h 0.01 0.001",
    );
    assert_ne!(felt, linear, "the felt line is in the preset");
    let rise = |script: &str| {
        let mut p = Player::new(script, SR);
        let soft = attack_centroid(&p.note(60, 0.2, 1.0).left(), SR);
        let hard = attack_centroid(&p.note(60, 1.0, 1.0).left(), SR);
        println!("centroid at C4: {soft:.0} Hz at velocity 0.2, {hard:.0} Hz at 1.0");
        hard / soft
    };
    let felt_rise = rise(&felt);
    let linear_rise = rise(&linear);
    assert!(felt_rise > 1.25, "the felt brightens by {felt_rise:.2}");
    assert!(
        linear_rise < 1.05,
        "the linear contact brightens by {linear_rise:.2}"
    );
}

/// Full-scale white noise, the same every run (a 64-bit LCG's high bits).
fn white_noise(frames: usize, seed: u64) -> Vec<f32> {
    let mut s = seed;
    (0..frames)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) as f32
        })
        .collect()
}

/// A sidechain routed to a finger's place (an `audioParam` in a connection point's
/// coordinate) slides the finger instead of teleporting it: full-scale noise there blew Two
/// Fingers String up at 192 kHz (its contacts injecting energy at every jump, spec §2.8).
#[test]
fn noise_on_a_fingers_place_slides_it_and_trips_no_guard() {
    for sr in [48_000.0, 192_000.0] {
        let mut p = Player::new(&preset("two-fingers-string"), sr);
        let noise = white_noise((1.5 * sr) as usize, 7);
        let take = p.play(
            Controls::DEFAULT,
            &[(0, Event::note_on(60, 0.8))],
            Some(&noise),
            1.5,
        );
        let finite = take.channels.iter().flatten().all(|v| v.is_finite());
        println!(
            "two-fingers-string at {sr} Hz, noise on the fingers: peak {:.3}, {} trip(s)",
            take.peak(),
            take.trips
        );
        assert_eq!(take.trips, 0, "the guard tripped at {sr} Hz");
        assert!(finite, "non-finite output at {sr} Hz");
        assert!(take.peak() > 1e-3, "the note went silent at {sr} Hz");
    }
}

/// A model whose `@in2` is an `audioParam` that places `@in1`'s force along a string: in1
/// reads the sidechain's left channel (host channel 2), in2 its right (3).
fn glide_model() -> Prepared {
    let script = "@f audioParam @in2\n@s string 10 1. 0.1 0.001 0. 0.\n\
                  @in1 frcInput [@s f]\n@out1 posOutput [@s 0.5]\n";
    instrument::prepare("glide", script, 48_000.0).expect("it prepares")
}

/// One chunk of the host's channels into `m`'s inputs.
fn fill(m: &mut Prepared, host: &[[f64; instrument::CHUNK]]) {
    let order = ressort_engine::instrument::host::default_order(false);
    m.fill_inputs(host, order, instrument::CHUNK, 1.0, 1.0, false);
}

/// The glide of a coordinate input: a step reaches 1 − 1/e of its height after
/// `PLACE_GLIDE_MS`, inputs that are no coordinate take the host signal as it comes, and a
/// host gone silent lets the coordinate glide back towards its rest.
#[test]
fn a_step_on_a_coordinate_input_glides_and_other_inputs_do_not() {
    let mut m = glide_model();
    let chunk = instrument::CHUNK;
    let mut host = vec![[0.0f64; instrument::CHUNK]; MAX_HOST_INPUTS];
    host[2] = [0.25; instrument::CHUNK];
    host[3] = [1.0; instrument::CHUNK];
    let frames = (instrument::PLACE_GLIDE_MS * 1e-3 * 48_000.0) as usize;
    let mut seen = Vec::new();
    let mut forces = Vec::new();
    for _ in 0..frames.div_ceil(chunk) {
        fill(&mut m, &host);
        forces.extend_from_slice(&m.inputs[..chunk]);
        seen.extend_from_slice(&m.inputs[chunk..2 * chunk]);
    }
    let at = seen[frames - 1];
    println!("a step of 1 on the coordinate: {at:.4} after {frames} samples");
    assert!((at - (1.0 - (-1.0f64).exp())).abs() < 0.01, "{at}");
    assert!(seen.windows(2).all(|w| w[1] > w[0]), "the glide rises");
    let force = forces[0];
    assert!(
        force != 0.0 && forces.iter().all(|&f| f == force),
        "{forces:?}"
    );
    // Silence: the coordinate glides back down.
    host[3] = [0.0; instrument::CHUNK];
    fill(&mut m, &host);
    assert!(m.inputs[chunk..2 * chunk].iter().all(|&v| v < at));
}

/// A coordinate gliding back to rest lands on it: after the host falls silent it reads 0
/// exactly, never a subnormal on its way.
#[test]
fn a_coordinate_glides_back_to_its_rest_exactly() {
    let mut m = glide_model();
    let chunk = instrument::CHUNK;
    let mut host = vec![[0.0f64; instrument::CHUNK]; MAX_HOST_INPUTS];
    host[3] = [0.7; instrument::CHUNK];
    for _ in 0..100 {
        fill(&mut m, &host);
    }
    host[3] = [0.0; instrument::CHUNK];
    let mut last = f64::NAN;
    for _ in 0..96_000 / chunk {
        fill(&mut m, &host);
        for &v in &m.inputs[chunk..2 * chunk] {
            assert!(v == 0.0 || v.is_normal(), "a subnormal glide value {v:e}");
        }
        last = m.inputs[2 * chunk - 1];
    }
    assert_eq!(
        last.to_bits(),
        0.0f64.to_bits(),
        "the glide ends at {last:e}"
    );
}
