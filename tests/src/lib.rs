//! A small CLAP test host for end-to-end tests of the bundled Ressort plugin.
//!
//! It loads the bundle (`target/bundled/Ressort.clap`, or the file named by the `RESSORT_CLAP`
//! environment variable) with [`clack_host`], creates an instance, activates it and calls its
//! `process()` with stereo sidechain (and optional main) input, note, pitch-bend and parameter
//! events, exactly as a DAW would. Everything runs on the calling thread: the host declares the
//! thread-check extension and tells the plugin which role ("main" or "audio") the thread has at
//! each call, so the plugin's realtime checks (the bundle is built with
//! `assert_process_allocs`, which aborts on any allocation in `process()`) see a realistic
//! picture.
//!
//! Host callbacks are answered: `request_callback` runs the plugin's `on_main_thread` at the
//! next [`TestPlugin::idle`] (called after every block and state load), `request_restart`
//! reactivates the plugin there, the log extension prints the plugin's messages to stderr and
//! keeps them, and parameter, state, audio-port and note-port notifications are counted
//! ([`HostCounters`]).
//!
//! ```no_run
//! use ressort_tests::{Score, TestPlugin};
//! let mut plugin = TestPlugin::new();
//! plugin.activate(48_000.0, 1, 512);
//! let out = plugin.render(0.5, 512, &Score::new().impulse(0, -0.5));
//! assert!(out.audio.is_finite());
//! ```

use clack_extensions::audio_ports::{
    AudioPortFlags, AudioPortInfoBuffer, AudioPortRescanFlags, HostAudioPorts, HostAudioPortsImpl,
    PluginAudioPorts,
};
use clack_extensions::audio_ports_config::{
    AudioPortsConfigBuffer, HostAudioPortsConfig, HostAudioPortsConfigImpl, PluginAudioPortsConfig,
};
use clack_extensions::gui::{
    GuiApiType, GuiConfiguration, GuiSize, HostGui, HostGuiImpl, PluginGui, Window,
};
use clack_extensions::log::{HostLog, HostLogImpl, LogSeverity};
use clack_extensions::note_ports::{
    HostNotePorts, HostNotePortsImpl, NoteDialects, NotePortInfoBuffer, NotePortRescanFlags,
    PluginNotePorts,
};
use clack_extensions::params::{
    HostParams, HostParamsImplMainThread, HostParamsImplShared, ParamClearFlags, ParamInfoBuffer,
    ParamRescanFlags, PluginParams,
};
use clack_extensions::preset_discovery::prelude::{HostPresetLoad, Location, PluginPresetLoad};
use clack_extensions::preset_discovery::HostPresetLoadImpl;
use clack_extensions::remote_controls::{
    HostRemoteControls, HostRemoteControlsImpl, PluginRemoteControls, RemoteControlsPageBuffer,
};
use clack_extensions::render::{PluginRender, RenderMode};
use clack_extensions::state::{HostState, HostStateImpl, PluginState, StateError};
use clack_extensions::thread_check::{HostThreadCheck, HostThreadCheckImpl};
use clack_host::events::event_types::{
    MidiEvent, NoteEndEvent, NoteExpressionEvent, NoteOffEvent, NoteOnEvent, ParamModEvent,
    ParamValueEvent, TransportEvent, TransportFlags,
};
use clack_host::events::{EventFlags, Match};
use clack_host::host::HostError;
use clack_host::prelude::*;
use clack_host::utils::{BeatTime, SecondsTime};
use std::cell::Cell;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

pub use clack_host::events::event_types::NoteExpressionType;
pub use clack_host::prelude::{ClapId, ProcessStatus};

/// The plugin's CLAP id.
pub const PLUGIN_ID: &str = "audio.ressort.ressort";

/// The environment variable that overrides the bundle's path.
pub const BUNDLE_ENV: &str = "RESSORT_CLAP";

/// The command that builds the bundle the tests load.
pub const BUILD_COMMAND: &str =
    "cd /work/main && cargo xtask bundle ressort-plugin --features assert_process_allocs";

/// Where the tests find the plugin: `$RESSORT_CLAP`, or `target/bundled/Ressort.clap` of the
/// workspace.
pub fn bundle_path() -> PathBuf {
    match std::env::var_os(BUNDLE_ENV) {
        Some(p) if !p.is_empty() => PathBuf::from(p),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/bundled/Ressort.clap"),
    }
}

/// Loads the bundle's entry. Panics with the command that builds it when it is missing: the
/// tests never skip silently.
/// How the test host introduces itself to the plugin and to its preset providers.
pub fn host_info() -> HostInfo {
    HostInfo::new(
        "Ressort end-to-end tests",
        "Ressort",
        "https://ressort.audio",
        env!("CARGO_PKG_VERSION"),
    )
    .expect("host info")
}

pub fn load_entry() -> PluginEntry {
    let path = bundle_path();
    if !path.exists() {
        panic!(
            "the Ressort CLAP bundle was not found at {}.\nBuild it with:\n    {BUILD_COMMAND}\n\
             or point {BUNDLE_ENV} at a bundle.",
            path.display()
        );
    }
    // SAFETY: loading a dynamic library runs its initialisers; the bundle is our own plugin.
    unsafe { PluginEntry::load(&path) }.unwrap_or_else(|e| {
        panic!(
            "could not load the CLAP bundle {}: {e}\nRebuild it with:\n    {BUILD_COMMAND}",
            path.display()
        )
    })
}

pub mod discovery;
mod host;
mod isolation;
mod measure;
mod models;
mod plugin;
mod score;

pub mod fixtures;
pub mod presets;
pub mod screen;
pub mod state;

pub use host::*;
pub use isolation::*;
pub use measure::*;
pub use models::*;
pub use plugin::*;
pub use score::*;
