//! Number literals (spec §3.5): their grammar, and their values, read exactly.

use super::diagnostics::DiagnosticCode;
use super::lexer::{TokKind, Token};

/// Scans the number grammar of spec §3.5 from byte `start` of `text` (a number is ASCII, so
/// bytes are characters). Returns the end index, or `None` when no number starts there.
pub(crate) fn scan_number(text: &[u8], start: usize) -> Option<usize> {
    let digits = |mut j: usize| {
        while text.get(j).is_some_and(u8::is_ascii_digit) {
            j += 1;
        }
        j
    };
    let mut j = digits(start);
    let int_digits = j - start;
    let mut frac_digits = 0;
    if text.get(j) == Some(&b'.') {
        let k = digits(j + 1);
        frac_digits = k - (j + 1);
        j = k;
    }
    if int_digits == 0 && frac_digits == 0 {
        return None;
    }
    if matches!(text.get(j), Some(b'e' | b'E')) {
        let mut k = j + 1;
        if matches!(text.get(k), Some(b'+' | b'-')) {
            k += 1;
        }
        if text.get(k).is_some_and(u8::is_ascii_digit) {
            j = digits(k);
        }
    }
    Some(j)
}

/// Why a literal was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum NumberError {
    Invalid,
    NonFinite,
}

impl NumberError {
    /// The diagnostic category of the rejection.
    pub(crate) fn code(self) -> DiagnosticCode {
        match self {
            NumberError::Invalid => DiagnosticCode::InvalidNumber,
            NumberError::NonFinite => DiagnosticCode::NonFiniteNumber,
        }
    }
}

/// A token read as a numeric literal ([`parse_number_literal`]); a bracketed item never is one.
pub(crate) fn token_number_literal(t: &Token) -> Result<f64, NumberError> {
    if t.kind == TokKind::Bracket {
        Err(NumberError::Invalid)
    } else {
        parse_number_literal(t.text)
    }
}

/// The value of a literal that [`scan_number`] accepted, correctly rounded.
pub(crate) fn to_f64(text: &str) -> Result<f64, NumberError> {
    if let Some(v) = exact_decimal(text.as_bytes()) {
        return Ok(v);
    }
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(NumberError::NonFinite),
        Err(_) => Err(NumberError::Invalid),
    }
}

/// Powers of ten that are exact in f64.
const EXACT_POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// A literal `digits[.digits]` (no sign, no exponent) of at most 19 digits which, read as an
/// integer m, are at most 2^53: m and 10^f (f ≤ 19 digits after the point) are then exact in
/// f64, and one correctly rounded division gives the correctly rounded value, the same as
/// `str::parse` (Clinger's fast path, which the standard library takes too). `None` for
/// anything else.
fn exact_decimal(text: &[u8]) -> Option<f64> {
    // One pass: at most 19 digits cannot overflow a u64, and the bound on m is checked after.
    let mut m: u64 = 0;
    let mut digits = 0usize;
    let mut point: Option<usize> = None;
    for &c in text {
        let d = c.wrapping_sub(b'0');
        if d < 10 {
            m = m.wrapping_mul(10).wrapping_add(u64::from(d));
            digits += 1;
        } else if c == b'.' && point.is_none() {
            point = Some(digits);
        } else {
            return None;
        }
    }
    if digits == 0 || digits > 19 || m > 1 << 53 {
        return None;
    }
    let frac = digits - point.unwrap_or(digits);
    if frac == 0 {
        return Some(m as f64);
    }
    let power = EXACT_POWERS_OF_TEN.get(frac)?;
    Some(m as f64 / power)
}

/// A leading `-` (true) or `+` taken off `text`.
fn split_sign(text: &str) -> (bool, &str) {
    match text.as_bytes().first() {
        Some(b'-') => (true, text.get(1..).unwrap_or("")),
        Some(b'+') => (false, text.get(1..).unwrap_or("")),
        _ => (false, text),
    }
}

/// A numeric literal with an optional sign, the only form allowed for `param` values and legacy
/// tag coordinates (spec §3.5, §3.8, §6.4).
pub(crate) fn parse_number_literal(text: &str) -> Result<f64, NumberError> {
    let (negative, body) = split_sign(text);
    match scan_number(body.as_bytes(), 0) {
        Some(end) if end == body.len() => to_f64(body).map(|v| if negative { -v } else { v }),
        _ => Err(NumberError::Invalid),
    }
}

/// The value of a signed number literal and nothing else (`0.1`, `-2e-3`): the commonest
/// argument, read without the tokens and tree of the general parser. Gives what the parser
/// gives (a sign before a literal folds into it, unary plus is dropped), and `None` for
/// anything else, a non-finite literal included, which the parser then reads and reports.
pub(crate) fn plain_number(text: &str) -> Option<f64> {
    let (negative, body) = split_sign(text);
    // A literal `exact_decimal` reads is one `scan_number` accepts whole: no second pass.
    if let Some(v) = exact_decimal(body.as_bytes()) {
        return Some(if negative { -v } else { v });
    }
    if scan_number(body.as_bytes(), 0)? != body.len() {
        return None;
    }
    let v = to_f64(body).ok()?;
    Some(if negative { -v } else { v })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_decimals_read_as_the_standard_parser_reads_them() {
        let check = |text: &str| {
            if let Some(v) = exact_decimal(text.as_bytes()) {
                let expected: f64 = text.parse().unwrap();
                assert_eq!(v.to_bits(), expected.to_bits(), "{text}");
            }
        };
        for text in [
            "0",
            "0.0",
            "1.",
            ".5",
            "0.1",
            "0.001",
            "1.0",
            "123.456",
            "00012.5000",
            "9007199254740992",
            "9007199254740993",
            "0.9007199254740992",
            "0.0000000000000000000001",
            "0.00000000000000000000001",
            "18446744073709551616",
        ] {
            check(text);
        }
        assert_eq!(exact_decimal(b"."), None);
        assert_eq!(exact_decimal(b"1e3"), None);
        // Every length and point position, with digits from a fixed pseudo-random sequence.
        let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
        for len in 1..=24 {
            for point in 0..=len {
                for _ in 0..40 {
                    let mut text = String::new();
                    for k in 0..len {
                        if k == point {
                            text.push('.');
                        }
                        seed ^= seed << 13;
                        seed ^= seed >> 7;
                        seed ^= seed << 17;
                        text.push(char::from(b'0' + (seed % 10) as u8));
                    }
                    check(&text);
                }
            }
        }
    }

    #[test]
    fn literals() {
        let l = parse_number_literal;
        assert_eq!(l("-0.2"), Ok(-0.2));
        assert_eq!(l("+3"), Ok(3.0));
        assert_eq!(l("1e999"), Err(NumberError::NonFinite));
        assert_eq!(l("1e"), Err(NumberError::Invalid));
        assert_eq!(l("a"), Err(NumberError::Invalid));
        assert_eq!(l(""), Err(NumberError::Invalid));
    }
}
