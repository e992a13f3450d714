//! Parameter values as text, and text back to values.
//!
//! Hosts show and parse these strings. The number comes first and the unit after
//! (`4.00 ×`, `24.0 dB`, `+3.00 st`): VST3 hosts get the number alone and the unit in the
//! parameter's `units` field, and JUCE-based hosts such as pedalboard read parameters by
//! parsing the number. Every formatter is paired with a parser that accepts what it writes,
//! so value → text → value → text gives the same text (clap-validator's
//! `param-conversions`), and what people type: `4`, `×4`, `4x`, `1/4`, `-6 dB`, `−6dB`,
//! `+3 st`.

/// Normalises what people and hosts type: trims, and reads the typographic minus (U+2212)
/// as `-`.
fn clean(text: &str) -> String {
    text.trim().replace('\u{2212}', "-")
}

/// Strips one of `units` (compared without case) from the end of `text`, then trims.
fn strip_unit<'a>(text: &'a str, units: &[&str]) -> &'a str {
    let t = text.trim();
    let lower = t.to_ascii_lowercase();
    for unit in units {
        if lower.ends_with(unit) {
            return t[..t.len() - unit.len()].trim();
        }
    }
    t
}

/// A finite number, with an optional leading `+`.
fn number(text: &str) -> Option<f64> {
    let t = text.trim();
    let t = t.strip_prefix('+').unwrap_or(t);
    t.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Formats a positive factor with three significant digits below 10 (`0.063`, `1.00`,
/// `4.00`) and one decimal from 10 on (`16.0`). The precision is chosen after rounding, so a
/// value that rounds up across 1 or 10 is written as the value it rounds to.
pub fn format_factor(f: f32) -> String {
    let small = format!("{f:.3}");
    if small.parse::<f32>().is_ok_and(|v| v < 1.0) {
        return small;
    }
    let mid = format!("{f:.2}");
    if mid.parse::<f32>().is_ok_and(|v| v < 10.0) {
        return mid;
    }
    format!("{f:.1}")
}

/// Parses a factor (`2`, `×2`, `x2`, `2x`, `2 ×`, `1/4`) and returns it in octaves (log₂),
/// clamped to ±`max_octaves`. Zero, negative and non-numbers give `None`.
pub fn parse_factor(text: &str, max_octaves: f32) -> Option<f32> {
    let t = clean(text);
    let t =
        t.trim_matches(|c: char| c == '×' || c == 'x' || c == 'X' || c == '*' || c.is_whitespace());
    let f = match t.split_once('/') {
        Some((a, b)) => number(a)? / number(b)?,
        None => number(t)?,
    };
    (f.is_finite() && f > 0.0).then(|| (f.log2() as f32).clamp(-max_octaves, max_octaves))
}

/// Decibels with one decimal: `24.0`, `-6.0`, `0.0` (never `-0.0`).
pub fn format_db(db: f32) -> String {
    let s = format!("{db:.1}");
    if s == "-0.0" {
        "0.0".to_string()
    } else {
        s
    }
}

/// Parses `-6`, `-6 dB`, `−6dB`, `+3.5 db`.
pub fn parse_db(text: &str) -> Option<f32> {
    number(strip_unit(&clean(text), &["db"])).map(|v| v as f32)
}

/// Semitones with a sign and two decimals: `+3.00`, `-12.00`, `0.00`.
pub fn format_semitones(st: f32) -> String {
    let s = format!("{st:+.2}");
    if s == "+0.00" || s == "-0.00" {
        "0.00".to_string()
    } else {
        s
    }
}

/// Parses `3`, `+3.00`, `-12 st`, `−1 semitones`.
pub fn parse_semitones(text: &str) -> Option<f32> {
    number(strip_unit(&clean(text), &["semitones", "semitone", "st"])).map(|v| v as f32)
}

/// The texts of an on/off parameter whose two states have names of their own (Guard
/// Tripped: `Clear` and `Tripped`). Parsing also accepts on/off, true/false and 1/0.
pub fn parse_switch(text: &str, off: &str, on: &str) -> Option<bool> {
    let t = clean(text).to_ascii_lowercase();
    if t == on.to_ascii_lowercase() || ["on", "true", "1", "yes"].contains(&t.as_str()) {
        Some(true)
    } else if t == off.to_ascii_lowercase() || ["off", "false", "0", "no"].contains(&t.as_str()) {
        Some(false)
    } else {
        None
    }
}

/// The text of an unbound macro slot: its position in percent.
pub fn format_unbound_macro(normalized: f64) -> String {
    format!("unbound ({:.0} %)", normalized * 100.0)
}

/// Parses `unbound (50 %)`, `50 %` and `50%` as 0.5, and a bare number as the position
/// (0 … 1).
pub fn parse_unbound_macro(text: &str) -> Option<f64> {
    let t = clean(text);
    let t = t.strip_prefix("unbound").unwrap_or(&t).trim();
    let t = t.trim_start_matches('(').trim_end_matches(')').trim();
    let v = match t.strip_suffix('%') {
        Some(p) => number(p)? / 100.0,
        None => number(t)?,
    };
    Some(v.clamp(0.0, 1.0))
}

/// A pitch-bend range: whole semitones, `12 st` (the unit comes from `with_unit`).
pub fn format_bend_range(st: f32) -> String {
    format!("{:.0}", st.round())
}

/// A velocity curve's exponent (stored as its log₂): `1.00` is linear, `2.00` makes soft notes
/// softer, `0.50` louder.
pub fn format_velocity_curve(log2_exponent: f32) -> String {
    format!("{:.2}", 2f32.powf(log2_exponent))
}

/// Reads a velocity-curve exponent (`2`, `0.5`, `v^2`, `linear`) as its log₂, clamped to
/// `max_octaves`.
pub fn parse_velocity_curve(text: &str, max_octaves: f32) -> Option<f32> {
    let t = clean(text).to_ascii_lowercase();
    if t == "linear" {
        return Some(0.0);
    }
    let t = t.trim_start_matches("v^").trim();
    let v = number(t)?;
    (v > 0.0).then(|| (v.log2() as f32).clamp(-max_octaves, max_octaves))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn factors_read_what_people_type() {
        assert_eq!(parse_factor("1/4", 4.0), Some(-2.0));
        for text in ["2", "2.00", "×2", "x2", "2x", "2 ×", "2.00 ×", "*2", " 2X "] {
            assert_eq!(parse_factor(text, 4.0), Some(1.0), "{text}");
        }
        assert_eq!(parse_factor("1000", 4.0), Some(4.0));
        assert_eq!(parse_factor("-1", 4.0), None);
        assert_eq!(parse_factor("0", 4.0), None);
        assert_eq!(parse_factor("abc", 4.0), None);
        assert_eq!(parse_factor("nan", 4.0), None);
        assert_eq!(format_factor(4.0), "4.00");
        assert_eq!(format_factor(16.0), "16.0");
        assert_eq!(format_factor(0.25), "0.250");
        // Rounding across a precision boundary writes the rounded value's own precision.
        assert_eq!(format_factor(9.996), "10.0");
        assert_eq!(format_factor(0.9996), "1.00");
    }

    #[test]
    fn decibels_and_semitones_read_what_people_type() {
        for text in ["-6", "-6 dB", "-6dB", "\u{2212}6 dB", "-6.0 db", " -6 DB "] {
            assert_eq!(parse_db(text), Some(-6.0), "{text}");
        }
        assert_eq!(parse_db("+3.5 dB"), Some(3.5));
        assert_eq!(parse_db("loud"), None);
        assert_eq!(parse_db("inf dB"), None);
        assert_eq!(format_db(24.0), "24.0");
        assert_eq!(format_db(-0.01), "0.0");
        for text in ["3", "+3", "+3.00 st", "3 semitones", "3st"] {
            assert_eq!(parse_semitones(text), Some(3.0), "{text}");
        }
        assert_eq!(parse_semitones("\u{2212}12 st"), Some(-12.0));
        assert_eq!(format_semitones(3.0), "+3.00");
        assert_eq!(format_semitones(-0.001), "0.00");
    }

    #[test]
    fn switches_and_macros_read_their_own_text() {
        assert_eq!(parse_switch("Tripped", "Clear", "Tripped"), Some(true));
        assert_eq!(parse_switch("clear", "Clear", "Tripped"), Some(false));
        assert_eq!(parse_switch("On", "Clear", "Tripped"), Some(true));
        assert_eq!(parse_switch("maybe", "Clear", "Tripped"), None);
        assert_eq!(parse_unbound_macro(&format_unbound_macro(0.5)), Some(0.5));
        assert_eq!(parse_unbound_macro("25%"), Some(0.25));
        assert_eq!(parse_unbound_macro("0.3"), Some(0.3));
        assert_eq!(parse_unbound_macro("loud"), None);
    }

    proptest! {
        /// The host's round trip: text → value → text is the same text.
        #[test]
        fn factor_text_round_trips(octaves in -4.0f32..=4.0) {
            let text = format_factor(2f32.powf(octaves));
            let back = parse_factor(&text, 4.0).unwrap();
            prop_assert_eq!(format_factor(2f32.powf(back)), text);
        }

        #[test]
        fn db_and_semitone_text_round_trips(v in -60.0f32..=60.0) {
            let text = format_db(v);
            prop_assert_eq!(format_db(parse_db(&text).unwrap()), text);
            let text = format_semitones(v);
            prop_assert_eq!(format_semitones(parse_semitones(&text).unwrap()), text);
        }
    }
}
