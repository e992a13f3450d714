//! CLAP preset discovery and preset load (Ressort's patch 9, vendor/README.md).
//!
//! Preset discovery (`clap.preset-discovery-factory/2`) is a factory beside the plugin factory:
//! a host indexes a plugin's presets without making an instance. For every plugin type whose
//! [`ClapPlugin::CLAP_PRESET_DISCOVERY`] is set, the factory offers one provider, which declares
//! the plugin's [`PresetFiletype`]s and [`PresetLocation`]s when the host initialises it, and
//! answers the host's `get_metadata` at a location with [`ClapPlugin::clap_preset_metadata`].
//!
//! Preset load (`clap.preset-load/2`) is a plugin extension: the host hands a location and a load
//! key it found by discovery to the [`ClapPresetLoader`] the plugin gave at creation
//! ([`ClapPlugin::clap_preset_loader`]), and is told `loaded` or `on_error` afterwards.

use clap_sys::factory::preset_discovery::{
    CLAP_PRESET_DISCOVERY_IS_DEMO_CONTENT, CLAP_PRESET_DISCOVERY_IS_FACTORY_CONTENT,
    CLAP_PRESET_DISCOVERY_IS_FAVORITE, CLAP_PRESET_DISCOVERY_IS_USER_CONTENT,
    CLAP_PRESET_DISCOVERY_LOCATION_FILE, CLAP_PRESET_DISCOVERY_LOCATION_PLUGIN,
    clap_preset_discovery_filetype, clap_preset_discovery_indexer, clap_preset_discovery_location,
    clap_preset_discovery_location_kind, clap_preset_discovery_metadata_receiver,
    clap_preset_discovery_provider, clap_preset_discovery_provider_descriptor,
};
use clap_sys::universal_plugin_id::clap_universal_plugin_id;
use clap_sys::version::CLAP_VERSION;
use std::ffi::{CStr, CString, c_void};
use std::marker::PhantomData;
use std::os::raw::c_char;
use std::path::{Path, PathBuf};

use crate::wrapper::clap::ClapPlugin;

/// Who made a preset and whether the user likes it (the CLAP flags of a location or a preset).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PresetFlags {
    pub factory: bool,
    pub user: bool,
    pub demo: bool,
    pub favorite: bool,
}

impl PresetFlags {
    /// The CLAP bits (`CLAP_PRESET_DISCOVERY_IS_*`).
    pub fn bits(self) -> u32 {
        let mut bits = 0;
        for (set, bit) in [
            (self.factory, CLAP_PRESET_DISCOVERY_IS_FACTORY_CONTENT),
            (self.user, CLAP_PRESET_DISCOVERY_IS_USER_CONTENT),
            (self.demo, CLAP_PRESET_DISCOVERY_IS_DEMO_CONTENT),
            (self.favorite, CLAP_PRESET_DISCOVERY_IS_FAVORITE),
        ] {
            if set {
                bits |= bit;
            }
        }
        bits
    }
}

/// Where presets are, as a host gives it back to the plugin.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PresetLocationRef<'a> {
    /// Inside the plugin: the presets are told apart by their load keys.
    Plugin,
    /// A file (in `get_metadata` and preset load) or a folder (as declared).
    File(&'a Path),
}

/// Where presets are, as the plugin declares it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PresetLocationKind {
    Plugin,
    File(PathBuf),
}

/// One location the provider declares to the host's indexer.
#[derive(Clone, Debug)]
pub struct PresetLocation {
    pub name: String,
    pub flags: PresetFlags,
    pub kind: PresetLocationKind,
}

/// A file type of the plugin's preset files (the host looks for them in file locations).
#[derive(Clone, Debug)]
pub struct PresetFiletype {
    pub name: String,
    pub description: String,
    /// Without the dot.
    pub extension: String,
}

/// What the host is told about one preset.
#[derive(Clone, Debug, Default)]
pub struct PresetMetadata {
    pub name: String,
    /// Tells presets of one location apart (required inside the plugin, none for a file that
    /// holds one preset).
    pub load_key: Option<String>,
    pub flags: PresetFlags,
    pub creators: Vec<String>,
    pub description: Option<String>,
    /// Free-form features (tags, categories) for the host's browser.
    pub features: Vec<String>,
    /// Key/value pairs the host may show.
    pub extra_info: Vec<(String, String)>,
}

/// Loads presets the host found by discovery. Made once by [`ClapPlugin::clap_preset_loader`]
/// and called on the main thread; it shares with the plugin what it needs (the plugin itself is
/// not locked).
pub trait ClapPresetLoader: Send + Sync {
    /// Starts playing the preset. An error is reported to the host with its message.
    fn load(&self, location: PresetLocationRef<'_>, load_key: Option<&str>) -> Result<(), String>;
}

/// A string for C: interior NULs are dropped rather than refusing the whole string.
pub(crate) fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', "")).unwrap_or_default()
}

/// A location handed over by the host, or None when the kind is unknown or a file location has
/// no path.
///
/// # Safety
///
/// `location` is null or a NUL-terminated string.
pub(crate) unsafe fn location_from_raw<'a>(
    kind: clap_preset_discovery_location_kind,
    location: *const c_char,
) -> Option<PresetLocationRef<'a>> {
    match kind {
        CLAP_PRESET_DISCOVERY_LOCATION_PLUGIN => Some(PresetLocationRef::Plugin),
        CLAP_PRESET_DISCOVERY_LOCATION_FILE if !location.is_null() => {
            let path = unsafe { CStr::from_ptr(location) }.to_str().ok()?;
            Some(PresetLocationRef::File(Path::new(path)))
        }
        _ => None,
    }
}

/// The optional string a host passed (a load key), None when null or not UTF-8.
///
/// # Safety
///
/// `s` is null or a NUL-terminated string.
pub(crate) unsafe fn optional_str<'a>(s: *const c_char) -> Option<&'a str> {
    (!s.is_null())
        .then(|| unsafe { CStr::from_ptr(s) }.to_str().ok())
        .flatten()
}

/// The factory's entry for one plugin type: its provider's descriptor and how to make one.
pub struct PresetProviderEntry {
    id: CString,
    _name: CString,
    _vendor: CString,
    descriptor: clap_preset_discovery_provider_descriptor,
    create: unsafe fn(
        &'static clap_preset_discovery_provider_descriptor,
        *const clap_preset_discovery_indexer,
    ) -> *const clap_preset_discovery_provider,
}

unsafe impl Send for PresetProviderEntry {}
unsafe impl Sync for PresetProviderEntry {}

impl PresetProviderEntry {
    /// The entry of `P`, when it declares presets. Its id is the plugin's CLAP id followed by
    /// `.presets`.
    pub fn for_plugin<P: ClapPlugin>() -> Option<Self> {
        if !P::CLAP_PRESET_DISCOVERY {
            return None;
        }
        let id = c_string(&format!("{}.presets", P::CLAP_ID));
        let name = c_string(&format!("{} presets", P::NAME));
        let vendor = c_string(P::VENDOR);
        let descriptor = clap_preset_discovery_provider_descriptor {
            clap_version: CLAP_VERSION,
            id: id.as_ptr(),
            name: name.as_ptr(),
            vendor: vendor.as_ptr(),
        };
        Some(Self {
            id,
            _name: name,
            _vendor: vendor,
            descriptor,
            create: Provider::<P>::create,
        })
    }

    pub fn descriptor(&'static self) -> &'static clap_preset_discovery_provider_descriptor {
        &self.descriptor
    }

    /// Whether `id` names this provider.
    pub fn is(&self, id: &CStr) -> bool {
        self.id.as_c_str() == id
    }

    /// A new provider for the host's indexer (the host initialises and destroys it).
    ///
    /// # Safety
    ///
    /// `indexer` is the host's, valid until the provider is destroyed.
    pub unsafe fn create(
        &'static self,
        indexer: *const clap_preset_discovery_indexer,
    ) -> *const clap_preset_discovery_provider {
        if indexer.is_null() {
            return std::ptr::null();
        }
        unsafe { (self.create)(&self.descriptor, indexer) }
    }
}

/// One provider instance. `raw` comes first, so the host's pointer is the provider's.
#[repr(C)]
struct Provider<P: ClapPlugin> {
    raw: clap_preset_discovery_provider,
    indexer: *const clap_preset_discovery_indexer,
    /// The strings of the declared file types and locations, kept while the host may read
    /// them.
    kept: Vec<CString>,
    _plugin: PhantomData<P>,
}

impl<P: ClapPlugin> Provider<P> {
    unsafe fn create(
        descriptor: &'static clap_preset_discovery_provider_descriptor,
        indexer: *const clap_preset_discovery_indexer,
    ) -> *const clap_preset_discovery_provider {
        let provider = Box::new(Self {
            raw: clap_preset_discovery_provider {
                desc: descriptor,
                provider_data: std::ptr::null_mut(),
                init: Some(Self::init),
                destroy: Some(Self::destroy),
                get_metadata: Some(Self::get_metadata),
                get_extension: Some(Self::get_extension),
            },
            indexer,
            kept: Vec::new(),
            _plugin: PhantomData,
        });
        let ptr = Box::into_raw(provider);
        unsafe { (*ptr).raw.provider_data = ptr as *mut c_void };
        ptr as *const clap_preset_discovery_provider
    }

    /// # Safety
    ///
    /// `provider` was made by [`Self::create`] and not destroyed.
    unsafe fn this<'a>(provider: *const clap_preset_discovery_provider) -> Option<&'a mut Self> {
        if provider.is_null() {
            return None;
        }
        let data = unsafe { (*provider).provider_data } as *mut Self;
        (!data.is_null()).then(|| unsafe { &mut *data })
    }

    /// Declares the file types and the locations to the indexer.
    unsafe extern "C" fn init(provider: *const clap_preset_discovery_provider) -> bool {
        let Some(this) = (unsafe { Self::this(provider) }) else {
            return false;
        };
        let indexer = unsafe { &*this.indexer };
        for filetype in P::clap_preset_filetypes() {
            let name = c_string(&filetype.name);
            let description = c_string(&filetype.description);
            let extension = c_string(&filetype.extension);
            let raw = clap_preset_discovery_filetype {
                name: name.as_ptr(),
                description: description.as_ptr(),
                file_extension: extension.as_ptr(),
            };
            if let Some(declare) = indexer.declare_filetype {
                unsafe { declare(this.indexer, &raw) };
            }
            this.kept.extend([name, description, extension]);
        }
        for location in P::clap_preset_locations() {
            let name = c_string(&location.name);
            let (kind, path) = match &location.kind {
                PresetLocationKind::Plugin => (CLAP_PRESET_DISCOVERY_LOCATION_PLUGIN, None),
                PresetLocationKind::File(path) => (
                    CLAP_PRESET_DISCOVERY_LOCATION_FILE,
                    Some(c_string(&path.to_string_lossy())),
                ),
            };
            let raw = clap_preset_discovery_location {
                flags: location.flags.bits(),
                name: name.as_ptr(),
                kind,
                location: path.as_ref().map_or(std::ptr::null(), |p| p.as_ptr()),
            };
            if let Some(declare) = indexer.declare_location {
                unsafe { declare(this.indexer, &raw) };
            }
            this.kept.push(name);
            this.kept.extend(path);
        }
        true
    }

    unsafe extern "C" fn destroy(provider: *const clap_preset_discovery_provider) {
        if let Some(this) = unsafe { Self::this(provider) } {
            drop(unsafe { Box::from_raw(this as *mut Self) });
        }
    }

    /// Tells the receiver about every preset at `location`.
    unsafe extern "C" fn get_metadata(
        _provider: *const clap_preset_discovery_provider,
        location_kind: clap_preset_discovery_location_kind,
        location: *const c_char,
        receiver: *const clap_preset_discovery_metadata_receiver,
    ) -> bool {
        if receiver.is_null() {
            return false;
        }
        let r = unsafe { &*receiver };
        let error = |message: &str| {
            if let Some(on_error) = r.on_error {
                let message = c_string(message);
                unsafe { on_error(receiver, 0, message.as_ptr()) };
            }
            false
        };
        let Some(where_) = (unsafe { location_from_raw(location_kind, location) }) else {
            return error("unknown preset location");
        };
        let presets = match P::clap_preset_metadata(where_) {
            Ok(presets) => presets,
            Err(e) => return error(&e),
        };
        let abi = c"clap";
        let plugin_id = c_string(P::CLAP_ID);
        for preset in presets {
            let name = c_string(&preset.name);
            let key = preset.load_key.as_deref().map(c_string);
            let Some(begin) = r.begin_preset else {
                return false;
            };
            let go_on = unsafe {
                begin(
                    receiver,
                    name.as_ptr(),
                    key.as_ref().map_or(std::ptr::null(), |k| k.as_ptr()),
                )
            };
            if !go_on {
                break;
            }
            if let Some(add) = r.add_plugin_id {
                let id = clap_universal_plugin_id {
                    abi: abi.as_ptr(),
                    id: plugin_id.as_ptr(),
                };
                unsafe { add(receiver, &id) };
            }
            if let Some(set) = r.set_flags {
                unsafe { set(receiver, preset.flags.bits()) };
            }
            if let Some(add) = r.add_creator {
                for creator in &preset.creators {
                    let c = c_string(creator);
                    unsafe { add(receiver, c.as_ptr()) };
                }
            }
            if let (Some(set), Some(d)) = (r.set_description, &preset.description) {
                let d = c_string(d);
                unsafe { set(receiver, d.as_ptr()) };
            }
            if let Some(add) = r.add_feature {
                for feature in &preset.features {
                    let f = c_string(feature);
                    unsafe { add(receiver, f.as_ptr()) };
                }
            }
            if let Some(add) = r.add_extra_info {
                for (key, value) in &preset.extra_info {
                    let (k, v) = (c_string(key), c_string(value));
                    unsafe { add(receiver, k.as_ptr(), v.as_ptr()) };
                }
            }
        }
        true
    }

    unsafe extern "C" fn get_extension(
        _provider: *const clap_preset_discovery_provider,
        _id: *const c_char,
    ) -> *const c_void {
        std::ptr::null()
    }
}
