//! Number literals (spec §3.5): their grammar, and their values, read exactly.

use super::diagnostics::DiagnosticCode;
use super::lexer::{TokKind, Token};

/// Scans the number grammar of spec §3.5 from `start`. Returns the end index, or `None` when no
/// number starts there.
pub(crate) fn scan_number(chars: &[char], start: usize) -> Option<usize> {
    let digits = |mut j: usize| {
        while chars.get(j).is_some_and(char::is_ascii_digit) {
            j += 1;
        }
        j
    };
    let mut j = digits(start);
    let int_digits = j - start;
    let mut frac_digits = 0;
    if chars.get(j) == Some(&'.') {
        let k = digits(j + 1);
        frac_digits = k - (j + 1);
        j = k;
    }
    if int_digits == 0 && frac_digits == 0 {
        return None;
    }
    if matches!(chars.get(j), Some('e' | 'E')) {
        let mut k = j + 1;
        if matches!(chars.get(k), Some('+' | '-')) {
            k += 1;
        }
        if chars.get(k).is_some_and(char::is_ascii_digit) {
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

pub(crate) fn to_f64(chars: &[char]) -> Result<f64, NumberError> {
    if let Some(v) = exact_decimal(chars) {
        return Ok(v);
    }
    // Literals are ASCII and short: read them from the stack, not from a fresh String.
    let mut buf = [0u8; 64];
    let parsed = if chars.len() <= buf.len() && chars.iter().all(char::is_ascii) {
        for (b, c) in buf.iter_mut().zip(chars) {
            *b = *c as u8;
        }
        std::str::from_utf8(&buf[..chars.len()])
            .map_err(|_| NumberError::Invalid)?
            .parse::<f64>()
    } else {
        chars.iter().collect::<String>().parse::<f64>()
    };
    match parsed {
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

/// A literal `digits[.digits]` (no sign, no exponent) whose digits, read as an integer m, are at
/// most 2^53, with at most 22 after the point: m and 10^f are then exact in f64, and one
/// correctly rounded division gives the correctly rounded value, the same as `str::parse`
/// (Clinger's fast path, which the standard library takes too). `None` for anything else.
fn exact_decimal(chars: &[char]) -> Option<f64> {
    let mut m: u64 = 0;
    let mut digits = 0usize;
    let mut frac: Option<usize> = None;
    for &c in chars {
        match c {
            '0'..='9' => {
                m = m
                    .checked_mul(10)?
                    .checked_add(u64::from(c) - u64::from('0'))?;
                digits += 1;
                if let Some(f) = frac.as_mut() {
                    *f += 1;
                }
            }
            '.' if frac.is_none() => frac = Some(0),
            _ => return None,
        }
    }
    if digits == 0 || m > 1 << 53 {
        return None;
    }
    let power = EXACT_POWERS_OF_TEN.get(frac.unwrap_or(0))?;
    Some(m as f64 / power)
}

/// A numeric literal with an optional sign, the only form allowed for `param` values and legacy
/// tag coordinates (spec §3.5, §3.8, §6.4).
pub(crate) fn parse_number_literal(chars: &[char]) -> Result<f64, NumberError> {
    let (negative, body) = match chars.split_first() {
        Some(('-', rest)) => (true, rest),
        Some(('+', rest)) => (false, rest),
        _ => (false, chars),
    };
    match scan_number(body, 0) {
        Some(end) if end == body.len() => to_f64(body).map(|v| if negative { -v } else { v }),
        _ => Err(NumberError::Invalid),
    }
}

/// The value of a signed number literal and nothing else (`0.1`, `-2e-3`): the commonest
/// argument, read without the tokens and tree of the general parser. Gives what the parser
/// gives (a sign before a literal folds into it, unary plus is dropped), and `None` for
/// anything else, a non-finite literal included, which the parser then reads and reports.
pub(crate) fn plain_number(chars: &[char]) -> Option<f64> {
    let (negative, body) = match chars.split_first()? {
        ('-', rest) => (true, rest),
        ('+', rest) => (false, rest),
        _ => (false, chars),
    };
    if scan_number(body, 0)? != body.len() {
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
            let chars: Vec<char> = text.chars().collect();
            if let Some(v) = exact_decimal(&chars) {
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
        assert_eq!(exact_decimal(&['.']), None);
        assert_eq!(exact_decimal(&['1', 'e', '3']), None);
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
        let l = |s: &str| parse_number_literal(&s.chars().collect::<Vec<_>>());
        assert_eq!(l("-0.2"), Ok(-0.2));
        assert_eq!(l("+3"), Ok(3.0));
        assert_eq!(l("1e999"), Err(NumberError::NonFinite));
        assert_eq!(l("1e"), Err(NumberError::Invalid));
        assert_eq!(l("a"), Err(NumberError::Invalid));
        assert_eq!(l(""), Err(NumberError::Invalid));
    }
}
