//! The example scripts of spec §7 parse without errors, compile to the counts the spec states,
//! match the Rust reference models, and survive `parse(print(parse(x))) == parse(x)`.

mod common;

use ressort_engine::lang::{parse, print};
use ressort_engine::{
    compile, reference, CompileOptions, ElementKind, Endpoint, Expr, Law, LawKind, ModelSpec,
};

/// Spec §7.6, `hammerOscillator.mdl`, verbatim (including the trailing blanks).
const HAMMER_OSCILLATOR: &str = "# MIMS script file
# Script author: James Leonard

# Integrated harmonic oscillator 
@o osc 1. 0.1 0.0003 0. 0.

# A slow moving oscillator placed above the other
# serving as a hammer
@ham mass 0.3 1. 0.
@g ground 1.
@sp springDamper @g @ham 0.0001 0.05

# Add force input to the hammer
@in1 frcInput @ham

@c contact @o @ham 0.1 0.001

# Add position output from the oscillator
@out1 posOutput @o
@out2 posOutput @ham

# end of MIMS script
";

/// Spec §7.7, tutorial 06 `pluckedString.mdl`.
const PLUCKED_STRING: &str = "@stiffness param 0.5
@damping param 0.0003

@excPos param 0.3
@listPos param 0.9

@s string 40 1. stiffness damping 0. 0.
@in1 posInput 0.

# Set a plucking interaction located at excPos
@pl nlPluck [@s excPos] @in1 0.5000 0.1000 0.0010

#Listen to the string at location listPos
@out1 posOutput [@s listPos]
";

/// Spec §7.7, tutorial 05 `motionRouting.mdl` (buffer scopes).
const MOTION_ROUTING: &str = "@stiffness param 0.5
@damping param 0.0003

~begin triangle
@g ground 0.
@m1 mass 1. 0. 0.
@m2 mass 1. 0. 0.
@m3 mass 1. 0. 0.
@s1 springDamper @g @m1 0.1 0.001
@s2 springDamper @m1 @m2 0.1 0.001
@s3 springDamper @m2 @m3 0.1 0.001
@s4 springDamper @m3 @m1 0.1 0.001
~end triangle

~begin string
@s string 10 1. 0.5 0.0003 0. 0.
~end string

@link springDamper @m2 [@s 0.3] stiffness damping

# Add force input
@in1 frcInput @m2

# Add position outputs from the 
# triangle and from the string
@out1 posOutput @m3
@out2 posOutput [@s 0.8]
";

/// Spec §7.10, 1000-mass string.
const STRING_1000: &str = "# 1000-mass string (canonical definition for this project)
@K param 0.1
@Z param 0.001
@s string 1002 1. K Z 0. 0.
@gh ground 0.1
@h mass 1. 0.1 0.
@sh springDamper @gh @h 0.0001 0.05
@hit contact [@s 0.13] @h 0.1 0.001
@in1 frcInput @h
@out1 posOutput [@s 0.77]
";

/// Spec §7.10, Mesh 15×15.
const MESH_15X15: &str = "# Mesh 15x15 (canonical definition for this project)
@K param 0.1
@Z param 0.001
@mesh cornerMesh 15 15 1. K Z 0. 0.
@gh ground 0.1
@h mass 1. 0.1 0.
@sh springDamper @gh @h 0.0001 0.05
@hit contact [@mesh 0.3 0.2] @h 0.1 0.001
@in1 frcInput @h
@out1 posOutput [@mesh 0.75 0.6]
";

/// Spec §7.10, Mesh 25×20.
const MESH_25X20: &str = "# Mesh 25x20 (canonical definition for this project)
@K param 0.1
@Z param 0.001
@mesh cornerMesh 25 20 1. K Z 0. 0.
@gh ground 0.1
@h mass 1. 0.1 0.
@sh springDamper @gh @h 0.0001 0.05
@hit contact [@mesh 0.3 0.2] @h 0.1 0.001
@in1 frcInput @h
@out1 posOutput [@mesh 0.75 0.6]
";

/// Constructs quoted in the tables of §7.6–§7.9 (Modelling tutorial 2, Oscillator tutorials 4–7,
/// the unit-test model's vectors and negative thresholds, legacy forms).
const GALLERY_FRAGMENTS: &str = "@bowPos audioParam @in2
@bowPres audioParam @in3
@type param 0
@grav param 0.001
@nlK param 0.005
@s stiffString 120 1. 0.7 0.2 0.0009 0.00016 0. 0.
@in1 posInput 0.
@b1 nlBow [@s bowPos] @in1 0.1*bowPres [0.002+0.004*bowPres] type
@b2 nlBow [@s bowPos-0.03] @in1 0.1*bowPres [0.002+0.004*bowPres] type
@b3 nlBow [@s (bowPos - 0.06)] @in1 0.1*bowPres [0.002+0.004*bowPres] type
@o osc 1. 0.04 0.0003 0. 0.
@p mass 1 grav 3. 0.
@c contact @o @p 0.1 0.05
@g ground 0.
@m mass 1. 0. 0.
@nl nlSpringDamper @g @m 0.03 nlK 0.8 0.0002
@ms3 mass 1 [0.5 -0.25 0.] [0 0 10000]
@c3 contact @ms3 @g 0.1 0.01 -1.
@nc nlContact @g @ms3 0.01 0.1 0.2 0.01 -1
@me1 cornerMesh 8 8 2 0.6 0.0008 5e-5 [0 0 0] [1 1 0]
@k1 springDamper [@s 0] [@me1 0.3 0.3] 0.4 1e-4
@mg massG 1 0.001 1. 1.
@ls spring @mg @g 0.1 0.01
@ns nlSpring @mg @g 0.1 0.01 0.001
@out1 posOutput [@s 0.96]
@out2 frcOutput [@me1 0.7 0.7]
";

fn counts(spec: &ModelSpec) -> (usize, usize) {
    let engine = compile(spec, &CompileOptions::default())
        .unwrap_or_else(|e| panic!("compile failed:\n{e}"));
    (engine.info().num_points, engine.info().num_interactions)
}

fn assert_round_trip(name: &str, text: &str) {
    let first = parse(text);
    let printed = print(first.spec.as_ref().expect("parses"));
    let second = parse(&printed);
    assert!(
        second.diagnostics.is_empty(),
        "{name}: printed text has diagnostics {:#?}\n{printed}",
        second.diagnostics
    );
    assert_eq!(
        second.spec, first.spec,
        "{name}: round trip changed the spec:\n{printed}"
    );
    // Printing is canonical: printing again gives the same text.
    assert_eq!(print(second.spec.as_ref().unwrap()), printed, "{name}");
}

#[test]
fn every_example_has_no_diagnostics_and_round_trips() {
    for (name, text) in [
        ("hammerOscillator", HAMMER_OSCILLATOR),
        ("pluckedString", PLUCKED_STRING),
        ("motionRouting", MOTION_ROUTING),
        ("string_1000", STRING_1000),
        ("mesh_15x15", MESH_15X15),
        ("mesh_25x20", MESH_25X20),
        ("gallery fragments", GALLERY_FRAGMENTS),
    ] {
        let parsed = parse(text);
        assert!(
            parsed.diagnostics.is_empty(),
            "{name}: {:#?}",
            parsed.diagnostics
        );
        assert_round_trip(name, text);
    }
}

#[test]
fn canonical_definitions_have_the_stated_counts() {
    // Spec §7.10: 1004/1003, 227/422, 502/957.
    assert_eq!(counts(&common::spec(STRING_1000)), (1004, 1003));
    assert_eq!(counts(&common::spec(MESH_15X15)), (227, 422));
    assert_eq!(counts(&common::spec(MESH_25X20)), (502, 957));
}

#[test]
fn tutorial_scripts_have_their_counts() {
    // hammerOscillator: o, ham, g / sp, c.
    assert_eq!(counts(&common::spec(HAMMER_OSCILLATOR)), (3, 2));
    // pluckedString: 40 nodes + avatar / 39 internal + pluck.
    assert_eq!(counts(&common::spec(PLUCKED_STRING)), (41, 40));
    // motionRouting: 4 + 10 nodes / 4 + 9 internal + link.
    assert_eq!(counts(&common::spec(MOTION_ROUTING)), (14, 14));
    let gallery = common::spec(GALLERY_FRAGMENTS);
    compile(&gallery, &CompileOptions::default()).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn canonical_scripts_equal_the_reference_builders() {
    assert_eq!(common::spec(STRING_1000), reference::string_1000());
    assert_eq!(common::spec(MESH_15X15), reference::mesh_15x15());
    assert_eq!(common::spec(MESH_25X20), reference::mesh_25x20());
    assert_eq!(
        common::spec(HAMMER_OSCILLATOR),
        reference::hammer_oscillator()
    );
}

#[test]
fn reference_models_print_and_parse_back() {
    for (name, spec) in reference::all() {
        let text = print(&spec);
        let parsed = parse(&text);
        assert!(
            parsed.diagnostics.is_empty(),
            "{name}: {:#?}",
            parsed.diagnostics
        );
        assert_eq!(parsed.spec.as_ref(), Some(&spec), "{name}");
    }
}

#[test]
fn motion_routing_scopes() {
    let spec = common::spec(MOTION_ROUTING);
    assert_eq!(spec.buffers, ["triangle", "string"]);
    let buffers = |l: &str| spec.element(l).unwrap().buffers.clone();
    for l in ["g", "m1", "m2", "m3", "s1", "s4"] {
        assert_eq!(buffers(l), [0], "{l}");
    }
    assert_eq!(buffers("s"), [1]);
    assert!(buffers("link").is_empty());
    let engine = compile(&spec, &CompileOptions::default()).unwrap();
    let layout = &engine.info().motion;
    assert_eq!(layout.named[0].members.len(), 4);
    assert_eq!(layout.named[1].members.len(), 10);
}

#[test]
fn values_and_shapes() {
    let spec = common::spec(PLUCKED_STRING);
    let Some(ElementKind::Interaction { law, a, b }) = spec.element("pl").map(|e| &e.kind) else {
        panic!("pl is an interaction");
    };
    assert_eq!(
        *law,
        Law::new(
            LawKind::Pluck,
            [Expr::Num(0.5), Expr::Num(0.1), Expr::Num(0.001)]
        )
    );
    assert_eq!(*a, Endpoint::at("s", "excPos"));
    assert_eq!(*b, Endpoint::label("in1"));

    let g = common::spec(GALLERY_FRAGMENTS);
    let kind = |l: &str| g.element(l).unwrap().kind.clone();
    let law = |l: &str| match kind(l) {
        ElementKind::Interaction { law, .. } => law,
        other => panic!("{other:?}"),
    };
    assert_eq!(law("ls").kind(), LawKind::SpringDamper);
    assert_eq!(law("ns").kind(), LawKind::NlSpring2);
    assert!(matches!(kind("mg"), ElementKind::MassG { .. }));
    assert_eq!(law("c3").kind(), LawKind::Contact);
    assert_eq!(law("c3").arg("thresh"), Some(&Expr::Num(-1.0)));
    let ElementKind::Interaction {
        a: Endpoint::Line { alpha, .. },
        ..
    } = kind("b3")
    else {
        panic!()
    };
    assert_eq!(*alpha, Expr::param("bowPos") - Expr::Num(0.06));
    let ElementKind::Macro(m) = kind("me1") else {
        panic!()
    };
    assert_eq!((m.length, m.width, m.zo.clone()), (8, 8, Expr::Num(5e-5)));
    let ElementKind::Macro(s) = kind("s") else {
        panic!()
    };
    assert_eq!(s.k2, Some(Expr::Num(0.2)));
    assert_eq!(s.zo, Expr::Num(0.00016));
}
