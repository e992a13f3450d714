//! The analyses a project keeps with its scripts, so that a project reopens without running
//! them again.
//!
//! A preset's analyses are shipped ([`super::analyses::shipped`]) and a script seen before in
//! the process is kept in memory, but a user's own script (or an edited preset) was analysed
//! afresh every time a project holding it opened: a second or more of the host's thread for a
//! large model, per instance. The plugin therefore saves, with each script of its state, the
//! analyses the process keeps for it ([`save`]), and a state load hands them back to the
//! process's memory ([`restore`]) before the script is prepared, which then takes
//! milliseconds. A reopened project also plays with the very numbers it was saved with, so a
//! bounce on another machine (whose eigensolvers round differently in their last bits) is
//! the same bounce.
//!
//! The saved text is a table of [`super::analyses::Table`]'s format, one entry per sample
//! rate, after a line `fingerprint HEX` naming the build's analyses
//! ([`super::analyses::fingerprint`]). Saved analyses are used only when:
//!
//! - the fingerprint is this build's: a law or an analysis that changed since gives the
//!   project's scripts a fresh analysis (once; the project then saves the new results);
//! - each entry names the script it comes with (its hash and length) and a sample rate of at
//!   most [`MAX_RATE`] Hz;
//! - every number is one the analyses can give ([`sane`]): a state edited by hand or damaged
//!   cannot hand the instrument a non-finite trim or envelope. (An entry that does not fit
//!   the compiled script, another macro count say, is refused at preparation as a shipped one
//!   is.)
//!
//! Anything else is dropped whole, with the reason, and the script is analysed as if nothing
//! had been saved.

use super::analyses::{self, fingerprint, Analyses, Table};
use super::prepare::Conventions;
use super::units::MacroUnit;
use crate::analysis::envelope::StabilityEnvelope;
use std::fmt::Write as _;

/// The highest sample rate an entry may name (Hz).
pub const MAX_RATE: f64 = 1.0e6;

/// The name every saved entry carries (the table's names are single words; a script's own
/// name is saved beside it).
const ENTRY_NAME: &str = "saved";

/// What a state load did with saved analyses.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Restored {
    /// This many entries (sample rates) are kept for the script now.
    Kept(usize),
    /// They were made by a build whose analyses differ: the script is analysed afresh.
    Stale,
}

/// The analyses the process keeps for `text` under `conventions`, as the text a project saves
/// with it; None when none are kept (a preset's come with the plugin, a script not yet
/// prepared has none).
pub fn save(text: &str, conventions: Conventions) -> Option<String> {
    let kept = analyses::kept_in_memory(text, conventions);
    if kept.is_empty() {
        return None;
    }
    let mut table = Table::default();
    for (rate, a) in kept {
        table.push(ENTRY_NAME, text, rate, (*a).clone());
    }
    let mut s = String::new();
    let _ = writeln!(s, "fingerprint {:016x}", fingerprint());
    s.push_str(&table.to_text(""));
    Some(s)
}

/// Hands analyses a project saved with `text` ([`save`]) to the process's memory, so that
/// preparing the script under `conventions` finds them. `Err` says why nothing was kept:
/// a damaged or foreign text, an entry for another script, or a number no analysis gives.
pub fn restore(text: &str, conventions: Conventions, saved: &str) -> Result<Restored, String> {
    let mut lines = saved.lines();
    let first = lines
        .by_ref()
        .find(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .ok_or("no `fingerprint` line")?;
    let hex = first
        .strip_prefix("fingerprint ")
        .ok_or_else(|| format!("expected `fingerprint HEX`, found `{first}`"))?;
    let saved_print =
        u64::from_str_radix(hex.trim(), 16).map_err(|_| format!("`{hex}` is not a fingerprint"))?;
    if saved_print != fingerprint() {
        return Ok(Restored::Stale);
    }
    let rest: Vec<&str> = lines.collect();
    let table = Table::parse(&rest.join("\n"))?;
    let (hash, length) = (analyses::text_hash(text), text.len());
    for e in &table.entries {
        if e.hash != hash || e.length != length {
            return Err(format!(
                "the entry at {} Hz is for another script ({:016x}, {} bytes)",
                e.sample_rate, e.hash, e.length
            ));
        }
        if !(e.sample_rate > 0.0 && e.sample_rate <= MAX_RATE) {
            return Err(format!("a sample rate of {} Hz", e.sample_rate));
        }
        sane(&e.analyses).map_err(|why| format!("the entry at {} Hz: {why}", e.sample_rate))?;
    }
    for e in &table.entries {
        analyses::remember(text, e.sample_rate, conventions, (*e.analyses).clone());
    }
    Ok(Restored::Kept(table.entries.len()))
}

/// Whether every number of `a` is one the analyses give: finite trims above 0 and at most
/// 10⁶, a finite positive pitch, finite envelopes, keys, loads, rests and bindings, unit
/// tables without NaN (a decay may be infinite).
pub fn sane(a: &Analyses) -> Result<(), String> {
    let finite = |what: &str, x: f64| {
        if x.is_finite() {
            Ok(())
        } else {
            Err(format!("{what} is {x}"))
        }
    };
    let envelope = |what: &str, e: &StabilityEnvelope| {
        finite(what, e.scale)?;
        e.lines.iter().try_for_each(|l| {
            finite(what, l.k)?;
            finite(what, l.z)
        })
    };
    for (what, trim) in [
        ("the output trim", a.output_trim),
        ("the input trim", a.input_trim),
    ] {
        if !(trim > 0.0 && trim <= 1e6) {
            return Err(format!("{what} is {trim}"));
        }
    }
    if let Some(p) = a.reference_pitch_hz {
        if !(p > 0.0 && p.is_finite()) {
            return Err(format!("the reference pitch is {p} Hz"));
        }
    }
    finite("the reference key", a.reference_key)?;
    envelope("the envelope", &a.envelope)?;
    envelope("the macros' reference envelope", &a.macro_reference)?;
    for (lo, hi) in a.macro_envelopes.iter().flatten() {
        envelope("a macro envelope", lo)?;
        envelope("a macro envelope", hi)?;
    }
    finite("the worst load", a.worst_load.0)?;
    a.rest_out
        .iter()
        .try_for_each(|&r| finite("a rest output", r))?;
    for b in a.macros.iter().flatten() {
        for x in [b.default, b.min, b.max] {
            finite("a macro binding", x)?;
        }
    }
    for u in &a.macro_units {
        if let MacroUnit::Frequency(t) | MacroUnit::Decay(t) = u {
            if t.points.iter().any(|(p, v)| p.is_nan() || v.is_nan()) {
                return Err("a macro unit table holds NaN".into());
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::prepare_with;

    const RATE: f64 = 48_000.0;

    /// A script no table knows (the harmonic oscillator with a comment of its own).
    fn script(tag: &str) -> String {
        format!(
            "{}\n# saved analyses test: {tag}\n",
            include_str!("../../../models/harmonic-oscillator.mdl")
        )
    }

    /// `text` prepared at [`RATE`] once, so that the process keeps its analyses.
    fn analysed(text: &str) -> Analyses {
        let p = prepare_with("saved", text, RATE, Conventions::Musical).expect("it prepares");
        Analyses::of(p.facts())
    }

    /// Forgets `text`'s analyses (the process's memory of others stays).
    fn forget(text: &str) {
        assert!(analyses::recall(text, RATE, Conventions::Musical).is_some());
        analyses::forget(text);
        assert!(analyses::recall(text, RATE, Conventions::Musical).is_none());
    }

    #[test]
    fn saved_analyses_come_back_bit_for_bit_and_are_the_ones_used() {
        let text = script("round trip");
        assert_eq!(save(&text, Conventions::Musical), None, "nothing kept yet");
        let fresh = analysed(&text);
        let saved = save(&text, Conventions::Musical).expect("kept after preparing");
        assert!(
            save(&text, Conventions::Legacy).is_none(),
            "per conventions"
        );
        forget(&text);
        assert_eq!(
            restore(&text, Conventions::Musical, &saved),
            Ok(Restored::Kept(1))
        );
        let kept = analyses::recall(&text, RATE, Conventions::Musical).expect("restored");
        assert_eq!(*kept, fresh, "the numbers read back to the same bits");
        // The model prepared now takes them: a trim changed in the saved text is the one
        // the prepared model plays with.
        forget(&text);
        let trims = saved
            .lines()
            .find(|l| l.starts_with("trims "))
            .expect("trims");
        let input = trims.split_whitespace().nth(2).expect("the input trim");
        let changed = saved.replace(trims, &format!("trims 0.125 {input}"));
        assert_eq!(
            restore(&text, Conventions::Musical, &changed),
            Ok(Restored::Kept(1))
        );
        let p = prepare_with("saved", &text, RATE, Conventions::Musical).expect("it prepares");
        assert_eq!(p.facts().output_trim, 0.125);
    }

    #[test]
    fn analyses_from_another_build_or_script_or_with_bad_numbers_are_not_kept() {
        let text = script("refusals");
        analysed(&text);
        let saved = save(&text, Conventions::Musical).expect("kept");
        forget(&text);
        let (_, body) = saved.split_once('\n').expect("more than a line");
        let stale = format!("fingerprint {:016x}\n{body}", fingerprint() ^ 1);
        assert_eq!(
            restore(&text, Conventions::Musical, &stale),
            Ok(Restored::Stale)
        );
        let trims = saved
            .lines()
            .find(|l| l.starts_with("trims "))
            .expect("trims");
        let pitch = saved
            .lines()
            .find(|l| l.starts_with("pitch "))
            .expect("pitch");
        let envelope = saved
            .lines()
            .find(|l| l.starts_with("envelope "))
            .expect("env");
        let model = saved
            .lines()
            .find(|l| l.starts_with("model "))
            .expect("model");
        let words: Vec<&str> = model.split_whitespace().collect();
        let bad = [
            (saved.replace(trims, "trims NaN 1.0"), "output trim"),
            (saved.replace(trims, "trims 1.0 -2.0"), "input trim"),
            (saved.replace(trims, "trims 1e300 1.0"), "output trim"),
            (saved.replace(pitch, "pitch -5.0"), "reference pitch"),
            (saved.replace(envelope, "envelope inf 0.5 0.5"), "envelope"),
            (
                saved.replace(model, &format!("model saved {} 3 {}", words[2], words[4])),
                "another script",
            ),
            (
                saved.replace(model, &format!("model saved {} {} 0", words[2], words[3])),
                "sample rate",
            ),
            (saved.replace("\nend\n", "\n"), "no `end`"),
            (body.to_string(), "fingerprint"),
            (String::new(), "fingerprint"),
            ("fingerprint zz\n".to_string(), "not a fingerprint"),
        ];
        for (text_of, why) in &bad {
            let r = restore(&text, Conventions::Musical, text_of);
            let err = r.expect_err(why);
            assert!(err.contains(why), "`{why}` not in `{err}`");
            assert!(
                analyses::recall(&text, RATE, Conventions::Musical).is_none(),
                "{why}: nothing kept"
            );
        }
    }
}
