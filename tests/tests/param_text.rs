//! Parameter text in a CLAP host: what hosts show (`value_to_text`) and what people type
//! (`text_to_value`). The number comes first and the unit after, and every text the plugin
//! writes reads back to a value that writes the same text (the check clap-validator's
//! `param-conversions` makes).

use ressort_tests::{state, TestPlugin};

/// A model with two bound macros (`K`, `Z`).
const BOUND_MACROS: &str = "\
# Two macros on a small string (parameter text tests).
@K param 0.08
@Z param 0.002
@s string 12 1. K Z 0. 0.
@in1 frcInput [@s 0.3]
@out1 posOutput [@s 0.7]
";

fn plugin_with(script: &str) -> TestPlugin {
    let mut plugin = TestPlugin::new();
    let blob = state::with_model(&plugin.save_state(), "bound-macros", script);
    plugin.load_state(&blob).expect("the model loads");
    // Macro slots are bound when the model is prepared for a sample rate.
    plugin.activate(48_000.0, 1, 512);
    plugin
}

/// value → text → value → text gives the same text for every parameter over its range.
fn assert_every_text_round_trips(plugin: &mut TestPlugin) -> usize {
    let mut checked = 0;
    for p in plugin.params() {
        for i in 0..=200 {
            let value = p.min + (p.max - p.min) * i as f64 / 200.0;
            let text = plugin
                .param_text(p.id, value)
                .unwrap_or_else(|| panic!("{}: no text for {value}", p.name));
            let back = plugin.param_value_of_text(p.id, &text).unwrap_or_else(|| {
                panic!("{}: '{text}' (from {value}) does not read back", p.name)
            });
            let again = plugin.param_text(p.id, back).unwrap();
            assert_eq!(
                again, text,
                "{}: {value} -> '{text}' -> {back} -> '{again}'",
                p.name
            );
            let last = plugin.param_value_of_text(p.id, &again).unwrap();
            assert_eq!(last, back, "{}: '{again}' reads {last}, not {back}", p.name);
            checked += 1;
        }
    }
    checked
}

#[test]
fn every_parameter_text_round_trips() {
    let mut plugin = TestPlugin::new();
    let n = assert_every_text_round_trips(&mut plugin);
    println!("{n} conversions with the default model");
    let mut plugin = plugin_with(BOUND_MACROS);
    let n = assert_every_text_round_trips(&mut plugin);
    println!("{n} conversions with bound macros");
}

#[test]
fn texts_put_the_number_first_and_read_what_people_type() {
    let mut plugin = plugin_with(BOUND_MACROS);
    let id = |plugin: &mut TestPlugin, name: &str| plugin.param(name).id;
    let stiffness = id(&mut plugin, "Stiffness");
    // Stiffness and Damping are stored in octaves over ±4 (nice-plug's normalized 0 … 1).
    let x4 = (2.0 + 4.0) / 8.0;
    assert_eq!(plugin.param_text(stiffness, x4).as_deref(), Some("4.00 ×"));
    for typed in ["4", "4.00", "×4", "4x", "4 ×", "x4"] {
        let v = plugin.param_value_of_text(stiffness, typed);
        assert!(
            v.is_some_and(|v| (v - x4).abs() < 1e-6),
            "Stiffness '{typed}' reads {v:?}"
        );
    }
    assert_eq!(
        plugin.param_value_of_text(stiffness, "1/4"),
        Some((-2.0 + 4.0) / 8.0)
    );
    assert_eq!(plugin.param_value_of_text(stiffness, "-4"), None);

    let gain = id(&mut plugin, "Output Gain");
    let minus6 = (-6.0 + 40.0) / 100.0;
    for typed in ["-6", "-6 dB", "-6dB", "\u{2212}6 dB", "-6.0"] {
        let v = plugin.param_value_of_text(gain, typed);
        assert!(
            v.is_some_and(|v| (v - minus6).abs() < 1e-6),
            "Output Gain '{typed}' reads {v:?}"
        );
    }
    assert_eq!(plugin.param_text(gain, minus6).as_deref(), Some("-6.0 dB"));

    let tune = id(&mut plugin, "Tune");
    assert_eq!(
        plugin.param_text(tune, (3.0 + 24.0) / 48.0).as_deref(),
        Some("+3.00 st")
    );
    assert_eq!(plugin.param_text(tune, 0.5).as_deref(), Some("0.00 st"));
    let v = plugin.param_value_of_text(tune, "-12 st").unwrap();
    assert!((v - 0.25).abs() < 1e-6, "Tune '-12 st' reads {v}");

    let guard = id(&mut plugin, "Guard Tripped");
    assert_eq!(plugin.param_text(guard, 1.0).as_deref(), Some("Tripped"));
    assert_eq!(plugin.param_value_of_text(guard, "Tripped"), Some(1.0));
    assert_eq!(plugin.param_value_of_text(guard, "Clear"), Some(0.0));

    // Macro slots read in musical units: the membrane's K as the frequency of its reference
    // mode, its Z as that mode's T60. The per-step value is still understood.
    let macro1 = id(&mut plugin, "Macro 1");
    let k_text = plugin.param_text(macro1, 0.5).unwrap();
    let low = plugin.param_text(macro1, 0.0).unwrap();
    let high = plugin.param_text(macro1, 1.0).unwrap();
    println!("Macro 1: {low} … {k_text} … {high}");
    let hz = |t: &str| -> f64 {
        let r = t.strip_prefix("K: ");
        r.and_then(|r| r.strip_suffix(" kHz"))
            .and_then(|v| v.parse::<f64>().ok())
            .map(|k| k * 1000.0)
            .or_else(|| {
                r.and_then(|r| r.strip_suffix(" Hz"))
                    .and_then(|v| v.parse().ok())
            })
            .unwrap_or_else(|| panic!("`{t}` is not `K: … Hz`"))
    };
    assert!(
        hz(&low) < hz(&k_text) && hz(&k_text) < hz(&high),
        "stiffer is higher"
    );
    let back = plugin.param_value_of_text(macro1, &k_text).unwrap();
    assert!((back - 0.5).abs() < 1e-4, "`{k_text}` reads {back}");
    assert_eq!(plugin.param_value_of_text(macro1, "K = 0.0800"), Some(0.5));
    assert_eq!(plugin.param_value_of_text(macro1, "0.08"), Some(0.5));
    assert_eq!(plugin.param_value_of_text(macro1, "Z = 0.08"), None);
    let macro2 = id(&mut plugin, "Macro 2");
    let z_text = plugin.param_text(macro2, 0.5).unwrap();
    let z_more = plugin.param_text(macro2, 1.0).unwrap();
    println!("Macro 2: {z_text} … {z_more}");
    assert!(
        z_text.starts_with("Z: T60 ") && z_text.ends_with(" s"),
        "{z_text}"
    );
    let macro3 = id(&mut plugin, "Macro 3");
    assert_eq!(
        plugin.param_text(macro3, 0.25).as_deref(),
        Some("unbound (25 %)")
    );
    assert_eq!(
        plugin.param_value_of_text(macro3, "unbound (25 %)"),
        Some(0.25)
    );
}
