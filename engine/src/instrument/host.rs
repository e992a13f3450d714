//! What a script tells the plugin beyond the physics: input routing, the MIDI note target,
//! the reference pitch and key, and macro ranges.

use crate::{ExciterKind, MacroRange, ModelSpec, RouteSource};
use std::fmt;

/// The default order: `@in1`, `@in2`… take the main input's left and right channels when
/// the plugin has a main input (effect layouts), then the sidechain's channels 1 … 8.
pub fn default_order(has_main_input: bool) -> &'static [RouteSource] {
    const WITH_MAIN: [RouteSource; 10] = [
        RouteSource::MainLeft,
        RouteSource::MainRight,
        RouteSource::SidechainLeft,
        RouteSource::SidechainRight,
        RouteSource::Sidechain(3),
        RouteSource::Sidechain(4),
        RouteSource::Sidechain(5),
        RouteSource::Sidechain(6),
        RouteSource::Sidechain(7),
        RouteSource::Sidechain(8),
    ];
    if has_main_input {
        &WITH_MAIN
    } else {
        &WITH_MAIN[2..]
    }
}

/// Index of a host channel in the instrument's per-chunk scratch: 0 and 1 the main input,
/// 2 … 9 the sidechain's channels 1 … 8; None for `none`.
pub fn channel(source: RouteSource) -> Option<usize> {
    match source {
        RouteSource::MainLeft => Some(0),
        RouteSource::MainRight => Some(1),
        RouteSource::SidechainLeft => Some(2),
        RouteSource::SidechainRight => Some(3),
        RouteSource::Sidechain(n) => Some(1 + n as usize),
        RouteSource::None => None,
    }
}

/// What full pressure adds to the `~pressure` input when the script gives no amount: a
/// sustained force of 0.001 (or a position offset of 0.001 units).
pub const DEFAULT_PRESSURE: f64 = 0.001;

/// The plugin-facing settings of a model.
#[derive(Clone, Debug, PartialEq)]
pub struct HostSettings {
    /// Per model input (index 0 = `@in1`): the host channel chosen by the script.
    pub routing: Vec<Option<RouteSource>>,
    /// The model input (0-based) that MIDI notes strike (`~note`, `~exciter … strike`);
    /// default: the first force input, unless the script declares other exciters.
    pub note_input: Option<u32>,
    /// The script declares exciters (`~exciter`): a note plays those, and strikes only the
    /// input its `strike` names.
    pub has_exciters: bool,
    /// `~unpitched`: the model keeps its own pitch at `reference_key` instead of playing in
    /// concert pitch.
    pub unpitched: bool,
    /// The force of a full-velocity note, before the Force gain.
    pub note_force: f64,
    /// The model's pitch in Hz at its reference key, when the script declares it.
    pub reference_pitch_hz: Option<f64>,
    /// The MIDI key at which the model sounds as written.
    pub reference_key: f64,
    pub macro_ranges: Vec<MacroRange>,
    /// `~voices N`: the notes the model plays at once unless the host says otherwise.
    pub voices: Option<u32>,
    /// `~pressure inK [AMOUNT]`: the input (0-based) that pressure drives, and what full
    /// pressure adds to it (a force or a position offset, before the host gains).
    pub pressure_input: Option<u32>,
    pub pressure_scale: f64,
}

impl Default for HostSettings {
    fn default() -> Self {
        HostSettings {
            routing: Vec::new(),
            note_input: None,
            has_exciters: false,
            unpitched: false,
            note_force: -0.02,
            reference_pitch_hz: None,
            reference_key: 60.0,
            macro_ranges: Vec::new(),
            voices: None,
            pressure_input: None,
            pressure_scale: DEFAULT_PRESSURE,
        }
    }
}

impl HostSettings {
    /// Reads the host directives of a parsed model (`~pitch`, `~key`, `~note`, `~route`,
    /// `~macro`, `~voices`, `~pressure`, `~exciter`, `~unpitched`; see docs/LANGUAGE.md §12.3,
    /// §12.4).
    pub fn from_spec(spec: &ModelSpec) -> Result<HostSettings, Vec<String>> {
        let h = &spec.host;
        let defaults = HostSettings::default();
        let mut routing: Vec<Option<RouteSource>> = Vec::new();
        for r in &h.routes {
            let i = r.input as usize - 1;
            if routing.len() <= i {
                routing.resize(i + 1, None);
            }
            routing[i] = Some(r.source);
        }
        let strike = h.exciters.iter().find(|e| e.kind == ExciterKind::Strike);
        let (note_input, note_force) = match strike {
            Some(e) => (Some(e.input), e.amount),
            None => (h.note_input, h.note_force),
        };
        Ok(HostSettings {
            routing,
            note_input: note_input.map(|k| k - 1),
            has_exciters: !h.exciters.is_empty(),
            unpitched: h.unpitched,
            note_force: note_force.unwrap_or(defaults.note_force),
            reference_pitch_hz: h.pitch_hz,
            reference_key: h.key.unwrap_or(defaults.reference_key),
            macro_ranges: h.macro_ranges.clone(),
            voices: h.voices,
            pressure_input: h.pressure_input.map(|k| k - 1),
            pressure_scale: h.pressure_scale.unwrap_or(defaults.pressure_scale),
        })
    }
}

/// What a model input carries, which decides its gain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputRole {
    /// A `frcInput`: × Force gain.
    Force,
    /// A `posInput`: × Position gain.
    Position,
    /// An `audioParam`: the raw channel.
    AudioParam,
    /// Declared by no element.
    Unused,
}

/// Why a script did not become the running model: `LINE:COL: error: …` lines.
#[derive(Clone, Debug, PartialEq)]
pub struct Rejected(pub Vec<String>);

impl fmt::Display for Rejected {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0.join("\n"))
    }
}

impl std::error::Error for Rejected {}
