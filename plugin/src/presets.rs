//! The built-in models: the scripts of `models/`, compiled into the plugin.
//!
//! Each script starts with a comment header whose `What:`, `How to play:` and `Source:` lines
//! describe it; the preset browser shows them. Its `Category:` line names one of
//! [`CATEGORIES`] and its `Tags:` line a few comma-separated words, which the browser filters
//! and searches by; a user's script may carry them too (README, "Presets").

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
    // The sound library (issue 37), by category.
    // Strings / Struck
    "hammered-dulcimer",
    "bolted-piano-string",
    "tangent-clavinet",
    // Strings / Plucked
    "harp",
    "koto",
    "jawari-sitar",
    "open-back-banjo",
    // Strings / Bowed
    "cello",
    "erhu",
    // Mallets and Bars
    "glockenspiel",
    "marimba",
    "xylophone",
    "kalimba-tine",
    "slit-drum",
    // Bells and Plates
    "bowed-plate",
    "crotales",
    "gong",
    "chime-tube",
    "musical-saw",
    // Membranes and Drums
    "frame-drum",
    "snare",
    "steel-pan",
    "timpani",
    "tom",
    "talking-drum",
    // Drones and Pads
    "bowed-pad",
    "glass-harmonica",
    "organ-pipes",
    "singing-bowl",
    "aeolian-harp",
    // Resonators for a sidechain
    "kick-resonator",
    "metal-sheet",
    "sympathetic-strings",
    "wood-box",
    // Polyphonic Keys
    "bright-grand",
    "electric-tine",
    "harpsichord",
    "celesta",
    // Experimental
    "bouncing-ball",
    "duffing",
    "friction-squeal",
    "rattle",
    // Models in space (~dim 3), in their categories' order.
    "glide-string",
    "plucked-string-3d",
    "bowed-string-3d",
    "mesh-bell",
    "ball-on-drum",
    "rope-and-plate",
    "pendulum-chain",
    "newtons-cradle",
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

    /// Its category, one of [`CATEGORIES`].
    pub fn category(&self) -> Option<&'static str> {
        category(self.text)
    }

    /// Its tags, lower case.
    pub fn tags(&self) -> Vec<String> {
        tags(self.text)
    }
}

/// The header fields the browser shows, in order.
pub const FIELDS: [&str; 3] = ["What:", "How to play:", "Source:"];

/// The header fields of the library: what the browser filters and searches by.
pub const LIBRARY_FIELDS: [&str; 2] = ["Category:", "Tags:"];

/// The categories of the library, in the browser's order. A script's `Category:` line names
/// one of them (any case, any spacing around the slash).
pub const CATEGORIES: [&str; 10] = [
    "Strings / Struck",
    "Strings / Plucked",
    "Strings / Bowed",
    "Mallets and Bars",
    "Bells and Plates",
    "Membranes and Drums",
    "Drones and Pads",
    "Resonators for a sidechain",
    "Polyphonic Keys",
    "Experimental",
];

/// The category a script's `Category:` line names, or None (no line, or a name not in
/// [`CATEGORIES`]).
pub fn category(text: &str) -> Option<&'static str> {
    let squeeze = |s: &str| -> String {
        s.split(|c: char| c.is_whitespace() || c == '/')
            .filter(|w| !w.is_empty())
            .collect::<Vec<_>>()
            .join(" ")
            .to_lowercase()
    };
    let named = squeeze(&header_field(text, "Category:"));
    CATEGORIES.into_iter().find(|c| squeeze(c) == named)
}

/// The words of a script's `Tags:` line: comma-separated, trimmed, lower case, without
/// repeats.
pub fn tags(text: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for tag in header_field(text, "Tags:").split(',') {
        let tag = tag.trim().to_lowercase();
        if !tag.is_empty() && !out.contains(&tag) {
            out.push(tag);
        }
    }
    out
}

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
            let starts_field = FIELDS
                .iter()
                .chain(&LIBRARY_FIELDS)
                .any(|f| body.starts_with(f));
            if body.is_empty() || starts_field {
                break;
            }
            out.push(' ');
            out.push_str(body);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every preset names a category of the library and two to six tags; every script in
    /// `models/` is a preset.
    #[test]
    fn every_preset_has_a_category_and_tags() {
        for p in PRESETS {
            assert!(
                p.category().is_some(),
                "{}: {:?}",
                p.id,
                p.header_field("Category:")
            );
            let tags = p.tags();
            assert!((2..=6).contains(&tags.len()), "{}: {tags:?}", p.id);
            assert!(!p.header_field("What:").is_empty(), "{}", p.id);
        }
        let files = std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../models"))
            .expect("models/")
            .filter(|e| {
                e.as_ref()
                    .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "mdl"))
            })
            .count();
        assert_eq!(files, PRESETS.len());
    }

    #[test]
    fn the_library_fields_are_read_as_written_and_leave_the_others_alone() {
        let text = "# A model\n#\n# Category:  strings/BOWED\n# Tags: Bowed, drone , ,bowed\n\
                    # What: a string\n# bowed.\n@m mass 1 0 0\n# Category: Experimental\n";
        assert_eq!(category(text), Some("Strings / Bowed"));
        assert_eq!(tags(text), ["bowed", "drone"]);
        assert_eq!(header_field(text, "What:"), "a string bowed.");
        assert_eq!(header_field(text, "Category:"), "strings/BOWED");
        assert_eq!(category("# Category: Strings\n"), None);
        assert_eq!(category("@m mass 1 0 0\n"), None);
        assert!(tags("# Tags:\n").is_empty());
    }
}
