//! The 3-D language (3-D spec §1.1, §2–§4, §8): scripts with `~dim 3` read into a
//! [`SpaceSpec`](ressort_engine::spec::space::SpaceSpec), print back to the same spec, and
//! report their errors with line and column.

use ressort_engine::lang::{parse, parse_with_files, print, DiagnosticCode};
use ressort_engine::spec::space::SpaceKind;

/// The examples of 3-D spec §8, as written there.
pub const EXAMPLES: [(&str, &str); 7] = [
    (
        "pendulum chain",
        "~dim 3
~gravity [0 0 -9.81]
~friction 0.00002
@K param 0.05
@Z param 0.001

@top ground [0 0 0]
@c1 mass 1. [0 0 -0.2] [0 0 0]
@c2 mass 1. [0 0 -0.4] [0 0 0]
@c3 mass 1. [0 0 -0.6] [0 0 0]
@c4 mass 1. [0 0 -0.8] [0 0 0]
@c5 mass 1. [0 0 -1.0] [0.3 0.4 0]
@l1 springDamper @top @c1 K Z auto
@l2 springDamper @c1 @c2 K Z auto
@l3 springDamper @c2 @c3 K Z auto
@l4 springDamper @c3 @c4 K Z auto
@l5 springDamper @c4 @c5 K Z auto

@out1 posOutput @c5 [1 0 0]
@out2 posOutput @c5 [0 1 0]
",
    ),
    (
        "struck string",
        "~dim 3
@K param 0.3
@s string3 42 1. K 0.001 [0 0 0] [41 0 0] [0.9*auto] 'Zo=2e-5'
@sv vdampers @s 0.0005

@gh ground [12 0.03 1.15]
@h mass 1. [12 0.03 0.15] [0 0 0]
@sh springDamper @gh @h 0.0001 0.05 auto
@hit contact @h @s_m12 0.1 0.001 0.05
@in1 frcInput @h

@out1 posOutput @s_m30
@out2 posOutput @s_m30 [0 1 0]
",
    ),
    (
        "membrane and ball",
        "~dim 3
~gravity [0 0 -20]
@mem mesh3 15 15 1. 0.2 0.001 [0 0 0] [14 0 0] [0 14 0] [0.9*auto] 'fix=borders'
@ball mass 20. [6.3 7.1 3] [0 0 0]
@hit contactSet @ball @mem 0.05 0.002 0.5
@out1 posOutput @mem_m4_9
@out2 mic @mem [7 7 6] [0 0 1] 1 0.5
",
    ),
    (
        "icosphere bell",
        "~dim 3
~friction 0.000005
@bell icosphere 2 1. 0.1 0.00002 [0 0 0] 10 auto 'fix=crown'
@gh ground [(0.8944*14) 0 (0.4472*14)]
@h mass 5. [(0.8944*10.7) 0 (0.4472*10.7)] [0 0 0]
@sh springDamper @gh @h 0.0002 0.05 auto
@hit contactSet @h @bell 0.2 0.002 0.6
@in1 frcInput @h [0.8944 0 0.4472]
@out1 posOutput @bell_m40 [1 0 0]
@out2 mic @bell [0 -30 0] radial 1 1
",
    ),
    (
        "plucked string",
        "~dim 3
@s string3 62 1. 0.4 0.001 [0 0 0] [61 0 0] [0.8*auto] 'Zo=3e-5'
@sv vdampers @s 0.0003
@in1 posInputXYZ [20 0 1.5]
@pl nlPluck @in1 @s_m20 0.1 0.5 0.0005
@out1 posOutput [@s 0.85]
@out2 posOutput [@s 0.85] [0 1 0]
",
    ),
    (
        "rope swing",
        "~dim 3
~gravity [0 0 -9.81]
@pivot ground [0 0 2]
@bob mass 1. [0.8 0 1.4] [0 0.5 0]
@rp rope @pivot @bob 0.5 0.002 1.0
@tine osc 0.2 [0.2*0.003929] 0.00002 [-0.3 0 1.05] [0 0 0]
@knock contact @bob @tine 0.05 0.0005 0.15
@floor planeContact @bob 0.05 0.002 [0 0 1] 0 0.1
@out1 posOutput @tine [1 0 0]
@out2 distOutput @pivot @bob
",
    ),
    (
        "bowed string",
        "~dim 3
@s string3 52 1. 0.5 0.001 [0 0 0] [51 0 0] [0.8*auto] 'Zo=2e-5'
@sv vdampers @s 0.0004
@in1 posInputXYZ [8 0 0]
@bw nlBow @in1 @s_m8 0.08 0.00005 1 [0 1 0]
@out1 posOutput [@s 0.7] [0 1 0]
@out2 posOutput [@s 0.7] [0 0 1]
",
    ),
];

#[test]
fn the_spec_examples_read_and_print_back() {
    for (name, text) in EXAMPLES {
        let parsed = parse(text);
        let errors: Vec<_> = parsed.errors().collect();
        assert!(errors.is_empty(), "{name}: {errors:#?}");
        let spec = parsed.spec.unwrap();
        let space = spec.space.as_ref().expect("a 3-D spec");
        assert!(spec.elements.is_empty(), "{name}");
        assert!(!space.elements.is_empty(), "{name}");
        let printed = print(&spec);
        let again = parse(&printed);
        assert!(
            again.errors().next().is_none(),
            "{name}: {printed}\n{:#?}",
            again.diagnostics
        );
        assert_eq!(
            again.spec.as_ref(),
            Some(&spec),
            "{name} printed as:\n{printed}"
        );
    }
}

#[test]
fn a_directional_pluck_and_bow_take_their_forms_by_count() {
    let spec = parse(EXAMPLES[6].1).spec.unwrap();
    let bow = spec.space.as_ref().unwrap().element("bw").unwrap();
    let SpaceKind::Interaction { law, args, .. } = &bow.kind else {
        panic!();
    };
    assert_eq!(format!("{law:?}"), "BowDir");
    assert_eq!(args.len(), 6);
}

fn first_error(text: &str) -> (DiagnosticCode, u32, u32, String) {
    let p = parse(text);
    let d = p
        .errors()
        .next()
        .unwrap_or_else(|| panic!("no error in {text}"));
    (d.code, d.line, d.col, d.message.clone())
}

#[test]
fn errors_have_their_line_and_column() {
    // A 1-D element in a 3-D script.
    let (code, line, col, _) = first_error("~dim 3\n@s string 10 1. 0.1 0.001 0. 0.\n");
    assert_eq!((code, line, col), (DiagnosticCode::DimensionMismatch, 2, 4));
    // A 3-D directive in a 1-D script.
    let (code, line, _, _) = first_error("@m mass 1. 0. 0.\n~gravity 9.81\n");
    assert_eq!((code, line), (DiagnosticCode::DimensionMismatch, 2));
    // A 1-D spring line pasted into a 3-D script reads K, L: right count, but a warning.
    let p =
        parse("~dim 3\n@a mass 1. [0 0 0] 0.\n@b mass 1. [1 0 0] 0.\n@l spring @a @b 0.1 0.001\n");
    assert!(p.errors().next().is_none());
    let w = p.warnings().next().expect("the 1-D spring hazard");
    assert_eq!((w.code, w.line), (DiagnosticCode::SuspiciousValue, 4));
    // A springDamper without its rest length.
    let (code, line, _, message) = first_error(
        "~dim 3\n@a mass 1. 0. 0.\n@b mass 1. 1. 0.\n@l springDamper @a @b 0.1 0.001\n",
    );
    assert_eq!((code, line), (DiagnosticCode::WrongArgumentCount, 4));
    assert!(message.contains("rest length"), "{message}");
    // `auto` outside a length slot.
    let (code, line, col, _) = first_error("~dim 3\n@a mass auto 0. 0.\n");
    assert_eq!((code, line, col), (DiagnosticCode::UndefinedName, 2, 9));
    // A zero direction.
    let (code, line, _, _) = first_error("~dim 3\n@a mass 1. 0. 0.\n@out1 posOutput @a [0 0 0]\n");
    assert_eq!((code, line), (DiagnosticCode::ZeroDirection, 3));
    // A node beyond the structure.
    let (code, line, _, _) = first_error(
        "~dim 3\n@s string3 5 1. 0.1 0 [0 0 0] [4 0 0] [0.9*auto]\n@out1 posOutput @s_m5\n",
    );
    assert_eq!((code, line), (DiagnosticCode::UndefinedElement, 3));
    // A label a structure creates.
    let (code, line, _, message) = first_error(
        "~dim 3\n@s string3 5 1. 0.1 0 [0 0 0] [4 0 0] [0.9*auto]\n@s_m2 mass 1. 0. 0.\n",
    );
    assert_eq!((code, line), (DiagnosticCode::DuplicateLabel, 3));
    assert!(message.contains("structure `@s`"), "{message}");
    // An unknown option.
    let (code, line, col, _) =
        first_error("~dim 3\n@s string3 5 1. 0.1 0 [0 0 0] [4 0 0] auto 'fix=both diag'\n");
    assert_eq!((code, line, col), (DiagnosticCode::InvalidOption, 2, 54));
    // A lattice bracket on a string.
    let (code, line, _, _) = first_error(
        "~dim 3\n@s string3 5 1. 0.1 0 [0 0 0] [4 0 0] auto\n@out1 posOutput [@s 0.1 0.2 0.3]\n",
    );
    assert_eq!((code, line), (DiagnosticCode::WrongCoordinateCount, 3));
    // Channels taken by an XYZ input.
    let (code, line, _, _) =
        first_error("~dim 3\n@in1 posInputXYZ [0 0 0]\n@m mass 1. 0. 0.\n@in2 frcInput @m\n");
    assert_eq!((code, line), (DiagnosticCode::DuplicateLabel, 4));
    // `~dim 2`.
    let (code, line, _, _) = first_error("~dim 3\n~dim 2\n");
    assert_eq!((code, line), (DiagnosticCode::InvalidDirectiveArgument, 2));
}

#[test]
fn a_mesh_file_is_read_through_the_files_and_its_errors_name_its_line() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 2 3 4\nf 1 3 4\n";
    let files = |path: &str| -> Result<String, String> {
        match path {
            "tet.obj" => Ok(obj.to_string()),
            "bad.obj" => Ok("v 0 0 0\nv 1 0 0\nf 1 2 7\n".to_string()),
            _ => Err("no such file".to_string()),
        }
    };
    let script = "~dim 3\n@t objMesh 'tet.obj' 1. 0.1 0.001 2 [0 0 0] auto 'fix=zmin hinge=0.01'\n@out1 posOutput @t_m3\n";
    let p = parse_with_files(script, &files);
    assert!(p.errors().next().is_none(), "{:#?}", p.diagnostics);
    let spec = p.spec.unwrap();
    let printed = print(&spec);
    assert_eq!(
        parse_with_files(&printed, &files).spec.as_ref(),
        Some(&spec),
        "{printed}"
    );
    let p = parse_with_files(
        "~dim 3\n@t objMesh 'bad.obj' 1. 0.1 0.001 2 [0 0 0] auto\n",
        &files,
    );
    let e = p.errors().next().unwrap();
    assert_eq!((e.code, e.line, e.col), (DiagnosticCode::MeshFile, 2, 12));
    assert!(e.message.contains("line 3"), "{}", e.message);
    let p = parse_with_files(
        "~dim 3\n@t objMesh 'gone.obj' 1. 0.1 0.001 2 [0 0 0] auto\n",
        &files,
    );
    let e = p.errors().next().unwrap();
    assert!(e.message.contains("no such file"), "{}", e.message);
    // Without files, the script says why.
    let p = parse(script);
    assert!(p
        .errors()
        .next()
        .unwrap()
        .message
        .contains("not read from a folder"));
}

#[test]
fn one_d_scripts_are_untouched() {
    let text = "@K param 0.1\n@o osc 1. K 0.0003 0. 0.\n@out1 posOutput @o\n";
    let spec = parse(text).spec.unwrap();
    assert!(spec.space.is_none());
    // `auto` stays an ordinary name in 1-D.
    assert!(parse("@auto param 1.\n@m mass auto 0. 0.\n").is_ok());
}
