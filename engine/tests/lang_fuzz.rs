//! No input may make the front end panic (spec §3.12 f): arbitrary strings, arbitrary bytes,
//! megabytes of garbage, and adversarial shapes (deep nesting, huge sizes, long lines).

use proptest::prelude::*;
use ressort_engine::lang::{parse, parse_bytes, print, Parsed};
use std::time::{Duration, Instant};

/// The number of characters of each line of `text` (spec §3.2: CR LF, CR and LF end a line).
fn line_widths(text: &str) -> Vec<usize> {
    text.replace("\r\n", "\n")
        .split(['\r', '\n'])
        .map(|l| l.chars().count())
        .collect()
}

/// Parses and, when that succeeds, prints and re-parses; checks the basic invariants. `text`
/// is the script as characters (bytes decoded lossily): every diagnostic stands on one of its
/// lines, at a column counted in characters, at most one past the line's end.
fn check(text: &str, parsed: &Parsed) {
    let has_error = parsed.errors().next().is_some();
    assert_eq!(parsed.spec.is_none(), has_error);
    let widths = line_widths(text);
    for d in &parsed.diagnostics {
        assert!(d.line >= 1 && d.col >= 1, "{d:?}");
        let width = widths.get(d.line as usize - 1).copied().unwrap_or(0);
        assert!(
            d.col as usize <= width + 1,
            "{d:?} on a line of {width} characters"
        );
        let _ = d.to_string();
    }
    if let Some(spec) = &parsed.spec {
        let again = parse(&print(spec));
        assert_eq!(again.spec.as_ref(), Some(spec));
    }
}

/// Characters the grammar cares about, so random text hits interesting paths. Each byte
/// picks a character (one random draw per character keeps the unoptimised RNG cheap).
fn scripty() -> impl Strategy<Value = String> {
    const ALPHABET: [char; 32] = [
        '@', '~', '[', ']', '(', ')', '\'', '#', '+', '-', '*', '/', '.', 'e', ' ', '\t', '\n',
        '\r', ',', '1', '0', '9', 'm', 'K', 'é', '\u{feff}', 'x', '_', 'g', 'G', 'h', '=',
    ];
    proptest::collection::vec(any::<u8>(), 0..200).prop_map(|bytes| {
        let s: String = bytes
            .into_iter()
            .map(|b| match ALPHABET.get(b as usize % 40) {
                Some(&c) => c,
                None => char::from_u32(0x80 + u32::from(b) * 131).unwrap_or('?'),
            })
            .collect();
        // Sprinkle whole keywords in too.
        s.replace('m', " mass ")
            .replace('K', " string 10 1 1 1 0 0\n@s ")
            // `~generate` directives (spec §4), whole and in pieces.
            .replace('g', "\n~generate ")
            .replace('G', " string s nodes=3 M=1 K=0.1 Z=0 ")
            .replace(
                'h',
                " mesh q size=3,2 fixed=corners hexagon ring lattice polyline points=0,0;1,1 \
                 span=2 diagonals=on ",
            )
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_strings_never_panic(s in any::<String>()) {
        check(&s, &parse(&s));
    }

    #[test]
    fn scripty_strings_never_panic(s in scripty()) {
        check(&s, &parse(&s));
    }

    #[test]
    fn arbitrary_bytes_never_panic(b in proptest::collection::vec(any::<u8>(), 0..400)) {
        let parsed = parse_bytes(&b);
        check(&String::from_utf8_lossy(&b), &parsed);
        if std::str::from_utf8(&b).is_ok() {
            prop_assert_eq!(parsed, parse(std::str::from_utf8(&b).unwrap()));
        } else {
            prop_assert!(parsed.spec.is_none());
        }
    }
}

/// A small deterministic generator (xorshift64*), so the garbage test needs no dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
}

#[test]
fn megabytes_of_garbage() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let alphabet = b"@~[]()'#+-*/.,e0123456789 \t\r\nmassKstring@in1@out1";
    let start = Instant::now();
    // 4 MB of biased garbage, 4 MB of raw random bytes.
    let biased: Vec<u8> = (0..4 << 20)
        .map(|_| {
            let r = rng.next();
            match r % 8 {
                0 => (r >> 8) as u8,
                _ => alphabet[((r >> 8) % alphabet.len() as u64) as usize],
            }
        })
        .collect();
    let lossy = String::from_utf8_lossy(&biased);
    check(&lossy, &parse_bytes(&biased));
    check(&lossy, &parse(&lossy));
    let raw: Vec<u8> = (0..4 << 20).map(|_| rng.next() as u8).collect();
    let parsed = parse_bytes(&raw);
    assert!(parsed.spec.is_none());
    assert!(parsed.diagnostics.len() <= ressort_engine::lang::MAX_DIAGNOSTICS + 2);
    assert!(
        start.elapsed() < Duration::from_secs(120),
        "{:?}",
        start.elapsed()
    );
}

#[test]
fn adversarial_shapes() {
    let mb = 1 << 20;
    let cases: Vec<String> = vec![
        format!("@m mass [{}1{}] 0 0", "(".repeat(mb), ")".repeat(mb)),
        format!("@m mass [{}1] 0 0", "-".repeat(mb)),
        format!("@m mass {}1 0 0", "-".repeat(mb)),
        format!("@m mass [{}] 0 0", vec!["1"; mb / 2].join("+")),
        format!(
            "@m mass [{}1{}] 0 0",
            "sqrt(".repeat(mb / 8),
            ")".repeat(mb / 8)
        ),
        format!("@m mass {} 0 0", "1".repeat(mb)),
        format!("@m mass 1{} 0 0", "e+1".repeat(mb / 4)),
        "[".repeat(mb),
        format!("@a {}", "]".repeat(mb)),
        format!("@a mass {}", "'".repeat(mb)),
        format!("@a mass {}", "+".repeat(mb)),
        format!("@a {}", "a+".repeat(mb / 2)),
        "@\n".repeat(mb / 2),
        "@a mass 1 0 0\n".repeat(mb / 16),
        "~begin a\n".repeat(mb / 16),
        (0..100_000)
            .map(|i| format!("~begin b{i}\n"))
            .collect::<String>()
            + "@m mass 1 0 0\n",
        (0..50_000)
            .map(|i| format!("@m{i} mass 1 0 0\n"))
            .collect::<String>()
            + &(0..200)
                .map(|i| format!("~begin s{i}\n"))
                .collect::<String>()
            + &(0..50_000)
                .map(|i| format!("@n{i} mass 1 0 0\n"))
                .collect::<String>(),
        "@s string 99999999999999999999999999999 1 1 1 0 0\n".to_string(),
        "@s mesh 4294967295 4294967295 1 1 1 0 0\n".to_string(),
        "@s mesh 1048576 2 1 1 1 0 0\n".to_string(),
        "@in99999999999 posInput 0\n@in4294967296 posInput 0\n@out4294967295 posOutput @in99\n"
            .to_string(),
        "@K param 1e308\n@m mass [K*K*K] 0 0\n".to_string(),
        "@m mass [1/0] [sqrt(-1)] [log(0)]\n".to_string(),
        "\r\r\n\n\r".repeat(mb / 4),
        "~generate lattice l size=1048576,1,1 span=999999999 diagonals=on M=1 K=1 Z=0\n"
            .to_string(),
        "~generate lattice l size=100,100,100 span=100 diagonals=on M=1 K=1 Z=0\n".to_string(),
        "~generate hexagon h size=99999999 M=1 K=1 Z=0\n".to_string(),
        "~generate triangle t size=18446744073709551615 M=1 K=1 Z=0\n".to_string(),
        format!(
            "~generate polyline p points={}1,1 M=1 K=1 Z=0\n",
            "0,0;".repeat(300_000)
        ),
        (0..100_000)
            .map(|i| format!("~generate string s{i} nodes=1 M=1 K=1 Z=0\n@o{i} mass 1 0 0\n"))
            .collect(),
        "~generate mesh m size=290,290 M=1 K=1 Z=0 fixed=borders\n@out1 posOutput @m_m1_1\n"
            .to_string(),
        "~generate hexagon h size=3 M=1 K=1 Z=0 from=-1e308,0,0 to=1e308,0,0\n".to_string(),
        "@P param 1e308\n~generate string s nodes=3 M=[P*10] K=[P-P] Z=0\n".to_string(),
        format!(
            "~generate string s nodes=3 M=1 K=[{}1{}] Z=0\n",
            "(".repeat(mb),
            ")".repeat(mb)
        ),
        "\u{feff}@m mass 1 0 0\n".to_string(),
    ];
    for (i, text) in cases.iter().enumerate() {
        let start = Instant::now();
        let parsed = parse(text);
        check(text, &parsed);
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "case {i} took {:?}",
            start.elapsed()
        );
    }
    // The BOM does not hide the first command; 1/0 is IEEE arithmetic, not an error.
    assert!(parse(&cases[cases.len() - 1]).spec.is_some());
    assert!(parse("@m mass [1/0] [sqrt(-1)] [log(0)]\n").spec.is_some());
}
