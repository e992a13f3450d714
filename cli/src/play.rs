//! `ressort render --as-plugin`: the model played through the instrument that the plugin
//! runs (`ressort_engine::instrument`), so the WAV file is what a host would record: host
//! channels through the Force and Position gains, notes retuning and striking, the stability
//! clamp, the output gain, the DC filter and the soft ceiling.

use crate::{midi, read_wav_channels, usage, Failure, RenderArgs};
use ressort_engine::instrument::{
    self, Controls, Event, Instrument, Prepared, Timed, MAX_HOST_INPUTS, MAX_HOST_OUTPUTS,
};
use std::path::Path;
use std::time::Instant;

/// The most voices `--voices` takes.
pub const MAX_VOICES: usize = 1024;

/// Host block size of the render. The instrument's output does not depend on it.
const BLOCK: usize = 512;
/// Ring-out after the last MIDI event when no length is given.
const TAIL_SECONDS: f64 = 2.0;

/// Whether the arguments ask for the plugin's signal path.
pub fn wanted(a: &RenderArgs) -> bool {
    a.as_plugin
        || a.midi.is_some()
        || !a.notes.is_empty()
        || !a.controls.is_empty()
        || !a.cc_maps.is_empty()
        || a.voices.is_some()
        || a.sidechain.is_some()
        || a.main.is_some()
}

/// Reads `--control NAME=VALUE` into the controls, in the units the plugin shows.
fn set_control(c: &mut Controls, text: &str) -> Result<(), Failure> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| usage(format!("expected NAME=VALUE, found `{text}`")))?;
    let number = || -> Result<f64, Failure> {
        value
            .trim()
            .trim_start_matches(['×', 'x'])
            .trim_end_matches(['×', 'x'])
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                usage(format!(
                    "`{value}` is not a finite number (in --control {text})"
                ))
            })
    };
    let factor_octaves = |v: f64| -> Result<f64, Failure> {
        if v > 0.0 {
            Ok(v.log2().clamp(-4.0, 4.0))
        } else {
            Err(usage(format!(
                "--control {text}: a factor must be positive (×1/16 … ×16)"
            )))
        }
    };
    match name.trim() {
        "stiffness" => c.stiffness_octaves = factor_octaves(number()?)?,
        "damping" => c.damping_octaves = factor_octaves(number()?)?,
        "tune" => c.tune_st = number()?.clamp(-24.0, 24.0),
        "output-gain" => c.output_db = number()?.clamp(-40.0, 60.0),
        "force-gain" => c.force_db = number()?.clamp(-60.0, 40.0),
        "position-gain" => c.position_db = number()?.clamp(-60.0, 40.0),
        "bend-range" => c.bend_range_st = number()?.clamp(0.0, 48.0),
        "velocity-curve" => c.velocity_exponent = number()?.clamp(0.25, 4.0),
        "dc-filter" | "mpe" => {
            let on = match value.trim() {
                "on" | "1" | "true" => true,
                "off" | "0" | "false" => false,
                v => return Err(usage(format!("--control {name}={v}: use on or off"))),
            };
            if name.trim() == "mpe" {
                c.mpe = on;
            } else {
                c.dc_filter = on;
            }
        }
        "release" => c.release = number()?.clamp(0.0, 1.0),
        "a4" => {
            let (lo, hi) = instrument::controls::A4_RANGE_HZ;
            let v = number()?;
            if !(lo..=hi).contains(&v) {
                return Err(usage(format!("--control {text}: A4 takes {lo} … {hi} Hz")));
            }
            c.a4_hz = v;
        }
        "trigger" => {
            c.trigger = match value.trim() {
                "on" | "1" | "true" => true,
                "off" | "0" | "false" => false,
                v => return Err(usage(format!("--control trigger={v}: use on or off"))),
            }
        }
        "sensitivity" => c.trigger_sensitivity_db = number()?.clamp(-40.0, 40.0),
        n if n.starts_with("macro") => {
            let slot: usize = n[5..]
                .parse()
                .ok()
                .filter(|s| (1..=instrument::NUM_MACROS).contains(s))
                .ok_or_else(|| {
                    usage(format!(
                        "unknown control `{n}`: macro slots are macro1 … macro{}",
                        instrument::NUM_MACROS
                    ))
                })?;
            c.macros[slot - 1] = number()?.clamp(0.0, 1.0);
        }
        n => {
            return Err(usage(format!(
                "unknown control `{n}`; the controls are stiffness, damping, tune, a4, \
                 output-gain, force-gain, position-gain, dc-filter, bend-range, \
                 velocity-curve, release, mpe, trigger, sensitivity and macro1 … macro{}",
                instrument::NUM_MACROS
            )))
        }
    }
    Ok(())
}

/// `--cc CC=macroN`: MIDI controller CC (1 … 127) moves macro slot N.
fn cc_map(map: &mut [Option<u8>; instrument::NUM_MACROS], text: &str) -> Result<(), Failure> {
    let bad = || {
        usage(format!(
            "--cc {text}: expected CC=macroN with CC 1 … 127 and N 1 … {}, e.g. 74=macro1",
            instrument::NUM_MACROS
        ))
    };
    let (cc, slot) = text.split_once('=').ok_or_else(bad)?;
    let cc: u8 = cc
        .trim()
        .parse()
        .ok()
        .filter(|c| (1..=127).contains(c))
        .ok_or_else(bad)?;
    let slot: usize = slot
        .trim()
        .strip_prefix("macro")
        .and_then(|n| n.parse().ok())
        .filter(|n| (1..=instrument::NUM_MACROS).contains(n))
        .ok_or_else(bad)?;
    map[slot - 1] = Some(cc);
    Ok(())
}

/// `--set NAME=VALUE`: a parameter on a macro slot moves its slot (the plugin would
/// overwrite the value with the slot's otherwise); any other is set in the model.
fn set_param(model: &mut Prepared, c: &mut Controls, text: &str) -> Result<(), Failure> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| usage(format!("expected NAME=VALUE, found `{text}`")))?;
    let v: f64 = value
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite())
        .ok_or_else(|| {
            usage(format!(
                "`{value}` is not a finite number (in --set {text})"
            ))
        })?;
    if let Some((slot, b)) = model
        .facts()
        .macros
        .iter()
        .enumerate()
        .find_map(|(i, b)| b.as_ref().filter(|b| b.name == name).map(|b| (i, b)))
    {
        if v < b.min.min(b.max) || v > b.max.max(b.min) {
            eprintln!(
                "ressort: note: --set {text}: Macro {} spans {} … {}; the value is clamped",
                slot + 1,
                b.min,
                b.max
            );
        }
        c.macros[slot] = b.normalized_of(v);
        return Ok(());
    }
    let id = model
        .engine
        .param_id(name)
        .ok_or_else(|| crate::unknown_parameter(&model.engine, name))?;
    model
        .engine
        .set_param(id, v)
        .map_err(|e| usage(format!("cannot set `{name}`: {e}")))
}

/// `--note KEY[:VELOCITY][@SECONDS][+LENGTH]`: a note-on (velocity 0 … 1, default 0.8; time
/// default 0), and its note-off LENGTH seconds later when given (else the key stays down).
fn note(text: &str, sample_rate: f64) -> Result<Vec<(u64, Event)>, Failure> {
    let bad = || {
        usage(format!(
            "--note {text}: expected KEY[:VELOCITY][@SECONDS][+LENGTH], e.g. 60, 64:0.5, \
             67:1@0.25 or 60:0.8@0+1.5"
        ))
    };
    let (text_on, length) = match text.rsplit_once('+') {
        Some((on, len)) => {
            let len: f64 = len.parse().map_err(|_| bad())?;
            if !(len.is_finite() && len > 0.0) {
                return Err(bad());
            }
            (on, Some(len))
        }
        None => (text, None),
    };
    let (rest, at) = match text_on.split_once('@') {
        Some((r, t)) => (r, t.parse::<f64>().map_err(|_| bad())?),
        None => (text_on, 0.0),
    };
    let (key, velocity) = match rest.split_once(':') {
        Some((k, v)) => (k, v.parse::<f32>().map_err(|_| bad())?),
        None => (rest, 0.8),
    };
    let key: u8 = key.parse().ok().filter(|k| *k <= 127).ok_or_else(bad)?;
    if !(at.is_finite() && at >= 0.0 && velocity.is_finite() && (0.0..=1.0).contains(&velocity)) {
        return Err(bad());
    }
    let start = (at * sample_rate).round() as u64;
    let mut events = vec![(
        start,
        Event::NoteOn {
            channel: 0,
            voice_id: None,
            note: key,
            velocity,
        },
    )];
    if let Some(len) = length {
        let end = ((at + len) * sample_rate).round() as u64;
        events.push((end.max(start + 1), Event::note_off(key)));
    }
    Ok(events)
}

/// How the plugin plays a prepared model: its pitch and key, the keys it plays in tune, its
/// exciters and its automatic trims.
pub fn describe(m: &Prepared) -> String {
    use ressort_engine::modes::note_name;
    let s = &m.facts().settings;
    let key_name = |k: f64| {
        note_name(440.0 * 2f64.powf((k.round() - 69.0) / 12.0)).map_or(String::new(), |n| n.0)
    };
    let pitch = match s.reference_pitch_hz {
        Some(f) => {
            let (name, cents) = note_name(f).unwrap_or_default();
            format!("reference pitch {f:.2} Hz ({name} {cents:+.0} cents)")
        }
        None => "no reference pitch".to_string(),
    };
    let mode = if m.facts().conventions == instrument::Conventions::Legacy {
        format!("relative to key {:.2} (legacy project)", s.reference_key)
    } else if s.unpitched {
        format!("unpitched: as written at key {:.0}", s.reference_key)
    } else {
        format!("concert pitch: at key {:.2}", s.reference_key)
    };
    let top = m
        .highest_key()
        .map(|k| {
            format!(
                "; in tune up to key {:.0} ({})",
                k.floor(),
                key_name(k.floor())
            )
        })
        .unwrap_or_default();
    let exciters: Vec<String> = m
        .facts()
        .exciters
        .iter()
        .map(|x| format!("{} in{}", x.kind.name(), x.input + 1))
        .chain(m.facts().note_input.map(|k| format!("strike in{}", k + 1)))
        .collect();
    format!(
        "ressort: {pitch}, {mode}{top}; a key plays: {}; output trim {:+.1} dB, sidechain force \
         trim {:+.1} dB",
        if exciters.is_empty() {
            "nothing".to_string()
        } else {
            exciters.join(", ")
        },
        20.0 * m.facts().output_trim.log10(),
        20.0 * m.facts().input_trim.log10()
    )
}

/// Renders through the instrument. See the module documentation.
pub fn render(a: &RenderArgs, total: Option<u64>) -> Result<(), Failure> {
    if !a.inputs.is_empty() || !a.impulses.is_empty() {
        return Err(usage(
            "--input and --impulse feed model inputs directly; the plugin's signal path takes \
             host audio (--sidechain FILE.wav, --main FILE.wav) and notes (--note, --midi)",
        ));
    }
    let sr = a.sample_rate;
    let srf = sr as f64;
    let text = std::fs::read_to_string(&a.model)
        .map_err(|e| usage(format!("cannot read {}: {e}", a.model.display())))?;
    let name = a
        .model
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut model = match instrument::prepare(&name, &text, srf) {
        Ok(m) => m,
        Err(rejected) => {
            for line in &rejected.0 {
                eprintln!("{}:{line}", a.model.display());
            }
            return Err(Failure::Model);
        }
    };
    // --voices, else the script's `~voices`, as the plugin's Voices does by default.
    if let Some(v) = a
        .voices
        .or(model.facts().settings.voices.map(|v| v as usize))
    {
        if !(1..=MAX_VOICES).contains(&v) {
            return Err(usage(format!(
                "--voices {v}: the plugin plays 1 to {MAX_VOICES} voices"
            )));
        }
        model.set_voices(v);
    }
    eprintln!("{}", describe(&model));
    let mut controls = Controls::DEFAULT;
    for c in &a.controls {
        set_control(&mut controls, c)?;
    }
    for s in &a.sets {
        set_param(&mut model, &mut controls, s)?;
    }

    let mut events: Vec<(u64, Event)> = Vec::new();
    for n in &a.notes {
        events.extend(note(n, srf)?);
    }
    if let Some(path) = &a.midi {
        let bytes = std::fs::read(path)
            .map_err(|e| usage(format!("cannot read {}: {e}", path.display())))?;
        let file = midi::read_events(&bytes, srf)
            .map_err(|e| usage(format!("{}: {e}", path.display())))?;
        events.extend(file);
    }
    events.sort_by_key(|e| e.0);

    // Host channels: main left and right, then the sidechain's.
    let mut host: Vec<Vec<f32>> = vec![Vec::new(); MAX_HOST_INPUTS];
    let has_main = a.main.is_some();
    if let Some(path) = &a.main {
        for (c, ch) in read_wav_channels(path, sr)?.into_iter().take(2).enumerate() {
            host[c] = ch;
        }
    }
    if let Some(path) = &a.sidechain {
        let channels = read_wav_channels(path, sr)?;
        if channels.len() > MAX_HOST_INPUTS - 2 {
            eprintln!(
                "ressort: note: {} has {} channels; the plugin reads the first {}",
                path.display(),
                channels.len(),
                MAX_HOST_INPUTS - 2
            );
        }
        for (c, ch) in channels.into_iter().take(MAX_HOST_INPUTS - 2).enumerate() {
            host[2 + c] = ch;
        }
    }
    let longest_input = host.iter().map(Vec::len).max().unwrap_or(0) as u64;
    let total = total.unwrap_or_else(|| {
        let last_event = events.last().map_or(0, |e| e.0);
        let tail = (TAIL_SECONDS * srf) as u64;
        (last_event + tail)
            .max(longest_input)
            .max(2 * sr as u64)
            .min(crate::MAX_RENDER_SAMPLES)
    });

    // Stereo like the plugin's main output; aux pairs for @out3 … when the model has them.
    let channels = if model.facts().num_outputs <= 2 {
        2
    } else {
        model.facts().num_outputs.min(MAX_HOST_OUTPUTS).div_ceil(2) * 2
    };
    let mut ccs = [None; instrument::NUM_MACROS];
    for m in &a.cc_maps {
        cc_map(&mut ccs, m)?;
    }
    let mut inst = Instrument::new(srf, controls);
    inst.set_cc_map(&ccs);
    inst.set_main_input(has_main);
    inst.set_model(Box::new(model));

    let io = |e: hound::Error| usage(format!("cannot write {}: {e}", a.output.display()));
    let mut writer = crate::float_wav(&a.output, channels, sr).map_err(io)?;
    let mut out: Vec<Vec<f32>> = vec![vec![0.0; BLOCK]; channels];
    let mut next_event = 0;
    let (mut done, mut peak, mut trips) = (0u64, 0.0f32, 0u32);
    while done < total {
        let len = BLOCK.min((total - done) as usize);
        let end = done + len as u64;
        let first = next_event;
        while next_event < events.len() && events[next_event].0 < end {
            next_event += 1;
        }
        let mut block_events = events[first..next_event]
            .iter()
            .map(|&(t, e)| Timed::new((t.saturating_sub(done)) as u32, e));
        let start = done as usize;
        let host_in: Vec<Option<&[f32]>> = host
            .iter()
            .map(|ch| ch.get(start..).filter(|s| !s.is_empty()))
            .collect();
        if has_main {
            for (c, o) in out.iter_mut().take(2).enumerate() {
                let src = host_in[c].unwrap_or(&[]);
                for (i, s) in o[..len].iter_mut().enumerate() {
                    *s = src.get(i).copied().unwrap_or(0.0);
                }
            }
        }
        let mut slices: Vec<&mut [f32]> = out.iter_mut().map(|o| &mut o[..len]).collect();
        let report = inst.process(
            len,
            &host_in,
            has_main,
            &mut block_events,
            &controls,
            &mut slices,
        );
        trips += report.trips;
        for i in 0..len {
            for o in &out {
                peak = peak.max(o[i].abs());
                writer.write_sample(o[i]).map_err(io)?;
            }
        }
        done = end;
    }
    writer.finalize().map_err(io)?;
    if trips > 0 {
        eprintln!(
            "ressort: warning: the guard reset the exploding model {trips} time(s), as the \
             plugin does; run `ressort check` for its stability report"
        );
    }
    let g = inst.gains();
    if g.clamped {
        eprintln!(
            "ressort: note: the stability clamp held Stiffness at ×{:.3} (asked ×{:.3}) and \
             Damping at ×{:.3} (asked ×{:.3})",
            g.stiffness, g.requested_stiffness, g.damping, g.requested_damping
        );
    }
    eprintln!(
        "wrote {} as the plugin plays it: {} samples at {} Hz, {} channel(s), peak {:.3e}",
        a.output.display(),
        total,
        sr,
        channels,
        peak
    );
    Ok(())
}

/// `ressort bench MODEL --voices N`: a bank of N voices through the instrument, every voice
/// struck at the first sample on its own note (the reference key, then a semitone apart,
/// wrapping over two octaves), then left to ring; the last line is `bench`'s, for the whole
/// bank.
pub fn bench_voices(
    model: &Path,
    sample_rate: f64,
    seconds: f64,
    voices: usize,
    sweep: bool,
) -> Result<(), Failure> {
    if !(1..=MAX_VOICES).contains(&voices) {
        return Err(usage(format!(
            "--voices {voices}: the bank takes 1 to {MAX_VOICES} voices"
        )));
    }
    if !(sample_rate.is_finite() && sample_rate > 0.0) {
        return Err(usage(format!("invalid sample rate {sample_rate}")));
    }
    let text = std::fs::read_to_string(model)
        .map_err(|e| usage(format!("cannot read {}: {e}", model.display())))?;
    let start = Instant::now();
    let mut prepared = match instrument::prepare("bench", &text, sample_rate) {
        Ok(m) => m,
        Err(rejected) => {
            for line in &rejected.0 {
                eprintln!("{}:{line}", model.display());
            }
            return Err(Failure::Model);
        }
    };
    let compile_ms = start.elapsed().as_secs_f64() * 1e3;
    prepared.set_voices(voices);
    let (points, interactions) = (
        prepared.engine.info().num_points,
        prepared.engine.info().num_interactions,
    );
    let key = prepared
        .facts()
        .settings
        .reference_key
        .round()
        .clamp(0.0, 127.0) as u8;
    let mut controls = Controls::DEFAULT;
    let mut inst = Instrument::new(sample_rate, controls);
    inst.set_model(Box::new(prepared));
    let notes: Vec<Timed> = (0..voices)
        .map(|i| {
            let note = (key as usize + i % 25).saturating_sub(12).min(127) as u8;
            Timed::new(0, Event::note_on(note, 0.8))
        })
        .collect();
    let block = 64;
    let total = (seconds * sample_rate).round().max(1.0) as u64;
    let (mut l, mut r) = (vec![0.0f32; block], vec![0.0f32; block]);
    let no_input: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
    let t = Instant::now();
    let mut done = 0u64;
    let mut most = 0;
    while done < total {
        let first = done == 0;
        let mut events = notes.iter().copied().filter(|_| first);
        let mut out: [&mut [f32]; 2] = [&mut l, &mut r];
        if sweep {
            // Stiffness automated: ×0.5 … ×1, one cycle per second (every voice retunes).
            let phase = std::f64::consts::TAU * done as f64 / sample_rate;
            controls.stiffness_octaves = -0.5 + 0.5 * phase.cos();
        }
        inst.process(block, &no_input, false, &mut events, &controls, &mut out);
        most = most.max(inst.voice_count().0);
        done += block as u64;
    }
    let ns_per_sample = t.elapsed().as_secs_f64() * 1e9 / done as f64;
    let realtime_factor = 1e9 / sample_rate / ns_per_sample;
    eprintln!(
        "{}: {voices} voices ({most} sounding at most, {} at the end), {done} samples at \
         {sample_rate} Hz, {:.2} % of one core",
        model.display(),
        inst.voice_count().0,
        100.0 / realtime_factor
    );
    println!(
        "ns_per_sample={ns_per_sample:.3} realtime_factor={realtime_factor:.3} points={points} \
         interactions={interactions} compile_ms={compile_ms:.3} voices={voices}{}",
        if sweep { " sweep=1" } else { "" }
    );
    Ok(())
}
