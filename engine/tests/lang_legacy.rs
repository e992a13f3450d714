//! The legacy syntax of MIMS's experimental proxy branch (spec §2.8, §3.14), used by mi-gen's
//! `_unsorted` proxy and Macro_Objects examples: bare connection points (`@in1 frcInput @s 0.3`,
//! `@c contact @s @in2 K Z 0. α`, mesh points `u:w`) and macros without their velocity. Each
//! legacy script builds exactly the model of its bracket form (same spec, same samples), and
//! reports one note per legacy form, at the right place. The scripts here are written for these
//! tests in the style of those examples.

mod common;

use common::{engine, render};
use ressort_engine::lang::{parse, print, DiagnosticCode as C, Parsed, Severity};
use ressort_engine::{ElementKind, Endpoint, Expr, ModelSpec};

/// Parses `text`, which must load (no error).
fn load(text: &str) -> Parsed {
    let p = parse(text);
    assert!(
        p.spec.is_some(),
        "{text}\n{:#?}",
        p.errors().collect::<Vec<_>>()
    );
    p
}

/// The legacy script and its bracket form give the same spec, the bracket form has no
/// diagnostic, the legacy one only notes; both compile and render the same samples for
/// `frames` samples. Returns the legacy notes as
/// `LINE:COL: note: message`.
fn same_model(legacy: &str, modern: &str, frames: usize) -> Vec<String> {
    let old = load(legacy);
    let new = load(modern);
    assert!(new.diagnostics.is_empty(), "{:#?}", new.diagnostics);
    assert!(
        old.diagnostics.iter().all(|d| d.severity == Severity::Note),
        "{:#?}",
        old.diagnostics
    );
    let (a, b) = (old.spec.clone().unwrap(), new.spec.unwrap());
    assert_eq!(a, b, "legacy:\n{legacy}\nmodern:\n{modern}");
    // The canonical printer writes the bracket form, which reads back without a note.
    let printed = print(&a);
    assert!(parse(&printed).diagnostics.is_empty(), "{printed}");
    assert_eq!(parse(&printed).spec, Some(a.clone()));
    assert_eq!(render_all(&a, frames), render_all(&b, frames));
    old.diagnostics.iter().map(|d| d.to_string()).collect()
}

/// Every output of `spec` at 48 kHz, with a slow sine of amplitude 0.5 on every input (it moves
/// position inputs through the strings, sweeps audio-rate coordinates, pushes force inputs).
fn render_all(spec: &ModelSpec, frames: usize) -> Vec<Vec<u64>> {
    let mut e = engine(spec, 48_000.0);
    let inputs: Vec<Vec<f64>> = (0..e.info().num_inputs())
        .map(|c| {
            (0..frames)
                .map(|n| 0.5 * (n as f64 * 0.005 * (c + 1) as f64).sin())
                .collect()
        })
        .collect();
    let out = render(&mut e, frames, 64, &inputs);
    assert!(out.iter().flatten().any(|v| *v != 0.0), "silent model");
    // Compared bit for bit.
    out.iter()
        .map(|ch| ch.iter().map(|v| v.to_bits()).collect())
        .collect()
}

#[test]
fn string_macro_object() {
    let notes = same_model(
        "# a macro string played on one point, heard on another\n\
         @s string 30 1. 0.5 0.01 0.\n\
         @in1 frcInput @s 0.3\n\
         @out1 posOutput @s 0.95\n\
         @out2 frcOutput @s 0.5\n",
        "# a macro string played on one point, heard on another\n\
         @s string 30 1. 0.5 0.01 0. 0\n\
         @in1 frcInput [@s 0.3]\n\
         @out1 posOutput [@s 0.95]\n\
         @out2 frcOutput [@s 0.5]\n",
        2000,
    );
    assert_eq!(
        notes,
        [
            "2:26: note: legacy macro syntax: the velocity is missing and defaults to 0; write `0. 0`",
            "3:15: note: legacy proxy syntax: write `[@s 0.3]` for `@s 0.3`",
            "4:17: note: legacy proxy syntax: write `[@s 0.95]` for `@s 0.95`",
            "5:17: note: legacy proxy syntax: write `[@s 0.5]` for `@s 0.5`",
        ]
    );
}

#[test]
fn chain_and_stiff_string_with_trailing_coordinates() {
    let notes = same_model(
        "@c chain 20 1. 0.4 0.01 0.\n\
         @g ground 0.\n\
         @tie springDamper @c @g 0.01 0.01 1.\n\
         @ss stiffString 40 1. 0.3 0.1 0.001 0.\n\
         @couple springDamper @c @ss 0.05 0.001 0.5 0.25\n\
         @in1 frcInput @c 0.3\n\
         @out1 posOutput @ss 0.8\n",
        "@c chain 20 1. 0.4 0.01 0. 0\n\
         @g ground 0.\n\
         @tie springDamper [@c 1.] @g 0.01 0.01\n\
         @ss stiffString 40 1. 0.3 0.1 0.001 0. 0\n\
         @couple springDamper [@c 0.5] [@ss 0.25] 0.05 0.001\n\
         @in1 frcInput [@c 0.3]\n\
         @out1 posOutput [@ss 0.8]\n",
        2000,
    );
    assert_eq!(
        notes,
        [
            "1:25: note: legacy macro syntax: the velocity is missing and defaults to 0; write `0. 0`",
            "3:19: note: legacy proxy syntax: write `[@c 1.]` for `@c` and drop the trailing `1.`",
            "4:37: note: legacy macro syntax: the velocity is missing and defaults to 0; write `0. 0`",
            "5:22: note: legacy proxy syntax: write `[@c 0.5]` for `@c` and drop the trailing `0.5`",
            "5:25: note: legacy proxy syntax: write `[@ss 0.25]` for `@ss` and drop the trailing `0.25`",
            "6:15: note: legacy proxy syntax: write `[@c 0.3]` for `@c 0.3`",
            "7:17: note: legacy proxy syntax: write `[@ss 0.8]` for `@ss 0.8`",
        ]
    );
}

#[test]
fn meshes_with_colon_and_two_token_points() {
    for kind in ["mesh", "cornerMesh", "closedMesh"] {
        let notes = same_model(
            &format!(
                "@u param 0.3\n\
                 @w param 0.6\n\
                 @me {kind} 8 6 1. 0.2 0.001 0.\n\
                 @g ground 0.\n\
                 @sp springDamper @me @g 0.1 0.01 1:0\n\
                 @in1 frcInput @me u:w\n\
                 @in2 frcInput @me 0.5 (u*0.5)\n\
                 @out1 posOutput @me 0.7:0.5\n"
            ),
            &format!(
                "@u param 0.3\n\
                 @w param 0.6\n\
                 @me {kind} 8 6 1. 0.2 0.001 0. 0\n\
                 @g ground 0.\n\
                 @sp springDamper [@me 1 0] @g 0.1 0.01\n\
                 @in1 frcInput [@me u w]\n\
                 @in2 frcInput [@me 0.5 (u*0.5)]\n\
                 @out1 posOutput [@me 0.7 0.5]\n"
            ),
            2000,
        );
        let decl = format!("@me {kind} 8 6 1. 0.2 0.001 0.");
        let col = decl.rfind(' ').unwrap() + 2;
        assert_eq!(
            notes,
            [
                format!(
                    "3:{col}: note: legacy macro syntax: the velocity is missing and defaults \
                     to 0; write `0. 0`"
                ),
                "5:18: note: legacy proxy syntax: write `[@me 1 0]` for `@me` and drop the \
                 trailing `1:0`"
                    .into(),
                "6:15: note: legacy proxy syntax: write `[@me u w]` for `@me u:w`".into(),
                "7:15: note: legacy proxy syntax: write `[@me 0.5 (u*0.5)]` for `@me 0.5 \
                 (u*0.5)`"
                    .into(),
                "8:17: note: legacy proxy syntax: write `[@me 0.7 0.5]` for `@me 0.7:0.5`".into(),
            ]
        );
    }
}

#[test]
fn moving_contacts_and_plucks_on_a_string() {
    // In the style of mi-gen's String_Proxy example: the coordinates end the line.
    let legacy = "@exc param 0.9\n\
                  @cp param 0.1\n\
                  @lp audioParam @in3\n\
                  @s stiffString 60 1. 0.6 0.2 0.001 0.\n\
                  @in1 posInput 0.\n\
                  @in2 posInput 0.\n\
                  @cont contact @s @in2 0.1 0.001 0. cp\n\
                  @pl nlPluck @in1 @s 0.5 0.05 exc\n\
                  @out1 posOutput @s lp\n";
    let modern = "@exc param 0.9\n\
                  @cp param 0.1\n\
                  @lp audioParam @in3\n\
                  @s stiffString 60 1. 0.6 0.2 0.001 0. 0\n\
                  @in1 posInput 0.\n\
                  @in2 posInput 0.\n\
                  @cont contact [@s cp] @in2 0.1 0.001 0.\n\
                  @pl nlPluck @in1 [@s exc] 0.5 0.05\n\
                  @out1 posOutput [@s lp]\n";
    let notes = same_model(legacy, modern, 3000);
    assert_eq!(notes.len(), 4);
    assert_eq!(
        notes[1],
        "7:15: note: legacy proxy syntax: write `[@s cp]` for `@s` and drop the trailing `cp`"
    );
    assert_eq!(
        notes[2],
        "8:18: note: legacy proxy syntax: write `[@s exc]` for `@s` and drop the trailing `exc`"
    );
    // The endpoint is the connection point, with its coordinate a parameter.
    let spec = parse(legacy).spec.unwrap();
    let ElementKind::Interaction { a, .. } = &spec.element("cont").unwrap().kind else {
        panic!()
    };
    assert_eq!(*a, Endpoint::at("s", Expr::param("cp")));
}

#[test]
fn mesh_contacts_with_parameter_coordinates() {
    // In the style of mi-gen's Mesh_Proxy examples.
    let legacy = "@eX param 0.9\n@eY param 0.8\n\
                  @cX audioParam @in5\n@cY audioParam @in6\n\
                  @mesh cornerMesh 12 10 1. 0.2 0.001 0.\n\
                  @p mass 4. 0.02 0.\n\
                  @c1 contact @mesh @p 0.1 0.1 0. eX:eY\n\
                  @in1 frcInput @p\n@in2 posInput 0.\n\
                  @cont contact @mesh @in2 0.1 0.001 0. cX:cY\n\
                  @out1 posOutput @mesh 0.3:0.4\n";
    let modern = "@eX param 0.9\n@eY param 0.8\n\
                  @cX audioParam @in5\n@cY audioParam @in6\n\
                  @mesh cornerMesh 12 10 1. 0.2 0.001 0. 0\n\
                  @p mass 4. 0.02 0.\n\
                  @c1 contact [@mesh eX eY] @p 0.1 0.1 0.\n\
                  @in1 frcInput @p\n@in2 posInput 0.\n\
                  @cont contact [@mesh cX cY] @in2 0.1 0.001 0.\n\
                  @out1 posOutput [@mesh 0.3 0.4]\n";
    let notes = same_model(legacy, modern, 2000);
    assert_eq!(
        notes[1],
        "7:13: note: legacy proxy syntax: write `[@mesh eX eY]` for `@mesh` and drop the \
         trailing `eX:eY`"
    );
}

#[test]
fn notes_carry_code_label_and_forms() {
    let p = load("@s string 10 1 0.1 0.01 0 0\n@in1 frcInput @s 0.3\n");
    let [d] = p.diagnostics.as_slice() else {
        panic!("{:#?}", p.diagnostics)
    };
    assert_eq!(d.code, C::LegacyProxySyntax);
    assert_eq!(d.code.severity(), Severity::Note);
    assert_eq!(d.label.as_deref(), Some("in1"));
    assert_eq!(d.expected.as_deref(), Some("[@s 0.3]"));
    assert_eq!(d.found.as_deref(), Some("@s"));
    assert_eq!(p.notes().count(), 1);
    assert_eq!(p.warnings().count(), 0);
    assert_eq!(p.errors().count(), 0);

    let p = load("@s string 10 1 0.1 0.01 0\n");
    let [d] = p.diagnostics.as_slice() else {
        panic!("{:#?}", p.diagnostics)
    };
    assert_eq!(d.code, C::LegacyMacroVelocity);
    assert_eq!((d.line, d.col), (1, 25));
    assert_eq!(d.expected.as_deref(), Some("0 0"));
}

/// The codes of the diagnostics of `text`, with their positions.
fn codes(text: &str) -> Vec<(C, u32, u32)> {
    parse(text)
        .diagnostics
        .iter()
        .map(|d| (d.code, d.line, d.col))
        .collect()
}

const PRELUDE: &str = "@m mass 1 0 0\n@n mass 1 0 0\n@s string 10 1 0.1 0.001 0 0\n\
                       @me mesh 4 5 1 0.1 0.001 0 0\n@K param 0.1\n";

#[test]
fn bare_mass_labels_behave_as_before() {
    // A number after a mass target is too many arguments, as before.
    let t = format!("{PRELUDE}@in1 frcInput @m 0.3\n");
    assert_eq!(codes(&t), [(C::WrongArgumentCount, 6, 18)]);
    // After two masses the extra value of a contact is its threshold.
    let t = format!("{PRELUDE}@c contact @m @n K 0.01 0.3\n");
    assert!(codes(&t).is_empty());
    let t = format!("{PRELUDE}@c springDamper @m @n K 0.01 0.3\n");
    assert_eq!(codes(&t), [(C::WrongArgumentCount, 6, 30)]);
    // A label that is a parameter or an output is not a macro.
    let t = format!("{PRELUDE}@out1 posOutput @K 0.3\n");
    assert_eq!(codes(&t), [(C::WrongArgumentCount, 6, 20)]);
}

#[test]
fn malformed_legacy_points_stay_errors() {
    // A bare macro without coordinates.
    let t = format!("{PRELUDE}@out1 posOutput @s\n");
    assert_eq!(codes(&t), [(C::BareMacroReference, 6, 17)]);
    // A mesh with one plain coordinate, a string with a mesh point.
    let t = format!("{PRELUDE}@out1 posOutput @me 0.3\n");
    assert_eq!(codes(&t), [(C::WrongArgumentCount, 6, 21)]);
    let t = format!("{PRELUDE}@out1 posOutput @s 0.3:0.5\n");
    assert_eq!(codes(&t), [(C::WrongArgumentCount, 6, 20)]);
    // Too many coordinates.
    let t = format!("{PRELUDE}@out1 posOutput @s 0.3 0.5\n");
    assert_eq!(codes(&t), [(C::WrongArgumentCount, 6, 20)]);
    // An interaction whose parameters run short once the coordinate is taken.
    let t = format!("{PRELUDE}@c springDamper @s @m K\n");
    assert_eq!(codes(&t), [(C::WrongArgumentCount, 6, 4)]);
    let t = format!("{PRELUDE}@c contact @s @m K 0.01\n");
    assert_eq!(codes(&t), [(C::BareMacroReference, 6, 12)]);
    // A coordinate that is a label or a connection point.
    let t = format!("{PRELUDE}@c springDamper @s @m K 0.01 @n\n");
    assert_eq!(codes(&t), [(C::WrongArgumentCount, 6, 30)]);
    // An empty side of `u:w`.
    let t = format!("{PRELUDE}@out1 posOutput @me 0.3:\n");
    assert_eq!(codes(&t), [(C::WrongArgumentCount, 6, 21)]);
    // A macro two arguments short is not a legacy form.
    let t = "@s string 10 1 0.1 0.001\n";
    assert_eq!(codes(t), [(C::WrongArgumentCount, 1, 4)]);
}

#[test]
fn what_mims_rejects_stays_rejected_with_its_line() {
    // Duplicate labels (as in mi-gen's Moving_Fret example).
    let t = "@s stiffString 20 1. 0.6 0.2 0.001 0.\n\
             @m mass 100 0. 0.\n\
             @det contact @s @m 0.02 0.05 0. 0.2\n\
             @det contact @s @m 0.02 0.05 0. 0.1\n";
    assert_eq!(
        codes(t),
        [
            (C::LegacyMacroVelocity, 1, 36),
            (C::LegacyProxySyntax, 3, 14),
            (C::DuplicateLabel, 4, 1),
            (C::LegacyProxySyntax, 4, 14),
        ]
    );
    assert!(parse(t).spec.is_none());
    // An undefined name in a coordinate, at its own column (also after a `:`).
    let t = format!("{PRELUDE}@in1 frcInput @s slide\n");
    assert_eq!(
        codes(&t),
        [(C::LegacyProxySyntax, 6, 15), (C::UndefinedName, 6, 18)]
    );
    let t = format!("{PRELUDE}@c contact @me @m K 0.01 0. 0.5:lY\n");
    assert_eq!(
        codes(&t),
        [(C::LegacyProxySyntax, 6, 12), (C::UndefinedName, 6, 33)]
    );
    assert!(parse(&t).spec.is_none());
    // An undefined macro label.
    let t = format!("{PRELUDE}@in1 frcInput @nope 0.3\n");
    assert_eq!(codes(&t), [(C::WrongArgumentCount, 6, 21)]);
    assert!(parse(&t).spec.is_none());
}

#[test]
fn macros_declared_later_are_found() {
    // Labels resolve globally (spec §3.4), so the macro may come after its use.
    same_model(
        "@in1 frcInput @s 0.3\n@out1 posOutput @s 0.6\n@s string 12 1 0.2 0.001 0.\n",
        "@in1 frcInput [@s 0.3]\n@out1 posOutput [@s 0.6]\n@s string 12 1 0.2 0.001 0. 0\n",
        500,
    );
}
