//! Loading a script for the instrument: [`super::prepare`] compiles and analyses it, then
//! [`super::level`] plays it to set its trims. The level calibration plays the model through
//! the whole instrument, so it comes after preparation here rather than inside it. A script
//! analysed before (in this process, or a preset of the shipped table) skips both: its
//! analyses are kept ([`super::analyses`]).

use super::analyses::{self, Analyses};
use super::host::Rejected;
use super::level::{calibrate, calibrate_quick};
use super::prepare::{prepare_uncalibrated, Conventions, Prepared, Source, UNITS_BUDGET_S};

/// Compiles a script for a sample rate and derives everything the audio thread needs.
pub fn prepare(name: &str, text: &str, sample_rate: f64) -> Result<Prepared, Rejected> {
    prepare_with(name, text, sample_rate, Conventions::Musical)
}

/// [`prepare`] under the given playing conventions: legacy projects get no trims. Takes the
/// analyses kept for the script when there are some, and keeps those it runs.
pub fn prepare_with(
    name: &str,
    text: &str,
    sample_rate: f64,
    conventions: Conventions,
) -> Result<Prepared, Rejected> {
    let source = match analyses::recall(text, sample_rate, conventions) {
        Some(kept) => Source::Known(kept),
        None => Source::Analyse {
            units_budget_s: UNITS_BUDGET_S,
            pitch: None,
        },
    };
    let (prepared, source) = prepare_uncalibrated(name, text, sample_rate, conventions, source)?;
    if let Source::Known(_) = source {
        return Ok(prepared);
    }
    let prepared = finish(prepared, conventions);
    analyses::remember(
        text,
        sample_rate,
        conventions,
        Analyses::of(prepared.facts()),
    );
    Ok(prepared)
}

/// [`prepare_with`] running every analysis, whatever is kept, with the macro units measured
/// for at most `units_budget_s` seconds (infinity measures them all): what the shipped table
/// is made from, and what its test compares it with.
pub fn prepare_analysed(
    name: &str,
    text: &str,
    sample_rate: f64,
    conventions: Conventions,
    units_budget_s: f64,
) -> Result<Prepared, Rejected> {
    prepare_analysed_at_pitch(name, text, sample_rate, conventions, units_budget_s, None)
}

/// [`prepare_analysed`] with the reference pitch given (`Some`) rather than analysed: every
/// other analysis runs at that pitch (the concert key, the level calibration's tuned note).
/// The shipped table keeps the pitches it was written with, unrounded
/// ([`super::pitch::settle_pitch`] rounds a fresh one); its test compares a fresh analysis
/// with it at its own pitch, and the pitches apart.
pub fn prepare_analysed_at_pitch(
    name: &str,
    text: &str,
    sample_rate: f64,
    conventions: Conventions,
    units_budget_s: f64,
    pitch: Option<f64>,
) -> Result<Prepared, Rejected> {
    let (prepared, _) = prepare_uncalibrated(
        name,
        text,
        sample_rate,
        conventions,
        Source::Analyse {
            units_budget_s,
            pitch,
        },
    )?;
    Ok(finish(prepared, conventions))
}

/// Whether [`prepare_with`] would take kept analyses for the script (the shipped table, the
/// process's memory, a project's saved ones) and so prepare it in milliseconds.
pub fn analyses_kept(text: &str, sample_rate: f64, conventions: Conventions) -> bool {
    analyses::recall(text, sample_rate, conventions).is_some()
}

/// A model that plays at once, for a script whose analyses are not kept: compiled as
/// [`prepare_with`] compiles it, with the quick stand-ins of [`Source::Provisional`] for its
/// analyses (the Gershgorin envelope, a short impulse response's pitch or none, values for
/// the macro units) and levels from shortened renders ([`calibrate_quick`]). Its facts say
/// [`super::Facts::provisional`]; nothing is kept for the script. The exact analyses come from
/// [`prepare_with`] on another thread, and [`super::Instrument::refine`] hands their facts to
/// the playing model. A milliseconds' matter where the full preparation takes up to seconds
/// (`cargo run --release -p ressort-engine --example first_sound`).
pub fn prepare_provisional(
    name: &str,
    text: &str,
    sample_rate: f64,
    conventions: Conventions,
) -> Result<Prepared, Rejected> {
    let (prepared, _) =
        prepare_uncalibrated(name, text, sample_rate, conventions, Source::Provisional)?;
    Ok(match conventions {
        Conventions::Musical => calibrate_quick(prepared),
        Conventions::Legacy => prepared,
    })
}

/// The level calibration of a freshly analysed model (legacy projects have none).
fn finish(prepared: Prepared, conventions: Conventions) -> Prepared {
    match conventions {
        Conventions::Musical => calibrate(prepared),
        Conventions::Legacy => prepared,
    }
}
