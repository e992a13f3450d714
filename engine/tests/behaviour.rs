//! Engine behaviour: block equivalence, reset, determinism, parameters, the guard, motion
//! buffers, stability analysis and compile errors.

mod common;

use common::{engine, hash_f64s, impulse, render};
use ressort_engine::{
    compile, reference, CompileErrorKind, CompileOptions, Endpoint, Expr, Func, GuardKind, Law,
    LawKind, MacroKind, ModelBuilder, MotionStore, ScaleClass, StabilityWarning,
};
use std::sync::Arc;

/// Deterministic excitation for a model: an impulse of −0.01 on in1 (spec §7.10), slow
/// sinusoids on position inputs and slow modulation of audio-rate parameters around their
/// defaults (the engine adds the default to the input).
fn excitation(e: &ressort_engine::Engine, frames: usize) -> Vec<Vec<f64>> {
    use ressort_engine::InputUse;
    e.info()
        .inputs
        .iter()
        .enumerate()
        .map(|(c, uses)| match uses.first() {
            Some(InputUse::Force(_)) if c == 0 => impulse(-0.01, frames),
            Some(InputUse::Force(_)) => vec![0.0; frames],
            Some(InputUse::Position(_)) => (0..frames)
                .map(|n| 0.05 * (n as f64 * 0.001 * (c + 1) as f64).sin())
                .collect(),
            Some(InputUse::Param(_)) => (0..frames)
                .map(|n| 0.2 * (n as f64 * 0.0003 * (c + 1) as f64).sin())
                .collect(),
            None => vec![0.0; frames],
        })
        .collect()
}

#[test]
fn one_block_equals_sample_by_sample_bit_for_bit() {
    for (name, spec) in reference::all() {
        let frames = if name == "chladni_150" { 300 } else { 3000 };
        let mut a = engine(&spec, 48_000.0);
        let input = excitation(&a, frames);
        let whole = render(&mut a, frames, frames, &input);
        for block in [1, 7, 333] {
            let mut b = engine(&spec, 48_000.0);
            let pieces = render(&mut b, frames, block, &input);
            assert_eq!(
                whole, pieces,
                "{name}: block {block} differs from one block"
            );
            assert_eq!(a.positions(), b.positions(), "{name}: state differs");
        }
        assert!(
            whole.iter().flatten().any(|v| *v != 0.0),
            "{name}: excitation produced nothing"
        );
    }
}

#[test]
fn reset_restores_the_initial_state_exactly() {
    for (name, spec) in reference::all() {
        let frames = if name == "chladni_150" { 200 } else { 2000 };
        let mut e = engine(&spec, 44_100.0);
        let x0 = e.positions().to_vec();
        let xp0 = e.delayed_positions().to_vec();
        let input = excitation(&e, frames);
        let first = render(&mut e, frames, 64, &input);
        e.reset();
        assert_eq!(e.positions(), &x0[..], "{name}: positions after reset");
        assert_eq!(
            e.delayed_positions(),
            &xp0[..],
            "{name}: delayed after reset"
        );
        assert!(
            e.forces().iter().all(|f| *f == 0.0),
            "{name}: forces after reset"
        );
        let second = render(&mut e, frames, 64, &input);
        assert_eq!(first, second, "{name}: render after reset differs");
    }
}

/// FNV-1a of the first 4096 output samples of each reference model at 44.1 kHz. A change of
/// these values is a change of the engine's numerics: check the physics tests, then update.
const DETERMINISM: [(&str, u64); 7] = [
    ("string_1000", 0x0145164e99b340f9),
    ("string_1000_expanded", 0xae3e7e7bcae8120b),
    ("mesh_15x15", 0x97662210c8507609),
    ("mesh_25x20", 0x7f5134ddbc354eaa),
    ("fretted_string", 0x077a366bccced988),
    ("chladni_150", 0x9d2e3c4662505908),
    ("hammer_oscillator", 0xda297d49f435515e),
];

#[test]
fn determinism_hash() {
    let mut report = String::new();
    let mut mismatch = false;
    for (name, spec) in reference::all() {
        let frames = if name == "chladni_150" { 512 } else { 4096 };
        let mut e = engine(&spec, 44_100.0);
        let input = excitation(&e, frames);
        let out = render(&mut e, frames, 128, &input);
        let h = hash_f64s(out.iter().flatten());
        let expected = DETERMINISM.iter().find(|(n, _)| *n == name).map(|p| p.1);
        report.push_str(&format!("    (\"{name}\", {h:#018x}),\n"));
        mismatch |= expected != Some(h);
    }
    assert!(!mismatch, "determinism hashes changed:\n{report}");
}

#[test]
fn control_parameters_change_without_recompiling() {
    // Raising K of the hammer oscillator raises its pitch: more zero crossings.
    let spec = {
        let mut b = ModelBuilder::new();
        b.param("K", 0.01);
        b.osc("o", 1.0, "K", 0.0, 1.0, 0.0);
        b.pos_output(1, Endpoint::label("o"));
        b.build()
    };
    let crossings = |v: &[f64]| v.windows(2).filter(|w| w[0] * w[1] < 0.0).count();
    let mut e = engine(&spec, 44_100.0);
    let low = render(&mut e, 4410, 441, &[]);
    let id = e.param_id("K").unwrap();
    e.set_param(id, 0.04).unwrap();
    let high = render(&mut e, 4410, 441, &[]);
    let ratio = crossings(&high[0]) as f64 / crossings(&low[0]) as f64;
    assert!(
        (ratio - 2.0).abs() < 0.1,
        "K × 4 should double the pitch, ratio {ratio}"
    );
    assert!(e.set_param(id, f64::NAN).is_err());
    assert_eq!(e.param(id), Some(0.04));
}

#[test]
fn expressions_are_evaluated_with_current_parameters() {
    // osc K = [stiffness + sqrt(kScale/3)] must equal a constant osc with the same value.
    let mut b = ModelBuilder::new();
    b.param("stiffness", 0.02).param("kScale", 0.0003);
    let k = Expr::param("stiffness")
        + Expr::call(Func::Sqrt, vec![Expr::param("kScale") / Expr::Num(3.0)]);
    b.osc("o", 1.0, k, 0.0, 1.0, 0.0);
    b.pos_output(1, Endpoint::label("o"));
    let a = render(&mut engine(&b.build(), 48_000.0), 1000, 100, &[]);
    let mut b = ModelBuilder::new();
    b.osc("o", 1.0, 0.02 + (0.0003f64 / 3.0).sqrt(), 0.0, 1.0, 0.0);
    b.pos_output(1, Endpoint::label("o"));
    let c = render(&mut engine(&b.build(), 48_000.0), 1000, 100, &[]);
    assert_eq!(a, c);
}

#[test]
fn audio_rate_parameters_follow_their_input_every_sample() {
    // Stability oscillator (tutorial 8): K is audio-rate on in2. Switching K from 0.01 to 0.04
    // mid-block changes the recurrence at exactly that sample.
    let spec = {
        let mut b = ModelBuilder::new();
        b.raw();
        b.audio_param("K", 2);
        b.osc("o", 1.0, "K", 0.0, 1.0, 0.0);
        b.pos_output(1, Endpoint::label("o"));
        b.build()
    };
    let frames = 100;
    let k: Vec<f64> = (0..frames)
        .map(|n| if n < 50 { 0.01 } else { 0.04 })
        .collect();
    let out = render(
        &mut engine(&spec, 44_100.0),
        frames,
        frames,
        &[vec![0.0; frames], k],
    );
    // Reproduce by hand: X = (2 − K)X − X̃.
    let (mut x, mut xp) = (1.0f64, 1.0f64);
    for n in 0..frames {
        let kk = if n < 50 { 0.01 } else { 0.04 };
        let next = (2.0 - kk) * x + (0.0 - 1.0) * xp;
        xp = x;
        x = next;
        assert!(
            (out[0][n] - x).abs() < 1e-13,
            "sample {n}: {} vs {x}",
            out[0][n]
        );
    }
}

/// `@K audioParam @in2 0.01`: K is 0.01 + in2 at every sample, so a silent input gives the
/// default and a connected one modulates around it; the value is the default before the first
/// sample too (stability analysis, `param`).
#[test]
fn audio_rate_parameters_are_their_default_plus_their_input() {
    let spec = {
        let mut b = ModelBuilder::new();
        b.raw();
        b.audio_param_with_default("K", 2, 0.01);
        b.osc("o", 1.0, "K", 0.0, 1.0, 0.0);
        b.pos_output(1, Endpoint::label("o"));
        b.build()
    };
    let mut e = engine(&spec, 44_100.0);
    let id = e.param_id("K").unwrap();
    assert_eq!(e.param(id), Some(0.01));
    assert_eq!(e.info().params[0].default, 0.01);
    let frames = 100;
    // Silent for 50 samples, then +0.03: K = 0.01, then 0.04.
    let k: Vec<f64> = (0..frames)
        .map(|n| if n < 50 { 0.0 } else { 0.03 })
        .collect();
    let out = render(&mut e, frames, 32, &[vec![0.0; frames], k]);
    assert!((e.param(id).unwrap() - 0.04).abs() < 1e-15);
    let (mut x, mut xp) = (1.0f64, 1.0f64);
    for n in 0..frames {
        let kk = if n < 50 { 0.01 } else { 0.01 + 0.03 };
        let next = (2.0 - kk) * x - xp;
        xp = x;
        x = next;
        assert!((out[0][n] - x).abs() < 1e-13, "sample {n}");
    }
    // The same model from text, with the input left out of the call entirely.
    let parsed = ressort_engine::parse(
        "~samplerate raw\n@K audioParam @in2 0.01\n@o osc 1 K 0 1 0\n@out1 posOutput @o\n",
    );
    assert_eq!(parsed.spec.as_ref(), Some(&spec));
}

/// A membrane struck on in1 and heard at (lX, 0.6), lX an `audioParam` on in2 with `default`.
fn listening_point(default: f64) -> ressort_engine::Engine {
    let text = format!(
        "@lX audioParam @in2 {default}\n@lY audioParam @in3 0.6\n\
         @m closedMesh 12 12 1 0.1 0.001 0 0\n@in1 frcInput [@m 0.8 0.7]\n\
         @out1 posOutput [@m lX lY]\n"
    );
    let spec = ressort_engine::parse(&text).spec.expect("valid script");
    engine(&spec, 48_000.0)
}

/// `set_param` on an `audioParam` sets its default: a model compiled at 0.2 and set to 0.7
/// renders bit for bit what the model written with 0.7 renders, with its input silent or
/// modulating around the new centre, in one block or sample by sample.
#[test]
fn setting_an_audio_rate_parameter_moves_its_default() {
    let frames = 3000;
    let lx_signal: Vec<f64> = (0..frames)
        .map(|n| 0.05 * (n as f64 * 0.002).sin())
        .collect();
    for inputs in [
        vec![impulse(-0.01, frames)],
        vec![impulse(-0.01, frames), lx_signal],
    ] {
        let mut written = listening_point(0.7);
        let expected = render(&mut written, frames, frames, &inputs);
        let mut set = listening_point(0.2);
        let id = set.param_id("lX").unwrap();
        assert_eq!(set.param(id), Some(0.2));
        set.set_param(id, 0.7).unwrap();
        // The new default is the value until the next sample reads the input.
        assert_eq!(set.param(id), Some(0.7));
        assert_eq!(set.info().params[id.0 as usize].default, 0.2);
        let got = render(&mut set, frames, 1, &inputs);
        assert_eq!(hash_f64s(&got[0]), hash_f64s(&expected[0]));
        assert_eq!(got, expected);
        // And the old default would not have done.
        let mut old = listening_point(0.2);
        assert_ne!(render(&mut old, frames, frames, &inputs), expected);
    }
    assert!(listening_point(0.3).info().params[0].coordinate);
    let k = ressort_engine::parse("@K param 0.1\n@m mass 1 0 0\n@g ground 0\n@s spring @m @g K\n");
    let k = engine(&k.spec.unwrap(), 48_000.0);
    assert!(!k.info().params[0].coordinate);
}

/// A default changed between blocks acts from the next block's first sample, as a control
/// parameter does: blocks of 64 and single samples agree bit for bit.
#[test]
fn an_audio_rate_default_changes_at_the_block_boundary() {
    let frames = 2048;
    let inputs = [impulse(-0.01, frames)];
    let run = |block: usize| {
        let mut e = listening_point(0.3);
        let id = e.param_id("lX").unwrap();
        let mut out = vec![0.0; frames];
        let mut buf = vec![0.0; block];
        for start in (0..frames).step_by(block) {
            // Change every 512 samples; a repeated value changes nothing.
            e.set_param(id, 0.3 + 0.1 * (start / 512) as f64).unwrap();
            e.process(block, &inputs[0][start..start + block], &mut buf);
            out[start..start + block].copy_from_slice(&buf);
        }
        out
    };
    let (a, b) = (run(64), run(1));
    assert_eq!(a, b);
    let mut fixed = listening_point(0.3);
    let c = render(&mut fixed, frames, frames, &inputs);
    assert_eq!(a[..512], c[0][..512]);
    assert_ne!(a[512..], c[0][512..]);
}

#[test]
fn class_gain_scales_every_stiffness() {
    // A stiffness gain of 4 on a string doubles its pitch (K ∝ f² for low modes).
    let spec = reference::mesh_15x15();
    let mut a = engine(&spec, 44_100.0);
    let mut b = engine(&spec, 44_100.0);
    b.set_class_gain(ScaleClass::Stiffness, 4.0);
    let mut c = engine(&spec, 44_100.0);
    c.set_class_gain(ScaleClass::Stiffness, 1.0);
    let input = excitation(&a, 2000);
    let ra = render(&mut a, 2000, 100, &input);
    let rb = render(&mut b, 2000, 100, &input);
    let rc = render(&mut c, 2000, 100, &input);
    assert_eq!(ra, rc, "a gain of 1 changes nothing");
    assert_ne!(ra, rb);
    assert_eq!(b.class_gain(ScaleClass::Stiffness), 4.0);
}

/// The guard holds the outputs to the position limit and the points to 10⁸ times it: a hammer
/// hung on a soft spring, pushed away by a steady force to 2·10⁵ units while the output (a
/// separate oscillator) rests, plays on; the same push with the outputs on the hammer trips,
/// and so does a point pushed past the point limit.
#[test]
fn a_point_pushed_far_by_a_steady_force_trips_only_when_heard_or_beyond_the_point_limit() {
    let spec = |heard: bool| {
        let mut b = ModelBuilder::new();
        b.raw();
        b.ground("g", 0.0);
        b.mass("h", 1.0, 0.0, 0.0);
        b.spring_damper("s", Endpoint::label("g"), Endpoint::label("h"), 1e-4, 0.01);
        b.osc("o", 1.0, 0.01, 0.001, 0.0, 0.0);
        b.frc_input(1, Endpoint::label("h"));
        b.pos_output(1, Endpoint::label(if heard { "h" } else { "o" }));
        b.build()
    };
    // F/K = 20 / 1e-4 = 2·10⁵: twenty times the output limit, far inside the point limit.
    let push = vec![vec![20.0; 40_000]];
    let mut e = engine(&spec(false), 44_100.0);
    assert_eq!(e.point_limit(), 1e12);
    render(&mut e, 40_000, 512, &push);
    assert_eq!(
        e.guard_event(),
        None,
        "an unheard point far away is not a blow-up"
    );
    let h = e.info().find_point("h").expect("the hammer");
    assert!(e.positions()[h] > 1.5e5, "{}", e.positions()[h]);

    let mut heard = engine(&spec(true), 44_100.0);
    render(&mut heard, 40_000, 512, &push);
    let ev = heard
        .guard_event()
        .expect("a heard point beyond the limit trips");
    assert_eq!((ev.kind, ev.output), (GuardKind::Runaway, Some(0)));

    let mut beyond = engine(&spec(false), 44_100.0);
    beyond.set_position_limit(1e-4); // points to 10⁴
    render(&mut beyond, 40_000, 512, &push);
    let ev = beyond
        .guard_event()
        .expect("a point beyond the point limit trips");
    assert_eq!((ev.kind, ev.output), (GuardKind::Runaway, None));
}

#[test]
fn guard_silences_an_exploding_model_until_reset() {
    // K/M = 5 > 4: numerically unstable (spec §5.1).
    let spec = {
        let mut b = ModelBuilder::new();
        b.raw();
        b.osc("o", 1.0, 5.0, 0.0, 0.001, 0.0);
        b.pos_output(1, Endpoint::label("o"));
        b.build()
    };
    let mut e = engine(&spec, 44_100.0);
    let out = render(&mut e, 20_000, 512, &[]);
    assert!(out[0]
        .iter()
        .all(|v| v.is_finite() && v.abs() <= e.position_limit()));
    let ev = e.guard_event().expect("the guard must trip");
    assert_eq!(ev.kind, GuardKind::Runaway);
    assert!(out[0][ev.sample as usize..].iter().all(|v| *v == 0.0));
    // Still silent on later blocks.
    let later = render(&mut e, 1000, 100, &[]);
    assert!(later[0].iter().all(|v| *v == 0.0));
    e.reset();
    assert!(!e.is_tripped());
    let again = render(&mut e, 10, 10, &[]);
    assert_ne!(again[0][1], 0.0);
    // The stability analysis predicted it.
    let report = e.stability();
    assert!(!report.is_stable());
    assert_eq!(report.violations().next().unwrap().label, "o");
}

#[test]
fn non_finite_inputs_count_as_silence() {
    let spec = reference::hammer_oscillator();
    let mut e = engine(&spec, 44_100.0);
    let bad = vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY, f64::NAN];
    let out = render(&mut e, 4, 4, &[bad]);
    assert!(out.iter().flatten().all(|v| v.is_finite()));
    assert!(!e.is_tripped());
}

#[test]
fn odd_block_shapes_are_harmless() {
    let spec = reference::hammer_oscillator();
    let mut e = engine(&spec, 44_100.0);
    // Zero frames, missing input channels, too few output channels.
    assert_eq!(e.process(0, &[], &mut []).simulated, 0);
    let mut one = vec![0.0; 16];
    assert_eq!(e.process(16, &[], &mut one).simulated, 16);
    let mut ragged = vec![0.0; 17];
    e.process(16, &[0.0; 5], &mut ragged);
}

#[test]
fn motion_buffers_are_written_on_the_first_sample_and_every_interval() {
    let mut b = ModelBuilder::new();
    b.raw();
    b.begin_scope("pair");
    b.mass("a", 1.0, 0.5, 0.01);
    b.begin_scope("both");
    b.mass("b", 1.0, -0.5, 0.0);
    b.end_scope("pair");
    b.macro_1d("s", MacroKind::String, 4, 1.0, 0.1, 0.0);
    b.end_scope("both");
    b.pos_input(1, 0.25);
    let spec = b.build();
    let mut e = compile(
        &spec,
        &CompileOptions {
            sample_rate_hz: 44_100.0,
            motion_interval: 10,
            ..CompileOptions::default()
        },
    )
    .unwrap();
    let store = Arc::new(MotionStore::new(e.info().num_points));
    e.set_motion_store(Some(Arc::clone(&store)));
    let mut z = vec![0.0; store.len()];
    assert_eq!(store.read(&mut z), None);
    e.process(1, &[0.3], &mut []);
    assert_eq!(store.frames_written(), 1);
    store.read(&mut z).unwrap();
    // Generic order: single masses, macro nodes, avatars (spec §6.2).
    assert_eq!(z.len(), 2 + 4 + 1);
    assert_eq!(z[0], e.positions()[0]);
    assert_eq!(z[6], 0.3, "the avatar follows its input");
    e.process(25, &[0.3; 25], &mut []);
    assert_eq!(store.frames_written(), 3, "frames at samples 0, 10 and 20");
    // Named buffers: nested and overlapping scopes (spec §3.10).
    let layout = &e.info().motion;
    assert_eq!(layout.named("pair").unwrap().members, vec![0, 1]);
    assert_eq!(layout.named("both").unwrap().members, vec![1, 2, 3, 4, 5]);
    let mut named = vec![0.0; 2];
    store
        .read_named(layout.named("pair").unwrap(), &mut z, &mut named)
        .unwrap();
    assert_eq!(named, vec![z[0], z[1]]);
    // Detached: no more frames.
    e.set_motion_store(None);
    e.process(50, &[0.3; 50], &mut []);
    assert_eq!(store.frames_written(), 3);
}

/// Stage 7 runs on its own samples whatever the block sizes: with R = 7, after every block of
/// a ragged sequence the store holds the positions of the last sample n with n % 7 = 0, and
/// as many frames as such samples.
#[test]
fn motion_frames_land_on_their_samples_in_any_block_sizes() {
    let spec = reference::string_1000();
    let options = CompileOptions {
        sample_rate_hz: 44_100.0,
        motion_interval: 7,
        ..CompileOptions::default()
    };
    let mut plain = compile(&spec, &options).unwrap();
    let mut watched = plain.clone();
    let store = Arc::new(MotionStore::new(watched.info().num_points));
    watched.set_motion_store(Some(Arc::clone(&store)));
    let n_in = plain.info().num_inputs();
    let n_out = plain.info().num_outputs();
    let points = plain.info().num_points;
    // The positions after every sample, one sample at a time.
    let total = 200;
    let mut history = Vec::new();
    let mut out = vec![0.0; n_out];
    for n in 0..total {
        let mut input = vec![0.0; n_in];
        if n == 0 && n_in > 0 {
            input[0] = -0.01;
        }
        plain.process(1, &input, &mut out);
        history.push(plain.positions()[..points].to_vec());
    }
    let mut done = 0;
    let mut frame = vec![0.0; store.len()];
    for len in [1, 3, 11, 7, 6, 1, 20, 64, 13, 74] {
        let mut input = vec![0.0; n_in * len];
        if done == 0 && n_in > 0 {
            input[0] = -0.01;
        }
        let mut out = vec![0.0; n_out * len];
        watched.process(len, &input, &mut out);
        done += len;
        let last_write = (done - 1) / 7 * 7;
        assert_eq!(
            store.frames_written() as usize,
            last_write / 7 + 1,
            "after {done}"
        );
        store.read(&mut frame).unwrap();
        assert_eq!(frame, history[last_write], "after {done} samples");
    }
    assert_eq!(done, total);
}

#[test]
fn stability_report_names_masses_and_structures() {
    // A string with K/M = 0.1 passes everything.
    let mut e = engine(&reference::string_1000(), 44_100.0);
    let r = e.stability();
    assert!(r.is_stable());
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    let worst = r.worst().unwrap();
    // An interior string node: K_eq = 2K, Z_eq = 2Z, margin 4 − (0.2 + 0.004).
    assert!(worst.label.starts_with("s["), "{}", worst.label);
    assert!(worst.k_eq >= 0.2 && worst.margin() < 3.8);

    // A mesh with K/M = 0.6 passes the per-mass rule (4K = 2.4 < 4) but not the stricter
    // mesh limit 2K + 4Z + Zo/2 < M.
    let mut b = ModelBuilder::new();
    b.mesh("me", MacroKind::CornerMesh, 8, 8, 1.0, 0.6, 0.001);
    let r = engine(&b.build(), 44_100.0).stability();
    assert!(r.is_stable());
    assert!(r
        .warnings
        .iter()
        .any(|w| matches!(w, StabilityWarning::StructureLimit { label, .. } if label == "me")));

    // Unbounded nonlinear springs are flagged; bounded ones count at 3k − 2s.
    let mut b = ModelBuilder::new();
    b.raw();
    b.mass("m", 1.0, 0.0, 0.0).ground("g", 0.0);
    b.interaction(
        "n3",
        Law::new(LawKind::NlSpring3, [0.1.into(), 2.0.into(), 0.0.into()]),
        Endpoint::label("g"),
        Endpoint::label("m"),
    );
    b.interaction(
        "nb",
        Law::new(
            LawKind::NlSpringDamper,
            [0.03.into(), 0.005.into(), 0.8.into(), 0.0002.into()],
        ),
        Endpoint::label("g"),
        Endpoint::label("m"),
    );
    let r = engine(&b.build(), 44_100.0).stability();
    assert!(r.warnings.iter().any(|w| matches!(
        w,
        StabilityWarning::Unbounded {
            keyword: "nlSpring3",
            ..
        }
    )));
    let m = &r.masses[0];
    assert!(
        (m.k_eq - (0.1 + 3.0 * 0.8 - 2.0 * 0.03)).abs() < 1e-12,
        "{}",
        m.k_eq
    );
    assert!((m.z_eq - (0.0002 + 0.3 * 0.8)).abs() < 1e-12, "{}", m.z_eq);

    // Scaling: at 22.05 kHz the per-step K quadruples and the string interior load grows.
    let mut lo = engine(&reference::string_1000(), 22_050.0);
    let l = lo.stability().worst().unwrap().k_eq;
    assert!((l / worst.k_eq - 4.0).abs() < 0.05);
}

#[test]
fn compile_errors_are_collected_with_labels() {
    let mut b = ModelBuilder::new();
    b.param("K", 0.1);
    b.macro_1d("s", MacroKind::String, 10, 1.0, "K", "Zz"); // undefined name
    b.mass("s", 1.0, 0.0, 0.0); // duplicate label
    b.spring_damper(
        "l1",
        Endpoint::label("s"),
        Endpoint::label("nowhere"),
        0.1,
        0.0,
    );
    b.spring_damper(
        "l2",
        Endpoint::at2("s", 0.1, 0.2),
        Endpoint::at("K", 0.5),
        0.1,
        0.0,
    );
    b.mass("bad", 0.0, 0.0, 0.0); // M must be > 0
    b.pos_output(1, Endpoint::label("l1")); // not a point
    let errors = compile(&b.build(), &CompileOptions::default())
        .unwrap_err()
        .0;
    let kinds: Vec<&CompileErrorKind> = errors.iter().map(|e| &e.kind).collect();
    let has = |f: &dyn Fn(&CompileErrorKind) -> bool| kinds.iter().any(|k| f(k));
    assert!(has(
        &|k| matches!(k, CompileErrorKind::UndefinedName(n) if n == "Zz")
    ));
    assert!(has(&|k| matches!(
        k,
        CompileErrorKind::DuplicateLabel { .. }
    )));
    assert!(has(
        &|k| matches!(k, CompileErrorKind::UndefinedElement(t) if t == "nowhere")
    ));
    assert!(has(&|k| matches!(
        k,
        CompileErrorKind::WrongCoordinateCount {
            expected: 1,
            found: 2,
            ..
        }
    )));
    assert!(has(
        &|k| matches!(k, CompileErrorKind::NotAMacro(t) if t == "K")
    ));
    assert!(has(&|k| matches!(k, CompileErrorKind::InvalidValue { .. })));
    assert!(has(&|k| matches!(
        k,
        CompileErrorKind::NotAPoint {
            found: "an interaction",
            ..
        }
    )));
    let text = errors
        .iter()
        .map(|e| e.to_string())
        .collect::<Vec<_>>()
        .join("\n");
    assert!(text.contains("@s: undefined name `Zz`"), "{text}");

    // Bad sample rates and absurd sizes.
    let spec = reference::hammer_oscillator();
    for sr in [0.0, -44_100.0, f64::NAN, f64::INFINITY, 1e12] {
        let e = compile(&spec, &CompileOptions::at(sr)).unwrap_err();
        assert!(matches!(
            e.0[0].kind,
            CompileErrorKind::InvalidSampleRate(_)
        ));
    }
    let mut b = ModelBuilder::new();
    b.mesh("huge", MacroKind::Mesh, 100_000, 100_000, 1.0, 0.1, 0.0);
    let e = compile(&b.build(), &CompileOptions::default()).unwrap_err();
    assert!(matches!(e.0[0].kind, CompileErrorKind::TooLarge { .. }));
}

#[test]
fn reference_models_have_the_published_counts() {
    // Points / interactions of spec §7.
    let expected = [
        ("string_1000", 1004, 1003),
        ("string_1000_expanded", 1004, 1003),
        ("mesh_15x15", 227, 422),
        ("mesh_25x20", 502, 957),
        ("fretted_string", 169, 203),
        ("chladni_150", 22_503, 44_703),
        ("hammer_oscillator", 3, 2),
    ];
    for (name, spec) in reference::all() {
        let e = engine(&spec, 44_100.0);
        let (_, points, interactions) = expected.iter().find(|x| x.0 == name).unwrap();
        assert_eq!(e.info().num_points, *points, "{name} points");
        assert_eq!(
            e.info().num_interactions,
            *interactions,
            "{name} interactions"
        );
    }
}

/// The coupled (Gershgorin) load counts links to other moving masses: for a chain of single
/// masses it is the uniform-string limit (λ_K = 4K), which the per-mass rule underestimates by
/// half; the same model as a `string` macro gives the same load. A chain just below its
/// coupled limit runs; just above the per-mass rule's silence about it, it explodes.
#[test]
fn coupled_loads_bound_chains_of_single_masses() {
    let text = |k: f64| {
        format!(
            "~samplerate raw\n@g0 ground 0\n@m1 mass 1 0 0\n@m2 mass 1 0 0\n@m3 mass 1 0 0\n\
             @g1 ground 0\n@r0 spring @g0 @m1 {k}\n@r1 spring @m1 @m2 {k}\n@r2 spring @m2 @m3 {k}\n\
             @r3 spring @m3 @g1 {k}\n@in1 frcInput @m2\n@out1 posOutput @m2\n"
        )
    };
    let k = 0.3;
    let spec = ressort_engine::parse(&text(k)).spec.unwrap();
    let mut e = engine(&spec, 44_100.0);
    let r = e.stability();
    let mid = r.masses.iter().find(|m| m.label == "m2").unwrap();
    assert_eq!((mid.k_eq, mid.k_coupled), (2.0 * k, 2.0 * k));
    let end = r.masses.iter().find(|m| m.label == "m1").unwrap();
    assert_eq!((end.k_eq, end.k_coupled), (2.0 * k, k));
    assert!((mid.coupled_load() - 4.0 * k / 4.0).abs() < 1e-12);

    let mut b = ModelBuilder::new();
    b.raw();
    b.macro_1d("s", MacroKind::String, 5, 1.0, k, 0.0);
    b.frc_input(1, Endpoint::at("s", 0.5));
    b.pos_output(1, Endpoint::at("s", 0.5));
    let mut m = engine(&b.build(), 44_100.0);
    let worst = m
        .stability()
        .masses
        .iter()
        .map(|m| m.coupled_load())
        .fold(0.0, f64::max);
    assert!((worst - 4.0 * k / 4.0).abs() < 1e-12, "{worst}");

    // K = 1.9: the per-mass rule passes (2K = 3.8 < 4M); the coupled load (1.9) says no, and
    // the chain's fastest mode (λ = (2 + √2)K ≈ 6.5 > 4) explodes.
    let spec = ressort_engine::parse(&text(1.9)).spec.unwrap();
    let mut e = engine(&spec, 44_100.0);
    let r = e.stability();
    assert!(r.is_stable());
    assert!(r.masses.iter().any(|m| m.coupled_load() > 1.0));
    let out = render(&mut e, 4_000, 64, &[impulse(-1e-3, 4_000)]);
    assert!(e.is_tripped() || out[0].iter().any(|x| x.abs() > 1.0));
    // K = 0.55: coupled load 0.55 everywhere, and the chain rings without growing.
    let spec = ressort_engine::parse(&text(0.55)).spec.unwrap();
    let mut e = engine(&spec, 44_100.0);
    let out = render(&mut e, 20_000, 64, &[impulse(-1e-3, 20_000)]);
    assert!(!e.is_tripped() && out[0].iter().all(|x| x.abs() < 1e-2));
}

/// Displays find inputs and outputs on material points, connection points on their heaviest
/// node, and explicit interactions as point pairs.
#[test]
fn io_points_and_links_locate_on_material_points() {
    use ressort_engine::{IoKind, PointKind};
    let text = include_str!("../../models/mesh-15x15.mdl");
    let spec = ressort_engine::parse(text).spec.expect("preset parses");
    let e = compile(&spec, &CompileOptions::at(44_100.0)).expect("compiles");
    let info = e.info();
    let label = |p: u32| info.point_label(p as usize);
    let io = e.io_points();
    assert_eq!(io.len(), 2, "{io:?}");
    let input = io.iter().find(|p| p.kind == IoKind::ForceInput).unwrap();
    assert_eq!((input.channel, label(input.point).as_str()), (1, "h"));
    let output = io
        .iter()
        .find(|p| p.kind == IoKind::PositionOutput)
        .unwrap();
    assert_eq!(output.channel, 1);
    // [@mesh 0.75 0.6] on 15 × 15 nodes sits at (10.5, 8.4): the heaviest corner is row 10
    // or 11 (equal weights), column 8.
    let out_label = label(output.point);
    assert!(
        out_label == "mesh[10,8]" || out_label == "mesh[11,8]",
        "{out_label}"
    );
    assert!(matches!(
        info.points[output.point as usize].kind,
        PointKind::MacroNode { .. }
    ));
    let links: Vec<(String, String)> = e
        .links()
        .into_iter()
        .map(|(a, b)| (label(a), label(b)))
        .collect();
    assert_eq!(links.len(), 2, "{links:?}");
    assert!(links.contains(&("gh".into(), "h".into())), "{links:?}");
    // The hammer's contact [@mesh 0.3 0.2] is at (4.2, 2.8): heaviest node (4, 3).
    assert!(
        links.contains(&("mesh[4,3]".into(), "h".into())),
        "{links:?}"
    );
}
