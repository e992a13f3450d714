//! The built-in models: the scripts of `models/`, compiled into the plugin.
//!
//! Each script starts with a comment header whose `What:`, `How to play:` and `Source:` lines
//! describe it; the preset browser shows them.

/// One built-in model.
#[derive(Clone, Copy, Debug)]
pub struct Preset {
    /// The file stem, stable across versions: `mesh-25x20`.
    pub id: &'static str,
    /// The script text.
    pub text: &'static str,
}

macro_rules! presets {
    ($($id:literal),* $(,)?) => {
        &[$(Preset { id: $id, text: include_str!(concat!("../../models/", $id, ".mdl")) }),*]
    };
}

/// Every built-in model, in the order the browser lists them.
pub const PRESETS: &[Preset] = presets![
    "string-1000",
    "mesh-15x15",
    "mesh-25x20",
    "chladni-150x150",
    "fretted-string",
    "bowed-string",
    "plucked-harmonics",
    "struck-string",
    "felt-piano",
    "harmonic-oscillator",
    "hammer-oscillator",
    "gravity-oscillator",
    "plucked-oscillator",
    "bowed-oscillator",
    "nonlinear-oscillator",
    "oscillator-bank",
    "drunk-triangles",
    "drunk-triangles-xl",
    "coupled-strings-bowed",
    "resonant-strings",
    "rolling-mesh",
    "two-fingers-string",
    "nofx-drone",
    "brokendown-string",
];

/// The model a new instance starts with.
pub const DEFAULT_PRESET: &str = "mesh-15x15";

impl Preset {
    /// Looks a preset up by id.
    pub fn find(id: &str) -> Option<&'static Preset> {
        PRESETS.iter().find(|p| p.id == id)
    }

    /// The default model.
    pub fn default_preset() -> &'static Preset {
        Preset::find(DEFAULT_PRESET).unwrap_or(&PRESETS[0])
    }

    /// The text after `key` (`What:`, `How to play:`, `Source:`) in the header, with its
    /// continuation lines joined.
    pub fn header_field(&self, key: &str) -> String {
        header_field(self.text, key)
    }
}

/// The header fields of a preset.
pub const FIELDS: [&str; 3] = ["What:", "How to play:", "Source:"];

/// The text after `key` in a script's leading `#` comment block, continuation lines (indented
/// comment lines that start no other field) joined with spaces.
pub fn header_field(text: &str, key: &str) -> String {
    let mut out = String::new();
    let mut inside = false;
    for line in text.lines() {
        let Some(body) = line.strip_prefix('#') else {
            break;
        };
        let body = body.trim();
        if let Some(rest) = body.strip_prefix(key) {
            inside = true;
            out.push_str(rest.trim());
        } else if inside {
            let starts_field = FIELDS.iter().any(|f| body.starts_with(f));
            if body.is_empty() || starts_field {
                break;
            }
            out.push(' ');
            out.push_str(body);
        }
    }
    out
}
