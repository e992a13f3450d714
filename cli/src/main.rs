//! `ressort`: check, render and benchmark mass-interaction models from the command line.
//!
//! ```text
//! ressort check MODEL.mdl
//! ressort render MODEL.mdl -o OUT.wav [--sample-rate HZ] [--samples N | --seconds S]
//!                [--input inK=FILE.wav]… [--impulse inK=AMPLITUDE]… [--set NAME=VALUE]…
//! ressort render MODEL.mdl -o OUT.wav --as-plugin [--midi FILE.mid] [--note KEY[:VEL][@S][+LEN]]…
//!                [--sidechain FILE.wav] [--main FILE.wav] [--control NAME=VALUE]…
//! ressort bench MODEL.mdl [--sample-rate HZ] [--seconds S]
//! ressort modes MODEL.mdl [--count N] [--sample-rate HZ] [--csv]
//! ressort tune MODEL.mdl --mode K --to FREQ|NOTE [--param NAME] [--sample-rate HZ]
//! ```
//!
//! Exit status: 0 for success, 1 when the model has errors, 2 for usage and I/O errors.

mod midi;
mod modes;
mod play;
mod report;

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use ressort_engine::lang::{folder_files, parse_bytes_with_files};
use ressort_engine::{compile, CompileOptions, Engine, InputUse, ModelSpec, ScaleClass};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(
    name = "ressort",
    version,
    about = "Check, render and benchmark mass-interaction models"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Parse and compile a model; print its diagnostics, summary and stability report.
    Check(CheckArgs),
    /// Render a model's outputs to a 32-bit float WAV file, one channel per @outN.
    Render(Box<RenderArgs>),
    /// Measure a model: parse and compile time, then time per sample with no I/O.
    Bench(BenchArgs),
    /// List a model's modes: frequency, note, T60 and the gain from each input to each
    /// output (linearised at rest, spec §5.5).
    Modes(modes::ModesArgs),
    /// Find the parameter value (or K-class gain) that puts one mode on a target pitch.
    Tune(modes::TuneArgs),
}

#[derive(Args, Debug)]
struct CheckArgs {
    /// The model script.
    model: PathBuf,
    /// The sample rate the stability analysis assumes, in Hz.
    #[arg(long, default_value_t = 44_100.0)]
    sample_rate: f64,
}

#[derive(Args, Debug)]
struct RenderArgs {
    /// The model script.
    model: PathBuf,
    /// The WAV file to write.
    #[arg(short, long)]
    output: PathBuf,
    /// Sample rate in Hz (an integer, as WAV files need).
    #[arg(long, default_value_t = 44_100)]
    sample_rate: u32,
    /// Length in samples.
    #[arg(long, conflicts_with = "seconds")]
    samples: Option<u64>,
    /// Length in seconds (default 2).
    #[arg(long, allow_hyphen_values = true)]
    seconds: Option<f64>,
    /// Feed a WAV file to input K: `in2=pluck.wav`. Its first channel is used.
    #[arg(long = "input", value_name = "inK=FILE.wav")]
    inputs: Vec<String>,
    /// Put AMPLITUDE at sample 0 of input K: `in1=-0.01`.
    #[arg(
        long = "impulse",
        value_name = "inK=AMPLITUDE",
        allow_hyphen_values = true
    )]
    impulses: Vec<String>,
    /// Set a control parameter before rendering: `K=0.2`. With `--as-plugin`, a parameter on
    /// a macro slot moves that slot.
    #[arg(long = "set", value_name = "NAME=VALUE", allow_hyphen_values = true)]
    sets: Vec<String>,
    /// Render what the plugin plays: host audio through its gains and routing, notes,
    /// the stability clamp, output gain, DC filter and soft ceiling; a stereo file (more
    /// channels for models with @out3…). Implied by the options below.
    #[arg(long)]
    as_plugin: bool,
    /// Play a standard MIDI file (notes and pitch bend; tempo map honoured). The render
    /// lasts until 2 s after its last event unless a length is given.
    #[arg(long, value_name = "FILE.mid")]
    midi: Option<PathBuf>,
    /// Play a note: key, velocity 0 … 1 (default 0.8), start in seconds, and how long the key
    /// stays down (else to the end): `60`, `64:0.5@0.25`, `60:0.8@0+1.5`.
    #[arg(long = "note", value_name = "KEY[:VEL][@SECONDS][+LENGTH]")]
    notes: Vec<String>,
    /// Feed the plugin's sidechain (its channels in order; up to 8).
    #[arg(long, value_name = "FILE.wav")]
    sidechain: Option<PathBuf>,
    /// Feed the plugin's main input (the effect layouts; stereo).
    #[arg(long, value_name = "FILE.wav")]
    main: Option<PathBuf>,
    /// Set a plugin control: stiffness=×F, damping=×F, tune=ST, a4=HZ, output-gain=DB,
    /// force-gain=DB, position-gain=DB, dc-filter=on|off, bend-range=ST, velocity-curve=EXP,
    /// trigger=on|off, sensitivity=DB, macroN=0…1.
    #[arg(
        long = "control",
        value_name = "NAME=VALUE",
        allow_hyphen_values = true
    )]
    controls: Vec<String>,
    /// Map a MIDI controller to a macro slot, as the editor's MIDI learn does: `74=macro1`.
    #[arg(long = "cc", value_name = "CC=macroN")]
    cc_maps: Vec<String>,
    /// Notes sounding at once, each on its own copy of the model (the plugin's Voices; 1 is
    /// monophonic: a note retunes the one model).
    #[arg(long, value_name = "N")]
    voices: Option<usize>,
}

#[derive(Args, Debug)]
struct BenchArgs {
    /// The model script.
    model: PathBuf,
    /// Sample rate in Hz.
    #[arg(long, default_value_t = 48_000.0)]
    sample_rate: f64,
    /// Simulated duration in seconds.
    #[arg(long, default_value_t = 5.0)]
    seconds: f64,
    /// Run a bank of N voices of the model, all struck at the start with different tunings
    /// (the plugin's polyphony, through its instrument).
    #[arg(long, value_name = "N")]
    voices: Option<usize>,
    /// Measure what automation costs: the same model steady and with its Stiffness gain swept
    /// (×0.5 to ×1, one cycle per second, a new value every 16 samples as the plugin's
    /// smoother gives), in one run, and print both and their ratio. With `--voices`, the
    /// bank plays with the instrument's Stiffness swept the same way (compare with a run
    /// without `--sweep`).
    #[arg(long)]
    sweep: bool,
    /// Run the model on the interpreter even where it would run on native code (a small
    /// model's sample loop compiled when it loads), to measure what that code gains.
    #[arg(long)]
    no_jit: bool,
}

/// Why a command failed: bad model (exit 1) or usage / I/O (exit 2). The message is printed
/// by `main`; model diagnostics are printed where they are found.
#[derive(Debug)]
enum Failure {
    Model,
    Usage(String),
}

pub(crate) fn usage(msg: impl Into<String>) -> Failure {
    Failure::Usage(msg.into())
}

/// A command piped into `head` ends quietly when the reader goes, as Unix tools do, instead of
/// panicking in `println!` (Rust's runtime ignores SIGPIPE, so a write fails with EPIPE).
fn die_on_a_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to its default before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    die_on_a_closed_pipe();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Check(a) => check(&a),
        Command::Render(a) => render(&a),
        Command::Bench(a) => bench(&a),
        Command::Modes(a) => modes::modes(&a),
        Command::Tune(a) => modes::tune(&a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Model) => ExitCode::from(1),
        Err(Failure::Usage(msg)) => {
            eprintln!("ressort: {msg}");
            ExitCode::from(2)
        }
    }
}

/// Reads and parses a model, printing its diagnostics as `FILE:LINE:COL: severity: message`.
fn load(path: &Path) -> Result<ModelSpec, Failure> {
    let bytes =
        std::fs::read(path).map_err(|e| usage(format!("cannot read {}: {e}", path.display())))?;
    let folder = path.parent().unwrap_or(Path::new("."));
    let parsed = parse_bytes_with_files(&bytes, &folder_files(folder));
    for d in &parsed.diagnostics {
        eprintln!("{}:{d}", path.display());
    }
    parsed.spec.ok_or(Failure::Model)
}

/// Compiles a spec, printing compile errors with their location.
fn build(path: &Path, spec: &ModelSpec, sample_rate_hz: f64) -> Result<Engine, Failure> {
    build_with(path, spec, &CompileOptions::at(sample_rate_hz))
}

fn build_with(path: &Path, spec: &ModelSpec, options: &CompileOptions) -> Result<Engine, Failure> {
    let sample_rate_hz = options.sample_rate_hz;
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Err(usage(format!(
            "invalid sample rate {sample_rate_hz}: it must be a positive number of Hz"
        )));
    }
    compile(spec, options).map_err(|errors| {
        for e in &errors.0 {
            report::print_compile_error(path, e);
        }
        Failure::Model
    })
}

/// The strike `ressort bench` gives a model: −0.01 on its first input if that is a force.
fn bench_strike(engine: &Engine, block: usize) -> Vec<f64> {
    let mut first = vec![0.0; engine.info().num_inputs() * block];
    if matches!(
        engine.info().inputs.first().and_then(|u| u.first()),
        Some(InputUse::Force(_))
    ) {
        first[0] = -0.01;
    }
    first
}

/// `ressort bench --sweep`: passes with the class gains still and with the Stiffness gain
/// moving every 16 samples, alternated on one engine (reset between passes, so both run on
/// the same memory) from the same struck start; the best pass of each kind is reported.
fn bench_sweep(a: &BenchArgs, mut engine: Engine, compile_ms: f64) -> Result<(), Failure> {
    const CHUNK: usize = 16;
    const PASSES: usize = 3;
    let total = ((a.seconds * a.sample_rate / PASSES as f64).round() as u64).max(CHUNK as u64);
    let first = bench_strike(&engine, CHUNK);
    let rest = vec![0.0; first.len()];
    let mut out = vec![0.0; engine.info().num_outputs() * CHUNK];
    let mut pass = |e: &mut Engine, sweep: bool| {
        e.set_class_gain(ScaleClass::Stiffness, 1.0);
        e.reset();
        let t = Instant::now();
        let mut done = 0u64;
        while done < total {
            if sweep {
                let phase = std::f64::consts::TAU * done as f64 / a.sample_rate;
                e.set_class_gain(ScaleClass::Stiffness, 0.75 + 0.25 * phase.cos());
            }
            e.process(CHUNK, if done == 0 { &first } else { &rest }, &mut out);
            done += CHUNK as u64;
        }
        t.elapsed().as_secs_f64() * 1e9 / done as f64
    };
    let (mut steady, mut swept) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..PASSES {
        steady = steady.min(pass(&mut engine, false));
        swept = swept.min(pass(&mut engine, true));
    }
    eprintln!(
        "{}: {PASSES} × {total} samples each at {} Hz in {CHUNK}-sample blocks, steady and with \
         Stiffness swept",
        a.model.display(),
        a.sample_rate
    );
    println!(
        "steady_ns_per_sample={steady:.3} sweep_ns_per_sample={swept:.3} sweep_cost={:.3}x \
         points={} interactions={} compile_ms={compile_ms:.3}",
        swept / steady,
        engine.info().num_points,
        engine.info().num_interactions
    );
    Ok(())
}

fn check(a: &CheckArgs) -> Result<(), Failure> {
    let spec = load(&a.model)?;
    let mut engine = build(&a.model, &spec, a.sample_rate)?;
    let stability = engine.stability();
    report::print_stability_warnings(&a.model, &spec, &engine, &stability);
    print!("{}", report::summary(&a.model, &spec, &engine, &stability));
    Ok(())
}

/// The error for a `--set` of a parameter the model does not declare, listing the ones it does.
pub(crate) fn unknown_parameter(engine: &Engine, name: &str) -> Failure {
    let names: Vec<&str> = engine
        .info()
        .params
        .iter()
        .map(|p| p.name.as_str())
        .collect();
    usage(format!(
        "unknown parameter `{name}`; the model's parameters are: {}",
        if names.is_empty() {
            "(none)".to_string()
        } else {
            names.join(", ")
        }
    ))
}

/// Splits `inK=VALUE` into the 0-based channel and the value text.
fn input_assignment<'a>(text: &'a str, engine: &Engine) -> Result<(usize, &'a str), Failure> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| usage(format!("expected inK=VALUE, found `{text}`")))?;
    let channel: usize = name
        .strip_prefix("in")
        .and_then(|n| n.parse().ok())
        .filter(|n| *n >= 1)
        .ok_or_else(|| usage(format!("`{name}` is not an input name such as in1")))?;
    let count = engine.info().num_inputs();
    if channel > count {
        let have = if count == 0 {
            "the model has no inputs".to_string()
        } else {
            format!("the model's inputs are in1..in{count}")
        };
        return Err(usage(format!("unknown input `{name}`: {have}")));
    }
    Ok((channel - 1, value))
}

/// Reads the first channel of a WAV file as f64 in [−1, 1] (integers) or as stored (floats).
fn read_wav(path: &Path, sample_rate: u32) -> Result<Vec<f64>, Failure> {
    let channels = read_wav_channels(path, sample_rate)?;
    if channels.len() > 1 {
        eprintln!(
            "ressort: note: {} has {} channels; using the first",
            path.display(),
            channels.len()
        );
    }
    Ok(channels
        .into_iter()
        .next()
        .unwrap_or_default()
        .into_iter()
        .map(f64::from)
        .collect())
}

/// Reads every channel of a WAV file, in [−1, 1] (integers) or as stored (floats).
pub(crate) fn read_wav_channels(path: &Path, sample_rate: u32) -> Result<Vec<Vec<f32>>, Failure> {
    let mut reader = hound::WavReader::open(path)
        .map_err(|e| usage(format!("cannot read {}: {e}", path.display())))?;
    let spec = reader.spec();
    if spec.sample_rate != sample_rate {
        return Err(usage(format!(
            "{} is at {} Hz but the render runs at {sample_rate} Hz; resample it or pass \
             --sample-rate {}",
            path.display(),
            spec.sample_rate,
            spec.sample_rate
        )));
    }
    let n = spec.channels.max(1) as usize;
    let bad = |e: hound::Error| usage(format!("cannot decode {}: {e}", path.display()));
    let interleaved: Vec<f32> = match spec.sample_format {
        hound::SampleFormat::Float => reader
            .samples::<f32>()
            .collect::<Result<_, _>>()
            .map_err(bad)?,
        hound::SampleFormat::Int => {
            let scale = 1.0 / (1u64 << (spec.bits_per_sample.clamp(1, 32) - 1)) as f64;
            reader
                .samples::<i32>()
                .map(|s| s.map(|v| (v as f64 * scale) as f32))
                .collect::<Result<_, _>>()
                .map_err(bad)?
        }
    };
    Ok((0..n)
        .map(|c| interleaved.iter().skip(c).step_by(n).copied().collect())
        .collect())
}

/// A 32-bit float WAV writer with `channels` channels at `sample_rate`.
pub(crate) fn float_wav(
    path: &Path,
    channels: usize,
    sample_rate: u32,
) -> Result<hound::WavWriter<std::io::BufWriter<std::fs::File>>, hound::Error> {
    let spec = hound::WavSpec {
        channels: channels as u16,
        sample_rate,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    hound::WavWriter::create(path, spec)
}

/// The maximum length of a render: one hour at 192 kHz.
pub(crate) const MAX_RENDER_SAMPLES: u64 = 192_000 * 3600;
const RENDER_BLOCK_FRAMES: usize = 4096;

fn render(a: &RenderArgs) -> Result<(), Failure> {
    let sr = a.sample_rate;
    if sr == 0 {
        return Err(usage(
            "invalid --sample-rate 0: it must be a positive number of Hz",
        ));
    }
    let total = match (a.samples, a.seconds) {
        (Some(n), _) => n,
        (None, Some(s)) if s.is_finite() && s >= 0.0 => (s * sr as f64).round() as u64,
        (None, Some(s)) => return Err(usage(format!("invalid --seconds {s}"))),
        (None, None) => 2 * sr as u64,
    };
    if total > MAX_RENDER_SAMPLES {
        return Err(usage(format!(
            "{total} samples is longer than the limit of {MAX_RENDER_SAMPLES} (one hour at 192 kHz)"
        )));
    }
    if play::wanted(a) {
        let given = a.samples.is_some() || a.seconds.is_some();
        return play::render(a, given.then_some(total));
    }
    let spec = load(&a.model)?;
    let mut engine = build(&a.model, &spec, sr as f64)?;
    let info = engine.info().clone();
    if info.num_outputs() == 0 {
        return Err(usage(format!(
            "{} has no outputs (@outN) to render",
            a.model.display()
        )));
    }

    for s in &a.sets {
        let (name, value) = s
            .split_once('=')
            .ok_or_else(|| usage(format!("expected NAME=VALUE, found `{s}`")))?;
        let v: f64 = value
            .parse()
            .map_err(|_| usage(format!("`{value}` is not a number (in --set {s})")))?;
        let id = engine
            .param_id(name)
            .ok_or_else(|| unknown_parameter(&engine, name))?;
        engine
            .set_param(id, v)
            .map_err(|e| usage(format!("cannot set `{name}`: {e}")))?;
    }

    // Input signals, each as long as it is; missing samples are 0.
    let mut inputs: Vec<Vec<f64>> = vec![Vec::new(); info.num_inputs()];
    for s in &a.inputs {
        let (ch, file) = input_assignment(s, &engine)?;
        inputs[ch] = read_wav(Path::new(file), sr)?;
    }
    for s in &a.impulses {
        let (ch, value) = input_assignment(s, &engine)?;
        let v: f64 = value
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| {
                usage(format!(
                    "`{value}` is not a finite number (in --impulse {s})"
                ))
            })?;
        if inputs[ch].is_empty() {
            inputs[ch].push(0.0);
        }
        inputs[ch][0] += v;
    }

    // A position input nothing feeds holds its avatar where the script puts it, as the plugin
    // does (0 would pull the avatar there in one sample: a kick through any link on it).
    let rests = ressort_engine::instrument::prepare::input_rests(&engine);

    let out_channels = info.num_outputs();
    let io = |e: hound::Error| usage(format!("cannot write {}: {e}", a.output.display()));
    let mut writer = float_wav(&a.output, out_channels, sr).map_err(io)?;
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{spinner} rendering [{bar:40}] {percent}% {eta} left")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    if total < 10 * sr as u64 {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let mut in_buf = vec![0.0; info.num_inputs() * RENDER_BLOCK_FRAMES];
    let mut out_buf = vec![0.0; out_channels * RENDER_BLOCK_FRAMES];
    let mut done: u64 = 0;
    let mut peak = 0.0f64;
    while done < total {
        let len = RENDER_BLOCK_FRAMES.min((total - done) as usize);
        for (c, signal) in inputs.iter().enumerate() {
            // An input fed by a file or an impulse reads 0 after its end.
            let rest = if signal.is_empty() { rests[c] } else { 0.0 };
            for n in 0..len {
                in_buf[c * len + n] = signal.get(done as usize + n).copied().unwrap_or(rest);
            }
        }
        engine.process(
            len,
            &in_buf[..info.num_inputs() * len],
            &mut out_buf[..out_channels * len],
        );
        for n in 0..len {
            for c in 0..out_channels {
                let v = out_buf[c * len + n];
                peak = peak.max(v.abs());
                // f32 has no room below 1.2e-38: tiny samples are written as 0, not subnormal.
                writer
                    .write_sample(ressort_engine::instrument::dsp::output_sample(v))
                    .map_err(io)?;
            }
        }
        done += len as u64;
        bar.set_position(done);
    }
    bar.finish_and_clear();
    writer.finalize().map_err(io)?;
    if let Some(ev) = engine.guard_event() {
        eprintln!(
            "ressort: warning: the model blew up at sample {} ({:?}{}); the output is silent \
             from there. Run `ressort check` for its stability report.",
            ev.sample,
            ev.kind,
            ev.point
                .map(|p| format!(" at {}", info.point_label(p as usize)))
                .unwrap_or_default()
        );
    }
    eprintln!(
        "wrote {}: {} samples at {} Hz, {} channel(s), peak {:.3e}",
        a.output.display(),
        total,
        sr,
        out_channels,
        peak
    );
    Ok(())
}

fn bench(a: &BenchArgs) -> Result<(), Failure> {
    if !(a.seconds.is_finite() && a.seconds > 0.0 && a.seconds <= 3600.0) {
        return Err(usage(format!(
            "invalid --seconds {}: it must be in (0, 3600]",
            a.seconds
        )));
    }
    if let Some(voices) = a.voices {
        return play::bench_voices(&a.model, a.sample_rate, a.seconds, voices, a.sweep);
    }
    let bytes = std::fs::read(&a.model)
        .map_err(|e| usage(format!("cannot read {}: {e}", a.model.display())))?;
    let start = Instant::now();
    let folder = a.model.parent().unwrap_or(Path::new("."));
    let parsed = parse_bytes_with_files(&bytes, &folder_files(folder));
    let spec = match parsed.spec {
        Some(spec) => spec,
        None => {
            for d in &parsed.diagnostics {
                eprintln!("{}:{d}", a.model.display());
            }
            return Err(Failure::Model);
        }
    };
    let options = CompileOptions {
        jit: !a.no_jit,
        ..CompileOptions::at(a.sample_rate)
    };
    let mut engine = build_with(&a.model, &spec, &options)?;
    let compile_ms = start.elapsed().as_secs_f64() * 1e3;

    if a.sweep {
        return bench_sweep(a, engine, compile_ms);
    }
    let block = 64;
    let n_in = engine.info().num_inputs();
    let n_out = engine.info().num_outputs();
    let total = (a.seconds * a.sample_rate).round().max(1.0) as u64;
    let first = bench_strike(&engine, block);
    let rest = vec![0.0; n_in * block];
    let mut out = vec![0.0; n_out * block];
    // Passes of one strike each: struck from rest, then one second of audio (so that a damped
    // model never reaches its fixed point, where the engine would hold it instead of
    // stepping, engine/src/sim/rest.rs). One untimed pass warms up; `ns_per_sample` is the best
    // timed pass, as the Faust renderer reports the best of its runs (`compare.sh`), and
    // `mean_ns` their mean (named so that it does not match `ns_per_sample=`).
    let total_blocks = total.div_ceil(block as u64).max(1);
    let pass_blocks = ((a.sample_rate / block as f64).round() as u64).clamp(1, total_blocks);
    let passes = ((total_blocks as f64 / pass_blocks as f64).round() as u64).max(1);
    let mut pass = |engine: &mut Engine| {
        engine.reset();
        engine.process(block, &first, &mut out);
        for _ in 1..pass_blocks {
            engine.process(block, &rest, &mut out);
        }
    };
    pass(&mut engine);
    let pass_samples = pass_blocks * block as u64;
    let times: Vec<f64> = (0..passes)
        .map(|_| {
            let t = Instant::now();
            pass(&mut engine);
            t.elapsed().as_secs_f64() * 1e9 / pass_samples as f64
        })
        .collect();
    let ns_per_sample = times.iter().copied().fold(f64::INFINITY, f64::min);
    let mean = times.iter().sum::<f64>() / times.len() as f64;
    let realtime_factor = 1e9 / a.sample_rate / ns_per_sample;
    eprintln!(
        "{}: {passes} passes of {pass_samples} samples at {} Hz after a warm-up; the best \
         takes {:.2} % of one core, the mean {:.2} %",
        a.model.display(),
        a.sample_rate,
        100.0 / realtime_factor,
        100.0 * mean * a.sample_rate / 1e9
    );
    println!(
        "ns_per_sample={ns_per_sample:.3} realtime_factor={realtime_factor:.3} points={} \
         interactions={} compile_ms={compile_ms:.3} mean_ns={mean:.3} native_bytes={}",
        engine.info().num_points,
        engine.info().num_interactions,
        engine.native_code_bytes().unwrap_or(0)
    );
    Ok(())
}
