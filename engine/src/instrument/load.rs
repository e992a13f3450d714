//! Loading a script for the instrument: [`super::prepare`] compiles and analyses it, then
//! [`super::level`] plays it to set its trims. The level calibration plays the model through
//! the whole instrument, so it comes after preparation here rather than inside it.

use super::host::Rejected;
use super::level::calibrate;
use super::prepare::{prepare_uncalibrated, Conventions, Prepared};

/// Compiles a script for a sample rate and derives everything the audio thread needs.
pub fn prepare(name: &str, text: &str, sample_rate: f64) -> Result<Prepared, Rejected> {
    prepare_with(name, text, sample_rate, Conventions::Musical)
}

/// [`prepare`] under the given playing conventions: legacy projects get no trims.
pub fn prepare_with(
    name: &str,
    text: &str,
    sample_rate: f64,
    conventions: Conventions,
) -> Result<Prepared, Rejected> {
    let prepared = prepare_uncalibrated(name, text, sample_rate, conventions)?;
    Ok(match conventions {
        Conventions::Musical => calibrate(prepared),
        Conventions::Legacy => prepared,
    })
}
