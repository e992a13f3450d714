//! Maps keyed by script labels, for the parser's and the compiler's symbol tables.
//!
//! A script written element by element has a label on every line and names two or three more
//! in its arguments, so loading a 1000-mass string hashes some ten thousand short strings.
//! std's default SipHash costs about as much as the rest of reading a line; labels come from a
//! script the user loads, not from an adversary, so a multiplicative hash (the one rustc uses
//! for its own symbol tables) serves: a few cycles per eight bytes.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};

/// A `HashMap` with [`LabelHasher`]. Iteration order is unspecified, as with std's.
pub(crate) type LabelMap<K, V> = HashMap<K, V, BuildHasherDefault<LabelHasher>>;

/// A label borrowed as a map key: hashed as a `str` is, and compared inline, with fixed-size
/// loads, where a `str` key calls `memcmp`, whose dispatch on length costs more than comparing
/// a label of a few bytes.
#[derive(Clone, Copy, Debug, Eq)]
pub(crate) struct LabelKey<'a>(pub(crate) &'a str);

impl PartialEq for LabelKey<'_> {
    #[inline]
    fn eq(&self, other: &Self) -> bool {
        same_bytes(self.0.as_bytes(), other.0.as_bytes())
    }
}

impl Hash for LabelKey<'_> {
    #[inline]
    fn hash<H: Hasher>(&self, state: &mut H) {
        // As `str` hashes: the terminator's round also mixes a short key's high bits into the
        // low ones, which pick the bucket.
        self.0.hash(state);
    }
}

/// `a == b`, for short slices without a call: equal lengths, then the words that cover every
/// byte ([`tail_word`] up to 7 bytes, the first and last 8 up to 16).
#[inline]
fn same_bytes(a: &[u8], b: &[u8]) -> bool {
    let n = a.len();
    if n != b.len() {
        return false;
    }
    let word = |s: &[u8], at: usize| {
        s.get(at..at + 8)
            .and_then(|w| <[u8; 8]>::try_from(w).ok())
            .map(u64::from_le_bytes)
    };
    match n {
        0 => true,
        1..=7 => tail_word(a) == tail_word(b),
        8..=16 => word(a, 0) == word(b, 0) && word(a, n - 8) == word(b, n - 8),
        _ => a == b,
    }
}

/// A multiplicative word-at-a-time hash for short keys (not collision-resistant).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct LabelHasher(u64);

const SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

impl LabelHasher {
    #[inline]
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(SEED);
    }
}

/// The last 1 to 7 bytes of a key as one word, read with fixed-size loads: two overlapping
/// halves, or the first, middle and last byte of a shorter tail, which between them cover every
/// byte; the length in the top byte tells tails of different lengths apart. (Copying the tail
/// into a zeroed word with a variable-length copy is a call, and its byte stores stall the
/// word's load.)
#[inline]
fn tail_word(rest: &[u8]) -> u64 {
    let n = rest.len();
    let word = match (rest.get(..4), rest.get(n.saturating_sub(4)..)) {
        (Some(lo), Some(hi)) if n >= 4 => {
            let half = |b: &[u8]| u64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
            half(lo) | half(hi) << 32
        }
        _ => {
            let at = |i: usize| u64::from(rest.get(i).copied().unwrap_or(0));
            at(0) | at(n / 2) << 8 | at(n.saturating_sub(1)) << 16
        }
    };
    word ^ (n as u64) << 56
}

impl Hasher for LabelHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        let mut words = bytes.chunks_exact(8);
        for w in &mut words {
            let mut b = [0u8; 8];
            b.copy_from_slice(w);
            self.add(u64::from_le_bytes(b));
        }
        let rest = words.remainder();
        if !rest.is_empty() {
            self.add(tail_word(rest));
        }
    }

    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.add(u64::from(i));
    }

    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.add(u64::from(i));
    }

    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.add(i);
    }

    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }

    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_that_differ_hash_apart() {
        let mut m: LabelMap<String, usize> = LabelMap::default();
        for k in 0..10_000 {
            m.insert(format!("n{k}"), k);
        }
        assert_eq!(m.len(), 10_000);
        assert!((0..10_000).all(|k| m.get(format!("n{k}").as_str()) == Some(&k)));
        // A prefix and a string padded with NUL bytes stay distinct keys.
        let mut m: LabelMap<&str, u8> = LabelMap::default();
        m.insert("a", 1);
        m.insert("a\0", 2);
        assert_eq!((m.get("a"), m.get("a\0")), (Some(&1), Some(&2)));
    }

    #[test]
    fn label_keys_compare_as_their_text() {
        let texts: Vec<String> = (0..=20)
            .flat_map(|n| {
                let base: String = (0..n).map(|i| char::from(b'a' + (i % 26) as u8)).collect();
                // The text, and the text with each byte changed in turn.
                let changed = (0..n).map({
                    let base = base.clone();
                    move |i| {
                        let mut b = base.clone().into_bytes();
                        b[i] = b'#';
                        String::from_utf8(b).unwrap()
                    }
                });
                std::iter::once(base).chain(changed).collect::<Vec<_>>()
            })
            .collect();
        for a in &texts {
            for b in &texts {
                assert_eq!(LabelKey(a) == LabelKey(b), a == b, "{a:?} {b:?}");
            }
        }
    }

    #[test]
    fn tails_of_one_length_read_every_byte() {
        // Two tails of the same length that differ in any one byte give different words.
        for n in 1..8 {
            let base: Vec<u8> = (1..=n as u8).collect();
            for i in 0..n {
                let mut other = base.clone();
                other[i] ^= 0x40;
                assert_ne!(tail_word(&base), tail_word(&other), "length {n}, byte {i}");
            }
        }
        assert_ne!(tail_word(b"ab"), tail_word(b"abb"));
    }
}
