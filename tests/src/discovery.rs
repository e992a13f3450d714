//! The host's preset browser: CLAP preset discovery as a DAW indexes a plugin's presets, with no
//! instance (the bundle's `clap.preset-discovery-factory/2`, its providers, their declared file
//! types and locations, and the metadata of every preset found there; the host walks the file
//! locations itself for files of the declared types).

use clack_extensions::preset_discovery::prelude::*;
use clack_host::host::HostError;
use std::ffi::{CStr, CString};
use std::path::{Path, PathBuf};

/// Where presets are, as a provider declared it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Place {
    Plugin,
    File(PathBuf),
}

/// A location a provider declared.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeclaredLocation {
    pub name: String,
    pub flags: u32,
    pub place: Place,
}

/// One preset as the host's browser lists it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct DiscoveredPreset {
    /// Where it was found: the plugin, or its file.
    pub file: Option<PathBuf>,
    pub name: String,
    pub load_key: Option<String>,
    pub plugin_ids: Vec<(String, String)>,
    pub flags: u32,
    pub creators: Vec<String>,
    pub description: String,
    pub features: Vec<String>,
    pub extra_info: Vec<(String, String)>,
}

impl DiscoveredPreset {
    /// An extra-info value by key.
    pub fn extra(&self, key: &str) -> Option<&str> {
        self.extra_info
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// What indexing the bundle found.
#[derive(Clone, Debug, Default)]
pub struct Index {
    /// Each provider's (id, name, vendor).
    pub providers: Vec<(String, String, String)>,
    /// Each declared file type's (name, extension).
    pub filetypes: Vec<(String, String)>,
    pub locations: Vec<DeclaredLocation>,
    pub presets: Vec<DiscoveredPreset>,
    /// Errors the provider reported while answering.
    pub errors: Vec<String>,
}

fn text(s: &CStr) -> String {
    s.to_string_lossy().into_owned()
}

#[derive(Default)]
struct Indexer {
    filetypes: Vec<(String, String)>,
    locations: Vec<DeclaredLocation>,
}

impl IndexerImpl for Indexer {
    fn declare_filetype(&mut self, file_type: FileType) -> Result<(), HostError> {
        self.filetypes.push((
            text(file_type.name),
            file_type.file_extension.map(text).unwrap_or_default(),
        ));
        Ok(())
    }

    fn declare_location(&mut self, location: LocationInfo) -> Result<(), HostError> {
        let place = match location.location {
            Location::Plugin => Place::Plugin,
            Location::File { path } => Place::File(PathBuf::from(text(path))),
        };
        self.locations.push(DeclaredLocation {
            name: text(location.name),
            flags: location.flags.bits(),
            place,
        });
        Ok(())
    }

    fn declare_soundpack(&mut self, _soundpack: Soundpack) -> Result<(), HostError> {
        Ok(())
    }
}

#[derive(Default)]
struct Receiver {
    file: Option<PathBuf>,
    presets: Vec<DiscoveredPreset>,
    errors: Vec<String>,
}

impl Receiver {
    fn current(&mut self) -> &mut DiscoveredPreset {
        self.presets
            .last_mut()
            .expect("metadata before begin_preset")
    }
}

impl MetadataReceiverImpl for Receiver {
    fn on_error(&mut self, error_code: i32, error_message: Option<&CStr>) {
        self.errors.push(format!(
            "{error_code}: {}",
            error_message.map(text).unwrap_or_default()
        ));
    }

    fn begin_preset(
        &mut self,
        name: Option<&CStr>,
        load_key: Option<&CStr>,
    ) -> Result<(), HostError> {
        self.presets.push(DiscoveredPreset {
            file: self.file.clone(),
            name: name.map(text).unwrap_or_default(),
            load_key: load_key.map(text),
            ..DiscoveredPreset::default()
        });
        Ok(())
    }

    fn add_plugin_id(&mut self, plugin_id: UniversalPluginId) {
        let id = (text(plugin_id.abi), text(plugin_id.id));
        self.current().plugin_ids.push(id);
    }

    fn set_soundpack_id(&mut self, _soundpack_id: &CStr) {}

    fn set_flags(&mut self, flags: Flags) {
        self.current().flags = flags.bits();
    }

    fn add_creator(&mut self, creator: &CStr) {
        self.current().creators.push(text(creator));
    }

    fn set_description(&mut self, description: &CStr) {
        self.current().description = text(description);
    }

    fn set_timestamps(&mut self, _creation: Option<Timestamp>, _modification: Option<Timestamp>) {}

    fn add_feature(&mut self, feature: &CStr) {
        self.current().features.push(text(feature));
    }

    fn add_extra_info(&mut self, key: &CStr, value: &CStr) {
        let pair = (text(key), text(value));
        self.current().extra_info.push(pair);
    }
}

/// The files of a declared file location that the host would index: the folder's files with
/// one of the declared extensions (or the file itself), sorted.
fn files_at(path: &Path, extensions: &[String]) -> Vec<PathBuf> {
    let wanted = |p: &Path| {
        extensions.iter().any(|x| x.is_empty())
            || p.extension()
                .is_some_and(|e| extensions.iter().any(|x| e == x.as_str()))
    };
    if path.is_file() {
        return vec![path.to_path_buf()];
    }
    let mut out: Vec<PathBuf> = std::fs::read_dir(path)
        .map(|rd| {
            rd.flatten()
                .map(|e| e.path())
                .filter(|p| p.is_file() && wanted(p))
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

/// Indexes the bundle's presets as a host does: every provider of the preset-discovery factory,
/// every location it declares, every file of a declared type in its file locations.
pub fn index() -> Index {
    let entry = crate::load_entry();
    let info = crate::host_info();
    let mut index = Index::default();
    let Some(factory) = entry.get_factory::<PresetDiscoveryFactory>() else {
        return index;
    };
    let ids: Vec<CString> = factory
        .provider_descriptors()
        .filter_map(|d| {
            index.providers.push((
                d.id().map(text).unwrap_or_default(),
                d.name().map(text).unwrap_or_default(),
                d.vendor().map(text).unwrap_or_default(),
            ));
            d.id().map(CStr::to_owned)
        })
        .collect();
    for id in ids {
        let mut provider = Provider::instantiate(Indexer::default(), &entry, &id, &info)
            .unwrap_or_else(|e| panic!("provider {id:?}: {e}"));
        let declared = provider.indexer().locations.clone();
        let filetypes = provider.indexer().filetypes.clone();
        let extensions: Vec<String> = filetypes.iter().map(|(_, x)| x.clone()).collect();
        index.filetypes.extend(filetypes);
        for location in &declared {
            match &location.place {
                Place::Plugin => {
                    let mut receiver = Receiver::default();
                    provider.get_metadata(Location::Plugin, &mut receiver);
                    index.presets.extend(receiver.presets);
                    index.errors.extend(receiver.errors);
                }
                Place::File(path) => {
                    for file in files_at(path, &extensions) {
                        let c = CString::new(file.to_string_lossy().as_bytes()).expect("path");
                        let mut receiver = Receiver {
                            file: Some(file.clone()),
                            ..Receiver::default()
                        };
                        provider.get_metadata(Location::File { path: &c }, &mut receiver);
                        index.presets.extend(receiver.presets);
                        index.errors.extend(receiver.errors);
                    }
                }
            }
        }
        index.locations.extend(declared);
    }
    index
}
