//! Helpers shared by the engine's integration tests.
#![allow(dead_code)]

pub mod native;
pub mod player;

use realfft::RealFftPlanner;
use ressort_engine::lang::{folder_files, parse_with_files, Parsed};
use ressort_engine::{compile, CompileOptions, Engine, ModelSpec};

/// `text` parsed as a script of `models/`: an `objMesh` line reads its file from there.
pub fn parse(text: &str) -> Parsed {
    let models = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let files = folder_files(&models);
    parse_with_files(text, &files)
}

/// The spec of `text`, which must parse without errors (warnings allowed); else the test fails
/// with the errors and the script's first line.
#[track_caller]
pub fn spec(text: &str) -> ModelSpec {
    let parsed = parse(text);
    let errors: Vec<String> = parsed.errors().map(|d| d.to_string()).collect();
    let first = text.lines().next().unwrap_or("");
    assert!(errors.is_empty(), "{first}\n{errors:#?}");
    parsed.spec.expect("no errors, so a spec")
}

/// As [`spec`], for a script that must parse without warnings either.
#[track_caller]
pub fn clean_spec(text: &str) -> ModelSpec {
    let parsed = parse(text);
    assert!(
        parsed.diagnostics.is_empty(),
        "{text}\n{:#?}",
        parsed.diagnostics
    );
    parsed.spec.expect("no diagnostics, so a spec")
}

/// Compiles `spec` at `sr` or fails the test with the compile errors.
pub fn engine(spec: &ModelSpec, sr: f64) -> Engine {
    compile(spec, &CompileOptions::at(sr)).unwrap_or_else(|e| panic!("compile failed:\n{e}"))
}

/// Renders `frames` samples in blocks of `block`, feeding `inputs[c][n]` (shorter channels are
/// padded with 0) and returning one Vec per output channel.
pub fn render(e: &mut Engine, frames: usize, block: usize, inputs: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n_out = e.info().num_outputs();
    let n_in = inputs.len();
    let mut out = vec![Vec::with_capacity(frames); n_out];
    let mut done = 0;
    let mut in_buf = Vec::new();
    let mut out_buf = Vec::new();
    while done < frames {
        let len = block.min(frames - done);
        in_buf.clear();
        for ch in inputs {
            in_buf.extend((done..done + len).map(|n| ch.get(n).copied().unwrap_or(0.0)));
        }
        debug_assert_eq!(in_buf.len(), n_in * len);
        out_buf.clear();
        out_buf.resize(n_out * len, 0.0);
        e.process(len, &in_buf, &mut out_buf);
        for (c, o) in out.iter_mut().enumerate() {
            o.extend_from_slice(&out_buf[c * len..(c + 1) * len]);
        }
        done += len;
    }
    out
}

/// A single-sample impulse of `amplitude` at n = 0, `frames` long.
pub fn impulse(amplitude: f64, frames: usize) -> Vec<f64> {
    let mut v = vec![0.0; frames];
    if frames > 0 {
        v[0] = amplitude;
    }
    v
}

/// The frequency of the strongest spectral peak of `signal` between `lo_hz` and `hi_hz`, with a
/// Hann window and Gaussian (log-parabolic) interpolation between bins.
pub fn peak_frequency(signal: &[f64], sr: f64, lo_hz: f64, hi_hz: f64) -> f64 {
    let n = signal.len();
    let mean = signal.iter().sum::<f64>() / n as f64;
    let mut buf: Vec<f64> = signal
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
            (v - mean) * w
        })
        .collect();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut spec = fft.make_output_vec();
    fft.process(&mut buf, &mut spec).unwrap();
    let bin_hz = sr / n as f64;
    let lo = ((lo_hz / bin_hz).floor() as usize).max(1);
    let hi = ((hi_hz / bin_hz).ceil() as usize).min(spec.len() - 2);
    let mag: Vec<f64> = spec.iter().map(|c| c.norm()).collect();
    let k = (lo..=hi)
        .max_by(|&a, &b| mag[a].total_cmp(&mag[b]))
        .unwrap();
    let (a, b, c) = (mag[k - 1].ln(), mag[k].ln(), mag[k + 1].ln());
    let delta = 0.5 * (a - c) / (a - 2.0 * b + c);
    (k as f64 + delta) * bin_hz
}

/// The interval from `b` to `a` in cents.
pub fn cents(a: f64, b: f64) -> f64 {
    1200.0 * (a / b).log2()
}

/// FNV-1a over the bits of a sequence of f64.
pub fn hash_f64s<'a>(values: impl IntoIterator<Item = &'a f64>) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for v in values {
        for byte in v.to_bits().to_le_bytes() {
            h ^= byte as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// Panics unless `text` writes every law of the table (its keyword between spaces), so that a
/// differential test over `text` runs a law as soon as it is added.
pub fn assert_writes_every_law(text: &str) {
    for kind in ressort_engine::LawKind::ALL {
        let keyword = kind.row().keyword;
        assert!(
            text.contains(&format!(" {keyword} ")),
            "the model has no {keyword}"
        );
    }
}

/// Every preset script of `models/`: (file stem, text), sorted by stem.
pub fn presets() -> Vec<(String, String)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let mut files: Vec<(String, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "mdl"))
        .map(|p| {
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&p).unwrap())
        })
        .collect();
    files.sort();
    files
}
