//! The examples of the language guide, `docs/LANGUAGE.md`, are real: every ```mims block parses
//! without a diagnostic, every ```mims-error block has an error, every ```mims-warning block
//! only warnings (and maybe notes) and every ```mims-note block only notes; the ```text block that follows an error or warning example is exactly what
//! the parser reports (in `ressort check`'s `model.mdl:LINE:COL: …` form); and every diagnostic
//! code is documented.

use ressort_engine::lang::{folder_files, parse_with_files, print};
use ressort_engine::DiagnosticCode;

const GUIDE: &str = include_str!("../../docs/LANGUAGE.md");

/// A block parsed as `ressort check` would parse a script in `models/`: a 3-D example's
/// `objMesh` reads its file there.
fn parse(text: &str) -> ressort_engine::lang::Parsed {
    let models = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../models"));
    parse_with_files(text, &folder_files(models))
}

/// A fenced block: its tag, its text and the line of the opening fence (1-based).
struct Block {
    tag: String,
    text: String,
    line: usize,
}

fn blocks() -> Vec<Block> {
    let mut out = Vec::new();
    let mut current: Option<Block> = None;
    for (i, line) in GUIDE.lines().enumerate() {
        match (&mut current, line.strip_prefix("```")) {
            (None, Some(tag)) => {
                current = Some(Block {
                    tag: tag.trim().to_string(),
                    text: String::new(),
                    line: i + 1,
                })
            }
            (Some(_), Some("")) => out.extend(current.take()),
            (Some(b), _) => {
                b.text.push_str(line);
                b.text.push('\n');
            }
            (None, None) => {}
        }
    }
    assert!(current.is_none(), "unclosed fence in LANGUAGE.md");
    out
}

#[test]
fn valid_examples_parse_cleanly_and_round_trip() {
    let mut count = 0;
    for b in blocks().iter().filter(|b| b.tag == "mims") {
        let p = parse(&b.text);
        assert!(
            p.diagnostics.is_empty(),
            "LANGUAGE.md line {}:\n{}\n{:#?}",
            b.line,
            b.text,
            p.diagnostics
        );
        let spec = p.spec.unwrap();
        assert_eq!(parse(&print(&spec)).spec, Some(spec.clone()));
        // A 3-D example also builds and plays (struck on every input) without tripping.
        if spec.space.is_some() {
            let mut e =
                ressort_engine::compile(&spec, &ressort_engine::CompileOptions::at(48000.0))
                    .unwrap_or_else(|e| panic!("LANGUAGE.md line {}: {e}", b.line));
            let (n_in, n_out, frames) = (e.info().num_inputs(), e.info().num_outputs(), 4800);
            let mut input = vec![0.0; n_in * frames];
            for c in 0..n_in {
                input[c * frames] = 0.001;
            }
            let mut out = vec![0.0; n_out * frames];
            let report = e.process(frames, &input, &mut out);
            assert!(
                !report.tripped,
                "LANGUAGE.md line {}: {:?}",
                b.line,
                e.guard_event()
            );
        }
        count += 1;
    }
    assert!(count >= 30, "only {count} examples");
}

#[test]
fn error_and_warning_examples_report_what_the_guide_shows() {
    let all = blocks();
    let mut checked = 0;
    for (i, b) in all.iter().enumerate() {
        if !matches!(b.tag.as_str(), "mims-error" | "mims-warning" | "mims-note") {
            continue;
        }
        let p = parse(&b.text);
        let where_ = format!("LANGUAGE.md line {}:\n{}", b.line, b.text);
        match b.tag.as_str() {
            "mims-error" => assert!(p.errors().next().is_some(), "{where_}: no error"),
            "mims-warning" => {
                assert!(p.spec.is_some(), "{where_}: has an error");
                assert!(p.warnings().next().is_some(), "{where_}: no warning");
            }
            _ => {
                assert!(p.spec.is_some(), "{where_}: has an error");
                assert!(p.warnings().next().is_none(), "{where_}: has a warning");
                assert!(p.notes().next().is_some(), "{where_}: no note");
                // The notes' modern form builds the same model without a note.
                let spec = p.spec.clone().unwrap();
                let printed = print(&spec);
                let again = parse(&printed);
                assert!(again.diagnostics.is_empty(), "{where_}: {printed}");
                assert_eq!(again.spec, Some(spec), "{where_}");
            }
        }
        let shown = all
            .get(i + 1)
            .filter(|n| n.tag == "text")
            .unwrap_or_else(|| panic!("{where_}: no ```text block with the output after it"));
        let reported: Vec<String> = p
            .diagnostics
            .iter()
            .map(|d| format!("model.mdl:{d}"))
            .collect();
        let shown: Vec<&str> = shown.text.lines().collect();
        assert_eq!(reported, shown, "{where_}");
        checked += 1;
    }
    assert!(checked >= 35, "only {checked} diagnostic examples");
}

#[test]
fn every_diagnostic_code_is_documented() {
    for code in DiagnosticCode::ALL {
        let heading = format!("**`{}`**", code.name());
        assert!(
            GUIDE.contains(&heading),
            "LANGUAGE.md does not document {heading}"
        );
    }
}
