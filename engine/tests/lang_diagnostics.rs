//! One case per diagnostic category of spec §3.12 f (errors and warnings), with positions, plus
//! the normative decisions of §3.12 a–f.

use ressort_engine::lang::{parse, parse_bytes, Diagnostic, DiagnosticCode as C, Parsed, Severity};
use ressort_engine::{ElementKind, Endpoint, Expr, Law, LawForm, LawKind, SampleRateMode, Vector};

const PRELUDE: &str =
    "@K param 0.1\n@m mass 1 0 0\n@s string 10 1 K 0.001 0 0\n@me mesh 4 5 1 K 0.001 0 0\n";

fn with_prelude(line: &str) -> String {
    format!("{PRELUDE}{line}\n")
}

/// Asserts that `parsed` has a diagnostic of `code` at `line:col`, and returns it.
fn find(parsed: &Parsed, code: C, line: u32, col: u32) -> Diagnostic {
    parsed
        .diagnostics
        .iter()
        .find(|d| d.code == code && d.line == line && d.col == col)
        .cloned()
        .unwrap_or_else(|| panic!("no {code:?} at {line}:{col} in {:#?}", parsed.diagnostics))
}

/// The script has exactly one diagnostic, of `code` at `line:col` (line counted after the
/// prelude when `prelude`).
fn only(text: &str, code: C, line: u32, col: u32) -> Diagnostic {
    let parsed = parse(text);
    assert_eq!(
        parsed.diagnostics.len(),
        1,
        "{text}\n{:#?}",
        parsed.diagnostics
    );
    let d = find(&parsed, code, line, col);
    assert_eq!(d.severity, code.severity());
    assert_eq!(
        parsed.spec.is_some(),
        d.severity == Severity::Warning,
        "{text}"
    );
    d
}

/// One diagnostic in the line after the prelude (line 5).
fn after_prelude(line: &str, code: C, col: u32) -> Diagnostic {
    only(&with_prelude(line), code, 5, col)
}

#[test]
fn prelude_is_clean() {
    let p = parse(PRELUDE);
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
}

// ---- lexical errors ---------------------------------------------------------------------------

#[test]
fn invalid_utf8() {
    let p = parse_bytes(b"@m mass 1 0 0\r\n@n mass \xff\xfe 0 0\n");
    let d = find(&p, C::InvalidUtf8, 2, 9);
    assert!(d.is_error());
    assert!(p.spec.is_none());
    // A line break right before the invalid byte.
    let p = parse_bytes(b"a\r\xc3");
    find(&p, C::InvalidUtf8, 2, 1);
    // Valid UTF-8 through parse_bytes is the same as parse.
    assert_eq!(parse_bytes(PRELUDE.as_bytes()), parse(PRELUDE));
    // One report per run of bad bytes, and nothing more on its line: the U+FFFD that stands
    // for them does not fail again as an expression or keyword character. The next lines are
    // read as usual.
    let p = parse_bytes(b"@m mass 1 0 0\n@n mass \xff\xfe 0 0\n@l \xffspring @m @n 0.1\n@x bad\n");
    let on = |line: u32| {
        p.diagnostics
            .iter()
            .filter(|d| d.line == line)
            .collect::<Vec<_>>()
    };
    assert_eq!(on(2).len(), 1, "{:#?}", p.diagnostics);
    assert_eq!(on(2)[0].found.as_deref(), Some("FF FE"));
    assert_eq!(on(3).len(), 1, "{:#?}", p.diagnostics);
    assert_eq!(on(3)[0].code, C::InvalidUtf8);
    find(&p, C::UnknownKeyword, 4, 4);
}

#[test]
fn unterminated_bracket() {
    after_prelude("@n mass [1 0 0", C::UnterminatedBracket, 9);
    // A `#` inside brackets starts a comment, so the bracket is unterminated (§3.2).
    after_prelude("@n mass 1 [0 # 0] 0", C::UnterminatedBracket, 11);
}

#[test]
fn nested_bracket() {
    after_prelude("@n mass [1 [2]] 0 0", C::NestedBracket, 12);
}

#[test]
fn stray_bracket() {
    after_prelude("@n mass 1] 0 0", C::StrayBracket, 10);
}

#[test]
fn unterminated_quote() {
    after_prelude("@n mass '1 0 0", C::UnterminatedQuote, 9);
}

#[test]
fn invalid_number() {
    after_prelude("@n mass 1.2.3 0 0", C::InvalidNumber, 9);
    after_prelude("@P param abc", C::InvalidNumber, 10);
    after_prelude("@P param [1]", C::InvalidNumber, 10);
    after_prelude("@n mass 1e 0 0", C::InvalidNumber, 9);
}

#[test]
fn non_finite_number() {
    let d = after_prelude("@n mass 1e999 0 0", C::NonFiniteNumber, 9);
    assert!(d.message.contains("non-finite number"), "{d}");
    after_prelude("@P param -1e999", C::NonFiniteNumber, 10);
}

// ---- syntactic errors -------------------------------------------------------------------------

#[test]
fn wrong_argument_count() {
    let d = after_prelude("@n mass 1 0", C::WrongArgumentCount, 4);
    assert_eq!(d.found.as_deref(), Some("2"));
    assert_eq!(d.label.as_deref(), Some("n"));
    after_prelude("@n mass 1 0 0 0 0", C::WrongArgumentCount, 17);
    after_prelude("@n", C::WrongArgumentCount, 1);
    after_prelude("@P param 1 2", C::WrongArgumentCount, 12);
    // A bare macro with a coordinate that is not a legacy proxy point (one coordinate for a
    // mesh) gets a hint; the legacy forms themselves load with a note (`lang_legacy.rs`).
    let d = after_prelude("@in1 frcInput @me 0.3", C::WrongArgumentCount, 19);
    assert!(d.message.contains("[@mesh u w]"), "{d}");
    // Extra tokens before a ground's position (§3.12 a).
    let d = after_prelude("@g ground 1 0.", C::WrongArgumentCount, 11);
    assert!(d.message.contains("ground"), "{d}");
    after_prelude("@g ground K 1 2 0.", C::WrongArgumentCount, 11);
}

#[test]
fn bad_label() {
    after_prelude("@2k param 1", C::BadLabel, 1);
    after_prelude("@sqrt param 1", C::BadLabel, 1);
    after_prelude("@ mass 1 0 0", C::BadLabel, 1);
    after_prelude("@c spring @ @m 1", C::BadLabel, 11);
}

#[test]
fn bad_channel_label() {
    after_prelude("@in3x posInput 0", C::BadChannelLabel, 1);
    after_prelude("@in0 frcInput @m", C::BadChannelLabel, 1);
    after_prelude("@in01 frcInput @m", C::BadChannelLabel, 1);
    after_prelude("@o1 posOutput @m", C::BadChannelLabel, 1);
    after_prelude("@out2a posOutput @m", C::BadChannelLabel, 1);
    after_prelude("@a audioParam @in2x", C::BadChannelLabel, 15);
    after_prelude("@a audioParam 2", C::BadChannelLabel, 15);
}

#[test]
fn non_integer_size() {
    after_prelude("@t string 40.5 1 K 0 0 0", C::NonIntegerSize, 11);
    after_prelude("@t string 40abc 1 K 0 0 0", C::NonIntegerSize, 11);
    let d = after_prelude("@t string K 1 K 0 0 0", C::NonIntegerSize, 11);
    assert!(d.message.contains("parameter"), "{d}");
    after_prelude("@t mesh 4 [5] 1 K 0 0 0", C::NonIntegerSize, 11);
    after_prelude("@t string 4e1 1 K 0 0 0", C::NonIntegerSize, 11);
    // `40.` and `40.0` are integer literals.
    assert!(parse(&with_prelude("@t string 40. 1 K 0 0 0"))
        .diagnostics
        .is_empty());
}

#[test]
fn invalid_size() {
    after_prelude("@t string 1 1 K 0 0 0", C::InvalidSize, 11);
    after_prelude("@t cornerMesh 3 0 1 K 0 0 0", C::InvalidSize, 17);
}

#[test]
fn too_large() {
    after_prelude("@t mesh 2000 2000 1 K 0 0 0", C::TooLarge, 9);
    after_prelude(
        "@t string 99999999999999999999999 1 K 0 0 0",
        C::TooLarge,
        11,
    );
    after_prelude("@t string 1048577 1 K 0 0 0", C::TooLarge, 11);
    assert!(parse(&with_prelude("@t mesh 1024 1024 1 K 0 0 0"))
        .diagnostics
        .is_empty());
}

#[test]
fn expression_syntax() {
    after_prelude("@n mass (1 0 0", C::ExpressionSyntax, 11);
    after_prelude("@n mass [1 2] 0 0", C::ExpressionSyntax, 12);
    after_prelude("@n mass [2^3] 0 0", C::ExpressionSyntax, 11);
    after_prelude("@n mass @K 0 0", C::ExpressionSyntax, 9);
    after_prelude("@n mass [@s 0.5] 0 0", C::ExpressionSyntax, 9);
    after_prelude("@n mass [] 0 0", C::ExpressionSyntax, 9);
    after_prelude("@n mass [1,2] 0 0", C::ExpressionSyntax, 11);
    after_prelude("@n mass 1 [(1 0 0] 0", C::ExpressionSyntax, 15);
}

#[test]
fn expression_too_deep() {
    let deep = format!("@n mass [{}1{}] 0 0", "(".repeat(300), ")".repeat(300));
    // `[` is column 9, so the 201st `(` is column 210.
    after_prelude(&deep, C::ExpressionTooDeep, 210);
    let long = format!("@n mass [{}] 0 0", vec!["K"; 1000].join("*"));
    let p = parse(&with_prelude(&long));
    assert_eq!(p.diagnostics.len(), 1);
    assert_eq!(p.diagnostics[0].code, C::ExpressionTooDeep);
    // 150 levels are fine.
    let ok = format!("@n mass [{}1{}] 0 0", "(".repeat(150), ")".repeat(150));
    assert!(parse(&with_prelude(&ok)).diagnostics.is_empty());
}

#[test]
fn wrong_arity() {
    let d = after_prelude("@n mass [pow(K)] 0 0", C::WrongArity, 10);
    assert_eq!(d.expected.as_deref(), Some("2"));
    after_prelude("@n mass [clamp(K, 1)] 0 0", C::WrongArity, 10);
    after_prelude("@n mass sqrt() 0 0", C::WrongArity, 9);
}

#[test]
fn function_without_call() {
    after_prelude("@n mass sqrt 0 0", C::FunctionWithoutCall, 9);
    after_prelude("@n mass [1 + max] 0 0", C::FunctionWithoutCall, 14);
}

#[test]
fn vector_size() {
    after_prelude("@n mass 1 [0 0] 0", C::VectorSize, 11);
    after_prelude("@n mass 1 0 [0 0 0 0]", C::VectorSize, 13);
    // A spaced expression in a vector must be parenthesised (§3.7): `[1 + 2]` is 3 items,
    // the middle one `+` is not an expression.
    after_prelude("@n mass 1 [1 + 2] 0", C::ExpressionSyntax, 15);
}

#[test]
fn expected_endpoint() {
    after_prelude("@c spring 1 @m 0.1", C::ExpectedEndpoint, 11);
    after_prelude("@out1 posOutput [0.5]", C::ExpectedEndpoint, 17);
}

#[test]
fn invalid_directive_argument() {
    after_prelude("~samplerate fast", C::InvalidDirectiveArgument, 13);
    after_prelude("~begin", C::InvalidDirectiveArgument, 1);
    after_prelude("~begin a b", C::InvalidDirectiveArgument, 10);
    after_prelude("~begin 1x", C::InvalidDirectiveArgument, 8);
}

// ---- semantic errors --------------------------------------------------------------------------

#[test]
fn duplicate_label() {
    let d = after_prelude("@m mass 1 0 0", C::DuplicateLabel, 1);
    assert!(d.message.contains("line 2 column 1"), "{d}");
    // Parameters and elements share one namespace.
    after_prelude("@s param 1", C::DuplicateLabel, 1);
    after_prelude("@K mass 1 0 0", C::DuplicateLabel, 1);
}

#[test]
fn undefined_name() {
    let p = parse(&with_prelude("@n mass [stiffness + sqrt(kScale3)] 0 0"));
    let d = find(&p, C::UndefinedName, 5, 10);
    assert_eq!(d.found.as_deref(), Some("stiffness"));
    find(&p, C::UndefinedName, 5, 27);
    assert_eq!(p.diagnostics.len(), 2, "all undefined names are reported");
    after_prelude("@n mass pi 0 0", C::UndefinedName, 9);
    after_prelude("@n mass SAMPLERATE 0 0", C::UndefinedName, 9);
    after_prelude("@n mass [floor(K)] 0 0", C::UndefinedName, 10);
    after_prelude("@n mass 1 [0 0 (2*x)] 0", C::UndefinedName, 19);
    after_prelude("@out1 posOutput [@s alpha]", C::UndefinedName, 21);
}

#[test]
fn not_a_parameter() {
    after_prelude("@n mass m 0 0", C::NotAParameter, 9);
}

#[test]
fn undefined_element() {
    after_prelude("@c spring @m @x 0.1", C::UndefinedElement, 14);
    after_prelude("@out1 posOutput [@x 0.5]", C::UndefinedElement, 18);
}

#[test]
fn not_a_point() {
    let d = after_prelude("@c spring @m @K 0.1", C::NotAPoint, 14);
    assert!(d.message.contains("a parameter"), "{d}");
    let p = parse(&with_prelude("@out1 posOutput @m\n@c spring @m @out1 1"));
    find(&p, C::NotAPoint, 6, 14);
    let p = parse(&with_prelude("@c spring @m @c 1"));
    find(&p, C::NotAPoint, 5, 14);
    let p = parse(&with_prelude("@in1 frcInput @m\n@out1 posOutput @in1"));
    find(&p, C::NotAPoint, 6, 17);
}

#[test]
fn not_a_macro() {
    after_prelude("@c spring @m [@m 0.5] 0.1", C::NotAMacro, 15);
}

#[test]
fn wrong_coordinate_count() {
    after_prelude("@c spring @m [@s 0.1 0.2] 0.1", C::WrongCoordinateCount, 14);
    after_prelude("@c spring @m [@me 0.5] 0.1", C::WrongCoordinateCount, 14);
    after_prelude("@c spring @m [@s] 0.1", C::WrongCoordinateCount, 14);
    // A spaced expression must be parenthesised (§3.12 a).
    after_prelude("@c spring @m [@s K + 0.1] 0.1", C::WrongCoordinateCount, 14);
    assert!(parse(&with_prelude("@c spring @m [@s (K + 0.1)] 0.1"))
        .diagnostics
        .is_empty());
}

#[test]
fn bare_macro_reference() {
    let d = after_prelude("@c spring @s @m 0.1", C::BareMacroReference, 11);
    assert_eq!(d.expected.as_deref(), Some("[@s α]"));
    after_prelude("@out1 posOutput @me", C::BareMacroReference, 17);
}

#[test]
fn unknown_keyword() {
    let d = after_prelude("@n Mass 1 0 0", C::UnknownKeyword, 4);
    assert_eq!(d.expected.as_deref(), Some("`mass`"));
    after_prelude("@n forceInput @m", C::UnknownKeyword, 4);
    // References to a line with an unknown keyword, or with a lexical error, do not cascade.
    let p = parse(&with_prelude("@n mass [1 0 0\n@c spring @n @m 1"));
    assert_eq!(p.diagnostics.len(), 1, "{:#?}", p.diagnostics);
    // A duplicate is reported on the later line, even when the later line is malformed.
    let p = parse(&with_prelude("@m mass [1 0 0"));
    find(&p, C::DuplicateLabel, 5, 1);
    find(&p, C::UnterminatedBracket, 5, 9);
    let p = parse(&with_prelude("@n cel 1 0 0\n@c spring @n @m 1"));
    assert_eq!(p.diagnostics.len(), 1, "{:#?}", p.diagnostics);
}

#[test]
fn conflicting_directive() {
    let d = only(
        "~samplerate raw\n@m mass 1 0 0\n~samplerate scaled\n",
        C::ConflictingDirective,
        3,
        13,
    );
    assert!(d.message.contains("line 1"), "{d}");
    // Repeating the same mode is fine.
    let p = parse("~samplerate raw\n~samplerate raw\n");
    assert!(p.diagnostics.is_empty());
    assert_eq!(p.spec.unwrap().sample_rate_mode, SampleRateMode::Raw);
}

// ---- `~generate` (spec §4) -------------------------------------------------------------------

/// The 1-based column of the first `needle` in `line`.
fn col(line: &str, needle: &str) -> u32 {
    line.find(needle)
        .unwrap_or_else(|| panic!("{needle} in {line}")) as u32
        + 1
}

/// `line` (after the prelude) has exactly one diagnostic, of `code`, at `needle`.
fn gen_error(line: &str, code: C, needle: &str) -> Diagnostic {
    after_prelude(line, code, col(line, needle))
}

#[test]
fn generate_is_clean_and_known() {
    let p = parse(&with_prelude(
        "~generate string g nodes=3 M=1 K=K Z=0.001\n@out1 posOutput @g_m1",
    ));
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
}

#[test]
fn unknown_generator() {
    let line = "~generate trangle g nodes=3 M=1 K=1 Z=0";
    let d = gen_error(line, C::UnknownGenerator, "trangle");
    assert!(d.expected.unwrap().contains("hexagon"));
    let line = "~generate String g nodes=3 M=1 K=1 Z=0";
    let d = gen_error(line, C::UnknownGenerator, "String");
    assert!(d.message.contains("did you mean `string`"), "{d}");
    // A macro keyword that is no generator, and a bracket in the kind slot.
    gen_error(
        "~generate closedMesh g size=3,3 M=1 K=1 Z=0",
        C::UnknownGenerator,
        "closedMesh",
    );
    gen_error(
        "~generate [mesh] g size=3,3 M=1 K=1 Z=0",
        C::UnknownGenerator,
        "[mesh]",
    );
}

#[test]
fn unknown_generator_key() {
    let line = "~generate string g nodes=3 M=1 K=1 Z=0 span=2";
    let d = gen_error(line, C::UnknownGeneratorKey, "span");
    assert!(d.message.contains("lattice"), "{d}");
    assert!(d.expected.unwrap().contains("nodes, M, K, Z, Zo, from, to"));
    let line = "~generate string g nodes=3 M=1 K=1 Z=0 zo=1e-4";
    let d = gen_error(line, C::UnknownGeneratorKey, "zo");
    assert!(d.message.contains("did you mean `Zo`"), "{d}");
    gen_error(
        "~generate ring g nodes=5 M=1 K=1 Z=0 from=0,0,0",
        C::UnknownGeneratorKey,
        "from",
    );
    gen_error(
        "~generate mesh g size=3,3 M=1 K=1 Ks=1 Z=0",
        C::UnknownGeneratorKey,
        "Ks",
    );
}

#[test]
fn missing_generator_key() {
    let line = "~generate mesh g size=3,4 M=1 Z=0";
    let d = gen_error(line, C::MissingGeneratorKey, "mesh");
    assert!(d.message.contains("`K=…`"), "{d}");
    assert!(d
        .expected
        .unwrap()
        .starts_with("~generate mesh NAME size=L,W"));
    let d = gen_error(
        "~generate stiffString g M=1 K=1 Z=0",
        C::MissingGeneratorKey,
        "stiffString",
    );
    assert!(d.message.contains("`nodes=N` and `Ks=…`"), "{d}");
    // A key written with a bad value is reported once, not as missing too.
    gen_error(
        "~generate chain g nodes=3 M= K=1 Z=0",
        C::InvalidGeneratorValue,
        "M=",
    );
}

#[test]
fn invalid_generator_value() {
    let line = "~generate mesh g size=3,4 M=1 K=1 Z=0 fixed=sides";
    let d = gen_error(line, C::InvalidGeneratorValue, "sides");
    assert_eq!(d.found.as_deref(), Some("sides"));
    gen_error(
        "~generate triangle g size=3 M=1 K=1 Z=0 fixed=centre",
        C::InvalidGeneratorValue,
        "centre",
    );
    gen_error(
        "~generate mesh g size=3 M=1 K=1 Z=0",
        C::InvalidGeneratorValue,
        "3 ",
    );
    gen_error(
        "~generate lattice g size=3,3 M=1 K=1 Z=0",
        C::InvalidGeneratorValue,
        "3,3",
    );
    gen_error(
        "~generate mesh g size=3,4 M=1 K=1 Z=0 from=0,0",
        C::InvalidGeneratorValue,
        "0,0",
    );
    gen_error(
        "~generate lattice g size=3,3,3 M=1 K=1 Z=0 diagonals=yes",
        C::InvalidGeneratorValue,
        "yes",
    );
    gen_error(
        "~generate polyline g points=0,0;1 M=1 K=1 Z=0",
        C::InvalidGeneratorValue,
        "1 M",
    );
    // Values evaluated when the script is read: finite, M > 0, from control parameters above.
    gen_error(
        "~generate chain g nodes=3 M=0 K=1 Z=0",
        C::InvalidGeneratorValue,
        "0 K",
    );
    gen_error(
        "~generate chain g nodes=3 M=1 K=1 Z=[sqrt(-1)]",
        C::InvalidGeneratorValue,
        "sqrt",
    );
    let p = parse("@a audioParam @in1\n~generate chain g nodes=3 M=1 K=a Z=0\n");
    let d = find(&p, C::InvalidGeneratorValue, 2, 33);
    assert!(d.message.contains("audio-rate"), "{d}");
    let p = parse("~generate chain g nodes=3 M=1 K=later Z=0\n@later param 1\n");
    let d = find(&p, C::InvalidGeneratorValue, 1, 33);
    assert!(d.message.contains("declared after"), "{d}");
    assert_eq!(p.diagnostics.len(), 1);
    // Names that are no parameter at all are the expression's own errors.
    gen_error(
        "~generate chain g nodes=3 M=1 K=nothing Z=0",
        C::UndefinedName,
        "nothing",
    );
    gen_error(
        "~generate chain g nodes=3 M=1 K=m Z=0",
        C::NotAParameter,
        "m Z",
    );
    // Geometry is literal.
    gen_error(
        "~generate mesh g size=3,4 M=1 K=1 Z=0 to=1,K,0",
        C::InvalidNumber,
        "K,0",
    );
    gen_error(
        "~generate ring g nodes=5 M=1 K=1 Z=0 radius=1e999",
        C::NonFiniteNumber,
        "1e999",
    );
}

#[test]
fn generator_directive_arguments() {
    gen_error("~generate", C::InvalidDirectiveArgument, "~generate");
    gen_error("~generate mesh", C::InvalidDirectiveArgument, "mesh");
    let line = "~generate mesh 1g size=3,3 M=1 K=1 Z=0";
    gen_error(line, C::InvalidDirectiveArgument, "1g");
    let line = "~generate mesh size=3,3 M=1 K=1 Z=0";
    let d = gen_error(line, C::InvalidDirectiveArgument, "size");
    assert!(d.message.contains("name comes before"), "{d}");
    gen_error(
        "~generate mesh g size=3,3 M=1 K=1 Z=0 junk",
        C::InvalidDirectiveArgument,
        "junk",
    );
    gen_error(
        "~generate mesh g size=3,3 M=1 K=1 Z=0 =2",
        C::InvalidDirectiveArgument,
        "=2",
    );
    let line = "~generate mesh g size=3,3 M=1 K=1 Z=0 K=2";
    after_prelude(line, C::InvalidDirectiveArgument, 39);
}

#[test]
fn generator_sizes() {
    gen_error(
        "~generate mesh g size=3.5,4 M=1 K=1 Z=0",
        C::NonIntegerSize,
        "3.5",
    );
    gen_error(
        "~generate mesh g size=3,K M=1 K=1 Z=0",
        C::NonIntegerSize,
        "K M",
    );
    gen_error(
        "~generate string g nodes=0 M=1 K=1 Z=0",
        C::InvalidSize,
        "0 M",
    );
    gen_error(
        "~generate ring g nodes=2 M=1 K=1 Z=0",
        C::InvalidSize,
        "2 M",
    );
    gen_error(
        "~generate mesh g size=4,1 M=1 K=1 Z=0",
        C::InvalidSize,
        "1 M",
    );
    gen_error(
        "~generate polyline g points=1,1 M=1 K=1 Z=0",
        C::InvalidSize,
        "1,1",
    );
    gen_error(
        "~generate mesh g size=3000,4000 M=1 K=1 Z=0",
        C::TooLarge,
        "3000",
    );
    let d = gen_error(
        "~generate lattice g size=30,40,50 M=1 K=1 Z=0 span=4 diagonals=on",
        C::TooLarge,
        "30",
    );
    assert!(d.message.contains("links"), "{d}");
    gen_error(
        "~generate chain g nodes=99999999999999999999999 M=1 K=1 Z=0",
        C::TooLarge,
        "999",
    );
    // The per-script budget counts every directive.
    let max = ressort_engine::lang::MAX_GENERATED_ELEMENTS;
    assert!(parse("~generate mesh a size=290,290 M=1 K=1 Z=0")
        .diagnostics
        .is_empty());
    let p = parse(
        "~generate mesh a size=250,250 M=1 K=1 Z=0\n~generate mesh b size=200,200 M=1 K=1 Z=0\n",
    );
    let d = find(&p, C::TooLarge, 2, 23);
    let left = max - 250 * 250 - 2 * 250 * 249;
    assert!(d
        .expected
        .unwrap()
        .contains(&format!("the {left} generated elements left")));
    assert_eq!(p.diagnostics.len(), 1);
}

#[test]
fn generated_label_clashes() {
    // A label declared before the directive: reported at the generator's name.
    let d = only(
        "@g_m0 mass 1 0 0\n~generate chain g nodes=3 M=1 K=1 Z=0\n",
        C::DuplicateLabel,
        2,
        17,
    );
    assert!(
        d.message.contains("`@g_m0`") && d.message.contains("line 1 column 1"),
        "{d}"
    );
    // A command after the directive: reported on the command, naming the directive.
    let d = only(
        "~generate chain g nodes=3 M=1 K=1 Z=0\n@g_K param 2\n",
        C::DuplicateLabel,
        2,
        1,
    );
    assert!(d.message.contains("`~generate` at line 1 column 17"), "{d}");
    // Two generators with the same name: one error, with the count of the others.
    let d = only(
        "~generate chain g nodes=3 M=1 K=1 Z=0\n~generate ring g nodes=3 M=1 K=1 Z=0\n",
        C::DuplicateLabel,
        2,
        16,
    );
    assert!(d.message.contains("more of its labels clash"), "{d}");
}

// ---- warnings ---------------------------------------------------------------------------------

#[test]
fn plus_separator() {
    // MIMS4Max reads `K+1` as two tokens, so this mass has gravity K and position 1.
    let p = parse(&with_prelude("@n mass 1 K+1 0"));
    let d = find(&p, C::PlusSeparator, 5, 12);
    assert_eq!(d.severity, Severity::Warning);
    assert_eq!(p.diagnostics.len(), 1);
    let spec = p.spec.expect("warnings do not block");
    let ElementKind::Mass { gravity, pos, .. } = &spec.element("n").unwrap().kind else {
        panic!()
    };
    assert_eq!((gravity, pos), (&Expr::param("K"), &Vector::from(1.0)));
    // No warning with blanks around it, or for an exponent.
    assert!(parse(&with_prelude("@n mass 1 K + 2.5e+3 0"))
        .diagnostics
        .is_empty());
}

#[test]
fn ignored_command_like_line() {
    let d = after_prelude("mass 1 0 0", C::IgnoredCommandLike, 1);
    assert_eq!(d.severity, Severity::Warning);
    after_prelude("  n springDamper @m @g 1 2", C::IgnoredCommandLike, 3);
    // Ordinary text is silently ignored.
    assert!(parse(&with_prelude("MIMS script, version 2"))
        .diagnostics
        .is_empty());
}

#[test]
fn unknown_directive() {
    after_prelude("~display on", C::UnknownDirective, 1);
}

#[test]
fn scope_not_open() {
    after_prelude("~end nothing", C::ScopeNotOpen, 1);
}

#[test]
fn scope_already_open() {
    only("~begin a\n~begin a\n", C::ScopeAlreadyOpen, 2, 1);
}

#[test]
fn too_many_diagnostics() {
    let text = "~end x\n".repeat(20_000) + "@m mass 1 0 0\n@m mass 1 0 0\n";
    let p = parse(&text);
    assert_eq!(
        p.diagnostics.len(),
        ressort_engine::lang::MAX_DIAGNOSTICS + 1
    );
    let last = p.diagnostics.last().unwrap();
    assert_eq!(last.code, C::TooManyDiagnostics);
    // The error after the cap still blocks the model.
    assert!(p.spec.is_none());
}

// ---- normative decisions of §3.12 -------------------------------------------------------------

#[test]
fn display_format() {
    let p = parse(&with_prelude("@n mass [1 + kScale3] 0 0"));
    assert_eq!(
        p.diagnostics[0].to_string(),
        "5:14: error: undefined name `kScale3`"
    );
    let p = parse(&with_prelude("~end x"));
    assert_eq!(
        p.diagnostics[0].to_string(),
        "5:1: warning: `~end x`: the scope `x` is not open"
    );
}

#[test]
fn columns_count_scalar_values_and_tabs() {
    // Tab = 1, `é` = 1 (not 2 bytes).
    let p = parse("\t@é mass\tü 0 0\n");
    find(&p, C::ExpressionSyntax, 1, 10);
    let p = parse("@m mass 1 0 0\r\n@n mass 1 0 0\r@o mass x 0 0\n");
    find(&p, C::UndefinedName, 3, 9);
    // Inside a bracket, after characters of two and four bytes and a no-break space.
    let p = parse("@é mass 1 [0\u{a0}(😀) 0] 0\n");
    find(&p, C::ExpressionSyntax, 1, 15);
    let p = parse("@s string 5 1 0.1 0.01 0 0\n@m mass 1 0 0\n@é spring [@s\u{2003}2x] @m 0.1\n");
    find(&p, C::InvalidNumber, 3, 15);
    let p = parse("~generate\u{a0}string s nodes=5 M=1 K=0.1 Z=0.001 from=é,0,0\n");
    find(&p, C::InvalidNumber, 1, 51);
    // A legacy mesh point `u:w` after a wide label: `w` starts after the colon.
    let p = parse("@😀 mesh 4 4 1 0.1 0.01 0 0\n@out1 posOutput @😀 0.5:y\n");
    find(&p, C::UndefinedName, 2, 24);
}

#[test]
fn all_diagnostics_in_one_pass() {
    let text = "@a mass 1 0\n@b Mass 1 0 0\n@c spring @a @zz 1\n@d mass [1 0 0\n~end q\n";
    let p = parse(text);
    let codes: Vec<C> = p.diagnostics.iter().map(|d| d.code).collect();
    assert_eq!(
        codes,
        [
            C::WrongArgumentCount,
            C::UnknownKeyword,
            C::UndefinedElement,
            C::UnterminatedBracket,
            C::ScopeNotOpen
        ]
    );
    assert!(p.spec.is_none());
}

#[test]
fn comments_anywhere_and_forward_references() {
    let p = parse(
        "@out1 posOutput @m # output before its target\n@m mass M 0 0#no space\n@M param 2 # a parameter after its use\n",
    );
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let spec = p.spec.unwrap();
    assert_eq!(spec.params[0].name, "M");
    assert_eq!(spec.elements[0].label, "out1");
}

#[test]
fn literal_forms_and_scientific_notation() {
    let p = parse("@m mass 1. .5 -0.2\n@n mass 100000 2.5e+3 1E-5\n@P param -1e-3\n");
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let spec = p.spec.unwrap();
    let ElementKind::Mass { m, pos, vel, .. } = &spec.elements[0].kind else {
        panic!()
    };
    assert_eq!(
        (m, pos, vel),
        (&Expr::Num(1.0), &Vector::from(0.5), &Vector::from(-0.2))
    );
    let ElementKind::Mass { pos, vel, .. } = &spec.elements[1].kind else {
        panic!()
    };
    assert_eq!((pos, vel), (&Vector::from(2500.0), &Vector::from(1e-5)));
}

#[test]
fn legacy_forms() {
    let p = parse("@g ground 0\n@m massG 1 0.001 1. 0.99\n@a spring @g @m 0.1 0.01\n@b nlSpring @g @m 0.1 0.2 0.3\n@c spring @g @m 0.1\n");
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let spec = p.spec.unwrap();
    let kind = |i: usize| &spec.elements[i].kind;
    assert!(matches!(kind(1), ElementKind::MassG { .. }));
    let form = |i: usize| match kind(i) {
        ElementKind::Interaction { law, .. } => law.form(),
        other => panic!("{other:?}"),
    };
    assert_eq!(form(2), LawForm::Full(LawKind::SpringDamper));
    assert_eq!(form(3), LawForm::Full(LawKind::NlSpring2));
    assert_eq!(form(4), LawForm::Spring);
}

#[test]
fn optional_arguments_default_to_zero() {
    let p = parse("@a mass 1 0 0\n@b mass 1 0 0\n@p nlPluck @a @b 1 2\n@w nlBow @a @b 1 2\n@c nlContact @a @b 1 2 3 4\n@o osc 1 2 3 0 0\n");
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let spec = p.spec.unwrap();
    let ElementKind::Interaction { law, .. } = &spec.elements[2].kind else {
        panic!()
    };
    assert_eq!(
        law,
        &Law::new(LawKind::Pluck, [1.0.into(), 2.0.into(), 0.0.into()])
    );
    let ElementKind::Interaction { law, .. } = &spec.elements[3].kind else {
        panic!()
    };
    assert_eq!(
        law,
        &Law::new(LawKind::Bow, [1.0.into(), 2.0.into(), 0.0.into()])
    );
    let ElementKind::Osc { gravity, .. } = &spec.elements[5].kind else {
        panic!()
    };
    assert_eq!(gravity, &Expr::Num(0.0));
}

#[test]
fn scopes_nest_overlap_and_reopen() {
    let text = "~begin a\n@p mass 1 0 0\n~begin b\n@q mass 1 0 0\n~end a\n@r mass 1 0 0\n~end b\n@s mass 1 0 0\n~begin a\n@t mass 1 0 0\n";
    let p = parse(text);
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let spec = p.spec.unwrap();
    assert_eq!(spec.buffers, ["a", "b"]);
    let b: Vec<Vec<u32>> = spec.elements.iter().map(|e| e.buffers.clone()).collect();
    assert_eq!(b, [vec![0], vec![0, 1], vec![1], vec![], vec![0]]);
}

#[test]
fn legacy_trailing_buffer_tag() {
    let p = parse("@K param 1\n~begin s\n@m mass 1 0 0 membrane 0.3 -0.1\n@n massG 1 0 1 1 membrane 1 2\n@g ground 0 membrane 0 0\n@o osc 1 K 0 0 0 s 4 5\n");
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let spec = p.spec.unwrap();
    assert_eq!(spec.buffers, ["s", "membrane"]);
    assert_eq!(spec.elements[0].buffers, [0, 1]);
    assert_eq!(spec.elements[0].tag_xy, Some((0.3, -0.1)));
    assert_eq!(spec.elements[2].tag_xy, Some((0.0, 0.0)));
    // A tag naming an open scope joins it once.
    assert_eq!(spec.elements[3].buffers, [0]);
    // The third token from the end must be a bare name that is not a declared parameter.
    let p = parse("@K param 1\n@m mass 1 0 0 K 1 2\n");
    find(&p, C::WrongArgumentCount, 2, 17);
    // Tag coordinates are numbers.
    let p = parse("@m mass 1 0 0 buf x 2\n");
    find(&p, C::InvalidNumber, 1, 19);
    // Not on interactions.
    let p = parse("@a mass 1 0 0\n@c spring @a @a 1 buf 1 2\n");
    find(&p, C::WrongArgumentCount, 2, 23);
}

#[test]
fn vectors_and_connection_expressions() {
    let p = parse("@K param 0.5\n@m mass 1 [(K + 1) -2 K*3] [0 0 0.1]\n@s string 10 1 1 0 0 0\n@c spring [@s (K - 0.1)] [@s K-0.1] 1\n");
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let spec = p.spec.unwrap();
    let ElementKind::Mass { pos, .. } = &spec.elements[0].kind else {
        panic!()
    };
    assert_eq!(
        pos,
        &Vector::Xyz(Box::new([
            Expr::param("K") + Expr::Num(1.0),
            Expr::Num(-2.0),
            Expr::param("K") * Expr::Num(3.0)
        ]))
    );
    let ElementKind::Interaction { a, b, .. } = &spec.elements[2].kind else {
        panic!()
    };
    assert_eq!(a, b);
    assert_eq!(a, &Endpoint::at("s", Expr::param("K") - Expr::Num(0.1)));
}

#[test]
fn audio_params() {
    let p = parse("@bowPos audioParam @in2\n@in2 posInput 0\n");
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let spec = p.spec.unwrap();
    assert_eq!(
        spec.params[0].kind,
        ressort_engine::ParamKind::Audio {
            input: 2,
            default: 0.0
        }
    );
    let p = parse("@lX audioParam @in2 0.3\n@lY audioParam @in3 -1e-3\n");
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let spec = p.spec.unwrap();
    assert_eq!(
        spec.params[1].kind,
        ressort_engine::ParamKind::Audio {
            input: 3,
            default: -1e-3
        }
    );
}

/// A bad `audioParam` default is reported at its column; a default written before the input
/// gets the right order in the message.
#[test]
fn audio_param_defaults() {
    after_prelude("@a audioParam @in2 x", C::InvalidNumber, 20);
    after_prelude("@a audioParam @in2 [0.1+0.2]", C::InvalidNumber, 20);
    after_prelude("@a audioParam @in2 K", C::InvalidNumber, 20);
    after_prelude("@a audioParam @in2 1e999", C::NonFiniteNumber, 20);
    after_prelude("@a audioParam @in2 0.3 0.4", C::WrongArgumentCount, 24);
    let d = after_prelude("@a audioParam 0.3 @in2", C::BadChannelLabel, 15);
    assert!(d.message.contains("write `@in2 0.3`"), "{}", d.message);
    // A bad input and a bad default are both reported.
    let p = parse(&with_prelude("@a audioParam @in0 y"));
    find(&p, C::BadChannelLabel, 5, 15);
    find(&p, C::InvalidNumber, 5, 20);
}
