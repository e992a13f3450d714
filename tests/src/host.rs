//! The host side of the CLAP test host: thread roles and the host's handlers (log, GUI,
//! parameters, thread check, state, ports), which count what the plugin asks of it.

use super::*;

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Role {
    Other,
    Main,
    Audio,
}

thread_local! {
    /// What the current thread is for the plugin: the thread that created a [`TestPlugin`] is
    /// its main thread, and becomes the audio thread while the host calls audio-thread
    /// functions. Const-initialised: reading it never allocates (it is read inside `process()`).
    pub(crate) static ROLE: Cell<Role> = const { Cell::new(Role::Other) };
}

/// Runs `f` with the current thread marked as the audio thread.
pub(crate) fn as_audio_thread<R>(f: impl FnOnce() -> R) -> R {
    let previous = ROLE.with(|r| r.replace(Role::Audio));
    let result = f();
    ROLE.with(|r| r.set(previous));
    result
}

// ---------------------------------------------------------------------------------------------
// Host handlers
// ---------------------------------------------------------------------------------------------

/// The host type: its handlers and extensions.
#[derive(Debug)]
pub struct TestHost;

/// One message from the plugin's log.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LogMessage {
    pub severity: String,
    pub text: String,
}

/// The thread-safe part of the host: requests that can come from any thread.
#[derive(Debug, Default)]
pub struct HostShared {
    pub(crate) callback_requested: AtomicBool,
    pub(crate) restart_requested: AtomicBool,
    pub(crate) process_requested: AtomicBool,
    pub(crate) flush_requested: AtomicBool,
    pub(crate) log: Mutex<Vec<LogMessage>>,
}

impl SharedHandler<'_> for HostShared {
    fn request_restart(&self) {
        self.restart_requested.store(true, Ordering::Release);
    }

    fn request_process(&self) {
        self.process_requested.store(true, Ordering::Release);
    }

    fn request_callback(&self) {
        self.callback_requested.store(true, Ordering::Release);
    }
}

impl HostLogImpl for HostShared {
    fn log(&self, severity: LogSeverity, message: &str) {
        eprintln!("[plugin log, {severity}] {message}");
        let mut log = self.log.lock().unwrap_or_else(|e| e.into_inner());
        log.push(LogMessage {
            severity: severity.to_string(),
            text: message.to_string(),
        });
    }
}

/// The editor's requests to the host window (the test host accepts them; the editor tests
/// drive sizes through `gui.set_size`).
impl HostGuiImpl for HostShared {
    fn resize_hints_changed(&self) {}

    fn request_resize(&self, _new_size: GuiSize) -> Result<(), HostError> {
        Ok(())
    }

    fn request_show(&self) -> Result<(), HostError> {
        Ok(())
    }

    fn request_hide(&self) -> Result<(), HostError> {
        Ok(())
    }

    fn closed(&self, _was_destroyed: bool) {}
}

impl HostParamsImplShared for HostShared {
    fn request_flush(&self) {
        self.flush_requested.store(true, Ordering::Release);
    }
}

impl HostThreadCheckImpl for HostShared {
    fn is_main_thread(&self) -> bool {
        ROLE.with(|r| r.get()) == Role::Main
    }

    fn is_audio_thread(&self) -> bool {
        ROLE.with(|r| r.get()) == Role::Audio
    }
}

/// How often the plugin notified the host of something, on the main thread.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HostCounters {
    /// `clap_host_params.rescan` calls, and the union of their flags.
    pub param_rescans: u32,
    pub param_rescan_flags: u32,
    pub param_clears: u32,
    /// `clap_host_state.mark_dirty` calls.
    pub state_dirty: u32,
    pub audio_port_rescans: u32,
    pub audio_ports_config_rescans: u32,
    pub note_port_rescans: u32,
    /// `on_main_thread` calls made after a `request_callback`.
    pub main_thread_callbacks: u32,
    /// Reactivations made after a `request_restart`.
    pub restarts: u32,
    /// `request_flush` calls seen (the host flushes at the next idle when inactive).
    pub flush_requests: u32,
    /// `clap_host_remote_controls.changed` calls: the plugin's pages changed.
    pub remote_controls_changed: u32,
}

/// The main-thread part of the host.
#[derive(Debug, Default)]
pub struct HostMainThread {
    pub(crate) counters: Cell<HostCounters>,
    /// What the plugin told the host after each preset load (`clap_host_preset_load`):
    /// `Ok(load key or path)` for `loaded`, `Err(message)` for `on_error`.
    pub(crate) preset_loads: std::cell::RefCell<Vec<Result<String, String>>>,
}

impl HostMainThread {
    pub(crate) fn count(&self, f: impl FnOnce(&mut HostCounters)) {
        let mut c = self.counters.get();
        f(&mut c);
        self.counters.set(c);
    }
}

impl MainThreadHandler<'_> for HostMainThread {}

impl HostParamsImplMainThread for HostMainThread {
    fn rescan(&self, flags: ParamRescanFlags) {
        self.count(|c| {
            c.param_rescans += 1;
            c.param_rescan_flags |= flags.bits();
        });
    }

    fn clear(&self, _param_id: ClapId, _flags: ParamClearFlags) {
        self.count(|c| c.param_clears += 1);
    }
}

impl HostStateImpl for HostMainThread {
    fn mark_dirty(&self) {
        self.count(|c| c.state_dirty += 1);
    }
}

impl HostAudioPortsImpl for HostMainThread {
    fn is_rescan_flag_supported(&self, _flag: AudioPortRescanFlags) -> bool {
        true
    }

    fn rescan(&self, _flags: AudioPortRescanFlags) {
        self.count(|c| c.audio_port_rescans += 1);
    }
}

impl HostAudioPortsConfigImpl for HostMainThread {
    fn rescan(&self) {
        self.count(|c| c.audio_ports_config_rescans += 1);
    }
}

impl HostNotePortsImpl for HostMainThread {
    fn supported_dialects(&self) -> NoteDialects {
        NoteDialects::CLAP | NoteDialects::MIDI
    }

    fn rescan(&self, _flags: NotePortRescanFlags) {
        self.count(|c| c.note_port_rescans += 1);
    }
}

impl HostRemoteControlsImpl for HostMainThread {
    fn changed(&self) {
        self.count(|c| c.remote_controls_changed += 1);
    }

    fn suggest_page(&self, _page_id: ClapId) {}
}

fn location_text(location: Location, load_key: Option<&std::ffi::CStr>) -> String {
    let key = load_key.map(|k| k.to_string_lossy().into_owned());
    match location {
        Location::Plugin => format!("plugin:{}", key.unwrap_or_default()),
        Location::File { path } => path.to_string_lossy().into_owned(),
    }
}

impl HostPresetLoadImpl for HostMainThread {
    fn on_error(
        &self,
        location: Location,
        load_key: Option<&std::ffi::CStr>,
        _os_error: i32,
        message: Option<&std::ffi::CStr>,
    ) {
        let message = message.map(|m| m.to_string_lossy().into_owned());
        self.preset_loads.borrow_mut().push(Err(format!(
            "{}: {}",
            location_text(location, load_key),
            message.unwrap_or_default()
        )));
    }

    fn loaded(&self, location: Location, load_key: Option<&std::ffi::CStr>) {
        self.preset_loads
            .borrow_mut()
            .push(Ok(location_text(location, load_key)));
    }
}

impl HostHandlers for TestHost {
    type Shared<'a> = HostShared;
    type MainThread<'a> = HostMainThread;
    type AudioProcessor<'a> = ();

    fn declare_extensions(builder: &mut HostExtensions<Self>, _shared: &Self::Shared<'_>) {
        builder
            .register::<HostLog>()
            .register::<HostParams>()
            .register::<HostState>()
            .register::<HostAudioPorts>()
            .register::<HostAudioPortsConfig>()
            .register::<HostNotePorts>()
            .register::<HostThreadCheck>()
            .register::<HostRemoteControls>()
            .register::<HostPresetLoad>()
            .register::<HostGui>();
    }
}
