//! Kernels of the sample loop that live in their own files, each with its equation.

pub(crate) mod links;
pub(crate) mod macros;
pub(crate) mod masses;
pub(crate) mod mesh;
#[cfg(target_arch = "x86_64")]
mod mesh_avx2;
pub(crate) mod proxies;

/// The position state of every point (spec §1.2): x, the delayed position x̃ and the force
/// accumulator F. Units: model units and per-step forces. Touched only by the audio thread.
#[derive(Clone, Debug, Default)]
pub(crate) struct Points {
    pub x: Vec<f64>,
    pub xp: Vec<f64>,
    pub f: Vec<f64>,
    /// Link forces of the longest chain of any interaction group ([`links::Group::chains`]).
    pub s: Vec<f64>,
}

/// Mesh macros with rows shorter than this run the sample loop with AVX2 rather than AVX-512.
/// The pass-by-pass mesh kernel loops over one row at a time; a row of 15 nodes is one 8-wide
/// vector and a remainder, and the 15 × 15 mesh measured 295 ns per sample with AVX2 against
/// 339 with AVX-512, while larger models gain 5–21 % from AVX-512.
const SHORT_MESH_ROW: usize = 32;

/// AVX2, when the CPU has it.
pub(crate) fn avx2() -> Option<pulp::Arch> {
    #[cfg(target_arch = "x86_64")]
    {
        pulp::x86::V3::try_new().map(pulp::Arch::V3)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

/// Whether `arch` is AVX2 (pulp's V3), which the large plates' row sweep has a loop of its
/// own for.
pub(crate) fn is_avx2(arch: pulp::Arch) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        matches!(arch, pulp::Arch::V3(_))
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = arch;
        false
    }
}

/// The instruction set a model's sample loop runs with: the best the CPU has, except AVX2 for
/// models with short mesh rows ([`SHORT_MESH_ROW`]). Every choice gives the same samples.
pub(crate) fn arch_for(macros: &macros::Macros) -> pulp::Arch {
    let short_rows = macros
        .meshes
        .iter()
        .any(|m| m.width < SHORT_MESH_ROW && m.length * m.width < mesh::ROW_SWEEP_NODES);
    match avx2() {
        Some(arch) if short_rows => arch,
        _ => pulp::Arch::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::masses::Update;
    use crate::laws::LawKind;
    use crate::{compile, parse, CompileOptions};

    /// A band of links (a string written element by element, the rows of a mesh, the links
    /// between its rows) runs as contiguous loops; the link-by-link scatter is its
    /// reference, bit for bit.
    #[test]
    fn chains_equal_the_link_by_link_scatter() {
        let mut text = forty_masses_from_g0();
        // A link out of the chain between two runs, and a nonlinear law on the same points.
        text += "@x springDamper @m3 @m30 0.05 0.\n@c contact @m10 @m20 0.05 0.001 0.\n";
        text += "@l40 springDamper @m39 @g1 0.1 0.001\n@in1 frcInput @m7\n@out1 posOutput @m25\n";
        assert!(!chain_and_scatter_agree(&text, 1));
        // Strings written from their far end (links (i + 1, i)), short and long (the long one
        // uniform), and a mesh whose links between rows are written upwards (d = 5).
        for len in [40, 100] {
            let mut text = String::from("@g0 ground 0.\n@g1 ground 0.\n");
            for i in 0..len {
                text += &format!("@m{i} mass 1. 0. 0.\n");
            }
            text += "@l0 springDamper @m0 @g0 0.1 0.001\n";
            for i in 0..len - 1 {
                text += &format!("@l{} springDamper @m{} @m{i} 0.1 0.001\n", i + 1, i + 1);
            }
            text += &format!("@e springDamper @g1 @m{} 0.1 0.001\n", len - 1);
            text += "@in1 frcInput @m7\n@out1 posOutput @m25\n";
            assert!(!chain_and_scatter_agree(&text, 1));
        }
        let (len, w) = (6, 5);
        let mut text = String::from("@g ground 0.\n");
        for i in 0..len * w {
            text += &format!("@n{i} mass 1. 0. 0.\n");
        }
        for i in 0..len * w {
            if i % w != w - 1 {
                text += &format!("@h{i} springDamper @n{i} @n{} 0.1 0.001\n", i + 1);
            }
        }
        for i in 0..(len - 1) * w {
            text += &format!("@v{i} springDamper @n{} @n{i} 0.1 0.001\n", i + w);
        }
        text += "@p springDamper @g @n0 0.1 0.001\n@in1 frcInput @n7\n@out1 posOutput @n22\n";
        chain_and_scatter_agree(&text, w as u32);
        // A 7 × 6 mesh written element by element: rows (d = 1), then the links between rows
        // (d = 6), with a corner pinned to a ground. Its rows run as one chain over all their
        // points, unless one row link reads other arguments.
        for odd in [None, Some(12)] {
            let (len, w) = (7, 6);
            let mut text = String::from("@g ground 0.\n");
            for i in 0..len * w {
                text += &format!("@n{i} mass 1. 0. 0.\n");
            }
            let mut k = 0;
            for r in 0..len {
                for c in 0..w - 1 {
                    let i = r * w + c;
                    let stiffness = if odd == Some(k) { 0.12 } else { 0.1 };
                    text += &format!("@h{k} springDamper @n{i} @n{} {stiffness} 0.001\n", i + 1);
                    k += 1;
                }
            }
            for i in 0..(len - 1) * w {
                text += &format!("@v{i} springDamper @n{i} @n{} 0.1 0.001\n", i + w);
            }
            text += "@p springDamper @g @n0 0.1 0.001\n@in1 frcInput @n8\n@out1 posOutput @n30\n";
            let merged = chain_and_scatter_agree(&text, w as u32);
            assert_eq!(merged, odd.is_none());
        }
        // Long forward bands run in tiles of TILE links: a 700-mass string, uniform or with one
        // odd link, and 7 interleaved strings (d = 7) of 515 links, whose last tile is shorter
        // than d. The strike and the output sit on either side of the tile seams.
        for (masses, d, odd) in [(700, 1, None), (700, 1, Some(300)), (522, 7, None)] {
            let mut text = String::from("@g0 ground 0.\n");
            for i in 0..masses {
                text += &format!("@m{i} mass 1. 0. 0.\n");
            }
            for i in 0..masses - d {
                let stiffness = if odd == Some(i) { 0.12 } else { 0.1 };
                text += &format!("@l{i} springDamper @m{i} @m{} {stiffness} 0.001\n", i + d);
            }
            text += "@p springDamper @g0 @m0 0.1 0.001\n@in1 frcInput @m500\n";
            text += "@out1 posOutput @m255\n";
            assert!(!chain_and_scatter_agree(&text, d as u32));
        }
    }

    /// A string written from its far end (every link (i + 1, i)) is the same string: each
    /// link's force is the exact negation and every point sums the same terms in the same
    /// order, so it plays the forward string's samples bit for bit. (Before reversed chains
    /// were recognised, four such links in a row were taken for a chain with a wrapped-around
    /// offset, and `process` panicked on an index out of range.)
    #[test]
    fn a_string_written_backwards_plays_the_same_samples() {
        let string = |backwards: bool| {
            let mut text = String::from("@g0 ground 0.\n");
            for i in 1..=100 {
                text += &format!("@n{i} mass 1. 0. 0.\n");
            }
            text += "@n101 ground 0.\n";
            for i in 0..=100 {
                let (a, b) = if backwards { (i + 1, i) } else { (i, i + 1) };
                let (a, b) = (format!("n{a}"), format!("n{b}"));
                let (a, b) = (a.replace("n0", "g0"), b.replace("n0", "g0"));
                text += &format!("@l{i} springDamper @{a} @{b} 0.1 0.001\n");
            }
            text + "@in1 frcInput @n33\n@out1 posOutput @n66\n"
        };
        let render = |text: String| {
            let spec = parse(&text).spec.expect("parses");
            let mut e = compile(&spec, &kernels_at(44_100.0)).expect("compiles");
            let mut input = vec![0.0; 4096];
            input[0] = 1.0;
            let mut out = vec![0.0; 4096];
            e.process(4096, &input, &mut out);
            assert!(e
                .interactions
                .group(LawKind::SpringDamper)
                .chains
                .iter()
                .any(|c| c.1 >= 64));
            out.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        };
        let forward = render(string(false));
        assert!(forward.iter().any(|&b| f64::from_bits(b).abs() > 1e-4));
        assert_eq!(forward, render(string(true)));
    }

    /// The compiler's band pass (`compile/bands.rs`): a mesh whose links are written in any
    /// order runs every link in a band, and plays what the mesh written row by row plays to
    /// rounding (only the order of the sums into F differs, spec §1.5). The row-by-row mesh,
    /// banded as written, keeps its script order.
    #[test]
    fn a_mesh_written_in_any_link_order_runs_in_bands() {
        let (rows, cols) = (12usize, 10usize);
        let id = |r: usize, c: usize| r * cols + c;
        let mut links = Vec::new();
        for r in 0..rows {
            for c in 0..cols - 1 {
                links.push((id(r, c), id(r, c + 1)));
            }
        }
        for r in 0..rows - 1 {
            for c in 0..cols {
                links.push((id(r, c), id(r + 1, c)));
            }
        }
        let mesh = |links: &[(usize, usize)]| {
            let mut text = String::new();
            for p in 0..rows * cols {
                let corner = (p == 0) || (p == rows * cols - 1);
                text += &if corner {
                    format!("@p{p} ground 0.\n")
                } else {
                    format!("@p{p} mass 1. 0. 0.\n")
                };
            }
            for (k, (a, b)) in links.iter().enumerate() {
                text += &format!("@l{k} springDamper @p{a} @p{b} 0.1 0.001\n");
            }
            text + "@in1 frcInput @p23\n@out1 posOutput @p77\n"
        };
        let run = |links: &[(usize, usize)]| {
            let spec = parse(&mesh(links)).spec.expect("parses");
            let mut e = compile(&spec, &kernels_at(48_000.0)).expect("compiles");
            let g = &e.interactions.group(LawKind::SpringDamper);
            let banded: u32 = g.chains.iter().map(|c| c.1).sum();
            assert_eq!(banded as usize, g.len(), "every link in a band");
            let order: Vec<(u32, u32)> = g.a.iter().copied().zip(g.b.iter().copied()).collect();
            let frames = 8192;
            let mut input = vec![0.0; frames];
            input[0] = 1.0;
            let mut out = vec![0.0; frames];
            e.process(frames, &input, &mut out);
            (out, order)
        };
        let (written, order) = run(&links);
        let as_written: Vec<(u32, u32)> =
            links.iter().map(|&(a, b)| (a as u32, b as u32)).collect();
        assert_eq!(order, as_written);
        // The same links shuffled (a fixed linear congruential sequence), some reversed.
        let mut shuffled = links.clone();
        let mut state = 12345u64;
        for i in (1..shuffled.len()).rev() {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            shuffled.swap(i, (state >> 33) as usize % (i + 1));
            if state & 1 == 1 {
                shuffled[i] = (shuffled[i].1, shuffled[i].0);
            }
        }
        let (any_order, _) = run(&shuffled);
        let peak = written.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = written
            .iter()
            .zip(&any_order)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(peak > 1e-4);
        assert!(diff <= 1e-9 * peak, "{diff:e} of {peak:e}");
    }

    /// Any network: runs of links forwards, backwards, with any offset, broken runs, rows,
    /// mixed with stray links and a contact, with shared or differing stiffness. The
    /// interaction kernels (chains, reversed chains, uniform chains, mesh rows) play what
    /// the link-by-link scatter plays, bit for bit, and nothing panics.
    #[test]
    fn any_link_layout_equals_the_scatter() {
        use proptest::prelude::*;
        let piece = (0usize..6, 1usize..12, 1usize..8, 0usize..40, any::<bool>());
        let layout = (
            8usize..60,
            proptest::collection::vec(piece, 1..8),
            any::<bool>(),
        );
        let config = ProptestConfig {
            cases: 64,
            ..ProptestConfig::default()
        };
        proptest!(config, |((n, pieces, shared) in layout)| {
            let mut text = String::from("@g ground 0.\n");
            for i in 0..n {
                text += &format!("@m{i} mass {}. 0. 0.\n", 1 + i % 2);
            }
            let mut links = Vec::new();
            for (kind, len, d, first, backwards) in pieces {
                for j in 0..len {
                    let (a, b) = match kind {
                        // A run with offset d, from `first`.
                        0..=2 => (first + j, first + j + d),
                        // Rows of width d + 2 (links within rows only).
                        3 => {
                            let w = d + 2;
                            let (r, c) = (j / (w - 1), j % (w - 1));
                            (first + r * w + c, first + r * w + c + 1)
                        }
                        // Strays.
                        _ => (first + j * 7, first + j * 3 + d),
                    };
                    let (a, b) = (a % n, b % n);
                    if a != b {
                        links.push(if backwards { (b, a) } else { (a, b) });
                    }
                }
            }
            for (i, (a, b)) in links.iter().enumerate() {
                let k = if shared { 0.1 } else { 0.05 + 0.001 * (i % 5) as f64 };
                text += &format!("@l{i} springDamper @m{a} @m{b} {k} 0.001\n");
            }
            text += &format!("@p springDamper @g @m0 0.1 0.001\n@c contact @m1 @m{} 0.05 0.001 0.\n", n - 1);
            text += &format!("@in1 frcInput @m{}\n@out1 posOutput @m{}\n", n / 3, n / 2);
            let spec = parse(&text).spec.expect("parses");
            let mut fast = compile(&spec, &kernels_at(44_100.0)).expect("compiles");
            let mut slow = fast.clone();
            scatter_only(&mut slow);
            let frames = 512;
            let mut input = vec![0.0; frames];
            input[0] = -0.01;
            let (mut a, mut b) = (vec![0.0; frames], vec![0.0; frames]);
            fast.process(frames, &input, &mut a);
            slow.process(frames, &input, &mut b);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            prop_assert_eq!(bits(&a), bits(&b));
            prop_assert_eq!(bits(fast.positions()), bits(slow.positions()));
        });
    }

    /// Plain masses (a = 2, b = −1, g = +0) run their own loop; the general update is its
    /// reference, bit for bit, also when a parameter turns a plain mass into an oscillator
    /// and back, and with gravity and −0 gravity beside them.
    #[test]
    fn plain_masses_equal_the_general_update() {
        let mut text = String::from("@K param 0.\n@g0 ground 0.\n");
        for i in 0..30 {
            text += &match i {
                7 => "@m7 osc 1. K 0. 0. 0.
"
                .to_string(),
                11 => "@m11 mass 2. 0.3 0. -0.
"
                .to_string(),
                12 => "@m12 mass 2. 0.3 0. 0.001
"
                .to_string(),
                20 => "@m20 ground 0.1
"
                .to_string(),
                // Unequal masses first (plain runs), then equal ones (uniform runs).
                _ => format!(
                    "@m{i} mass {}. 0. 0.
",
                    if i < 13 { 1 + i % 3 } else { 1 }
                ),
            };
        }
        text += "@l0 springDamper @g0 @m0 0.1 0.001
";
        for i in 0..29 {
            text += &format!(
                "@l{} springDamper @m{i} @m{} 0.1 0.001
",
                i + 1,
                i + 1
            );
        }
        text += "@in1 frcInput @m3
@out1 posOutput @m25
@out2 frcOutput @m11
";
        let spec = parse(&text).spec.expect("parses");
        let mut fast = compile(&spec, &kernels_at(44_100.0)).expect("compiles");
        let runs = |e: &crate::Engine| e.singles.runs[..e.singles.num_runs].to_vec();
        assert!(
            [Update::Plain, Update::PlainUniform]
                .iter()
                .all(|&u| runs(&fast).iter().any(|r| r.2 == u && r.1 > 4)),
            "{:?}",
            runs(&fast)
        );
        let mut general = fast.clone();
        let k = fast.param_id("K").unwrap();
        let frames = 512;
        let mut input = vec![0.0; frames];
        input[0] = -0.01;
        let (mut a, mut b) = (vec![0.0; 2 * frames], vec![0.0; 2 * frames]);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for (block, value) in [0.0, 0.02, 0.0, 0.05].into_iter().enumerate() {
            fast.set_param(k, value).unwrap();
            general.set_param(k, value).unwrap();
            fast.apply_pending_changes();
            general.apply_pending_changes();
            // m7 is point 8 (the ground g0 is point 0).
            let plain_osc = runs(&fast)
                .iter()
                .any(|r| r.2 != Update::General && (r.0..r.0 + r.1).contains(&8));
            assert_eq!(plain_osc, value == 0.0, "{:?}", runs(&fast));
            let n = general.singles.len() as u32;
            general.singles.runs[0] = (0, n, Update::General, true);
            general.singles.num_runs = 1;
            fast.process(frames, &input, &mut a);
            general.process(frames, &input, &mut b);
            assert!(a.iter().any(|v| v.abs() > 1e-6));
            assert_eq!(bits(&a), bits(&b), "block {block}");
            assert_eq!(bits(fast.positions()), bits(general.positions()));
            input[0] = 0.0;
        }
    }

    /// A long chain whose links all read the same arguments runs without argument streams;
    /// when a parameter makes one link differ it reads them link by link again. Both equal the
    /// link-by-link scatter, bit for bit.
    #[test]
    fn uniform_chains_equal_the_link_by_link_scatter() {
        let mut text = String::from(
            "@K param 0.1
@K2 param 0.1
@g0 ground 0.
@g1 ground 0.
",
        );
        for i in 0..120 {
            text += &format!(
                "@m{i} mass 1. 0. 0.
"
            );
        }
        text += "@l0 springDamper @g0 @m0 K 0.001
";
        for i in 0..119 {
            let k = if i == 60 { "K2" } else { "K" };
            text += &format!(
                "@l{} springDamper @m{i} @m{} {k} 0.001
",
                i + 1,
                i + 1
            );
        }
        text += "@l120 springDamper @m119 @g1 K 0.001
@in1 frcInput @m7
@out1 posOutput @m90
";
        let spec = parse(&text).spec.expect("parses");
        let mut chained = compile(&spec, &kernels_at(44_100.0)).expect("compiles");
        let mut reference = chained.clone();
        scatter_only(&mut reference);
        reference
            .interactions
            .group_mut(LawKind::SpringDamper)
            .uniform
            .clear();
        let k2 = chained.param_id("K2").unwrap();
        let frames = 1024;
        let mut input = vec![0.0; frames];
        input[0] = -0.01;
        let (mut a, mut b) = (vec![0.0; frames], vec![0.0; frames]);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let gains = [1.0, 1.0, 1.0, 0.7, 1.3];
        for (block, value) in [0.1, 0.15, 0.1, 0.1, 0.15].into_iter().enumerate() {
            chained.set_param(k2, value).unwrap();
            reference.set_param(k2, value).unwrap();
            // A class gain alone keeps the chain uniform.
            chained.set_class_gain(crate::ScaleClass::Stiffness, gains[block]);
            reference.set_class_gain(crate::ScaleClass::Stiffness, gains[block]);
            chained.apply_pending_changes();
            let linear = &chained.interactions.group(LawKind::SpringDamper);
            assert_eq!(linear.chains.len(), 1, "{:?}", linear.chains);
            assert!(linear.chains[0].1 as usize >= 64);
            assert_eq!(linear.uniform, [value == 0.1], "block {block}");
            chained.process(frames, &input, &mut a);
            reference.process(frames, &input, &mut b);
            assert!(a.iter().any(|v| v.abs() > 1e-6));
            assert_eq!(bits(&a), bits(&b), "block {block}");
            input[0] = 0.0;
        }
        assert_eq!(bits(chained.positions()), bits(reference.positions()));
    }

    /// Grounds g0 and g1, masses m0 … m39, and the spring-dampers from g0 along the masses
    /// to m39 (not yet to g1).
    fn forty_masses_from_g0() -> String {
        let mut text = String::from("@g0 ground 0.\n@g1 ground 0.\n");
        for i in 0..40 {
            text += &format!("@m{i} mass 1. 0. 0.\n");
        }
        text += "@l0 springDamper @g0 @m0 0.1 0.001\n";
        for i in 0..39 {
            text += &format!("@l{} springDamper @m{i} @m{} 0.1 0.001\n", i + 1, i + 1);
        }
        text
    }

    /// Options that keep a model on the kernels: small models (up to 60 points and links)
    /// would otherwise run on native code (`jit`), which these tests are not about.
    fn kernels_at(sample_rate_hz: f64) -> CompileOptions {
        CompileOptions {
            jit: false,
            ..CompileOptions::at(sample_rate_hz)
        }
    }

    /// The reference for the bands: every link one by one, adding to forces the mass pass
    /// clears (no band sets its points' forces).
    fn scatter_only(e: &mut crate::Engine) {
        for g in e.interactions.groups_mut() {
            g.chains.clear();
            g.sets.clear();
        }
        e.singles.force_set.fill(false);
        e.singles.classify();
    }

    /// A band that is the first of stage 4 to write its points' forces sets them, and their
    /// masses do not clear them; a band whose points an earlier one writes adds to them. Both
    /// give the bits of [`scatter_only`] (as every model of the tests above does).
    #[test]
    fn bands_set_the_forces_they_write_first() {
        // Returns each band's `sets`, group by group (the groups without bands left out),
        // and how many masses leave their force to a band.
        let check = |text: &str| {
            let spec = parse(text).spec.expect("parses");
            let mut e = compile(&spec, &kernels_at(48_000.0)).expect("compiles");
            let mut groups = e.interactions.clone();
            let sets: Vec<Vec<bool>> = groups
                .groups_mut()
                .filter(|g| !g.sets.is_empty())
                .map(|g| g.sets.clone())
                .collect();
            let set_masses = e.singles.force_set.iter().filter(|&&s| s).count();
            let mut reference = e.clone();
            scatter_only(&mut reference);
            let frames = 1024;
            let mut input = vec![0.0; frames];
            input[0] = -0.01;
            let (mut a, mut b) = (vec![0.0; 2 * frames], vec![0.0; 2 * frames]);
            e.process(frames, &input, &mut a);
            reference.process(frames, &input, &mut b);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert!(a.iter().any(|v| v.abs() > 1e-6));
            assert_eq!(bits(&a), bits(&b));
            assert_eq!(bits(e.forces()), bits(reference.forces()));
            (sets, set_masses)
        };
        let string =
            |extra: &str| forty_masses_from_g0() + "@l40 springDamper @m39 @g1 0.1 0.001\n" + extra;
        let io = "@in1 frcInput @m7\n@out1 posOutput @m25\n@out2 frcOutput @m25\n";
        // The string's 40 masses (its end links, to grounds, are not in the band).
        assert_eq!(check(&(string("") + io)), (vec![vec![true]], 40));
        // Links after the band, and a contact (a later group) on its points: still set.
        let after = "@x springDamper @m3 @m30 0.05 0.\n@c contact @m10 @m20 0.05 0.001 0.\n";
        assert_eq!(check(&(string(after) + io)), (vec![vec![true]], 40));
        // A band of contacts (a later group) over points the string's band wrote: it adds.
        let mut contacts = String::new();
        for i in 5..13 {
            contacts += &format!("@c{i} contact @m{i} @m{} 0.05 0.001 0.\n", i + 1);
        }
        assert_eq!(
            check(&(string(&contacts) + io)),
            (vec![vec![true], vec![false]], 40)
        );
        // A 4 × 6 mesh written element by element: its rows set every node's force, and the
        // band of links between rows (d = 6) adds to them.
        let (len, w) = (4, 6);
        let mesh = |law: &str, args: &str| {
            let mut text = String::from("@g ground 0.\n");
            for i in 0..len * w {
                text += &format!("@m{i} mass 1. 0. 0.\n");
            }
            for r in 0..len {
                for c in 0..w - 1 {
                    let i = r * w + c;
                    text += &format!("@h{i} {law} @m{i} @m{} {args}\n", i + 1);
                }
            }
            for i in 0..(len - 1) * w {
                text += &format!("@v{i} {law} @m{i} @m{} {args}\n", i + w);
            }
            text + "@p springDamper @g @m0 0.1 0.001\n"
        };
        let io = "@in1 frcInput @m7\n@out1 posOutput @m20\n@out2 frcOutput @m14\n";
        let (sets, masses) = check(&(mesh("springDamper", "0.1 0.001") + io));
        assert_eq!(sets, [vec![true, true, true, true, false]]);
        // The ground's link to the first node joins the first row's band: 24 nodes and it.
        assert_eq!(masses, len * w + 1);
        // The same mesh of nlSpring2 links, with a string of spring-dampers (an earlier
        // group) over its third row: that row's band cannot set, so no row does (the rows
        // may run as one loop); only the string's band sets.
        let mut text = mesh("nlSpring2", "0.1 0.01 0.001");
        for i in 12..17 {
            text += &format!("@s{i} springDamper @m{i} @m{} 0.05 0.001\n", i + 1);
        }
        let (sets, masses) = check(&(text + io));
        assert_eq!(sets, [vec![true], vec![false; 5]]);
        assert_eq!(masses, 6);
    }

    /// Runs `text` with its chains and with the scatter only; returns whether rows of a mesh
    /// ran as one chain.
    fn chain_and_scatter_agree(text: &str, widest: u32) -> bool {
        let spec = parse(text).spec.expect("parses");
        let mut chained = compile(&spec, &kernels_at(48_000.0)).expect("compiles");
        let bands = &chained.interactions.group(LawKind::SpringDamper).chains;
        assert!(bands.iter().any(|b| b.2 == widest), "{bands:?}");
        // Every link of these models is in a band, whichever way it is written.
        let in_bands: u32 = bands.iter().map(|b| b.1).sum();
        assert!(
            in_bands as usize + 3 >= chained.interactions.group(LawKind::SpringDamper).len(),
            "{bands:?}"
        );
        let mut reference = chained.clone();
        scatter_only(&mut reference);
        let merged = chained
            .interactions
            .group(LawKind::SpringDamper)
            .rows_uniform
            .contains(&true);
        let frames = 4096;
        let mut input = vec![0.0; frames];
        input[0] = -0.01;
        let (mut a, mut b) = (vec![0.0; frames], vec![0.0; frames]);
        chained.process(frames, &input, &mut a);
        reference.process(frames, &input, &mut b);
        assert!(a.iter().any(|v| v.abs() > 1e-6));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b));
        assert_eq!(bits(chained.positions()), bits(reference.positions()));
        merged
    }

    /// The sample loop gives the same bits whichever instruction set runs it (the baseline,
    /// AVX2 or AVX-512 through pulp, each this CPU has): every preset, 4096 samples after a
    /// strike on every input.
    #[test]
    fn every_instruction_set_gives_the_same_samples() {
        #[allow(unused_mut)]
        let mut archs: Vec<_> = super::avx2().map(|a| ("AVX2", a)).into_iter().collect();
        #[cfg(target_arch = "x86_64")]
        if let Some(v4) = pulp::x86::V4::try_new() {
            archs.push(("AVX-512", pulp::Arch::V4(v4)));
        }
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
        let mut names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "mdl"))
            .collect();
        names.sort();
        assert!(names.len() > 10);
        for path in names {
            let text = std::fs::read_to_string(&path).unwrap();
            let spec = crate::lang::parse_with_files(&text, &crate::lang::folder_files(&dir))
                .spec
                .expect("a preset parses");
            let mut plain = compile(&spec, &CompileOptions::at(48_000.0)).expect("compiles");
            plain.arch = pulp::Arch::Scalar;
            let (n_in, n_out) = (plain.info().num_inputs(), plain.info().num_outputs());
            let frames = if plain.info().num_points > 5000 {
                256
            } else {
                4096
            };
            let mut inputs = vec![0.0; n_in * frames];
            for c in 0..n_in {
                inputs[c * frames] = -0.01;
            }
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let mut want = vec![0.0; n_out * frames];
            let start = plain.clone();
            plain.process(frames, &inputs, &mut want);
            for &(name, arch) in &archs {
                let mut fast = start.clone();
                fast.arch = arch;
                let mut got = vec![0.0; n_out * frames];
                fast.process(frames, &inputs, &mut got);
                let at = format!("{} with {name}", path.display());
                assert_eq!(bits(&got), bits(&want), "{at}");
                assert_eq!(bits(fast.positions()), bits(plain.positions()), "{at}");
            }
        }
    }
}
