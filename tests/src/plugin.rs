//! The plugin instance in the test host: loading, activation, `process()`, the editor,
//! parameters, state and the callbacks it asks for.

use super::*;

/// The plugin's extensions, queried once after instantiation.
#[derive(Clone, Copy)]
pub(crate) struct Extensions {
    params: Option<PluginParams>,
    state: Option<PluginState>,
    audio_ports: Option<PluginAudioPorts>,
    audio_ports_config: Option<PluginAudioPortsConfig>,
    note_ports: Option<PluginNotePorts>,
    gui: Option<PluginGui>,
    remote_controls: Option<PluginRemoteControls>,
    preset_load: Option<PluginPresetLoad>,
    render: Option<PluginRender>,
}

/// A CLAP remote-controls page as the host reads it.
#[derive(Clone, Debug, PartialEq)]
pub struct RemotePage {
    pub section: String,
    pub name: String,
    /// The eight slots: a parameter id, or None for an empty one.
    pub params: [Option<ClapId>; 8],
}

/// Host-side buffers of an active plugin, allocated at activation.
pub(crate) struct Io {
    config: PluginAudioConfiguration,
    /// The plugin's input ports, in order, with one buffer per channel.
    inputs: Vec<(PortDesc, Vec<Vec<f32>>)>,
    outputs: Vec<(PortDesc, Vec<Vec<f32>>)>,
    input_ports: AudioPorts,
    output_ports: AudioPorts,
    events: EventBuffer,
    out_events: EventBuffer,
    steady_time: u64,
}

/// One instance of the plugin, loaded from the bundle, with its host.
pub struct TestPlugin {
    /// Declared before `instance`: dropped (stopped and deactivated) first.
    processor: Option<StartedPluginAudioProcessor<TestHost>>,
    io: Option<Io>,
    ext: Extensions,
    /// Parameter values the plugin sent to the host (`CLAP_EVENT_PARAM_VALUE` in the output
    /// events of `process()` and `flush()`), in order.
    param_output: Vec<(ClapId, f64)>,
    /// Keys of the voices the plugin reported ended (CLAP note-end events), in order.
    note_ends: Vec<u16>,
    instance: PluginInstance<TestHost>,
}

impl fmt::Debug for TestPlugin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TestPlugin")
            .field("active", &self.io.as_ref().map(|io| io.config.sample_rate))
            .finish_non_exhaustive()
    }
}

impl Default for TestPlugin {
    fn default() -> Self {
        TestPlugin::new()
    }
}

impl TestPlugin {
    /// Loads the bundle and creates an instance that renders offline (CLAP render extension),
    /// as a DAW bouncing a project: every model it loads is prepared in full before it plays,
    /// so that a render never depends on a background thread's timing. The calling thread
    /// becomes the instance's main thread (and its audio thread during audio calls).
    pub fn new() -> TestPlugin {
        let mut plugin = TestPlugin::realtime();
        plugin.set_offline(true);
        plugin
    }

    /// [`TestPlugin::new`] in the render mode of a DAW playing live (the CLAP default): a
    /// script whose analyses are not kept plays at once on provisional facts, and the exact
    /// ones follow from a thread of the plugin.
    pub fn realtime() -> TestPlugin {
        ROLE.with(|r| r.set(Role::Main));
        let entry = load_entry();
        let info = crate::host_info();
        let id = std::ffi::CString::new(PLUGIN_ID).expect("plugin id");
        let factory = entry
            .get_plugin_factory()
            .expect("the bundle has no plugin factory");
        let ids: Vec<String> = factory
            .plugin_descriptors()
            .filter_map(|d| d.id().map(|i| i.to_string_lossy().into_owned()))
            .collect();
        assert!(
            ids.iter().any(|i| i == PLUGIN_ID),
            "the bundle does not contain {PLUGIN_ID}; it has {ids:?}"
        );
        let instance = PluginInstance::<TestHost>::new(
            |_| HostShared::default(),
            |_| HostMainThread::default(),
            &entry,
            &id,
            &info,
        )
        .unwrap_or_else(|e| panic!("could not instantiate {PLUGIN_ID}: {e}"));
        let shared = instance.plugin_shared_handle();
        let ext = Extensions {
            params: shared.get_extension(),
            state: shared.get_extension(),
            audio_ports: shared.get_extension(),
            audio_ports_config: shared.get_extension(),
            note_ports: shared.get_extension(),
            gui: shared.get_extension(),
            remote_controls: shared.get_extension(),
            preset_load: shared.get_extension(),
            render: shared.get_extension(),
        };
        let mut plugin = TestPlugin {
            processor: None,
            io: None,
            ext,
            param_output: Vec::new(),
            note_ends: Vec::new(),
            instance,
        };
        plugin.idle();
        plugin
    }

    /// Sets the render mode (CLAP render extension): offline or realtime. While active, the
    /// plugin asks for a restart, which the next [`TestPlugin::idle`] performs.
    pub fn set_offline(&mut self, offline: bool) {
        let render = self.ext.render.expect("the plugin has no render extension");
        let mode = if offline {
            RenderMode::Offline
        } else {
            RenderMode::Realtime
        };
        let handle = self.instance.plugin_handle();
        render
            .set(&handle, mode)
            .unwrap_or_else(|e| panic!("render.set({mode:?}): {e}"));
        self.idle();
    }

    /// Opens the plugin's editor embedded in the X11 window `parent` (CLAP gui extension:
    /// `is_api_supported`, `create`, `set_scale`, `get_size`, `set_parent`, `show`), as a DAW
    /// does on Linux. Returns the editor's size.
    pub fn open_editor(&mut self, parent: u32) -> Result<(u32, u32), String> {
        let gui = self.ext.gui.ok_or("the plugin has no gui extension")?;
        let handle = self.instance.plugin_handle();
        let config = GuiConfiguration {
            api_type: GuiApiType::X11,
            is_floating: false,
        };
        if !gui.is_api_supported(&handle, config) {
            return Err("the plugin does not support embedded X11 editors".into());
        }
        gui.create(&handle, config)
            .map_err(|e| format!("gui.create: {e:?}"))?;
        let _ = gui.set_scale(&handle, 1.0);
        let size = gui.get_size(&handle).ok_or("gui.get_size failed")?;
        // SAFETY: `parent` is a live X11 window that outlives the editor (the caller destroys
        // the editor with `close_editor` first).
        unsafe { gui.set_parent(&handle, Window::from_x11_handle(parent as _)) }
            .map_err(|e| format!("gui.set_parent: {e:?}"))?;
        gui.show(&handle).map_err(|e| format!("gui.show: {e:?}"))?;
        Ok((size.width, size.height))
    }

    /// Whether the editor can be resized, and its size after asking for `width` × `height`.
    pub fn resize_editor(&mut self, width: u32, height: u32) -> Result<(bool, u32, u32), String> {
        let gui = self.ext.gui.ok_or("the plugin has no gui extension")?;
        let handle = self.instance.plugin_handle();
        let can = gui.can_resize(&handle);
        let asked = GuiSize { width, height };
        let adjusted = gui.adjust_size(&handle, asked).unwrap_or(asked);
        gui.set_size(&handle, adjusted)
            .map_err(|e| format!("gui.set_size: {e:?}"))?;
        let size = gui.get_size(&handle).ok_or("gui.get_size failed")?;
        Ok((can, size.width, size.height))
    }

    /// Hides and destroys the editor.
    pub fn close_editor(&mut self) {
        if let Some(gui) = self.ext.gui {
            let handle = self.instance.plugin_handle();
            let _ = gui.hide(&handle);
            gui.destroy(&handle);
        }
    }

    /// [`TestPlugin::close_editor`], then waits (up to `timeout`) until the process has no
    /// more threads than `threads_before`: baseview tears its window thread down after
    /// `destroy` returns, and a process that exits meanwhile crashes in Mesa's EGL teardown
    /// (`eglTerminate` unloading the DRI driver during `exit`). Returns whether it got there.
    pub fn close_editor_and_wait(
        &mut self,
        threads_before: usize,
        timeout: std::time::Duration,
    ) -> bool {
        self.close_editor();
        let deadline = std::time::Instant::now() + timeout;
        loop {
            if thread_count() <= threads_before {
                return true;
            }
            if std::time::Instant::now() > deadline {
                return false;
            }
            self.idle();
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
    }

    /// The plugin's name from its descriptor.
    pub fn descriptor_name(&self) -> String {
        let factory = self
            .instance
            .entry()
            .get_plugin_factory()
            .expect("plugin factory");
        factory
            .plugin_descriptors()
            .find(|d| d.id().is_some_and(|i| i.to_bytes() == PLUGIN_ID.as_bytes()))
            .and_then(|d| d.name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_default()
    }

    // --- lifecycle -------------------------------------------------------------------------

    /// Activates at `sample_rate` with the given block-size bounds and starts processing.
    /// Panics if the plugin refuses (use [`TestPlugin::try_activate`] to test refusals).
    pub fn activate(&mut self, sample_rate: f64, min_frames: u32, max_frames: u32) {
        if let Err(e) = self.try_activate(sample_rate, min_frames, max_frames) {
            panic!("activation at {sample_rate} Hz, blocks {min_frames}..={max_frames}: {e}");
        }
    }

    /// Activates and starts processing; deactivates first if active.
    pub fn try_activate(
        &mut self,
        sample_rate: f64,
        min_frames: u32,
        max_frames: u32,
    ) -> Result<(), PluginInstanceError> {
        self.deactivate();
        let inputs = self.audio_ports(true);
        let outputs = self.audio_ports(false);
        let config = PluginAudioConfiguration {
            sample_rate,
            min_frames_count: min_frames,
            max_frames_count: max_frames,
        };
        let stopped = self.instance.activate(|_, _| (), config)?;
        let started = match as_audio_thread(|| stopped.start_processing()) {
            Ok(s) => s,
            Err(e) => {
                self.instance.deactivate(e.into_stopped_processor());
                return Err(PluginInstanceError::StartProcessingFailed);
            }
        };
        let frames = max_frames as usize;
        let buffers = |ports: Vec<PortDesc>| -> Vec<(PortDesc, Vec<Vec<f32>>)> {
            ports
                .into_iter()
                .map(|p| {
                    let channels = (0..p.channels).map(|_| vec![0.0; frames]).collect();
                    (p, channels)
                })
                .collect()
        };
        let channels = |ports: &[PortDesc]| ports.iter().map(|p| p.channels as usize).sum();
        self.io = Some(Io {
            config,
            input_ports: AudioPorts::with_capacity(channels(&inputs), inputs.len()),
            output_ports: AudioPorts::with_capacity(channels(&outputs), outputs.len()),
            inputs: buffers(inputs),
            outputs: buffers(outputs),
            events: EventBuffer::with_capacity(256),
            out_events: EventBuffer::with_capacity(256),
            steady_time: 0,
        });
        self.processor = Some(started);
        self.idle();
        Ok(())
    }

    /// Stops processing and deactivates, if active.
    pub fn deactivate(&mut self) {
        if let Some(started) = self.processor.take() {
            let stopped = as_audio_thread(|| started.stop_processing());
            self.instance.deactivate(stopped);
        }
        self.io = None;
        self.idle();
    }

    pub fn is_active(&self) -> bool {
        self.processor.is_some()
    }

    /// The active configuration.
    pub fn config(&self) -> Option<PluginAudioConfiguration> {
        self.io.as_ref().map(|io| io.config)
    }

    /// Calls the plugin's `reset()` (audio thread).
    pub fn reset(&mut self) {
        if let Some(p) = self.processor.as_mut() {
            as_audio_thread(|| p.reset());
        }
        self.idle();
    }

    /// The host's main-thread idle work: runs `on_main_thread` when the plugin asked for a
    /// callback, reactivates when it asked for a restart, and flushes parameters when it asked
    /// for a flush while inactive. Called after every block and state operation.
    pub fn idle(&mut self) {
        self.run_callbacks();
        if self.take_request(|s| &s.restart_requested) {
            if let Some(config) = self.config() {
                self.count(|c| c.restarts += 1);
                self.activate(
                    config.sample_rate,
                    config.min_frames_count,
                    config.max_frames_count,
                );
            }
        }
    }

    /// Reads and clears one of the plugin's requests.
    fn take_request(&self, flag: fn(&HostShared) -> &AtomicBool) -> bool {
        self.instance
            .access_shared_handler(|s| flag(s).swap(false, Ordering::AcqRel))
    }

    /// Runs `on_main_thread` if requested and flushes parameters if requested while inactive.
    fn run_callbacks(&mut self) {
        // A callback can request another one; bound the loop.
        for _ in 0..16 {
            if !self.take_request(|s| &s.callback_requested) {
                break;
            }
            self.instance.call_on_main_thread_callback();
            self.count(|c| c.main_thread_callbacks += 1);
        }
        if self.take_request(|s| &s.flush_requested) {
            self.count(|c| c.flush_requests += 1);
            if !self.is_active() {
                self.flush_params(&[]);
            }
        }
        // The host processes continuously: a process request needs no action.
        self.take_request(|s| &s.process_requested);
    }

    fn count(&self, f: impl FnOnce(&mut HostCounters)) {
        self.instance.access_handler(|h| h.count(f));
    }

    /// What the plugin notified the host of so far.
    pub fn counters(&self) -> HostCounters {
        self.instance.access_handler(|h| h.counters.get())
    }

    /// Everything the plugin wrote to the host's log.
    pub fn log(&self) -> Vec<LogMessage> {
        self.instance
            .access_shared_handler(|s| s.log.lock().unwrap_or_else(|e| e.into_inner()).clone())
    }

    // --- ports -----------------------------------------------------------------------------

    /// The plugin's audio ports in the current configuration.
    pub fn audio_ports(&mut self, is_input: bool) -> Vec<PortDesc> {
        let Some(ext) = self.ext.audio_ports else {
            return Vec::new();
        };
        let handle = self.instance.plugin_handle();
        let mut buffer = AudioPortInfoBuffer::new();
        (0..ext.count(&handle, is_input))
            .filter_map(|i| {
                ext.get(&handle, i, is_input, &mut buffer)
                    .map(|info| PortDesc {
                        name: String::from_utf8_lossy(info.name).into_owned(),
                        channels: info.channel_count,
                        is_main: info.flags.contains(AudioPortFlags::IS_MAIN),
                    })
            })
            .collect()
    }

    /// The names of the plugin's audio-port configurations.
    pub fn audio_port_configs(&mut self) -> Vec<String> {
        let Some(ext) = self.ext.audio_ports_config else {
            return Vec::new();
        };
        let handle = self.instance.plugin_handle();
        let mut buffer = AudioPortsConfigBuffer::new();
        (0..ext.count(&handle))
            .filter_map(|i| {
                ext.get(&handle, i, &mut buffer)
                    .map(|c| String::from_utf8_lossy(c.name).into_owned())
            })
            .collect()
    }

    /// Selects an audio-port configuration by name (inactive only).
    pub fn select_audio_config(&mut self, name: &str) -> Result<(), String> {
        if self.is_active() {
            return Err("the plugin is active".into());
        }
        let ext = self
            .ext
            .audio_ports_config
            .ok_or("no audio-ports-config extension")?;
        let handle = self.instance.plugin_handle();
        let mut buffer = AudioPortsConfigBuffer::new();
        let id = (0..ext.count(&handle))
            .filter_map(|i| {
                ext.get(&handle, i, &mut buffer)
                    .map(|c| (c.id, c.name.to_vec()))
            })
            .find(|(_, n)| n == name.as_bytes())
            .map(|(id, _)| id)
            .ok_or_else(|| format!("no audio-port configuration named {name:?}"))?;
        ext.select(&handle, id)
            .map_err(|_| format!("the plugin refused configuration {name:?}"))
    }

    /// The plugin's note ports.
    pub fn note_ports(&mut self, is_input: bool) -> Vec<NotePortDesc> {
        let Some(ext) = self.ext.note_ports else {
            return Vec::new();
        };
        let handle = self.instance.plugin_handle();
        let mut buffer = NotePortInfoBuffer::new();
        (0..ext.count(&handle, is_input))
            .filter_map(|i| {
                ext.get(&handle, i, is_input, &mut buffer)
                    .map(|info| NotePortDesc {
                        name: String::from_utf8_lossy(info.name).into_owned(),
                        dialects: info.supported_dialects.bits(),
                        preferred: info.preferred_dialect.map(|d| d as u32).unwrap_or(0),
                    })
            })
            .collect()
    }

    // --- processing ------------------------------------------------------------------------

    /// Calls `process()` once. Panics when the plugin is inactive, when `frames` is outside
    /// the activated bounds, or when the plugin returns `CLAP_PROCESS_ERROR`.
    pub fn process(&mut self, block: &Block) -> Processed<'_> {
        let status = self.process_inner(block);
        // Callbacks only: a restart would replace the output buffers read below.
        self.run_callbacks();
        let io = self.io.as_ref().expect("active");
        let main = io
            .outputs
            .iter()
            .find(|(p, _)| p.is_main)
            .or(io.outputs.first())
            .expect("the plugin has an output port");
        let n = block.frames;
        let left = &main.1[0][..n];
        let right = main.1.get(1).map(|c| &c[..n]).unwrap_or(left);
        Processed {
            left,
            right,
            status,
        }
    }

    /// Every output channel of the last `process()` call, `frames` long: the main port's
    /// first, then the other ports' in order.
    pub fn all_outputs(&self, frames: usize) -> Vec<Vec<f32>> {
        let io = self.io.as_ref().expect("active");
        let main = io.outputs.iter().filter(|(p, _)| p.is_main);
        let aux = io.outputs.iter().filter(|(p, _)| !p.is_main);
        main.chain(aux)
            .flat_map(|(_, channels)| channels.iter().map(|c| c[..frames].to_vec()))
            .collect()
    }

    fn process_inner(&mut self, block: &Block) -> ProcessStatus {
        let (Some(processor), Some(io)) = (self.processor.as_mut(), self.io.as_mut()) else {
            panic!("process() on an inactive plugin");
        };
        let n = block.frames;
        assert!(
            n >= 1 && n <= io.config.max_frames_count as usize,
            "block of {n} frames outside 1..={}",
            io.config.max_frames_count
        );
        for (port, channels) in io.inputs.iter_mut() {
            let source: &[&[f32]] = if port.is_main {
                block.main_input.as_ref().map_or(&[], |m| m.as_slice())
            } else {
                block.sidechain
            };
            for (c, buffer) in channels.iter_mut().enumerate() {
                let dst = &mut buffer[..n];
                dst.fill(0.0);
                if let Some(src) = source.get(c).copied() {
                    let m = src.len().min(n);
                    dst[..m].copy_from_slice(&src[..m]);
                }
            }
        }
        for (_, channels) in io.outputs.iter_mut() {
            for buffer in channels.iter_mut() {
                // Garbage the plugin must overwrite.
                buffer[..n].fill(f32::NAN);
            }
        }
        io.events.clear();
        let mut events: Vec<HostEvent> = block.events.to_vec();
        events.sort_by_key(HostEvent::time);
        for e in &events {
            assert!(
                (e.time() as usize) < n,
                "event at {} outside a block of {n} frames",
                e.time()
            );
            e.push_to(&mut io.events);
        }
        io.out_events.clear();

        let inputs =
            io.input_ports
                .with_input_buffers(io.inputs.iter_mut().map(|(_, channels)| {
                    AudioPortBuffer {
                        latency: 0,
                        channels: AudioPortBufferType::f32_input_only(
                            channels
                                .iter_mut()
                                .map(|c| InputChannel::variable(&mut c[..n])),
                        ),
                    }
                }));
        let mut outputs = io
            .output_ports
            .with_output_buffers(io.outputs.iter_mut().map(|(_, channels)| AudioPortBuffer {
                latency: 0,
                channels: AudioPortBufferType::f32_output_only(
                    channels.iter_mut().map(|c| &mut c[..n]),
                ),
            }));
        let in_events = InputEvents::from_buffer(&io.events);
        let mut out_events = OutputEvents::from_buffer(&mut io.out_events);
        let steady = io.steady_time;
        let transport = block
            .song_position
            .map(|p| playing_transport(p, io.config.sample_rate));
        let result = as_audio_thread(|| {
            processor.process(
                &inputs,
                &mut outputs,
                &in_events,
                &mut out_events,
                Some(steady),
                transport.as_ref(),
            )
        });
        io.steady_time += n as u64;
        collect_param_values(&io.out_events, &mut self.param_output);
        collect_note_ends(&io.out_events, &mut self.note_ends);
        match result {
            Ok(status) => status,
            Err(e) => panic!("process() failed: {e}"),
        }
    }

    /// Renders `seconds` of audio in blocks of `block_size` frames (the last one shorter),
    /// feeding the score. Events are delivered in the block that contains their time.
    pub fn render(&mut self, seconds: f64, block_size: usize, score: &Score) -> Rendered {
        let sr = self
            .config()
            .expect("render() on an inactive plugin")
            .sample_rate;
        let frames = (seconds * sr).round() as usize;
        self.render_frames(frames, block_size, score)
    }

    /// [`TestPlugin::render`] by frame count.
    pub fn render_frames(&mut self, frames: usize, block_size: usize, score: &Score) -> Rendered {
        self.render_song(frames, &[block_size], None, score)
    }

    /// Renders `frames` samples in blocks whose sizes cycle through `block_sizes`, feeding the
    /// score (event times from the render's start). With `song_start`, the transport plays
    /// and each block carries its song position, `song_start` at the render's first sample.
    pub fn render_song(
        &mut self,
        frames: usize,
        block_sizes: &[usize],
        song_start: Option<u64>,
        score: &Score,
    ) -> Rendered {
        assert!(!block_sizes.is_empty() && block_sizes.iter().all(|&b| b >= 1));
        let block_size = block_sizes[0];
        let mut sidechain = score.sidechain.clone();
        sidechain.pad_to(frames);
        let mut main = score.main_input.clone();
        if let Some(m) = main.as_mut() {
            m.pad_to(frames);
        }
        let mut events = score.events.clone();
        events.sort_by_key(HostEvent::time);
        let mut out = Rendered {
            audio: Stereo {
                left: Vec::with_capacity(frames),
                right: Vec::with_capacity(frames),
            },
            statuses: Vec::with_capacity(frames / block_size + 1),
        };
        let mut next_event = 0;
        let mut start = 0;
        let mut sizes = block_sizes.iter().copied().cycle();
        while start < frames {
            let n = sizes.next().unwrap_or(block_size).min(frames - start);
            let end = start + n;
            let first = next_event;
            while next_event < events.len() && (events[next_event].time() as usize) < end {
                next_event += 1;
            }
            let block_events: Vec<HostEvent> = events[first..next_event]
                .iter()
                .map(|e| e.at(e.time().saturating_sub(start as u32)))
                .collect();
            let sc = [&sidechain.left[start..end], &sidechain.right[start..end]];
            let block = Block {
                frames: n,
                sidechain: &sc,
                main_input: main
                    .as_ref()
                    .map(|m| [&m.left[start..end], &m.right[start..end]]),
                events: &block_events,
                song_position: song_start.map(|s| s + start as u64),
            };
            let processed = self.process(&block);
            out.audio.left.extend_from_slice(processed.left);
            out.audio.right.extend_from_slice(processed.right);
            out.statuses.push((start, processed.status));
            self.idle();
            start = end;
        }
        assert!(
            next_event == events.len(),
            "{} score events lie after the end of the render ({frames} frames)",
            events.len() - next_event
        );
        out
    }

    // --- parameters ------------------------------------------------------------------------

    fn params_ext(&self) -> PluginParams {
        self.ext.params.expect("the plugin has no params extension")
    }

    /// Every parameter the plugin exposes.
    pub fn params(&mut self) -> Vec<ParamDesc> {
        let ext = self.params_ext();
        let handle = self.instance.plugin_handle();
        let mut buffer = ParamInfoBuffer::new();
        (0..ext.count(&handle))
            .filter_map(|i| {
                ext.get_info(&handle, i, &mut buffer).map(|p| ParamDesc {
                    id: p.id,
                    name: String::from_utf8_lossy(p.name).into_owned(),
                    module: String::from_utf8_lossy(p.module).into_owned(),
                    min: p.min_value,
                    max: p.max_value,
                    default: p.default_value,
                    flags: p.flags.bits(),
                })
            })
            .collect()
    }

    /// Loads a preset the host found by discovery (CLAP preset load): a factory preset by its
    /// load key (`file` None), or a user preset's file. Returns what the plugin then told the
    /// host: `loaded`, or `on_error` with its message.
    pub fn load_preset(
        &mut self,
        file: Option<&Path>,
        load_key: Option<&str>,
    ) -> Result<String, String> {
        let ext = self
            .ext
            .preset_load
            .ok_or("the plugin has no preset-load extension")?;
        let path =
            file.map(|f| std::ffi::CString::new(f.to_string_lossy().as_bytes()).expect("path"));
        let key = load_key.map(|k| std::ffi::CString::new(k).expect("load key"));
        let location = match &path {
            Some(p) => Location::File { path: p },
            None => Location::Plugin,
        };
        let returned = {
            let handle = self.instance.plugin_handle();
            ext.load_from_location(&handle, location, key.as_deref())
        };
        let told = self
            .instance
            .access_handler(|h| h.preset_loads.borrow_mut().pop());
        self.idle();
        match (returned, told) {
            (Ok(()), Some(Ok(what))) => Ok(what),
            (Err(_), Some(Err(message))) => Err(message),
            (r, t) => Err(format!("the plugin returned {r:?} but told the host {t:?}")),
        }
    }

    /// The plugin's remote-control pages, in its order (none without the extension).
    pub fn remote_control_pages(&mut self) -> Vec<RemotePage> {
        let Some(ext) = self.ext.remote_controls else {
            return Vec::new();
        };
        let handle = self.instance.plugin_handle();
        let mut buffer = RemoteControlsPageBuffer::new();
        (0..ext.count(&handle))
            .filter_map(|i| {
                ext.get(&handle, i, &mut buffer).map(|p| RemotePage {
                    section: String::from_utf8_lossy(p.section_name).into_owned(),
                    name: String::from_utf8_lossy(p.page_name).into_owned(),
                    params: p.param_ids,
                })
            })
            .collect()
    }

    /// The parameter named `name`; panics with the list of names when there is none.
    pub fn param(&mut self, name: &str) -> ParamDesc {
        let params = self.params();
        match params.iter().find(|p| p.name == name) {
            Some(p) => p.clone(),
            None => panic!(
                "no parameter named {name:?}; the plugin has {:?}",
                params.iter().map(|p| &p.name).collect::<Vec<_>>()
            ),
        }
    }

    /// A parameter's current plain value.
    pub fn param_value(&mut self, id: ClapId) -> Option<f64> {
        let ext = self.params_ext();
        ext.get_value(&self.instance.plugin_handle(), id)
    }

    /// The plugin's text for a plain value of a parameter.
    pub fn param_text(&mut self, id: ClapId, value: f64) -> Option<String> {
        let ext = self.params_ext();
        let mut buffer = [0u8; 256];
        ext.value_to_text(&self.instance.plugin_handle(), id, value, &mut buffer)
            .ok()
            .map(|b| String::from_utf8_lossy(b).into_owned())
    }

    /// The value the plugin reads from `text` (`clap_plugin_params.text_to_value`).
    pub fn param_value_of_text(&mut self, id: ClapId, text: &str) -> Option<f64> {
        let ext = self.params_ext();
        let text = std::ffi::CString::new(text).ok()?;
        ext.text_to_value(&self.instance.plugin_handle(), id, &text)
    }

    /// Sets parameters outside `process()` through `clap_plugin_params.flush` (on the main
    /// thread when inactive, on the audio thread when active, as CLAP requires).
    pub fn flush_params(&mut self, values: &[(ClapId, f64)]) {
        let ext = self.params_ext();
        let mut input = EventBuffer::with_capacity(values.len());
        for &(id, value) in values {
            input.push(&ParamValueEvent::new(0, id, Pckn::match_all(), value));
        }
        let mut output = EventBuffer::new();
        let in_events = InputEvents::from_buffer(&input);
        let mut out_events = OutputEvents::from_buffer(&mut output);
        if let Some(processor) = self.processor.as_mut() {
            as_audio_thread(|| {
                let mut handle = processor.plugin_handle();
                ext.flush_active(&mut handle, &in_events, &mut out_events);
            });
        } else {
            let mut handle = self
                .instance
                .inactive_plugin_handle()
                .expect("inactive plugin");
            ext.flush(&mut handle, &in_events, &mut out_events);
        }
        collect_param_values(&output, &mut self.param_output);
        self.idle();
    }

    /// The parameter values the plugin has sent to the host since the last call.
    /// The keys of the voices reported ended since the last call.
    pub fn take_note_ends(&mut self) -> Vec<u16> {
        std::mem::take(&mut self.note_ends)
    }

    pub fn take_param_output(&mut self) -> Vec<(ClapId, f64)> {
        std::mem::take(&mut self.param_output)
    }

    // --- state -----------------------------------------------------------------------------

    fn state_ext(&self) -> PluginState {
        self.ext.state.expect("the plugin has no state extension")
    }

    /// Saves the plugin's state.
    pub fn save_state(&mut self) -> Vec<u8> {
        let ext = self.state_ext();
        let mut bytes = Vec::new();
        ext.save(&self.instance.plugin_handle(), &mut bytes)
            .unwrap_or_else(|e| panic!("saving the state failed: {e}"));
        self.idle();
        bytes
    }

    /// Loads a state saved by [`TestPlugin::save_state`] (or a corrupted one).
    pub fn load_state(&mut self, bytes: &[u8]) -> Result<(), StateError> {
        let ext = self.state_ext();
        let mut reader: &[u8] = bytes;
        let result = ext.load(&self.instance.plugin_handle(), &mut reader);
        self.idle();
        result
    }
}

impl Drop for TestPlugin {
    fn drop(&mut self) {
        self.deactivate();
    }
}
