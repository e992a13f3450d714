//! The plugin's parameters. Their ids are part of every saved project: never rename one.

use crate::model::{ModelStore, NUM_MACROS};
use nice_plug::prelude::*;
use std::sync::Arc;

/// Stiffness and Damping are stored in octaves (log₂ of the factor): the knob is logarithmic
/// from ×1/16 to ×16 and automation lanes are linear in octaves.
pub const GAIN_OCTAVES: f32 = 4.0;

#[derive(Params)]
pub struct RessortParams {
    /// The running model's script (saved with the project).
    #[persist = "model"]
    pub model: Arc<ModelStore>,

    /// × on every K-class argument (log₂ of the factor).
    #[id = "stiffness"]
    pub stiffness: FloatParam,
    /// × on every Z-class argument (log₂ of the factor).
    #[id = "damping"]
    pub damping: FloatParam,
    /// Semitones, by the exact discrete tuning law.
    #[id = "tune"]
    pub tune: FloatParam,
    #[id = "output_gain"]
    pub output_gain: FloatParam,
    #[id = "force_gain"]
    pub force_gain: FloatParam,
    #[id = "position_gain"]
    pub position_gain: FloatParam,
    /// The 40 Hz high-pass of the mi-gen example patches.
    #[id = "dc_filter"]
    pub dc_filter: BoolParam,
    /// On when the explosion guard has reset the model; off again with the editor's Reset
    /// model or by the user. Set by the plugin (see `report`), not automatable.
    #[id = "guard"]
    pub guard: BoolParam,

    /// Generic slots bound to the model's `param`s in declaration order.
    #[nested(array, group = "Macros")]
    pub macros: [MacroParam; NUM_MACROS],
}

#[derive(Params)]
pub struct MacroParam {
    /// 0 … 1: the bound parameter's minimum, declared value (0.5) and maximum.
    #[id = "macro"]
    pub value: FloatParam,
}

fn factor_param(name: &'static str) -> FloatParam {
    FloatParam::new(
        name,
        0.0,
        FloatRange::Linear {
            min: -GAIN_OCTAVES,
            max: GAIN_OCTAVES,
        },
    )
    .with_value_to_string(Arc::new(|octaves| format_factor(2f32.powf(octaves))))
    .with_string_to_value(Arc::new(parse_factor))
}

/// `×1.00`, `×0.063`, `×16.0`.
pub fn format_factor(f: f32) -> String {
    if f >= 10.0 {
        format!("×{f:.1}")
    } else if f >= 1.0 {
        format!("×{f:.2}")
    } else {
        format!("×{f:.3}")
    }
}

/// Accepts `×2`, `x2`, `2`, `1/4`; returns octaves.
pub fn parse_factor(text: &str) -> Option<f32> {
    let t = text.trim().trim_start_matches(['×', 'x', 'X', '*']).trim();
    let f: f32 = match t.split_once('/') {
        Some((a, b)) => a.trim().parse::<f32>().ok()? / b.trim().parse::<f32>().ok()?,
        None => t.parse().ok()?,
    };
    (f.is_finite() && f > 0.0).then(|| f.log2().clamp(-GAIN_OCTAVES, GAIN_OCTAVES))
}

fn gain_param(name: &'static str, default_db: f32, min_db: f32, max_db: f32) -> FloatParam {
    FloatParam::new(
        name,
        default_db,
        FloatRange::Linear {
            min: min_db,
            max: max_db,
        },
    )
    .with_unit(" dB")
    .with_step_size(0.1)
}

impl RessortParams {
    pub fn new(model: Arc<ModelStore>) -> RessortParams {
        let macros = std::array::from_fn(|slot| {
            let store = model.clone();
            MacroParam {
                value: FloatParam::new(
                    format!("Macro {}", slot + 1),
                    0.5,
                    FloatRange::Linear { min: 0.0, max: 1.0 },
                )
                .with_value_to_string(Arc::new(move |v| store.macro_text(slot, v as f64))),
            }
        });
        RessortParams {
            model,
            stiffness: factor_param("Stiffness"),
            damping: factor_param("Damping"),
            tune: FloatParam::new(
                "Tune",
                0.0,
                FloatRange::Linear {
                    min: -24.0,
                    max: 24.0,
                },
            )
            .with_unit(" st")
            .with_step_size(0.01),
            output_gain: gain_param("Output Gain", 24.0, -40.0, 60.0),
            force_gain: gain_param("Force Gain", 0.0, -60.0, 40.0),
            position_gain: gain_param("Position Gain", 0.0, -60.0, 40.0),
            dc_filter: BoolParam::new("DC Filter", true),
            guard: BoolParam::new("Guard Tripped", false)
                .non_automatable()
                .with_value_to_string(Arc::new(|on| {
                    if on { "Tripped" } else { "Clear" }.to_string()
                })),
            macros,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_round_trip_through_text() {
        for octaves in [-4.0f32, -1.0, 0.0, 0.5, 4.0] {
            let text = format_factor(2f32.powf(octaves));
            let back = parse_factor(&text).unwrap();
            assert!((back - octaves).abs() < 0.01, "{text}: {back}");
        }
        assert_eq!(parse_factor("1/4"), Some(-2.0));
        assert_eq!(parse_factor("x2"), Some(1.0));
        assert_eq!(parse_factor("1000"), Some(4.0));
        assert_eq!(parse_factor("-1"), None);
        assert_eq!(parse_factor("abc"), None);
    }
}
