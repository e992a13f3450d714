//! How a host plays a model: the host directives (`~pitch`, `~key`, `~note`, `~route`,
//! `~macro`, `~voices`, `~pressure`) as the spec keeps them. The engine ignores them.

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
}
