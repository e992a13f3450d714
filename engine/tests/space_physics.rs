//! 3-D physics against the closed forms of 3-D spec §7: a tensioned string's transverse and
//! longitudinal modes (§7.1, §7.2), energy with zero damping (§7.6), momentum and angular
//! momentum (§7.7), rotation invariance (§7.8), a bouncing ball's restitution (§7.9), a
//! pendulum (§7.10) and the 1-D embedding (§1.8, §7.11).

mod common;

use ressort_engine::{compile, parse, CompileOptions, Engine};

const SR: f64 = 44_100.0;

fn engine(text: &str) -> Engine {
    let parsed = parse(text);
    let errors: Vec<_> = parsed.errors().collect();
    assert!(errors.is_empty(), "{errors:#?}\n{text}");
    compile(&parsed.spec.unwrap(), &CompileOptions::at(SR))
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// `frames` samples of every output, channel-major, with `inputs` (channel-major, may be
/// empty).
fn render(e: &mut Engine, frames: usize, inputs: &[f64]) -> Vec<Vec<f64>> {
    let n = e.info().num_outputs();
    let mut out = vec![0.0; n * frames];
    let report = e.process(frames, inputs, &mut out);
    assert!(!report.tripped, "the guard tripped: {:?}", e.guard_event());
    out.chunks(frames).map(|c| c.to_vec()).collect()
}

/// The mean frequency of `x` in Hz from its upward zero crossings (linearly interpolated)
/// about its mean, first to last.
fn frequency(x: &[f64]) -> f64 {
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let mut first = None;
    let mut last = 0.0;
    let mut count = 0;
    for i in 1..x.len() {
        let (a, b) = (x[i - 1] - mean, x[i] - mean);
        if a < 0.0 && b >= 0.0 {
            let t = (i - 1) as f64 + a / (a - b);
            if first.is_none() {
                first = Some(t);
            } else {
                count += 1;
            }
            last = t;
        }
    }
    count as f64 * SR / (last - first.expect("no crossing"))
}

fn cents(f: f64, want: f64) -> f64 {
    1200.0 * (f / want).log2()
}

/// A string of `nm` moving masses between two grounds along x, spacing 1, links `spring K L`,
/// its nodes displaced at rest by `shape(k)` (a vector per node, k = 1 … nm).
fn explicit_string(nm: usize, k: f64, rest: f64, shape: impl Fn(usize) -> [f64; 3]) -> String {
    let mut t = String::from("~dim 3\n@g0 ground [0 0 0]\n");
    t += &format!("@g1 ground [{} 0 0]\n", nm + 1);
    for i in 1..=nm {
        let d = shape(i);
        t += &format!(
            "@m{i} mass 1. [{} {} {}] [0 0 0]\n",
            i as f64 + d[0],
            d[1],
            d[2]
        );
    }
    let node = |i: usize| match i {
        0 => "g0".to_string(),
        i if i == nm + 1 => "g1".to_string(),
        i => format!("m{i}"),
    };
    for i in 0..=nm {
        t += &format!("@l{i} spring @{} @{} {k} {rest}\n", node(i), node(i + 1));
    }
    t
}

/// Transverse modes of a pre-tensioned string (3-D spec §7.1): f_n = SR/π·asin(√(κ_t/M)·
/// sin(nπ/(2(N_m+1)))) with κ_t = K(1 − L/a), each in two polarisations, within 0.1 cent;
/// the longitudinal modes (§7.2) with K itself.
#[test]
fn a_tensioned_string_rings_at_its_discrete_modes() {
    let (nm, k, rest) = (40, 0.3, 0.9);
    let kt: f64 = k * (1.0 - rest);
    let want = |n: usize, stiffness: f64| {
        SR / std::f64::consts::PI
            * (stiffness.sqrt() * (n as f64 * std::f64::consts::PI / (2.0 * (nm + 1) as f64)).sin())
                .asin()
    };
    assert!(
        (want(1, kt) - 93.13).abs() < 0.01,
        "the spec's example value: {}",
        want(1, kt)
    );
    assert!((want(1, k) - 294.52).abs() < 0.01, "{}", want(1, k));
    for (n, axis, longitudinal) in [
        (1, 1, false),
        (2, 2, false),
        (3, 1, false),
        (1, 0, true),
        (2, 0, true),
    ] {
        let amp = 1e-5;
        let shape = |i: usize| {
            let mut d = [0.0; 3];
            d[axis] = amp * (n as f64 * std::f64::consts::PI * i as f64 / (nm + 1) as f64).sin();
            d
        };
        let probe = 7;
        let dir = ["[1 0 0]", "[0 1 0]", "[0 0 1]"][axis];
        let text =
            explicit_string(nm, k, rest, shape) + &format!("@out1 posOutput @m{probe} {dir}\n");
        let mut e = engine(&text);
        let out = render(&mut e, (SR * 2.5) as usize, &[]);
        let f = frequency(&out[0]);
        let w = want(n, if longitudinal { k } else { kt });
        let c = cents(f, w);
        println!(
            "{} mode {n} along {}: {f:.4} Hz, closed form {w:.4} Hz, {c:+.4} cents",
            if longitudinal {
                "longitudinal"
            } else {
                "transverse"
            },
            ["x", "y", "z"][axis]
        );
        assert!(c.abs() < 0.1, "mode {n}: {f} Hz against {w} Hz ({c} cents)");
    }
}

/// The same string written as a `string3` rings at the same modes: the generator and the
/// explicit lines are one model (§4.1).
#[test]
fn a_string3_is_its_explicit_lines() {
    let text = "~dim 3\n@s string3 42 1. 0.3 0 [0 0 0] [41 0 0] [0.9*auto]\n\
                @in1 frcInput @s_m9 [0 1 0]\n@out1 posOutput @s_m30 [0 1 0]\n";
    let mut e = engine(text);
    let mut input = vec![0.0; 44100];
    input[0] = 1e-4;
    let out = render(&mut e, 44100, &input);
    let mut lines = engine(
        &(explicit_string(40, 0.3, 0.9, |_| [0.0; 3])
            + "@in1 frcInput @m9 [0 1 0]\n@out1 posOutput @m30 [0 1 0]\n"),
    );
    let out2 = render(&mut lines, 44100, &input);
    let worst = out[0]
        .iter()
        .zip(&out2[0])
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let peak = out[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(peak > 1e-6);
    assert!(worst <= 1e-10 * peak, "worst {worst}, peak {peak}");
}

/// Energy with zero damping (3-D spec §7.6): zero-length springs and masses conserve the
/// leapfrog invariant E = ½ΣM|x^{n+1} − x^n|² + ½ΣK(d^{n+1}·d^n) to 1e-10 over 10⁶ steps;
/// springs with rest lengths (geometric nonlinearity) keep H bounded and without drift.
#[test]
fn energy_is_conserved_without_damping() {
    // A linear network: four masses, zero-length springs in a loop to two grounds.
    let text = "~dim 3\n@g ground [0 0 0]\n@h ground [3 1 0]\n\
                @a mass 1. [0.3 0.1 -0.2] [0 0 0]\n@b mass 2. [1 0.5 0.1] [0.01 0 0.02]\n\
                @c mass 1.5 [2 -0.3 0.4] [0 -0.01 0]\n@d mass 1. [2.5 1 0] [0 0 0]\n\
                @l1 spring @g @a 0.05 0\n@l2 spring @a @b 0.1 0\n@l3 spring @b @c 0.07 0\n\
                @l4 spring @c @d 0.03 0\n@l5 spring @d @h 0.09 0\n@l6 spring @a @c 0.02 0\n";
    let energy = |e: &Engine, prev: &[[f64; 3]], masses: &[f64]| -> f64 {
        let pos = |i: usize| [e.axis(0)[i], e.axis(1)[i], e.axis(2)[i]];
        let mut kin = 0.0;
        for (i, m) in masses.iter().enumerate() {
            let (now, was) = (pos(i + 2), prev[i + 2]);
            kin += 0.5 * m * (0..3).map(|c| (now[c] - was[c]).powi(2)).sum::<f64>();
        }
        let links: [(usize, usize, f64); 6] = [
            (0, 2, 0.05),
            (2, 3, 0.1),
            (3, 4, 0.07),
            (4, 5, 0.03),
            (5, 1, 0.09),
            (2, 4, 0.02),
        ];
        let mut pot = 0.0;
        for (a, b, k) in links {
            let (dn, dp) = (
                [0, 1, 2].map(|c| pos(a)[c] - pos(b)[c]),
                [0, 1, 2].map(|c| prev[a][c] - prev[b][c]),
            );
            pot += 0.5 * k * (0..3).map(|c| dn[c] * dp[c]).sum::<f64>();
        }
        kin + pot
    };
    let mut e = engine(text);
    let masses = [1.0, 2.0, 1.5, 1.0];
    let snapshot = |e: &Engine| -> Vec<[f64; 3]> {
        (0..e.axis(0).len())
            .map(|i| [e.axis(0)[i], e.axis(1)[i], e.axis(2)[i]])
            .collect()
    };
    let mut prev = snapshot(&e);
    render(&mut e, 1, &[]);
    let e0 = energy(&e, &prev, &masses);
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        render(&mut e, 999, &[]);
        prev = snapshot(&e);
        render(&mut e, 1, &[]);
        let en = energy(&e, &prev, &masses);
        worst = worst.max(((en - e0) / e0).abs());
    }
    println!("linear network: energy {e0:.6e}, largest relative drift {worst:.2e} over 10⁶ steps");
    assert!(worst < 1e-10, "{worst}");
}

/// Momentum and angular momentum of a free network with radial laws (3-D spec §7.7):
/// P = ΣM(x^{n+1} − x^n) and J = ΣM x^n × x^{n+1} are conserved to rounding.
#[test]
fn a_free_network_keeps_its_momentum_and_angular_momentum() {
    let mut t = String::from("~dim 3\n");
    let pts = [
        [0.0, 0.0, 0.0],
        [1.1, 0.1, -0.2],
        [0.4, 1.3, 0.2],
        [-0.5, 0.6, 1.0],
        [1.2, 1.1, 0.9],
        [0.2, -0.9, 0.7],
        [-1.0, -0.4, -0.3],
        [0.7, 0.3, -1.2],
    ];
    let vel = [
        [0.5, 0.0, 0.1],
        [0.0, -0.3, 0.2],
        [0.1, 0.1, -0.4],
        [-0.2, 0.3, 0.0],
        [0.0, 0.0, 0.3],
        [0.3, 0.2, -0.1],
        [-0.1, -0.2, 0.2],
        [0.2, -0.1, 0.0],
    ];
    let masses = [1.0, 2.0, 1.5, 0.7, 1.2, 0.9, 1.1, 1.3];
    for i in 0..8 {
        let (p, v) = (pts[i], vel[i]);
        t += &format!(
            "@p{i} mass {} [{} {} {}] [{} {} {}]\n",
            masses[i], p[0], p[1], p[2], v[0], v[1], v[2]
        );
    }
    let mut l = 0;
    for i in 0..8 {
        for j in (i + 1)..8 {
            if (i + j) % 3 != 0 {
                t += &format!("@l{l} springDamper @p{i} @p{j} 0.05 0.002 [0.9*auto]\n");
                l += 1;
            }
        }
    }
    let mut e = engine(&t);
    let state = |e: &Engine| -> Vec<[f64; 3]> {
        (0..8)
            .map(|i| [e.axis(0)[i], e.axis(1)[i], e.axis(2)[i]])
            .collect()
    };
    let moments = |was: &[[f64; 3]], now: &[[f64; 3]]| {
        let mut p = [0.0; 3];
        let mut j = [0.0; 3];
        for i in 0..8 {
            let (a, b, m) = (was[i], now[i], masses[i]);
            for c in 0..3 {
                p[c] += m * (b[c] - a[c]);
            }
            let cross = [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ];
            for c in 0..3 {
                j[c] += m * cross[c];
            }
        }
        (p, j)
    };
    let was = state(&e);
    render(&mut e, 1, &[]);
    let (p0, j0) = moments(&was, &state(&e));
    render(&mut e, 19_998, &[]);
    let was = state(&e);
    render(&mut e, 1, &[]);
    let (p1, j1) = moments(&was, &state(&e));
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let dp = norm([p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]]);
    let dj = norm([j1[0] - j0[0], j1[1] - j0[1], j1[2] - j0[2]]) / norm(j0);
    println!("free network over 2·10⁴ steps: |ΔP| = {dp:.2e}, |ΔJ|/|J| = {dj:.2e}");
    assert!(dp < 1e-12, "{dp}");
    assert!(dj < 1e-9, "{dj}");
}

/// Rotating the whole model (3-D spec §7.8): positions, velocities, directions rotated by Q,
/// outputs projected on the rotated directions equal the original within 10⁻⁹ of their peak.
#[test]
fn a_rotated_model_gives_the_same_projected_outputs() {
    let (s, c) = (0.3f64.sin(), 0.3f64.cos());
    let (s2, c2) = (1.1f64.sin(), 1.1f64.cos());
    // Q = Rz(0.3)·Rx(1.1).
    let rz = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
    let rx = [[1.0, 0.0, 0.0], [0.0, c2, -s2], [0.0, s2, c2]];
    let mut q = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            q[i][j] = (0..3).map(|k| rz[i][k] * rx[k][j]).sum();
        }
    }
    let rot = |v: [f64; 3]| [0, 1, 2].map(|i| (0..3).map(|k| q[i][k] * v[k]).sum::<f64>());
    let vec = |v: [f64; 3]| format!("[{:.17e} {:.17e} {:.17e}]", v[0], v[1], v[2]);
    let model = |r: &dyn Fn([f64; 3]) -> [f64; 3]| {
        format!(
            "~dim 3\n~gravity {}\n@s string3 24 1. 0.3 0.001 {} {} [0.9*auto] 'Zo=1e-5'\n\
             @sv vdampers @s 0.0003\n@gh ground {}\n@h mass 2. {} {}\n\
             @sh springDamper @gh @h 0.001 0.01 auto\n@hit contact @h [@s 0.31] 0.2 0.001 0.3\n\
             @floor planeContact @h 0.1 0.01 {} -2 0.05\n@in1 frcInput @h {}\n\
             @out1 posOutput [@s 0.7] {}\n@out2 velOutput @s_m12 {}\n@out3 distOutput @h @s_m7\n\
             @out4 frcOutput @s_m3 {}\n",
            vec(r([0.0, 0.0, -3.0])),
            vec(r([0.0, 0.0, 0.0])),
            vec(r([23.0, 0.0, 0.0])),
            vec(r([7.1, 0.05, 1.3])),
            vec(r([7.1, 0.05, 0.36])),
            vec(r([0.0, 0.0, -0.2])),
            vec(r([0.0, 0.0, 1.0])),
            vec(r([0.0, 0.0, -1.0])),
            vec(r([0.0, 1.0, 0.0])),
            vec(r([0.0, 0.3, 1.0])),
            vec(r([0.2, 0.1, 0.97])),
        )
    };
    let frames = 20_000;
    let mut input = vec![0.0; frames];
    input[0] = -0.02;
    let mut a = engine(&model(&|v| v));
    let mut b = engine(&model(&rot));
    let (oa, ob) = (
        render(&mut a, frames, &input),
        render(&mut b, frames, &input),
    );
    for ch in 0..4 {
        let peak = oa[ch].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = oa[ch]
            .iter()
            .zip(&ob[ch])
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        println!("rotated model, out{}: peak {peak:.3e}, largest difference {worst:.2e} ({:.1e} of the peak)", ch + 1, worst / peak);
        assert!(peak > 0.0, "out{} is silent", ch + 1);
        assert!(
            worst <= 1e-9 * peak,
            "out{}: {worst} against a peak of {peak}",
            ch + 1
        );
    }
}

/// A ball dropped on a plane contact bounces with the restitution of the discrete damped
/// oscillator (3-D spec §7.9), within 0.5 % for K/M ≤ 0.01: with no gravity it comes in and
/// leaves at constant speeds, whose ratio is e.
#[test]
fn a_bouncing_ball_has_the_discrete_restitution() {
    for (k, z) in [(0.001f64, 0.0005f64), (0.01, 0.001)] {
        let text = format!(
            "~dim 3\n~samplerate raw\n@b mass 1. [0 0 0.02] [0 0 -0.0001]\n\
             @f planeContact @b {k} {z} [0 0 1] 0\n@out1 velOutput @b\n@out2 posOutput @b\n"
        );
        let mut e = engine(&text);
        let out = render(&mut e, 20_000, &[]);
        let (v, x) = (&out[0], &out[1]);
        assert!(
            x.last().copied().unwrap() > 0.0 && x.iter().any(|p| *p < 0.0),
            "it bounced"
        );
        let measured = v.last().copied().unwrap() / -v[1];
        let rho = (1.0 - z).sqrt();
        let wp = ((2.0 - (k + z)) / (2.0 * rho)).acos();
        let disc = rho.powf(std::f64::consts::PI / wp);
        let err = (measured - disc).abs() / disc;
        println!(
            "K {k}, Z {z}: restitution {measured:.5}, discrete closed form {disc:.5} ({:.3} %)",
            err * 100.0
        );
        assert!(err < 0.005, "K {k} Z {z}: {measured} against {disc}");
    }
}

/// A pendulum under `~gravity` swings at f = SR/2π·acos(1 − a/(2ℓ*)) ≈ √(g/ℓ)/2π whatever
/// its mass (3-D spec §7.10).
#[test]
fn a_pendulum_swings_at_its_length_not_its_mass() {
    for m in [1.0, 7.0] {
        let text = format!(
            "~dim 3\n~gravity 9.81\n@p ground [0 0 0]\n@b mass {m} [0.01 0 -1] [0 0 0]\n\
             @l springDamper @p @b 1 0 auto\n@out1 posOutput @b [1 0 0]\n"
        );
        let mut e = engine(&text);
        let out = render(&mut e, (SR * 12.0) as usize, &[]);
        let f = frequency(&out[0]);
        // ℓ* includes the static stretch M·a/K.
        let a = 9.81 / (SR * SR);
        let l = 1.0 + m * a;
        let want = SR / (2.0 * std::f64::consts::PI) * (1.0 - a / (2.0 * l)).acos();
        println!("pendulum M = {m}: {f:.5} Hz, closed form {want:.5} Hz");
        assert!((f - want).abs() / want < 2e-3, "M {m}: {f} against {want}");
    }
}

/// The 1-D embedding (3-D spec §1.8, §7.11): a 1-D script and its 3-D rewrite (zero-length
/// springs plus vdampers, contacts with D = θ) give the same z trajectories within 10⁻¹⁰.
#[test]
fn a_1d_model_embedded_in_3d_moves_the_same_along_z() {
    let one = "@g ground 0.\n@m1 mass 1. 0. 0.\n@m2 mass 1. 0.1 0.\n@m3 mass 2. -0.2 0.\n\
               @h mass 3. 1.2 0.\n@l1 springDamper @g @m1 0.1 0.001\n@l2 springDamper @m1 @m2 0.05 0.002\n\
               @l3 springDamper @m2 @m3 0.08 0.0005\n@l4 nlSpring3 @m3 @g 0.01 0.5 0.0001\n\
               @hit contact @m2 @h 0.2 0.001 0.05\n@gh ground 2.\n@sh spring @gh @h 0.0001\n\
               @in1 frcInput @h\n@out1 posOutput @m1\n@out2 posOutput @m3\n@out3 posOutput @h\n";
    let three =
        "~dim 3\n@g ground 0.\n@m1 mass 1. 0. 0.\n@m2 mass 1. 0.1 0.\n@m3 mass 2. -0.2 0.\n\
               @h mass 3. 1.2 0.\n@l1 spring @g @m1 0.1 0\n@v1 vdamper @g @m1 0.001\n\
               @l2 spring @m1 @m2 0.05 0\n@v2 vdamper @m1 @m2 0.002\n\
               @l3 spring @m2 @m3 0.08 0\n@v3 vdamper @m2 @m3 0.0005\n\
               @l4 nlSpring3 @m3 @g 0.01 0.5 0 0\n@v4 vdamper @m3 @g 0.0001\n\
               @hit contact @m2 @h 0.2 0.001 0.05\n@gh ground 2.\n@sh spring @gh @h 0.0001 0\n\
               @in1 frcInput @h\n@out1 posOutput @m1\n@out2 posOutput @m3\n@out3 posOutput @h\n";
    let frames = 100_000;
    let mut input = vec![0.0; frames];
    // Gentle enough that the hammer never passes through what it strikes (§1.8's condition).
    input[0] = -0.002;
    let spec = parse(one).spec.unwrap();
    let mut e1 = compile(&spec, &CompileOptions::at(SR)).unwrap();
    let mut o1 = vec![0.0; 3 * frames];
    e1.process(frames, &input, &mut o1);
    let mut e3 = engine(three);
    let o3 = render(&mut e3, frames, &input);
    for ch in 0..3 {
        let a = &o1[ch * frames..(ch + 1) * frames];
        let peak = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = a
            .iter()
            .zip(&o3[ch])
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        println!(
            "1-D embedding, out{}: peak {peak:.3e}, largest difference {worst:.2e}",
            ch + 1
        );
        assert!(worst <= 1e-10 * peak.max(1.0), "out{}: {worst}", ch + 1);
    }
}

/// An `audioParam` of a 3-D script reads its own input channel, as in 1-D: the plectrum's grip
/// on in2 is 0 at rest (the sweep on in1 leaves the string still) and plucks once in2 opens.
#[test]
fn an_audio_param_of_a_3d_script_has_its_input() {
    let text = "~dim 3\n@nlK audioParam @in2\n\
                @s string3 11 1. 0.05 0.0002 [0 0 0] [10 0 0] [0.9*auto]\n\
                @in1 posInput [3 0 -0.5] [0 0 1]\n\
                @p nlPluck @in1 @s_m3 nlK 0.1 0 [0 0 1]\n\
                @out1 posOutput @s_m6\n";
    let mut e = common::engine(&common::spec(text), 48_000.0);
    assert_eq!(
        e.info().num_inputs(),
        2,
        "in1 and the audio parameter's in2"
    );
    let frames = 2_000;
    let sweep: Vec<f64> = (0..frames)
        .map(|n| -0.5 + (n as f64 / frames as f64).min(1.0))
        .collect();
    let closed = common::render(&mut e, frames, 64, &[sweep.clone(), vec![0.0; frames]]);
    let still = closed[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    e.reset();
    let open = common::render(&mut e, frames, 64, &[sweep, vec![0.05; frames]]);
    let plucked = open[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    println!("grip 0: peak {still:.3e}; grip 0.05: peak {plucked:.3e}");
    assert!(still < 1e-12 && plucked > 1e-3, "{still} {plucked}");
}
