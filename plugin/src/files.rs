//! Script files: reading and saving `.mdl` scripts, the user preset folder, and the editor's
//! small file browser. Nothing here runs on the audio thread.
//!
//! User presets live in `ressort/presets` under the platform's data folder (on Linux
//! `$XDG_DATA_HOME`, by default `~/.local/share`; `RESSORT_PRESET_DIR` overrides it), one
//! `.mdl` script per preset, named by its file.

use std::path::{Path, PathBuf};

/// Largest file the model panel loads.
pub const MAX_SCRIPT_BYTES: u64 = 16 << 20;

/// The user preset folder (it may not exist yet).
pub fn user_preset_dir() -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os("RESSORT_PRESET_DIR").filter(|d| !d.is_empty()) {
        return Some(PathBuf::from(dir));
    }
    dirs::data_dir().map(|d| d.join("ressort").join("presets"))
}

/// A user preset: its name (the file stem) and file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UserPreset {
    pub name: String,
    pub path: PathBuf,
}

/// The `.mdl` files of `dir`, by name. A folder that does not exist has none.
pub fn user_presets(dir: &Path) -> Vec<UserPreset> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut out: Vec<UserPreset> = rd
        .flatten()
        .filter_map(|e| {
            let path = e.path();
            let is_script = path.extension().is_some_and(|x| x == "mdl") && path.is_file();
            let name = path.file_stem()?.to_string_lossy().into_owned();
            (is_script && !name.starts_with('.')).then_some(UserPreset { name, path })
        })
        .collect();
    out.sort_by_key(|p| p.name.to_lowercase());
    out
}

/// A file name for a preset called `name`: letters, digits, spaces, `-`, `_` and `.` kept,
/// anything else (path separators among them) replaced by `_`; `.mdl` added. None for a
/// name with nothing to keep.
pub fn preset_file_name(name: &str) -> Option<String> {
    let stem: String = name
        .trim()
        .trim_end_matches(".mdl")
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || matches!(c, ' ' | '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    let stem = stem.trim().trim_start_matches('.').to_string();
    (!stem.is_empty()).then(|| format!("{stem}.mdl"))
}

/// Writes `script` to `path`, creating its folder. The file is written beside its final name
/// and renamed, so a failure never leaves half a script.
pub fn save_script(path: &Path, script: &str) -> Result<(), String> {
    let shown = path.display();
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    }
    let tmp = path.with_extension("mdl.part");
    std::fs::write(&tmp, script).map_err(|e| format!("{shown}: {e}"))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{shown}: {e}")
    })
}

/// Reads a script file for the model panel.
pub fn read_script(path: &Path) -> Result<String, String> {
    let meta = std::fs::metadata(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if meta.len() > MAX_SCRIPT_BYTES {
        return Err(format!(
            "{}: {} bytes is larger than the {} MB a script may have",
            path.display(),
            meta.len(),
            MAX_SCRIPT_BYTES >> 20
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// A minimal file browser for `.mdl` scripts.
#[derive(Debug)]
pub struct FileBrowser {
    pub dir: PathBuf,
    pub path_text: String,
    pub entries: Vec<(String, bool)>,
    pub error: Option<String>,
}

impl FileBrowser {
    /// A browser in the home folder.
    pub fn new() -> FileBrowser {
        let dir = std::env::var_os("HOME")
            .map(PathBuf::from)
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_else(|| PathBuf::from("/"));
        let mut b = FileBrowser {
            path_text: dir.display().to_string(),
            dir,
            entries: Vec::new(),
            error: None,
        };
        b.refresh();
        b
    }

    pub fn go(&mut self, dir: PathBuf) {
        self.dir = dir;
        self.path_text = self.dir.display().to_string();
        self.refresh();
    }

    pub fn refresh(&mut self) {
        self.entries.clear();
        self.error = None;
        match std::fs::read_dir(&self.dir) {
            Ok(rd) => {
                for e in rd.flatten() {
                    let name = e.file_name().to_string_lossy().into_owned();
                    if name.starts_with('.') {
                        continue;
                    }
                    let is_dir = e.file_type().map(|t| t.is_dir()).unwrap_or(false);
                    if is_dir || name.ends_with(".mdl") {
                        self.entries.push((name, is_dir));
                    }
                }
                self.entries
                    .sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
            }
            Err(e) => self.error = Some(format!("{}: {e}", self.dir.display())),
        }
    }
}

impl Default for FileBrowser {
    fn default() -> Self {
        FileBrowser::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preset_names_become_safe_file_names() {
        assert_eq!(preset_file_name("My Bell").as_deref(), Some("My Bell.mdl"));
        assert_eq!(preset_file_name("bell.mdl").as_deref(), Some("bell.mdl"));
        assert_eq!(
            preset_file_name("../../etc/passwd").as_deref(),
            Some("_.._etc_passwd.mdl")
        );
        assert_eq!(preset_file_name("a/b\\c:d").as_deref(), Some("a_b_c_d.mdl"));
        assert_eq!(preset_file_name("   "), None);
        assert_eq!(preset_file_name(".hidden").as_deref(), Some("hidden.mdl"));
    }

    #[test]
    fn saved_scripts_list_and_read_back() {
        let dir = std::env::temp_dir().join(format!("ressort-presets-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        assert!(
            user_presets(&dir).is_empty(),
            "a missing folder has no presets"
        );
        let script = "@o osc 1. 0.1 0.001 0. 0.\n@out1 posOutput @o\n";
        for name in ["b bell", "A drum"] {
            let path = dir.join(preset_file_name(name).unwrap());
            save_script(&path, script).unwrap();
        }
        std::fs::write(dir.join("notes.txt"), "not a preset").unwrap();
        let list = user_presets(&dir);
        let names: Vec<&str> = list.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["A drum", "b bell"]);
        assert_eq!(read_script(&list[0].path).unwrap(), script);
        // Saving again replaces the file whole.
        save_script(&list[0].path, "# changed\n").unwrap();
        assert_eq!(read_script(&list[0].path).unwrap(), "# changed\n");
        assert!(!list[0].path.with_extension("mdl.part").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
