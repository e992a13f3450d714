//! Reference models of spec §7, built with the Rust builder API. They are the benchmark scenes
//! and the regression inputs of the engine's tests. Values are script values "as tuned at
//! 44.1 kHz" (scaled mode).

use crate::laws::LawKind;
use crate::spec::expr::Expr;
use crate::spec::{Endpoint, Law, MacroKind, MacroSpec, ModelBuilder, ModelSpec};

/// A contact law with threshold 0.
fn contact(k: impl Into<Expr>, z: impl Into<Expr>) -> Law {
    Law::new(LawKind::Contact, [k.into(), z.into()])
}

/// The hammer block of the canonical definitions (spec §7.10): a hammer of M = 1 resting at
/// 0.1, hung from a ground at 0.1 by a soft over-damped spring-damper, striking `target`, with a
/// force input on in1.
fn canonical_hammer(b: &mut ModelBuilder, target: Endpoint) {
    b.ground("gh", 0.1);
    b.mass("h", 1.0, 0.1, 0.0);
    b.spring_damper(
        "sh",
        Endpoint::label("gh"),
        Endpoint::label("h"),
        0.0001,
        0.05,
    );
    b.contact("hit", target, Endpoint::label("h"), 0.1, 0.001, 0.0);
    b.frc_input(1, Endpoint::label("h"));
}

/// The 1000-mass string, canonical definition (spec §7.10): `string 1002`, 1004 points and
/// 1003 interactions, struck at α = 0.13 and heard at α = 0.77.
pub fn string_1000() -> ModelSpec {
    let mut b = ModelBuilder::new();
    b.param("K", 0.1).param("Z", 0.001);
    b.macro_1d("s", MacroKind::String, 1002, 1.0, "K", "Z");
    canonical_hammer(&mut b, Endpoint::at("s", 0.13));
    b.pos_output(1, Endpoint::at("s", 0.77));
    b.build()
}

/// The expanded variant of the 1000-mass string (spec §7.10, generator §4.1): grounds `g0`,
/// `g1`, single masses `m0…m999` and 1001 spring-dampers. It exercises the per-element path.
pub fn string_1000_expanded() -> ModelSpec {
    let mut b = ModelBuilder::new();
    b.param("K", 0.1).param("Z", 0.001);
    b.ground("g0", 0.0);
    for k in 0..1000 {
        b.mass(&format!("m{k}"), 1.0, 0.0, 0.0);
    }
    b.ground("g1", 0.0);
    let node = |k: i32| match k {
        -1 => Endpoint::label("g0"),
        1000 => Endpoint::label("g1"),
        k => Endpoint::label(&format!("m{k}")),
    };
    for k in -1..1000 {
        b.spring_damper(&format!("r{}", k + 1), node(k), node(k + 1), "K", "Z");
    }
    canonical_hammer(&mut b, Endpoint::label("m129"));
    b.pos_output(1, Endpoint::label("m770"));
    b.build()
}

fn canonical_mesh(length: u32, width: u32) -> ModelSpec {
    let mut b = ModelBuilder::new();
    b.param("K", 0.1).param("Z", 0.001);
    b.mesh("mesh", MacroKind::CornerMesh, length, width, 1.0, "K", "Z");
    canonical_hammer(&mut b, Endpoint::at2("mesh", 0.3, 0.2));
    b.pos_output(1, Endpoint::at2("mesh", 0.75, 0.6));
    b.build()
}

/// Mesh 15×15, canonical definition (spec §7.10): 227 points, 422 interactions.
pub fn mesh_15x15() -> ModelSpec {
    canonical_mesh(15, 15)
}

/// Mesh 25×20, canonical definition (spec §7.10): 502 points, 957 interactions.
pub fn mesh_25x20() -> ModelSpec {
    canonical_mesh(25, 20)
}

/// The hammer block of the gallery (spec §7.0): hammer `p1` (pM = 4) just above the structure
/// at 0.02 with 0.02 units/s, the strike contact `target → p1`, and the catch: a ground at 1 and
/// a soft, mostly viscous contact `p1 → catch`. `in1` is the force on the hammer.
fn gallery_hammer(b: &mut ModelBuilder, target: Endpoint) {
    b.param("pM", 4.0)
        .param("pK", 0.1)
        .param("pZ", 0.1)
        .param("catchK", 1e-6)
        .param("catchZ", 0.06);
    b.mass("p1", "pM", 0.02, 0.02);
    b.ground("catch", 1.0);
    b.interaction("strike", contact("pK", "pZ"), target, Endpoint::label("p1"));
    b.interaction(
        "catchC",
        contact("catchK", "catchZ"),
        Endpoint::label("p1"),
        Endpoint::label("catch"),
    );
    b.frc_input(1, Endpoint::label("p1"));
}

/// The seven frets of the Fretted String (spec §7.3): (lower jaw masses, upper jaw masses,
/// upper jaw touch masses).
const FRETS: [([u32; 3], [u32; 2], [u32; 2]); 7] = [
    ([16, 15, 14], [13, 12], [5, 8]),
    ([30, 29, 28], [27, 26], [5, 18]),
    ([37, 36, 35], [34, 33], [15, 28]),
    // The published model lists mass 48 twice here (46 was probably meant); kept as published.
    ([50, 49, 48], [47, 48], [28, 38]),
    ([60, 59, 58], [57, 56], [25, 48]),
    ([70, 69, 68], [67, 66], [35, 58]),
    ([75, 74, 73], [72, 71], [35, 58]),
];

/// Fretted String (spec §7.3; Fig. 1 of the SMC'19 paper): a 151-node osc string between two
/// grounds, a hammer block on `low_m135` and seven two-jaw fret clamps driven by in2…in15.
/// 169 points, 203 interactions.
pub fn fretted_string() -> ModelSpec {
    let mut b = ModelBuilder::new();
    b.param("low_M", 1.0)
        .param("low_K", 0.4)
        .param("low_Z", 0.0008)
        .param("low_Zosc", 1e-5)
        .param("fK", 0.2)
        .param("fZ", 0.01);
    let names: Vec<String> = std::iter::once("low_s0".to_string())
        .chain(std::iter::once("low_mX".to_string()))
        .chain((0..150).map(|k| format!("low_m{k}")))
        .chain(std::iter::once("low_s1".to_string()))
        .collect();
    b.ground("low_s0", 0.0);
    for name in &names[1..names.len() - 1] {
        b.osc(name, "low_M", 0.0, "low_Zosc", 0.0, 0.0);
    }
    b.ground("low_s1", 0.0);
    for (r, pair) in names.windows(2).enumerate() {
        b.spring_damper(
            &format!("low_r{r}"),
            Endpoint::label(&pair[0]),
            Endpoint::label(&pair[1]),
            "low_K",
            "low_Z",
        );
    }
    gallery_hammer(&mut b, Endpoint::label("low_m135"));
    let mass = |k: u32| Endpoint::label(&format!("low_m{k}"));
    for (f, (lower, upper, touch)) in FRETS.iter().enumerate() {
        let (lo_in, up_in) = (2 + 2 * f as u32, 3 + 2 * f as u32);
        b.pos_input(lo_in, 0.0);
        b.pos_input(up_in, 0.0);
        let lo = Endpoint::label(&format!("in{lo_in}"));
        let up = Endpoint::label(&format!("in{up_in}"));
        let laws = [contact("fK", 0.0), contact("fK", "fZ"), contact(0.0, "fZ")];
        for (j, (m, law)) in lower.iter().zip(laws).enumerate() {
            b.interaction(&format!("f{f}_lo{j}"), law, lo.clone(), mass(*m));
        }
        for (j, m) in upper.iter().enumerate() {
            b.interaction(
                &format!("f{f}_up{j}"),
                contact("fK", "fZ"),
                mass(*m),
                up.clone(),
            );
        }
        for (j, m) in touch.iter().enumerate() {
            b.interaction(
                &format!("f{f}_t{j}"),
                contact(0.0, "fZ"),
                mass(*m),
                up.clone(),
            );
        }
    }
    b.pos_output(1, mass(133));
    b.pos_output(2, mass(130));
    b.build()
}

/// Chladni Huge Model (spec §7.4): `closedMesh 150 150`, the gallery hammer block at
/// (eX, eY) = (0.9, 0.8), a moving contact at audio-rate (cX, cY) pressed by the avatar in2,
/// and a listening point at audio-rate (lX, lY). 22 503 points, 44 703 interactions. The
/// audio-rate coordinates have defaults, which the specification does not give, so that the
/// model sounds with their inputs silent: it listens at (0.3, 0.6) and the contact sits at
/// (0.7, 0.3), away from the pinned border and the hammer.
pub fn chladni_150() -> ModelSpec {
    let mut b = ModelBuilder::new();
    b.param("meshK", 0.01)
        .param("meshZ", 0.01)
        .param("meshZo", 0.001)
        .param("eX", 0.9)
        .param("eY", 0.8)
        .param("contactStiffness", 0.1)
        .audio_param_with_default("lX", 3, 0.3)
        .audio_param_with_default("lY", 4, 0.6)
        .audio_param_with_default("cX", 5, 0.7)
        .audio_param_with_default("cY", 6, 0.3);
    b.macro_spec(
        "mesh",
        MacroSpec {
            kind: MacroKind::ClosedMesh,
            length: 150,
            width: 150,
            m: 1.0.into(),
            k: "meshK".into(),
            k2: None,
            z: "meshZ".into(),
            zo: "meshZo".into(),
            pos: 0.0.into(),
            vel: 0.0.into(),
        },
    );
    gallery_hammer(&mut b, Endpoint::at2("mesh", "eX", "eY"));
    b.pos_input(2, 0.0);
    b.interaction(
        "move",
        contact("contactStiffness", 0.001),
        Endpoint::at2("mesh", "cX", "cY"),
        Endpoint::label("in2"),
    );
    b.pos_output(1, Endpoint::at2("mesh", "lX", "lY"));
    b.build()
}

/// Hammer Oscillator (spec §7.6, `hammerOscillator.mdl`): an osc struck by a slow hanging
/// hammer; force input on the hammer, outputs on both.
pub fn hammer_oscillator() -> ModelSpec {
    let mut b = ModelBuilder::new();
    b.osc("o", 1.0, 0.1, 0.0003, 0.0, 0.0);
    b.mass("ham", 0.3, 1.0, 0.0);
    b.ground("g", 1.0);
    b.spring_damper(
        "sp",
        Endpoint::label("g"),
        Endpoint::label("ham"),
        0.0001,
        0.05,
    );
    b.frc_input(1, Endpoint::label("ham"));
    b.contact(
        "c",
        Endpoint::label("o"),
        Endpoint::label("ham"),
        0.1,
        0.001,
        0.0,
    );
    b.pos_output(1, Endpoint::label("o"));
    b.pos_output(2, Endpoint::label("ham"));
    b.build()
}

/// Every reference model with its name, for tests and benchmarks.
pub fn all() -> Vec<(&'static str, ModelSpec)> {
    vec![
        ("string_1000", string_1000()),
        ("string_1000_expanded", string_1000_expanded()),
        ("mesh_15x15", mesh_15x15()),
        ("mesh_25x20", mesh_25x20()),
        ("fretted_string", fretted_string()),
        ("chladni_150", chladni_150()),
        ("hammer_oscillator", hammer_oscillator()),
    ]
}
