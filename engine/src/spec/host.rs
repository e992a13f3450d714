//! How a host plays a model: the host directives (`~pitch`, `~key`, `~note`, `~route`,
//! `~macro`, `~voices`, `~pressure`, `~exciter`, `~unpitched`) as the spec keeps them. The
//! engine ignores them.

use super::Span;

/// A host channel a model input can be routed to (`~route inK SOURCE`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RouteSource {
    MainLeft,
    MainRight,
    /// Sidechain channel 1.
    SidechainLeft,
    /// Sidechain channel 2.
    SidechainRight,
    /// Sidechain channel 3 … 8 (`sidechain_3` … `sidechain_8`), in the plugin's multichannel
    /// layout.
    Sidechain(u8),
    /// Fed by nothing but MIDI strikes.
    None,
}

impl RouteSource {
    /// The widest sidechain a host can feed.
    pub const MAX_SIDECHAIN_CHANNELS: u8 = 8;

    /// The script names: `main_left`, `main_right`, `sidechain_left` (also `sidechain_1`),
    /// `sidechain_right` (`sidechain_2`), `sidechain_3` … `sidechain_8`, `none`.
    pub const NAMES: [(&'static str, RouteSource); 11] = [
        ("main_left", RouteSource::MainLeft),
        ("main_right", RouteSource::MainRight),
        ("sidechain_left", RouteSource::SidechainLeft),
        ("sidechain_right", RouteSource::SidechainRight),
        ("sidechain_3", RouteSource::Sidechain(3)),
        ("sidechain_4", RouteSource::Sidechain(4)),
        ("sidechain_5", RouteSource::Sidechain(5)),
        ("sidechain_6", RouteSource::Sidechain(6)),
        ("sidechain_7", RouteSource::Sidechain(7)),
        ("sidechain_8", RouteSource::Sidechain(8)),
        ("none", RouteSource::None),
    ];

    /// The sidechain channel `n` (1-based; 1 and 2 are left and right), if it exists.
    pub fn sidechain(n: u8) -> Option<RouteSource> {
        match n {
            1 => Some(RouteSource::SidechainLeft),
            2 => Some(RouteSource::SidechainRight),
            3..=Self::MAX_SIDECHAIN_CHANNELS => Some(RouteSource::Sidechain(n)),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        RouteSource::NAMES
            .iter()
            .find(|(_, s)| *s == self)
            .map(|(n, _)| *n)
            .unwrap_or("none")
    }

    pub fn from_name(name: &str) -> Option<RouteSource> {
        if let Some(n) = name.strip_prefix("sidechain_").and_then(|n| n.parse().ok()) {
            return RouteSource::sidechain(n);
        }
        RouteSource::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, s)| *s)
    }
}

/// `~route inK SOURCE`.
#[derive(Clone, Debug, PartialEq)]
pub struct Route {
    /// 1-based model input channel.
    pub input: u32,
    pub source: RouteSource,
}

/// `~macro NAME MIN MAX`.
#[derive(Clone, Debug, PartialEq)]
pub struct MacroRange {
    pub name: String,
    pub min: f64,
    pub max: f64,
}

/// What a key does to a model input (`~exciter inK KIND …`, docs/LANGUAGE.md §12.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ExciterKind {
    /// A one-sample force impulse at note-on (today's `~note`).
    Strike,
    /// A held key moves the input at a steady speed, set by velocity; the speed rises and
    /// falls over a ramp at note-on and note-off.
    Bow,
    /// Key-down sweeps the input across to the other side of its rest, once.
    Pluck,
    /// A held key pushes the input to a depth and lets it back at note-off.
    Press,
}

impl ExciterKind {
    pub const ALL: [ExciterKind; 4] = [
        ExciterKind::Strike,
        ExciterKind::Bow,
        ExciterKind::Pluck,
        ExciterKind::Press,
    ];

    /// The script's word for the kind.
    pub fn name(self) -> &'static str {
        match self {
            ExciterKind::Strike => "strike",
            ExciterKind::Bow => "bow",
            ExciterKind::Pluck => "pluck",
            ExciterKind::Press => "press",
        }
    }

    pub fn from_name(name: &str) -> Option<ExciterKind> {
        ExciterKind::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// `~exciter inK KIND [AMOUNT [TIME_MS]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct ExciterDecl {
    /// 1-based model input channel.
    pub input: u32,
    pub kind: ExciterKind,
    /// The strike's force, the bow's speed (units/s), the pluck's travel, the press's depth;
    /// None takes the default the model's laws give.
    pub amount: Option<f64>,
    /// The bow's and the press's ramp, the pluck's sweep, in milliseconds.
    pub time_ms: Option<f64>,
    /// Where the directive stands, for the errors found when the model is prepared.
    pub span: Span,
}

/// How a host plays the model. Every field is optional; a host uses its defaults.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HostSpec {
    /// `~pitch HZ`: the model's pitch at its reference key, in Hz.
    pub pitch_hz: Option<f64>,
    /// `~key NOTE`: the MIDI key at which the model sounds as written (default 60).
    pub key: Option<f64>,
    /// `~note inK [FORCE]`: the input (1-based) that MIDI notes strike, and the force of a
    /// full-velocity note.
    pub note_input: Option<u32>,
    pub note_force: Option<f64>,
    /// `~route` lines, in script order.
    pub routes: Vec<Route>,
    /// `~macro` lines, in script order.
    pub macro_ranges: Vec<MacroRange>,
    /// `~voices N`: how many notes the model plays at once by default (1 … 1024).
    pub voices: Option<u32>,
    /// `~pressure inK [AMOUNT]`: the input (1-based) that key pressure drives, and what full
    /// pressure adds to it.
    pub pressure_input: Option<u32>,
    pub pressure_scale: Option<f64>,
    /// `~exciter` lines, in script order.
    pub exciters: Vec<ExciterDecl>,
    /// `~unpitched`: the model keeps its own pitch at its `~key` instead of playing in
    /// concert pitch.
    pub unpitched: bool,
}
