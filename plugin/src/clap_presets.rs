//! The sound library as a CLAP host sees it: preset discovery (the host's browser lists the
//! factory presets and the user's `.mdl` files with their categories and tags, without making an
//! instance) and preset load (the host hands one back and the running instance plays it). The
//! vendored wrapper does the C side (vendor/README.md, patch 9).
//!
//! - The factory presets are inside the plugin: one location of kind `PLUGIN`, each preset
//!   told apart by its load key, the preset's id (`felt-piano`).
//! - The user folder ([`crate::files::user_preset_dir`]) is a location of kind `FILE` when it
//!   exists; the host finds its `.mdl` files and asks about each.
//! - Each preset's metadata: its title, the header's `What:` as description, its category and
//!   tags as features and as the extra info `category` and `tags`, the favourite flag from the
//!   browser's favourites.
//!
//! A preset load does what choosing the preset in the editor's browser does
//! ([`ModelStore::choose_in_background`]): the model is prepared in the background and the old
//! one plays until the new one is ready.

use crate::files::{read_script, user_preset_dir};
use crate::library::{entries, title, Favourites, Source};
use crate::model::ModelStore;
use crate::presets::{category, header_field, tags, PRESETS};
use nice_plug::prelude::*;
use std::path::Path;
use std::sync::Arc;

/// The extension of user preset files.
pub const EXTENSION: &str = "mdl";

/// The load key of a factory preset: its id.
pub fn load_key(id: &str) -> String {
    id.to_string()
}

pub fn filetypes() -> Vec<PresetFiletype> {
    vec![PresetFiletype {
        name: "Ressort script".to_string(),
        description: "A MIMS model script with Ressort's preset header".to_string(),
        extension: EXTENSION.to_string(),
    }]
}

/// The factory presets inside the plugin, and the user folder when it exists.
pub fn locations() -> Vec<PresetLocation> {
    let mut out = vec![PresetLocation {
        name: "Ressort factory presets".to_string(),
        flags: PresetFlags {
            factory: true,
            ..PresetFlags::default()
        },
        kind: PresetLocationKind::Plugin,
    }];
    if let Some(dir) = user_preset_dir().filter(|d| d.is_dir()) {
        out.push(PresetLocation {
            name: "Ressort user presets".to_string(),
            flags: PresetFlags {
                user: true,
                ..PresetFlags::default()
            },
            kind: PresetLocationKind::File(dir),
        });
    }
    out
}

/// What a script's header says of it, for the host.
fn describe(
    name: String,
    load_key: Option<String>,
    text: &str,
    flags: PresetFlags,
) -> PresetMetadata {
    let category = category(text);
    let tags = tags(text);
    let what = header_field(text, "What:");
    let mut features: Vec<String> = category.iter().map(|c| c.to_string()).collect();
    features.extend(tags.iter().cloned());
    let mut extra_info = Vec::new();
    if let Some(c) = category {
        extra_info.push(("category".to_string(), c.to_string()));
    }
    if !tags.is_empty() {
        extra_info.push(("tags".to_string(), tags.join(", ")));
    }
    PresetMetadata {
        name,
        load_key,
        flags,
        creators: if flags.factory {
            vec!["Ressort".to_string()]
        } else {
            Vec::new()
        },
        description: (!what.is_empty()).then_some(what),
        features,
        extra_info,
    }
}

/// The presets at `location`: every factory preset inside the plugin, in the browser's order;
/// the one preset of a user file.
pub fn metadata(location: PresetLocationRef<'_>) -> Result<Vec<PresetMetadata>, String> {
    let dir = user_preset_dir();
    let favourites = Favourites::load(dir.as_deref());
    match location {
        PresetLocationRef::Plugin => Ok(entries(&[])
            .into_iter()
            .filter_map(|e| {
                let Source::Factory(i) = e.source else {
                    return None;
                };
                let flags = PresetFlags {
                    factory: true,
                    favorite: favourites.contains(&e.key),
                    ..PresetFlags::default()
                };
                Some(describe(
                    e.name,
                    Some(load_key(&e.id)),
                    PRESETS[i].text,
                    flags,
                ))
            })
            .collect()),
        PresetLocationRef::File(path) => {
            let text = read_script(path)?;
            let stem = file_stem(path)?;
            let flags = PresetFlags {
                user: true,
                favorite: favourites.contains(&format!("user:{stem}")),
                ..PresetFlags::default()
            };
            let name = title(&text).unwrap_or_else(|| stem.clone());
            Ok(vec![describe(name, None, &text, flags)])
        }
    }
}

fn file_stem(path: &Path) -> Result<String, String> {
    if path.extension().is_none_or(|x| x != EXTENSION) {
        return Err(format!("{}: not a .{EXTENSION} script", path.display()));
    }
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .ok_or_else(|| format!("{}: no file name", path.display()))
}

/// The model a location and load key name: its name (what the editor shows and the state keeps)
/// and its script.
pub fn find(
    location: PresetLocationRef<'_>,
    key: Option<&str>,
) -> Result<(String, String), String> {
    match location {
        PresetLocationRef::Plugin => {
            let key = key.ok_or("a factory preset needs a load key")?;
            PRESETS
                .iter()
                .find(|p| load_key(p.id) == key)
                .map(|p| (p.id.to_string(), p.text.to_string()))
                .ok_or_else(|| format!("no factory preset `{key}`"))
        }
        PresetLocationRef::File(path) => {
            let (name, script) = (file_stem(path)?, read_script(path)?);
            // The script's first error goes back to the host with its place; the running
            // model keeps playing.
            let parsed = ressort_engine::parse(&script);
            if let Some(error) = parsed.errors().next() {
                return Err(format!("{}: {error}", path.display()));
            }
            Ok((name, script))
        }
    }
}

/// Loads presets for the CLAP preset-load extension into the instance's model store.
pub struct Loader {
    pub store: Arc<ModelStore>,
}

impl ClapPresetLoader for Loader {
    fn load(&self, location: PresetLocationRef<'_>, key: Option<&str>) -> Result<(), String> {
        let (name, script) = find(location, key)?;
        self.store.choose_in_background(name, script);
        Ok(())
    }
}
