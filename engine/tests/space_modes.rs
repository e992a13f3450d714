//! The analyses of 3-D models against 3-D spec §6 and §7: the modes of a tensioned string
//! (§7.1, §7.2), a hanging chain about its equilibrium under gravity (§6.1, §7.10), the
//! icosphere's zero modes and first multiplets (§6.4, §7.12), and the stability limits
//! (§5.4) of a string and a membrane.

use ressort_engine::{compile, parse, CompileOptions, Engine, ScaleClass};

const SR: f64 = 44_100.0;

fn engine(text: &str) -> Engine {
    let parsed = parse(text);
    let errors: Vec<_> = parsed.errors().collect();
    assert!(errors.is_empty(), "{errors:#?}");
    compile(&parsed.spec.unwrap(), &CompileOptions::at(SR)).unwrap_or_else(|e| panic!("{e}"))
}

fn cents(f: f64, want: f64) -> f64 {
    1200.0 * (f / want).log2()
}

/// Frequencies of the modes, with multiplicities: (f, count) within `tol` relative.
fn clusters(freqs: &[f64], tol: f64) -> Vec<(f64, usize)> {
    let mut out: Vec<(f64, usize)> = Vec::new();
    for &f in freqs {
        match out.last_mut() {
            Some((g, n)) if (f - *g).abs() <= tol * g.abs().max(1e-9) => *n += 1,
            _ => out.push((f, 1)),
        }
    }
    out
}

/// The string3 of §7.1 (N_m = 40, K = 0.3, L = 0.9a): transverse modes in pairs at the
/// closed form, longitudinal modes at K, within 0.1 cent.
#[test]
fn a_tensioned_string3_has_the_closed_form_modes() {
    let mut e = engine(
        "~dim 3\n@s string3 42 1. 0.3 0 [0 0 0] [41 0 0] [0.9*auto]\n\
         @in1 frcInput @s_m20 [0 0.6 0.8]\n@out1 posOutput @s_m20 [0 0.6 0.8]\n",
    );
    let a = e.modes(None);
    assert_eq!(a.degrees_of_freedom, 40 * 3);
    let freqs: Vec<f64> = a.modes.iter().map(|m| m.frequency_hz).collect();
    let c = clusters(&freqs, 1e-9);
    let (nm, kt, k) = (40.0, 0.03f64, 0.3f64);
    let f = |n: f64, stiffness: f64| {
        SR / std::f64::consts::PI
            * (stiffness.sqrt() * (n * std::f64::consts::PI / (2.0 * (nm + 1.0))).sin()).asin()
    };
    for n in 1..=3 {
        let want = f(n as f64, kt);
        let (got, mult) = *c
            .iter()
            .min_by(|a, b| (a.0 - want).abs().total_cmp(&(b.0 - want).abs()))
            .unwrap();
        println!(
            "transverse {n}: {got:.4} Hz ×{mult}, closed form {want:.4} Hz ({:+.5} cents)",
            cents(got, want)
        );
        assert!(
            cents(got, want).abs() < 0.1 && mult == 2,
            "transverse {n}: {got} ×{mult}"
        );
        let want = f(n as f64, k);
        let (got, mult) = *c
            .iter()
            .min_by(|a, b| (a.0 - want).abs().total_cmp(&(b.0 - want).abs()))
            .unwrap();
        println!(
            "longitudinal {n}: {got:.4} Hz ×{mult}, closed form {want:.4} Hz ({:+.5} cents)",
            cents(got, want)
        );
        assert!(
            cents(got, want).abs() < 0.1 && mult == 1,
            "longitudinal {n}: {got} ×{mult}"
        );
    }
    // The input and output lean 37° off the string: they see the transverse modes.
    let strongest = a.strongest(1, 1, 20.0).unwrap();
    assert!(
        cents(strongest.frequency_hz, f(1.0, kt)).abs() < 0.1,
        "{}",
        strongest.frequency_hz
    );
}

/// A chain of 5 masses hanging under `~gravity` (3-D spec §7.10): at its equilibrium the
/// tension of each link is the weight below it, and the swing modes are 0.572, 1.325, 2.114,
/// 2.967 and 3.963 Hz, each doubly degenerate.
#[test]
fn a_hanging_chain_swings_at_its_equilibrium_modes() {
    let mut text = String::from("~dim 3\n~gravity 9.81\n@top ground [0 0 0]\n");
    for i in 1..=5 {
        text += &format!("@c{i} mass 1. [0 0 {}] [0 0 0]\n", -0.2 * i as f64);
    }
    text += "@l1 spring @top @c1 0.5 auto\n";
    for i in 2..=5 {
        text += &format!("@l{i} spring @c{} @c{i} 0.5 auto\n", i - 1);
    }
    text += "@in1 frcInput @c5 [1 0 0]\n@out1 posOutput @c5 [1 0 0]\n";
    let mut e = engine(&text);
    let a = e.modes(None);
    let freqs: Vec<f64> = a.modes.iter().map(|m| m.frequency_hz).collect();
    let c = clusters(&freqs, 1e-6);
    let want = [0.572, 1.325, 2.114, 2.967, 3.963];
    for (k, w) in want.iter().enumerate() {
        let (got, mult) = c[k];
        println!(
            "hanging chain swing {}: {got:.4} Hz ×{mult} (spec {w} Hz)",
            k + 1
        );
        assert!(
            (got - w).abs() < 0.002 * w && mult == 2,
            "swing {}: {got} ×{mult}",
            k + 1
        );
    }
}

/// An icosphere (3-D spec §7.12): free with L = auto it has exactly 6 zero modes, pinned at
/// its pole 3, at its crown none; free at S = 2, K = 0.1 its first nonzero cluster is the
/// 5-fold ℓ = 2 multiplet at 476.0 Hz, then 527.5 Hz ×3; on its crown 20.6 Hz ×2.
#[test]
fn an_icosphere_has_its_zero_modes_and_multiplets() {
    let zero_modes = |fix: &str| -> (usize, Vec<(f64, usize)>) {
        let mut e = engine(&format!(
            "~dim 3\n@b icosphere 2 1. 0.1 0 [0 0 0] 10 auto 'fix={fix}'\n\
             @in1 frcInput @b_m1\n@out1 posOutput @b_m40 [1 0 0]\n"
        ));
        let a = e.modes(None);
        let freqs: Vec<f64> = a.modes.iter().map(|m| m.frequency_hz).collect();
        let zero = freqs.iter().filter(|f| f.abs() < 1e-3).count();
        let nonzero: Vec<f64> = freqs.into_iter().filter(|f| f.abs() >= 1e-3).collect();
        (zero, clusters(&nonzero, 2e-4))
    };
    let (free, c) = zero_modes("none");
    println!("free icosphere: {free} zero modes, then {:?}", &c[..3]);
    assert_eq!(free, 6);
    assert!((c[0].0 - 476.0).abs() < 0.1 && c[0].1 == 5, "{:?}", c[0]);
    assert!((c[1].0 - 527.5).abs() < 0.1 && c[1].1 == 3, "{:?}", c[1]);
    let (pole, _) = zero_modes("pole");
    println!("pinned at its pole: {pole} zero modes");
    assert_eq!(pole, 3);
    let (crown, c) = zero_modes("crown");
    println!("on its crown: {crown} zero modes, then {:?}", &c[..4]);
    assert_eq!(crown, 0);
    assert!((c[0].0 - 20.6).abs() < 0.1 && c[0].1 == 2, "{:?}", c[0]);
}

/// The stability rule in 3-D (§5.4 rule (b)): a string's interior points carry
/// 2·(K + 2Z) per neighbour, so K + 2Z + Z_o/2 < M; the exact limit of a tensioned string is
/// set by its longitudinal waves (K, not κ_t).
#[test]
fn the_stability_rule_counts_each_link_by_its_largest_eigenvalue() {
    let mut e = engine(
        "~dim 3\n@s string3 20 1. 0.3 0.01 [0 0 0] [19 0 0] [0.5*auto]\n@out1 posOutput @s_m5\n",
    );
    let report = e.stability_numbers();
    let worst = report
        .masses
        .iter()
        .map(|m| m.coupled_load())
        .fold(0.0, f64::max);
    // (K + 2Z)·4 / 4M for an interior node.
    let want = (0.3 + 2.0 * 0.01) * 4.0 / 4.0;
    assert!((worst - want).abs() < 1e-12, "{worst} vs {want}");
    // The exact limit: the largest Stiffness gain keeping 4M − K − 2Z positive definite.
    let ex = e.exact_stability();
    assert!(ex.applies());
    let limit = ex.max_stiffness(1.0).unwrap();
    // Longitudinal: λ_max = 4K sin²(πN_m/(2(N_m+1))) plus the damping's 2·4Z sin²(…).
    let s2 = (std::f64::consts::PI * 18.0 / (2.0 * 19.0)).sin().powi(2);
    let exact = (4.0 - 2.0 * 4.0 * 0.01 * s2) / (4.0 * 0.3 * s2);
    println!("string stability: Gershgorin load {worst:.4}, exact Stiffness limit ×{limit:.4} (closed form ×{exact:.4})");
    assert!((limit - exact).abs() < 1e-6 * exact, "{limit} vs {exact}");
    e.set_class_gain(ScaleClass::Stiffness, 1.0);
}
