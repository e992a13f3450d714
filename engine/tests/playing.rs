//! Every preset as a musician plays it, through the instrument the plugin runs: a note lands
//! in the level band and in tune, softer notes are softer, every exciter kind sounds and stops
//! as docs/LANGUAGE.md §12.4 says, and a bowed chord is the sum of its notes. What the
//! sidechain does is in `sidechain.rs`.

mod common;

use common::player::{db, preset, Player, Take};
use common::{cents, peak_frequency, presets};
use ressort_engine::instrument::dsp::CEILING_KNEE;
use ressort_engine::instrument::{self, Controls, Event, Gains, Prepared};
use ressort_engine::{ExciterKind, ScaleClass};

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
