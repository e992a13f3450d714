//! The 1-D corpus, bit for bit: every 1-D script of `models/` and of the mi-gen legacy scripts
//! (`tests/legacy/`), rendered on the bare engine (an impulse on every input) and through the
//! instrument the plugin runs (a C4 at velocity 0.8), hashes to the digests recorded before the
//! 3-D engine landed (commit 2caca8a). A 3-D law, stage or path that changed one sample of a
//! 1-D render would change a digest (issue 39: "every existing 1-D script keeps its exact
//! meaning").
//!
//! `cargo test --release -p ressort-engine --test corpus_1d print_the_1d_corpus_digests --
//! --ignored --nocapture` prints the table; it was run at 2caca8a to fill [`DIGESTS`].

mod common;

use common::{engine, hash_f64s, impulse, render, spec};
use ressort_engine::instrument::{self, Controls, Event, Instrument, Timed, MAX_HOST_INPUTS};
use std::path::Path;

/// Frames of each render: enough for every model's first echoes and the instrument's attack.
const FRAMES: usize = 4096;

/// Every 1-D script of the corpus: (name, text), sorted.
fn corpus() -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for (prefix, dir) in [
        ("models/", root.join("../models")),
        ("legacy/", root.join("tests/legacy")),
    ] {
        for entry in std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()) {
            let path = entry.path();
            if path.extension().is_none_or(|x| x != "mdl") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            if text.lines().any(|l| l.trim_start().starts_with("~dim 3")) {
                continue;
            }
            let stem = path.file_stem().unwrap().to_string_lossy();
            files.push((format!("{prefix}{stem}"), text));
        }
    }
    files.sort();
    files
}

/// The digest of the bare engine at 44.1 kHz, an impulse of 0.001 on every input at n = 0.
fn engine_digest(text: &str) -> u64 {
    let mut e = engine(&spec(text), 44_100.0);
    let inputs: Vec<Vec<f64>> = (0..e.info().num_inputs())
        .map(|_| impulse(0.001, FRAMES))
        .collect();
    let out = render(&mut e, FRAMES, 256, &inputs);
    hash_f64s(out.iter().flatten())
}

/// The digest of what the plugin plays at 48 kHz: a C4 at velocity 0.8, every host output.
fn instrument_digest(name: &str, text: &str) -> u64 {
    let sr = 48_000.0;
    let mut model = instrument::prepare(name, text, sr).expect("it prepares");
    if let Some(v) = model.facts().settings.voices {
        model.set_voices(v as usize);
    }
    let channels = model.facts().num_outputs.clamp(2, 8).div_ceil(2) * 2;
    let mut inst = Instrument::new(sr, Controls::DEFAULT);
    inst.set_model(Box::new(model));
    let mut out = vec![vec![0.0f32; FRAMES]; channels];
    let block = 512;
    let mut done = 0;
    while done < FRAMES {
        let len = block.min(FRAMES - done);
        let first = [Timed::new(0, Event::note_on(60, 0.8))];
        let mut evs = first.iter().copied().filter(|_| done == 0);
        let host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
        let mut slices: Vec<&mut [f32]> =
            out.iter_mut().map(|c| &mut c[done..done + len]).collect();
        inst.process(len, &host, false, &mut evs, &Controls::DEFAULT, &mut slices);
        done += len;
    }
    let wide: Vec<f64> = out.iter().flatten().map(|&v| v as f64).collect();
    hash_f64s(&wide)
}

/// (name, bare engine, instrument), as `print_the_1d_corpus_digests` printed them at 2caca8a, the
/// commit before the 3-D engine. 14 of the 178 renders are silent within their 4096 frames (a
/// bow or a falling hammer that has not spoken yet; the digest of silence is 0xeb05052ea5b62325):
/// they still pin the output's length and its silence.
///
/// Eight instrument digests of mi-gen legacy scripts (coupled-strings-bowed, drunk-triangles-xl,
/// harmonic-oscillator, mesh-15x15, mesh-25x20, nonlinear-oscillator, oscillator-bank,
/// rolling-mesh) were recorded again when analysed reference pitches began to be rounded to 20
/// bits of mantissa ([`ressort_engine::instrument::pitch::settle_pitch`]): those scripts have no
/// shipped analyses, and their pitch's last bits followed the processor's SIMD width, so two
/// of their digests differed between an AVX2 and an AVX-512 machine. Their bare-engine digests,
/// and every digest of `models/` (played by the shipped analyses), are 2caca8a's.
const DIGESTS: &[(&str, u64, u64)] = &[
    (
        "legacy/bowed-oscillator",
        0xaba3fe0a0ba858ef,
        0xeb05052ea5b62325,
    ),
    (
        "legacy/bowed-string",
        0xeb05052ea5b62325,
        0xeb05052ea5b62325,
    ),
    (
        "legacy/brokendown-string",
        0xc397c77bbfa09f3c,
        0xdab071a17dcb6941,
    ),
    (
        "legacy/chladni-150x150",
        0x8f6955bf94ec2325,
        0x7c25a07b724a1d65,
    ),
    (
        "legacy/coupled-strings-bowed",
        0xeb05052ea5b62325,
        0x93b606e1fe496152,
    ),
    (
        "legacy/drunk-triangles",
        0x11787b0d82941e1b,
        0x8f706d260aa7b3e1,
    ),
    (
        "legacy/drunk-triangles-xl",
        0x5199d4910c75c4e9,
        0x344dcab49a15f2b9,
    ),
    (
        "legacy/fretted-string",
        0x97c12ced2897edd8,
        0xe13868bf0b87cabf,
    ),
    (
        "legacy/gravity-oscillator",
        0xb4974b3970de1e1b,
        0x905dbc621045df61,
    ),
    (
        "legacy/hammer-oscillator",
        0x7fb876e6ba8552f7,
        0x63c15d350828279d,
    ),
    (
        "legacy/harmonic-oscillator",
        0xd48459edd5dbfa2e,
        0x6ca0997525b609c5,
    ),
    ("legacy/mesh-15x15", 0x8f6955bf94ec2325, 0xfb2e9495298138ed),
    ("legacy/mesh-25x20", 0x8f6955bf94ec2325, 0x4b6a5fc78d643751),
    ("legacy/nofx-drone", 0xeb05052ea5b62325, 0x67aaa3e61f74f774),
    (
        "legacy/nonlinear-oscillator",
        0x7fb876e6ba8552f7,
        0xf7e3cc2883b955f1,
    ),
    (
        "legacy/oscillator-bank",
        0xbd334b583e6e13e5,
        0x2134541348c89fa3,
    ),
    (
        "legacy/plucked-harmonics",
        0x2a81ab620793a6ca,
        0xeb05052ea5b62325,
    ),
    (
        "legacy/plucked-oscillator",
        0xef38202ee94d0d44,
        0xeb05052ea5b62325,
    ),
    (
        "legacy/resonant-strings",
        0xc74b47c8c74a2325,
        0xc74b47c8c74a2325,
    ),
    (
        "legacy/rolling-mesh",
        0x8a4b67d77598f9b6,
        0xe93c0fe927bbc125,
    ),
    ("legacy/string-1000", 0x8f6955bf94ec2325, 0x6307939c72928bd5),
    (
        "legacy/struck-string",
        0x8f6955bf94ec2325,
        0x7f2507018fba20b5,
    ),
    (
        "legacy/two-fingers-string",
        0x82f73e8ff0015b95,
        0xeb05052ea5b62325,
    ),
    (
        "models/aeolian-harp",
        0x7300288824707a97,
        0x67dd5f7e9dcf857c,
    ),
    (
        "models/bolted-piano-string",
        0x89d94e340dd6c0a2,
        0xdf7c567110f5b7f7,
    ),
    (
        "models/bouncing-ball",
        0x73f9c5a9c94e9cce,
        0xeb05052ea5b62325,
    ),
    (
        "models/bowed-oscillator",
        0x8f6955bf94ec2325,
        0x79f78ba84dfde9e9,
    ),
    ("models/bowed-pad", 0xe2468c6d9e9d7740, 0xade8f9d840cb23d5),
    ("models/bowed-plate", 0xe7c57df50ece636c, 0xb287f73b2babc8b3),
    (
        "models/bowed-string",
        0xeb05052ea5b62325,
        0x91a1b52eae886f26,
    ),
    (
        "models/bright-grand",
        0xeb05052ea5b62325,
        0x6f12bae44d56c79a,
    ),
    (
        "models/brokendown-string",
        0xc397c77bbfa09f3c,
        0x8724d054f543881d,
    ),
    ("models/celesta", 0x17f4f96075c12e8b, 0x605729f24b3ff0df),
    ("models/cello", 0x9a920d0e464a3a40, 0xd2fa3799fd05423d),
    ("models/chime-tube", 0x5bd29743afa0da1f, 0x5120fe5fccffbdb6),
    (
        "models/chladni-150x150",
        0x7a33997f47ae361c,
        0xac82f4641a8ce7c9,
    ),
    (
        "models/coupled-strings-bowed",
        0x5c35cbfa6d6c9d0b,
        0x1d3a8d4b36094822,
    ),
    ("models/crotales", 0x9adf638d106d323b, 0x643c5fbed0c598cc),
    (
        "models/drunk-triangles",
        0xeb05052ea5b62325,
        0xeb05052ea5b62325,
    ),
    (
        "models/drunk-triangles-xl",
        0xeb05052ea5b62325,
        0x5343996dcaa4190e,
    ),
    ("models/duffing", 0x1e6be0b23c38036d, 0x1cb15a728c35d605),
    (
        "models/electric-tine",
        0xeb05052ea5b62325,
        0xa419f0e92789f533,
    ),
    ("models/erhu", 0x99f62cf97d09ce65, 0xd94952ccb3ae0d35),
    ("models/felt-piano", 0x8f6955bf94ec2325, 0x7c3f4d933b203589),
    ("models/frame-drum", 0x7c7b8854260ff081, 0x94177c14ebada8b8),
    (
        "models/fretted-string",
        0x7346648c4d40a283,
        0xa4990aecae6e558f,
    ),
    (
        "models/friction-squeal",
        0xea7963bcb84991c9,
        0x4f60cae348c86d91,
    ),
    (
        "models/glass-harmonica",
        0x5ec4b4955a3d7a69,
        0xd1c2e8bdf4221f79,
    ),
    (
        "models/glockenspiel",
        0x5073176fd5355fee,
        0x0304cb38be41b600,
    ),
    ("models/gong", 0x53708dca5e8ad5a5, 0x44b20a4b2cefd079),
    (
        "models/gravity-oscillator",
        0x8f6955bf94ec2325,
        0x7675e3bf58f41635,
    ),
    (
        "models/hammer-oscillator",
        0xd48459edd5dbfa2e,
        0xf2fa096ee773e7b5,
    ),
    (
        "models/hammered-dulcimer",
        0xeb05052ea5b62325,
        0x07405b928aee4041,
    ),
    (
        "models/harmonic-oscillator",
        0xd48459edd5dbfa2e,
        0xd0674cfddc2ccd85,
    ),
    ("models/harp", 0x5d50e4543f2304eb, 0xc742a22a71b11869),
    ("models/harpsichord", 0x39404a6dba0cfdc7, 0xe81a627450772e5f),
    (
        "models/jawari-sitar",
        0x1575bac5cd280f1b,
        0x10926a6f639a00c3,
    ),
    (
        "models/kalimba-tine",
        0x2f805586677ae03e,
        0x6537bec8207a051d,
    ),
    (
        "models/kick-resonator",
        0xba80d00ce6f519f7,
        0x21fb8c49cde5d534,
    ),
    ("models/koto", 0x08220c6b3aa0c6d4, 0x2e43b14eaed56a51),
    ("models/marimba", 0xa09d63b7881aecee, 0xf868e904a52ef8e3),
    ("models/mesh-15x15", 0x8f6955bf94ec2325, 0x7cd7be9d06a9b8fd),
    ("models/mesh-25x20", 0x8f6955bf94ec2325, 0x907bc5628996486d),
    ("models/metal-sheet", 0x40f4a1099faa9f79, 0x37c8aaa6036f7d02),
    ("models/musical-saw", 0x6b67022cbdf7bfca, 0xc061c08e142072fa),
    ("models/nofx-drone", 0xa7a3d23b623f1645, 0x6165f0533b30b5c7),
    (
        "models/nonlinear-oscillator",
        0x8f6955bf94ec2325,
        0x081fa0951a5e58a5,
    ),
    (
        "models/open-back-banjo",
        0xd0914d7beff7e724,
        0x441f02c5549f6676,
    ),
    ("models/organ-pipes", 0x8b66ae572230bc4b, 0xcd592650b92c93c6),
    (
        "models/oscillator-bank",
        0xbd334b583e6e13e5,
        0x7d2b3e31e992f33d,
    ),
    (
        "models/plucked-harmonics",
        0x9a0af808b03bae03,
        0x1ede21c575be8c7b,
    ),
    (
        "models/plucked-oscillator",
        0x6284bce3dda186c2,
        0xc3931f5afd71fa99,
    ),
    ("models/rattle", 0x4c3d667e0b5a7675, 0x3dfbaf298c25ad6d),
    (
        "models/resonant-strings",
        0xc74b47c8c74a2325,
        0xfd40428968353227,
    ),
    (
        "models/rolling-mesh",
        0x8a4b67d77598f9b6,
        0xd73551c6bea76d66,
    ),
    (
        "models/singing-bowl",
        0xb0b4650f24d797f9,
        0x50e72cb0d0c5e0d9,
    ),
    ("models/slit-drum", 0xbc138e50039f572a, 0x0eb9e57829b983d5),
    ("models/snare", 0x3faaba335a5a0b3a, 0x4248885694ea0d9f),
    ("models/steel-pan", 0x7698a9639598a1d0, 0x97e3d334666789dc),
    ("models/string-1000", 0x8f6955bf94ec2325, 0x7a8900ecc9dc5b65),
    (
        "models/struck-string",
        0x8f6955bf94ec2325,
        0x7c9d5d509a67e94d,
    ),
    (
        "models/sympathetic-strings",
        0xe516b8a45d5a4c41,
        0xeb5c65df6abf0e35,
    ),
    (
        "models/talking-drum",
        0x08297ace52c9b60a,
        0xe9719fe5dfd658e5,
    ),
    (
        "models/tangent-clavinet",
        0x36b062ad33c38e71,
        0x33cf1220e8847e8f,
    ),
    ("models/timpani", 0xe66833af2d263cb5, 0x561776fd90978fa8),
    ("models/tom", 0xe609465df4222ba0, 0xaed9f1b33b9bdbe0),
    (
        "models/two-fingers-string",
        0xd8a94a00ca2ba8b8,
        0x2c5f55484439a427,
    ),
    ("models/wood-box", 0xf913745de84c7fa6, 0x75edd726a5d0a3d8),
    ("models/xylophone", 0x8a307f9da7915595, 0xf03998c29771a8ca),
];

#[test]
#[ignore = "prints the table DIGESTS holds"]
fn print_the_1d_corpus_digests() {
    for (name, text) in corpus() {
        println!(
            "    (\"{name}\", 0x{:016x}, 0x{:016x}),",
            engine_digest(&text),
            instrument_digest(&name, &text)
        );
    }
}

/// The corpus renders as it did before the 3-D engine: every digest equal, no script missing
/// from the table or added to the corpus without a recorded digest.
#[test]
fn the_1d_corpus_renders_bit_identical_to_before_the_3d_engine() {
    let corpus = corpus();
    let names: Vec<&str> = corpus.iter().map(|(n, _)| n.as_str()).collect();
    let recorded: Vec<&str> = DIGESTS.iter().map(|d| d.0).collect();
    assert_eq!(
        names, recorded,
        "the corpus and the table list the same scripts"
    );
    let mut changed = Vec::new();
    let mut all = 0xcbf2_9ce4_8422_2325u64;
    for ((name, text), &(_, bare, played)) in corpus.iter().zip(DIGESTS) {
        let (b, p) = (engine_digest(text), instrument_digest(name, text));
        all = (all ^ b).wrapping_mul(0x0000_0100_0000_01b3);
        all = (all ^ p).wrapping_mul(0x0000_0100_0000_01b3);
        if (b, p) != (bare, played) {
            changed.push(format!(
                "{name}: engine 0x{b:016x} (was 0x{bare:016x}), instrument 0x{p:016x} (was \
                 0x{played:016x})"
            ));
        }
    }
    println!(
        "{} scripts, {} renders: corpus digest 0x{all:016x}, {} changed",
        corpus.len(),
        2 * corpus.len(),
        changed.len()
    );
    assert!(changed.is_empty(), "{}", changed.join("\n"));
}
