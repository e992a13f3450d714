//! What a model's analyses found, kept so that a model analysed once loads at once.
//!
//! Preparing a model ([`super::prepare`]) is mostly its analyses: the reference pitch (a modal
//! analysis), the exact stability envelope (bisections of sparse factorisations), the macro
//! envelopes and units (modal analyses per slot position) and the level calibration (renders
//! through the instrument). On the 150 × 150 plate they take seconds, where parsing and
//! compiling take milliseconds. Their results depend only on the script's text, the sample rate
//! and the playing conventions, so they are kept:
//!
//! - **in memory**, for the process: an A/B switch, a Voices change, a second instance of the
//!   same model or a preset chosen again skip them ([`MEMORY_ENTRIES`] models, newest kept);
//! - **shipped with the presets**: `models/analyses.txt` holds them for every script of
//!   `models/` at the common sample rates ([`SHIPPED_RATES`]), under today's conventions, so a
//!   preset loads in milliseconds from the first time. It is written by `cargo run --release -p
//!   ressort-engine --example analyses_table -- --write`; `engine/tests/analyses_table.rs`
//!   checks that it covers every preset as written today and equals a fresh analysis.
//!
//! A model prepared from kept analyses is the model the analyses would have prepared, sample
//! for sample (the test above renders both). The shipped entries hold the macro units in full;
//! a fresh preparation measures them within a time budget.
//!
//! The table's format is line-based text: an entry starts with `model NAME HASH LENGTH RATE`
//! (the FNV-1a hash of the script's bytes and its length identify the text) and ends with
//! `end`; numbers are written as Rust prints an `f64` (the shortest text that reads back to
//! the same bits).

use super::macros::MacroBinding;
use super::prepare::{Conventions, Facts};
use super::units::{MacroUnit, UnitTable};
use super::NUM_MACROS;
use crate::analysis::envelope::{LoadLine, StabilityEnvelope};
use crate::{Engine, ParamId};
use std::collections::VecDeque;
use std::fmt::Write as _;
use std::sync::{Arc, Mutex, OnceLock};

/// The sample rates the shipped table covers (Hz).
pub const SHIPPED_RATES: [f64; 7] = [
    22050.0, 44100.0, 48000.0, 88200.0, 96000.0, 176400.0, 192000.0,
];
/// How many analysed models the process keeps in memory.
pub const MEMORY_ENTRIES: usize = 32;

/// The largest relative difference [`Analyses::distance`] lets pass as the same analysis run on
/// another processor.
pub const AGREEMENT: f64 = 1e-6;

/// The analyses' results: every part of [`Facts`] that is not read off the script and its
/// compiled engine.
#[derive(Clone, Debug, PartialEq)]
pub struct Analyses {
    pub reference_pitch_hz: Option<f64>,
    pub reference_key: f64,
    pub envelope: StabilityEnvelope,
    pub macro_envelopes: Vec<Option<(StabilityEnvelope, StabilityEnvelope)>>,
    pub macro_reference: StabilityEnvelope,
    pub worst_load: (f64, String),
    pub macros: Vec<Option<MacroBinding>>,
    pub macro_units: Vec<MacroUnit>,
    pub rest_out: Vec<f64>,
    pub output_trim: f64,
    pub input_trim: f64,
}

impl Analyses {
    /// The analyses' part of a prepared model's facts.
    pub fn of(f: &Facts) -> Analyses {
        Analyses {
            reference_pitch_hz: f.settings.reference_pitch_hz,
            reference_key: f.settings.reference_key,
            envelope: f.envelope.clone(),
            macro_envelopes: f.macro_envelopes.clone(),
            macro_reference: f.macro_reference.clone(),
            worst_load: f.worst_load.clone(),
            macros: f.macros.clone(),
            macro_units: f.macro_units.clone(),
            rest_out: f.rest_out.clone(),
            output_trim: f.output_trim,
            input_trim: f.input_trim,
        }
    }

    /// How far these analyses are from `other`: the largest relative difference of their
    /// numbers, or what differs when their words or shapes do. The eigensolvers' floating-point
    /// sums follow the processor's SIMD width (faer dispatches at run time), so the same
    /// analysis on another machine differs in its last bits; a law or an analysis that
    /// changed moves the numbers far more ([`AGREEMENT`]).
    pub fn distance(&self, other: &Analyses) -> Result<f64, String> {
        let text = |a: &Analyses| {
            let mut t = Table::default();
            t.push("compared", "", 48_000.0, a.clone());
            t.to_text("")
        };
        let (a, b) = (text(self), text(other));
        let mut worst = 0.0f64;
        for (la, lb) in a.lines().zip(b.lines()) {
            let (wa, wb): (Vec<&str>, Vec<&str>) = (
                la.split_whitespace().collect(),
                lb.split_whitespace().collect(),
            );
            if wa.len() != wb.len() {
                return Err(format!("`{la}` against `{lb}`"));
            }
            for (x, y) in wa.iter().zip(&wb) {
                match (x.parse::<f64>(), y.parse::<f64>()) {
                    (Ok(x), Ok(y)) if x == y || (x.is_nan() && y.is_nan()) => {}
                    (Ok(x), Ok(y)) => {
                        worst = worst.max((x - y).abs() / x.abs().max(y.abs()));
                    }
                    _ if x == y => {}
                    _ => return Err(format!("`{la}` against `{lb}`")),
                }
            }
        }
        if a.lines().count() != b.lines().count() {
            return Err("a different number of lines".to_string());
        }
        Ok(worst)
    }

    /// Writes the results into facts made from the same script.
    pub(crate) fn apply(&self, f: &mut Facts) {
        f.settings.reference_pitch_hz = self.reference_pitch_hz;
        f.settings.reference_key = self.reference_key;
        f.envelope = self.envelope.clone();
        f.macro_envelopes = self.macro_envelopes.clone();
        f.macro_reference = self.macro_reference.clone();
        f.worst_load = self.worst_load.clone();
        f.macros = self.macros.clone();
        f.macro_units = self.macro_units.clone();
        f.rest_out = self.rest_out.clone();
        f.output_trim = self.output_trim;
        f.input_trim = self.input_trim;
    }

    /// Whether these results fit facts made from the script and its engine: every macro
    /// slot with its envelopes and unit, bindings to the engine's parameters, one rest per
    /// output. A table entry that does not fit is not used.
    pub(crate) fn fits(&self, f: &Facts, engine: &Engine) -> bool {
        let params = &engine.info().params;
        self.macros.len() == NUM_MACROS
            && self.macro_envelopes.len() == NUM_MACROS
            && self.macro_units.len() == NUM_MACROS
            && self.rest_out.len() == f.rest_out.len()
            && self.macros.iter().flatten().all(|b| {
                params
                    .get(b.param.0 as usize)
                    .is_some_and(|p| p.name == b.name)
            })
    }
}

/// FNV-1a, 64 bits: the shipped table's name for a script's text.
pub fn text_hash(text: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// The analyses kept for a script at a sample rate under the conventions: the process's
/// memory first, then the shipped table (today's conventions only).
pub fn recall(text: &str, sample_rate: f64, conventions: Conventions) -> Option<Arc<Analyses>> {
    let kept = lock_memory()
        .iter()
        .find(|e| e.rate == sample_rate.to_bits() && e.conventions == conventions && e.text == text)
        .map(|e| Arc::clone(&e.analyses));
    kept.or_else(|| {
        (conventions == Conventions::Musical)
            .then(|| shipped().find(text, sample_rate))
            .flatten()
    })
}

/// Keeps a fresh preparation's analyses in memory, the oldest going first when full.
pub fn remember(text: &str, sample_rate: f64, conventions: Conventions, analyses: Analyses) {
    let mut memory = lock_memory();
    memory.retain(|e| {
        !(e.rate == sample_rate.to_bits() && e.conventions == conventions && e.text == text)
    });
    if memory.len() >= MEMORY_ENTRIES {
        memory.pop_front();
    }
    memory.push_back(Kept {
        text: text.to_string(),
        rate: sample_rate.to_bits(),
        conventions,
        analyses: Arc::new(analyses),
    });
}

struct Kept {
    text: String,
    rate: u64,
    conventions: Conventions,
    analyses: Arc<Analyses>,
}

fn lock_memory() -> std::sync::MutexGuard<'static, VecDeque<Kept>> {
    static MEMORY: Mutex<VecDeque<Kept>> = Mutex::new(VecDeque::new());
    MEMORY.lock().unwrap_or_else(|e| e.into_inner())
}

/// Every analysis the process keeps in memory for a script under the conventions, one per
/// sample rate (what a project saves with the script: [`super::saved_analyses`]).
pub(crate) fn kept_in_memory(text: &str, conventions: Conventions) -> Vec<(f64, Arc<Analyses>)> {
    lock_memory()
        .iter()
        .filter(|e| e.conventions == conventions && e.text == text)
        .map(|e| (f64::from_bits(e.rate), Arc::clone(&e.analyses)))
        .collect()
}

/// Forgets the analyses kept in memory for a script, at every rate and under every
/// convention, as a new process would not have them: for tests of what a project brings.
#[doc(hidden)]
pub fn forget(text: &str) {
    lock_memory().retain(|e| e.text != text);
}

/// The text of `models/analyses.txt`.
const SHIPPED_TEXT: &str = include_str!("../../../models/analyses.txt");

/// The table shipped in `models/analyses.txt`.
pub fn shipped() -> &'static Table {
    static SHIPPED: OnceLock<Table> = OnceLock::new();
    SHIPPED.get_or_init(|| Table::parse(SHIPPED_TEXT).unwrap_or_default())
}

/// The hash of the shipped table's text: it changes whenever a law, an analysis or a preset
/// changed what the table says (its test fails until it is written again), so analyses saved
/// by a build with another fingerprint are not trusted ([`super::saved_analyses`]).
pub fn fingerprint() -> u64 {
    text_hash(SHIPPED_TEXT)
}

/// One entry of a table: which script and rate it is for.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    pub name: String,
    pub hash: u64,
    pub length: usize,
    pub sample_rate: f64,
    pub analyses: Arc<Analyses>,
}

/// Analyses by script text and sample rate.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    pub entries: Vec<Entry>,
}

impl Table {
    /// The entry for a script's text at a sample rate.
    pub fn find(&self, text: &str, sample_rate: f64) -> Option<Arc<Analyses>> {
        let (hash, length) = (text_hash(text), text.len());
        self.entries
            .iter()
            .find(|e| {
                e.hash == hash
                    && e.length == length
                    && e.sample_rate.to_bits() == sample_rate.to_bits()
            })
            .map(|e| Arc::clone(&e.analyses))
    }

    /// Adds the analyses of a script (by its preset name) at a sample rate.
    pub fn push(&mut self, name: &str, text: &str, sample_rate: f64, analyses: Analyses) {
        self.entries.push(Entry {
            name: name.to_string(),
            hash: text_hash(text),
            length: text.len(),
            sample_rate,
            analyses: Arc::new(analyses),
        });
    }

    /// The table as text (see the module's documentation).
    pub fn to_text(&self, header: &str) -> String {
        let mut s = String::new();
        for line in header.lines() {
            let _ = writeln!(s, "# {line}");
        }
        for e in &self.entries {
            let a = &e.analyses;
            let _ = writeln!(
                s,
                "model {} {:016x} {} {}",
                e.name, e.hash, e.length, e.sample_rate
            );
            match a.reference_pitch_hz {
                Some(f) => {
                    let _ = writeln!(s, "pitch {f:?}");
                }
                None => s.push_str("pitch none\n"),
            }
            let _ = writeln!(s, "key {:?}", a.reference_key);
            let _ = writeln!(s, "envelope {}", envelope_text(&a.envelope));
            let _ = writeln!(s, "reference {}", envelope_text(&a.macro_reference));
            for (i, m) in a.macro_envelopes.iter().enumerate() {
                match m {
                    Some((lo, hi)) => {
                        let _ =
                            writeln!(s, "slot {i} {} | {}", envelope_text(lo), envelope_text(hi));
                    }
                    None => {
                        let _ = writeln!(s, "slot {i} none");
                    }
                }
            }
            for (i, b) in a.macros.iter().enumerate() {
                match b {
                    Some(b) => {
                        let _ = writeln!(
                            s,
                            "bind {i} {} {:?} {:?} {:?} {}",
                            b.param.0, b.default, b.min, b.max, b.name
                        );
                    }
                    None => {
                        let _ = writeln!(s, "bind {i} none");
                    }
                }
            }
            for (i, u) in a.macro_units.iter().enumerate() {
                let _ = writeln!(s, "unit {i} {}", unit_text(u));
            }
            let _ = writeln!(s, "worst {:?} {}", a.worst_load.0, a.worst_load.1);
            let _ = writeln!(s, "rest{}", numbers_text(&a.rest_out));
            let _ = writeln!(s, "trims {:?} {:?}", a.output_trim, a.input_trim);
            s.push_str("end\n");
        }
        s
    }

    /// Reads a table written by [`Table::to_text`]; the error names the line.
    pub fn parse(text: &str) -> Result<Table, String> {
        let mut table = Table::default();
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'));
        while let Some((n, line)) = lines.next() {
            let at = |what: &str| format!("line {}: {what}", n + 1);
            let mut words = line.split_whitespace();
            if words.next() != Some("model") {
                return Err(at("expected `model NAME HASH LENGTH RATE`"));
            }
            let name = words.next().ok_or_else(|| at("no model name"))?.to_string();
            let hash = words
                .next()
                .and_then(|h| u64::from_str_radix(h, 16).ok())
                .ok_or_else(|| at("no hash"))?;
            let length = words
                .next()
                .and_then(|l| l.parse().ok())
                .ok_or_else(|| at("no length"))?;
            let sample_rate = words
                .next()
                .and_then(|r| r.parse().ok())
                .ok_or_else(|| at("no sample rate"))?;
            let mut body = Vec::new();
            loop {
                let (n, l) = lines.next().ok_or_else(|| at("the entry has no `end`"))?;
                if l.trim() == "end" {
                    break;
                }
                body.push((n, l));
            }
            let analyses = parse_entry(&body)?;
            table.entries.push(Entry {
                name,
                hash,
                length,
                sample_rate,
                analyses: Arc::new(analyses),
            });
        }
        Ok(table)
    }
}

fn numbers_text(v: &[f64]) -> String {
    v.iter().map(|x| format!(" {x:?}")).collect()
}

fn envelope_text(e: &StabilityEnvelope) -> String {
    let mut s = format!("{:?}", e.scale);
    for l in &e.lines {
        let _ = write!(s, " {:?} {:?}", l.k, l.z);
    }
    s
}

fn unit_text(u: &MacroUnit) -> String {
    let table = |name: &str, t: &UnitTable| {
        let mut s = name.to_string();
        for (p, v) in &t.points {
            let _ = write!(s, " {p:?} {v:?}");
        }
        s
    };
    match u {
        MacroUnit::Value => "value".into(),
        MacroUnit::Position => "position".into(),
        MacroUnit::MassRatio => "mass".into(),
        MacroUnit::Frequency(t) => table("frequency", t),
        MacroUnit::Decay(t) => table("decay", t),
    }
}

fn numbers(words: &[&str]) -> Option<Vec<f64>> {
    words.iter().map(|w| w.parse().ok()).collect()
}

fn parse_envelope(words: &[&str]) -> Option<StabilityEnvelope> {
    let (scale, rest) = words.split_first()?;
    let v = numbers(rest)?;
    if v.len() % 2 != 0 {
        return None;
    }
    Some(StabilityEnvelope {
        scale: scale.parse().ok()?,
        lines: v.chunks(2).map(|c| LoadLine { k: c[0], z: c[1] }).collect(),
    })
}

fn parse_unit(words: &[&str]) -> Option<MacroUnit> {
    let (kind, rest) = words.split_first()?;
    let table = || -> Option<UnitTable> {
        let v = numbers(rest)?;
        (v.len() % 2 == 0 && !v.is_empty()).then(|| UnitTable {
            points: v.chunks(2).map(|c| (c[0], c[1])).collect(),
        })
    };
    match *kind {
        "value" => Some(MacroUnit::Value),
        "position" => Some(MacroUnit::Position),
        "mass" => Some(MacroUnit::MassRatio),
        "frequency" => table().map(MacroUnit::Frequency),
        "decay" => table().map(MacroUnit::Decay),
        _ => None,
    }
}

fn parse_entry(body: &[(usize, &str)]) -> Result<Analyses, String> {
    let mut a = Analyses {
        reference_pitch_hz: None,
        reference_key: 60.0,
        envelope: StabilityEnvelope::default(),
        macro_envelopes: Vec::new(),
        macro_reference: StabilityEnvelope::default(),
        worst_load: (0.0, String::new()),
        macros: Vec::new(),
        macro_units: Vec::new(),
        rest_out: Vec::new(),
        output_trim: 1.0,
        input_trim: 1.0,
    };
    for &(n, line) in body {
        let bad = || format!("line {}: cannot read `{line}`", n + 1);
        let words: Vec<&str> = line.split_whitespace().collect();
        let (&kind, rest) = words.split_first().ok_or_else(bad)?;
        match kind {
            "pitch" => {
                a.reference_pitch_hz = match rest {
                    ["none"] => None,
                    [f] => Some(f.parse().map_err(|_| bad())?),
                    _ => return Err(bad()),
                }
            }
            "key" => a.reference_key = rest.first().and_then(|k| k.parse().ok()).ok_or_else(bad)?,
            "envelope" => a.envelope = parse_envelope(rest).ok_or_else(bad)?,
            "reference" => a.macro_reference = parse_envelope(rest).ok_or_else(bad)?,
            "slot" => {
                let (i, rest) = rest.split_first().ok_or_else(bad)?;
                if i.parse::<usize>().ok() != Some(a.macro_envelopes.len()) {
                    return Err(bad());
                }
                let pair = if rest == ["none"] {
                    None
                } else {
                    let bar = rest.iter().position(|w| *w == "|").ok_or_else(bad)?;
                    let lo = parse_envelope(&rest[..bar]).ok_or_else(bad)?;
                    let hi = parse_envelope(&rest[bar + 1..]).ok_or_else(bad)?;
                    Some((lo, hi))
                };
                a.macro_envelopes.push(pair);
            }
            "bind" => {
                let (i, rest) = rest.split_first().ok_or_else(bad)?;
                if i.parse::<usize>().ok() != Some(a.macros.len()) {
                    return Err(bad());
                }
                let binding = match rest {
                    ["none"] => None,
                    [param, default, min, max, name] => Some(MacroBinding {
                        param: ParamId(param.parse().map_err(|_| bad())?),
                        name: name.to_string(),
                        default: default.parse().map_err(|_| bad())?,
                        min: min.parse().map_err(|_| bad())?,
                        max: max.parse().map_err(|_| bad())?,
                    }),
                    _ => return Err(bad()),
                };
                a.macros.push(binding);
            }
            "unit" => {
                let (i, rest) = rest.split_first().ok_or_else(bad)?;
                if i.parse::<usize>().ok() != Some(a.macro_units.len()) {
                    return Err(bad());
                }
                a.macro_units.push(parse_unit(rest).ok_or_else(bad)?);
            }
            "worst" => {
                let (load, label) = rest.split_first().ok_or_else(bad)?;
                a.worst_load = (load.parse().map_err(|_| bad())?, label.join(" "));
            }
            "rest" => a.rest_out = numbers(rest).ok_or_else(bad)?,
            "trims" => match numbers(rest).as_deref() {
                Some([o, i]) => (a.output_trim, a.input_trim) = (*o, *i),
                _ => return Err(bad()),
            },
            _ => return Err(bad()),
        }
    }
    Ok(a)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Analyses {
        let env = |s: f64| StabilityEnvelope {
            scale: s,
            lines: vec![
                LoadLine {
                    k: 0.1 + s,
                    z: 1e-300,
                },
                LoadLine {
                    k: 1.0 / 3.0,
                    z: 0.0,
                },
            ],
        };
        Analyses {
            reference_pitch_hz: Some(261.625_565_300_598_6),
            reference_key: 59.999_999_999_999_99,
            envelope: env(1.0),
            macro_envelopes: vec![None, Some((env(0.5), env(0.25))), None],
            macro_reference: env(0.95),
            worst_load: (0.123_456_789, "mesh m3_4".into()),
            macros: vec![
                None,
                Some(MacroBinding {
                    param: ParamId(3),
                    name: "K".into(),
                    default: 0.1,
                    min: 0.01,
                    max: 0.300_000_000_000_000_04,
                }),
                None,
            ],
            macro_units: vec![
                MacroUnit::Value,
                MacroUnit::Frequency(UnitTable {
                    points: vec![(0.0, 110.0), (0.5, 220.000_000_1), (1.0, 440.0)],
                }),
                MacroUnit::Decay(UnitTable {
                    points: vec![(0.0, f64::INFINITY), (1.0, 0.1)],
                }),
            ],
            rest_out: vec![0.0, -1.5e-17],
            output_trim: 12.345,
            input_trim: 1e-5,
        }
    }

    #[test]
    fn a_table_reads_back_bit_for_bit() {
        let mut t = Table::default();
        t.push("one", "a script", 48000.0, sample());
        t.push("two", "another", 44100.0, sample());
        let text = t.to_text("a header\non two lines");
        let back = Table::parse(&text).expect("the table reads back");
        assert_eq!(back, t);
        assert_eq!(back.find("a script", 48000.0).as_deref(), Some(&sample()));
        assert!(back.find("a script", 44100.0).is_none());
        assert!(back.find("a scripT", 48000.0).is_none());
    }

    #[test]
    fn a_broken_table_names_its_line() {
        let mut t = Table::default();
        t.push("one", "a script", 48000.0, sample());
        let text = t.to_text("").replace("trims", "trimz");
        let err = Table::parse(&text).expect_err("a broken entry is refused");
        assert!(err.contains("cannot read `trimz"), "{err}");
        let cut = t.to_text("").replace("end\n", "");
        assert!(Table::parse(&cut).expect_err("no end").contains("no `end`"));
    }

    #[test]
    fn memory_keeps_the_newest_models() {
        let rate = 12345.0;
        for i in 0..MEMORY_ENTRIES + 3 {
            remember(
                &format!("memory test {i}"),
                rate,
                Conventions::Musical,
                sample(),
            );
        }
        assert!(recall("memory test 0", rate, Conventions::Musical).is_none());
        let last = format!("memory test {}", MEMORY_ENTRIES + 2);
        assert!(recall(&last, rate, Conventions::Musical).is_some());
        assert!(recall(&last, rate, Conventions::Legacy).is_none());
    }
}
