//! The diagnostics shown in the language guide, `docs/LANGUAGE.md`, are what `ressort check`
//! prints: every example block followed by a ```text block of `model.mdl:…` lines is written to
//! `model.mdl`, checked, and its standard error compared line by line.

use std::process::Command;

const GUIDE: &str = include_str!("../../docs/LANGUAGE.md");

#[test]
fn guide_diagnostics_are_what_check_prints() {
    let mut blocks: Vec<(String, String, usize)> = Vec::new();
    let mut current: Option<(String, String, usize)> = None;
    for (i, line) in GUIDE.lines().enumerate() {
        match (&mut current, line.strip_prefix("```")) {
            (None, Some(tag)) => current = Some((tag.trim().to_string(), String::new(), i + 1)),
            (Some(_), Some("")) => blocks.extend(current.take()),
            (Some((_, text, _)), _) => {
                text.push_str(line);
                text.push('\n');
            }
            (None, None) => {}
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let mut checked = 0;
    for pair in blocks.windows(2) {
        let [(tag, script, line), (next, shown, _)] = pair else {
            continue;
        };
        let is_example = matches!(
            tag.as_str(),
            "mims" | "mims-error" | "mims-warning" | "mims-note"
        );
        if !is_example || next != "text" || !shown.starts_with("model.mdl:") {
            continue;
        }
        std::fs::write(dir.path().join("model.mdl"), script).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_ressort"))
            .args(["check", "model.mdl"])
            .current_dir(dir.path())
            .output()
            .expect("run ressort");
        let stderr = String::from_utf8_lossy(&out.stderr);
        let printed: Vec<&str> = stderr.lines().collect();
        let expected: Vec<&str> = shown.lines().collect();
        assert_eq!(printed, expected, "LANGUAGE.md line {line}:\n{script}");
        let has_error = expected.iter().any(|l| l.contains(": error: "));
        assert_eq!(out.status.code(), Some(if has_error { 1 } else { 0 }));
        checked += 1;
    }
    assert!(checked >= 35, "only {checked} examples checked");
}
