//! The editor: a resizable egui window (nice-plug-egui) with the motion view, the model panel
//! (presets, files, script editor with diagnostics), the controls and the status.
//!
//! Everything it shows comes from the [`ModelStore`] (the running model's summary, the last
//! submission's diagnostics), the [`crate::runtime::RuntimeStatus`] atomics (clamp, guard,
//! CPU load) and the model's [`MotionReader`]. It changes the model only through
//! [`ModelStore::submit`], so a script with errors never replaces the running one, and the
//! parameters only through the host's `ParamSetter`.

use crate::files::{
    preset_file_name, read_script, save_script, user_preset_dir, user_presets, FileBrowser,
    UserPreset,
};
use crate::library::{Entry, Favourites, Filter};
use crate::model::{Loaded, ModelState, ModelStatus, ModelStore, NUM_MACROS};
use crate::modes_view::ModesView;
use crate::motion::MotionReader;
use crate::params::RessortParams;
use crate::plot::PlotState;
#[cfg(test)]
use crate::presets::Preset;
use crate::report::{set_guard_with, HostLink};
use egui::{Color32, RichText, Ui};
use nice_plug::context::gui::GuiContext;
use nice_plug::editor::dpi::LogicalSize;
use nice_plug::editor::{ResizeHint, SizeConstraints};
use nice_plug_egui::widgets::ParamSlider;
use nice_plug_egui::{
    create_egui_editor, EguiEditor, EguiEditorState, EguiNiceSettings, NiceEguiApp, RepaintNotifier,
};
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Instant;

mod browser;
mod controls_panel;
mod model_panel;
mod motion_panel;
mod playing;
mod vary_panel;

/// The editor's size when first opened, in logical pixels.
pub const DEFAULT_SIZE: (f32, f32) = (1100.0, 700.0);
/// The smallest size the window can be resized to.
pub const MIN_SIZE: (f32, f32) = (780.0, 500.0);
/// Widths of the model panel (left) and the controls (right): minimum, default, maximum.
const LEFT_PANEL: (f32, f32, f32) = (240.0, 380.0, 700.0);
const RIGHT_PANEL: (f32, f32, f32) = (240.0, 300.0, 480.0);
/// Height of the Modes view: minimum, default, maximum.
const MODES_HEIGHT: (f32, f32, f32) = (150.0, 210.0, 480.0);
/// The width the side panels leave to the motion view when the window allows it.
const MIN_VIEW_WIDTH: f32 = 300.0;

const ORANGE: Color32 = Color32::from_rgb(255, 165, 60);
const RED: Color32 = Color32::from_rgb(255, 90, 80);
const GREEN: Color32 = Color32::from_rgb(120, 220, 130);

/// The editor state shared with the plugin: size and whether the window is open.
pub fn default_state() -> Arc<EguiEditorState> {
    EguiEditorState::from_size(LogicalSize::new(DEFAULT_SIZE.0, DEFAULT_SIZE.1), 1.0)
}

/// The plugin's editor.
pub fn create(
    params: Arc<RessortParams>,
    store: Arc<ModelStore>,
    state: Arc<EguiEditorState>,
    link: Arc<HostLink>,
) -> Option<EguiEditor<EditorApp>> {
    let settings = EguiNiceSettings::new()
        .with_tile("Ressort")
        .with_resize_hint(ResizeHint {
            size_constraints: SizeConstraints::Logical {
                min_size: Some(LogicalSize::new(MIN_SIZE.0, MIN_SIZE.1)),
                max_size: None,
            },
            ..ResizeHint::RESIZABLE
        });
    create_egui_editor(
        state,
        RepaintNotifier::new(),
        settings,
        EditorApp::new(params, store).with_host_link(link),
    )
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Tab {
    Presets,
    Script,
    File,
}

/// A diagnostic line split into its position and message.
#[derive(Clone, Debug, PartialEq)]
struct Diagnostic {
    line: usize,
    col: usize,
    text: String,
}

impl Diagnostic {
    /// `LINE:COL: severity: message`; lines without a position count as line 1.
    fn parse(s: &str) -> Diagnostic {
        let mut parts = s.splitn(3, ':');
        let line = parts.next().and_then(|p| p.trim().parse().ok());
        let col = parts.next().and_then(|p| p.trim().parse().ok());
        match (line, col, parts.next()) {
            (Some(line), Some(col), Some(rest)) => Diagnostic {
                line,
                col,
                text: rest.trim().to_string(),
            },
            _ => Diagnostic {
                line: 1,
                col: 1,
                text: s.to_string(),
            },
        }
    }
}

/// The editor's state between frames.
pub struct EditorApp {
    params: Arc<RessortParams>,
    store: Arc<ModelStore>,
    gui: Option<GuiContext>,
    /// Where the editor leaves its context so the plugin can show guard trips to the host.
    link: Option<Arc<HostLink>>,
    /// The guard's trip count the `guard` parameter was last raised for.
    reported_trips: u32,
    reader: Option<MotionReader>,
    plot: PlotState,
    /// The motion view of 3-D models, and the frames of an animated mode shape it was given.
    view3d: crate::view3d::View3d,
    shape_frames: u64,
    /// The Modes view under the motion view, and whether it is open.
    modes: ModesView,
    modes_open: bool,
    tab: Tab,
    /// The sound library (factory and user presets), the browser's filter, the entry whose
    /// notes it shows, and the user's favourites.
    library: Vec<Entry>,
    filter: Filter,
    selected: Option<usize>,
    favourites: Favourites,
    /// The selected entry was chosen by the keys or the arrows: scroll it into view.
    scroll_to_selected: bool,
    /// The script of the entry whose notes the browser shows, by entry key.
    notes: Option<(String, String)>,
    vary: vary_panel::VaryState,
    /// The text in the script editor, and the name it will be applied under.
    script: String,
    script_name: String,
    /// The running script the editor last showed: when the running model changes (a preset,
    /// a state load) and the text has not been edited, the editor follows.
    synced: ModelState,
    message: Option<(String, Color32)>,
    /// The submission being prepared in the background: its number, name and script.
    loading: Option<(u64, String, String)>,
    browser: FileBrowser,
    /// The user preset folder, its presets (read when the editor opens, after a save and on
    /// Refresh), and the name typed for the next save.
    user_dir: Option<PathBuf>,
    user: Vec<UserPreset>,
    save_name: String,
    /// The path typed for "Save as" in the file tab.
    save_path: String,
    last_frame: Option<Instant>,
    frame_times: [f32; 32],
    frame_count: usize,
    /// The sidechain meter's level (dBFS), falling between peaks.
    meter_db: f32,
}

impl EditorApp {
    pub fn new(params: Arc<RessortParams>, store: Arc<ModelStore>) -> EditorApp {
        let running = store.running();
        // A script that failed to load (a project saved with a broken script, a bad
        // `--model` file) opens in the script editor with its diagnostics.
        let (script, script_name, tab) = match store.status().rejected {
            Some(r) => (r.script, r.name, Tab::Script),
            None => (running.script.clone(), running.name.clone(), Tab::Presets),
        };
        let user_dir = user_preset_dir();
        let user = user_dir.as_deref().map(user_presets).unwrap_or_default();
        let library = crate::library::entries(&user);
        let selected = library
            .iter()
            .position(|e| !e.is_user() && e.id == running.name);
        EditorApp {
            params,
            script,
            script_name,
            synced: running,
            store,
            gui: None,
            link: None,
            reported_trips: 0,
            reader: None,
            plot: PlotState::default(),
            view3d: crate::view3d::View3d::default(),
            shape_frames: 0,
            modes: ModesView::default(),
            modes_open: true,
            tab,
            favourites: Favourites::load(user_dir.as_deref()),
            library,
            filter: Filter::all(),
            selected,
            scroll_to_selected: true,
            notes: None,
            vary: vary_panel::VaryState::default(),
            message: None,
            loading: None,
            browser: FileBrowser::new(),
            user,
            user_dir,
            save_name: String::new(),
            save_path: String::new(),
            last_frame: None,
            frame_times: [0.0; 32],
            frame_count: 0,
            meter_db: -60.0,
        }
    }

    /// Hands the editor's context to `link` when the editor is built.
    pub fn with_host_link(mut self, link: Arc<HostLink>) -> EditorApp {
        self.link = Some(link);
        self
    }

    /// Raises the `guard` parameter for trips the audio thread has not had reported (the
    /// editor's own frames cover formats without a main-thread report).
    fn report_trips(&mut self) {
        let trips = self.store.runtime.guard_trips.load(Ordering::Acquire);
        if trips != self.reported_trips {
            self.reported_trips = trips;
            if let Some(gui) = &self.gui {
                set_guard_with(gui, &self.params, true);
            }
        }
    }

    /// Frames per second over the last 32 frames.
    fn fps(&self) -> f32 {
        let n = self.frame_count.min(self.frame_times.len());
        let total: f32 = self.frame_times[..n].iter().sum();
        if total > 0.0 {
            n as f32 / total
        } else {
            0.0
        }
    }

    /// Follows the running model when the script editor holds no edits of its own.
    fn sync_script(&mut self) {
        let running = self.store.running();
        if running != self.synced {
            if self.script == self.synced.script {
                self.script = running.script.clone();
                self.script_name = running.name.clone();
            }
            self.synced = running;
        }
    }

    /// Runs a script: prepared in the background ([`ModelStore::submit_in_background`]) while
    /// the running model plays on; [`EditorApp::poll_loading`] reports how it went.
    fn submit(&mut self, name: String, script: String) {
        let ticket = self
            .store
            .choose_in_background(name.clone(), script.clone());
        self.message = Some((format!("loading {name}…"), ORANGE));
        self.loading = Some((ticket, name, script));
    }

    /// Reports the background submission once it has finished (each frame).
    fn poll_loading(&mut self) {
        let Some((ticket, _, _)) = &self.loading else {
            return;
        };
        let Some(loaded) = self.store.take_loaded(*ticket) else {
            return;
        };
        let (_, name, script) = self.loading.take().expect("a submission is loading");
        match loaded {
            Loaded::Running => {
                self.message = Some((format!("{name} is running"), GREEN));
                self.script = script;
                self.script_name = name;
                self.synced = self.store.running();
                self.mark_edited();
            }
            Loaded::Rejected(rejected) => {
                self.script = script;
                self.script_name = name;
                self.tab = Tab::Script;
                let n = rejected.0.len();
                self.message = Some((
                    format!(
                        "{n} error{} — the running model is unchanged",
                        if n == 1 { "" } else { "s" }
                    ),
                    RED,
                ));
            }
            // A state load or an A/B switch came after it, and its model runs instead.
            Loaded::Overtaken => self.message = None,
        }
    }

    /// Waits until the background submission has finished and reports it (tests).
    #[cfg(test)]
    fn finish_loading(&mut self) {
        while self.loading.is_some() {
            self.poll_loading();
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    }

    /// Tells the host the project changed: a gesture on the hidden `model_edits` parameter
    /// (see [`RessortParams::model_edits`]).
    fn mark_edited(&self) {
        if let Some(gui) = &self.gui {
            let setter = gui.param_setter();
            let p = &self.params.model_edits;
            setter.begin_set_parameter(p);
            setter.set_parameter(p, (p.value() + 1) % 256);
            setter.end_set_parameter(p);
        }
    }

    /// The A/B compare switch: the running slot is lit; the other one runs on a click.
    fn compare_switch(&mut self, ui: &mut Ui) {
        let compare = self.store.compare();
        for (slot, label) in ["A", "B"].iter().enumerate() {
            let name = compare.slots[slot]
                .as_ref()
                .map(|m| m.name.clone())
                .unwrap_or_else(|| "empty: a copy of the running script".into());
            let r = ui
                .selectable_label(compare.active == slot, *label)
                .on_hover_text(format!("Compare slot {label}: {name}"));
            if r.clicked() && compare.active != slot {
                match self.store.switch_compare() {
                    Ok(()) => {
                        let running = self.store.running();
                        self.message =
                            Some((format!("{label}: {} is running", running.name), GREEN));
                        self.script = running.script.clone();
                        self.script_name = running.name.clone();
                        self.synced = running;
                        self.mark_edited();
                    }
                    Err(r) => {
                        self.message = Some((
                            format!("slot {label} does not load: {}", r.0.join("; ")),
                            RED,
                        ))
                    }
                }
            }
        }
        let other = ["B", "A"][compare.active];
        if ui
            .small_button(format!("copy to {other}"))
            .on_hover_text(format!("Copy the running script into slot {other}"))
            .clicked()
        {
            self.store.copy_to_other_slot();
            self.message = Some((format!("copied into slot {other}"), GREEN));
        }
    }

    fn top_bar(&mut self, ui: &mut Ui, status: &ModelStatus) {
        let store = self.store.clone();
        let rt = &store.runtime;
        let s = &status.summary;
        ui.horizontal_wrapped(|ui| {
            ui.label(RichText::new("Ressort").strong().size(16.0));
            ui.separator();
            ui.label(RichText::new(&s.name).strong());
            self.compare_switch(ui);
            ui.label(format!(
                "{} points · {} interactions",
                s.points, s.interactions
            ));
            if let Some((text, hover)) = playing::pitch_text(s) {
                ui.label(text).on_hover_text(hover);
            }
            let total = rt.voices_total.load(Ordering::Relaxed);
            if total > 1 {
                ui.label(format!(
                    "voices {}/{total}",
                    rt.voices_sounding.load(Ordering::Relaxed)
                ))
                .on_hover_text("Voices sounding, of the Voices setting");
            }
            ui.separator();
            let load = rt.cpu_load.load(Ordering::Relaxed) * 100.0;
            ui.label(format!("CPU {load:.1} %"))
                .on_hover_text("Time spent in the audio callback, as a share of real time");
            ui.separator();
            let trips = rt.guard_trips.load(Ordering::Relaxed);
            let exploded = rt.guard_active.load(Ordering::Acquire);
            let (dot, _) = ui.allocate_exact_size(egui::vec2(12.0, 12.0), egui::Sense::hover());
            ui.painter()
                .circle_filled(dot.center(), 5.0, if exploded { RED } else { GREEN });
            if exploded {
                ui.colored_label(RED, format!("Exploded — reset by the guard ({trips}×)"))
                    .on_hover_text(
                        "The model ran away; the guard silenced it, put it back at rest and \
                         faded in. Lower Stiffness or the force that drives it.",
                    );
            } else {
                ui.colored_label(GREEN, "Stable");
            }
            if ui
                .button("Reset model")
                .on_hover_text("Put every mass back at rest and clear the indicator")
                .clicked()
            {
                rt.reset_requested.store(true, Ordering::Release);
                if let Some(gui) = &self.gui {
                    set_guard_with(gui, &self.params, false);
                }
            }
            ui.separator();
            ui.label(
                RichText::new(format!("{:.0} fps", self.fps()))
                    .color(Color32::GRAY)
                    .small(),
            );
        });
    }

    fn model_status(&self, ui: &mut Ui, status: &ModelStatus) {
        let s = &status.summary;
        egui::CollapsingHeader::new("Stability")
            .default_open(true)
            .show(ui, |ui| {
                if s.provisional {
                    ui.colored_label(
                        ORANGE,
                        RichText::new(
                            "Analysing: playing on quick limits (the Gershgorin clamp, an \
                             estimated pitch and level) until the exact analyses are done",
                        )
                        .small(),
                    );
                }
                if s.stability.is_empty() {
                    ui.label("No mass is loaded.");
                }
                for (i, line) in s.stability.iter().enumerate() {
                    let colour = if i == 0 && line.starts_with("closest") {
                        ui.visuals().text_color()
                    } else {
                        ORANGE
                    };
                    ui.colored_label(colour, RichText::new(line).small());
                }
            });
        egui::CollapsingHeader::new("Inputs and outputs")
            .default_open(false)
            .show(ui, |ui| {
                for line in s.inputs.iter().chain(&s.outputs) {
                    ui.label(RichText::new(line).small().monospace());
                }
                if !s.params.is_empty() {
                    ui.label(
                        RichText::new(format!("params: {}", s.params.join(", ")))
                            .small()
                            .monospace(),
                    );
                }
            });
    }

    /// The Modes view under the motion view: follows the running model and the controls in
    /// use (the macro slots as the audio thread last used them, MIDI-learned controllers
    /// included).
    fn modes_panel(&mut self, ui: &mut Ui) {
        if self.modes_open {
            let mut controls = self.params.controls();
            for (c, used) in controls.macros.iter_mut().zip(&self.store.runtime.macros) {
                *c = used.load(Ordering::Relaxed);
            }
            self.modes.update(self.store.modal_model(), controls);
        }
        // One id per state: the open panel keeps its own (resizable) height.
        let panel = if self.modes_open {
            egui::Panel::bottom("modes_open")
                .resizable(true)
                .default_size(MODES_HEIGHT.1)
                .size_range(MODES_HEIGHT.0..=MODES_HEIGHT.2)
        } else {
            egui::Panel::bottom("modes_closed").resizable(false)
        };
        panel.show(ui, |ui| {
            ui.add_space(2.0);
            self.modes.show(ui, &mut self.modes_open);
        });
    }
}

impl NiceEguiApp for EditorApp {
    fn build(
        &mut self,
        egui_ctx: egui::Context,
        nice_gui_ctx: GuiContext,
        _frame: &mut nice_plug_egui::Frame,
    ) -> Result<(), nice_plug_egui::baseview::HandlerError> {
        // egui is built without its default-fonts feature in nice-plug-egui: set them here so
        // text renders (this crate enables the feature).
        egui_ctx.set_fonts(egui::FontDefinitions::default());
        egui_ctx.set_visuals(egui::Visuals::dark());
        if let Some(link) = &self.link {
            link.attach(nice_gui_ctx.clone());
        }
        // Trips from before the editor opened are for the host's report, not this one.
        self.reported_trips = self.store.runtime.guard_trips.load(Ordering::Acquire);
        self.gui = Some(nice_gui_ctx);
        self.last_frame = None;
        Ok(())
    }

    fn ui(&mut self, ui: &mut Ui, _frame: &mut nice_plug_egui::Frame) {
        let now = Instant::now();
        let dt = self
            .last_frame
            .map(|t| (now - t).as_secs_f32())
            .unwrap_or(1.0 / 60.0)
            .clamp(1e-4, 1.0);
        self.last_frame = Some(now);
        self.frame_times[self.frame_count % self.frame_times.len()] = dt;
        self.frame_count += 1;
        // A new Voices setting from the host: re-prepare the model here, off the audio thread.
        self.store.apply_voices();
        if let Some(r) = self.store.take_motion_reader() {
            self.reader = Some(r);
        }
        self.store.collect_garbage();
        self.poll_loading();
        self.sync_script();
        self.report_trips();
        let status = self.store.status();

        egui::Panel::top("top").show(ui, |ui| {
            ui.add_space(2.0);
            self.top_bar(ui, &status);
            ui.add_space(2.0);
        });
        // The side panels give way so that the motion view keeps room in a narrow window.
        let width = ui.available_width();
        let left_max = (width - RIGHT_PANEL.1 - MIN_VIEW_WIDTH).clamp(LEFT_PANEL.0, LEFT_PANEL.2);
        let right_max = (width - LEFT_PANEL.0 - MIN_VIEW_WIDTH).clamp(RIGHT_PANEL.0, RIGHT_PANEL.2);
        egui::Panel::left("model")
            .default_size(LEFT_PANEL.1.min(left_max))
            .size_range(LEFT_PANEL.0..=left_max)
            .show(ui, |ui| {
                ui.horizontal(|ui| {
                    ui.selectable_value(&mut self.tab, Tab::Presets, "Presets");
                    ui.selectable_value(&mut self.tab, Tab::Script, "Script");
                    ui.selectable_value(&mut self.tab, Tab::File, "Open file");
                });
                if let Some((text, colour)) = &self.message {
                    ui.colored_label(*colour, text);
                }
                ui.separator();
                match self.tab {
                    Tab::Presets => self.presets_tab(ui),
                    Tab::Script => self.script_tab(ui, &status),
                    Tab::File => self.file_tab(ui),
                }
            });
        egui::Panel::right("controls")
            .default_size(RIGHT_PANEL.1.min(right_max))
            .size_range(RIGHT_PANEL.0..=right_max)
            .show(ui, |ui| {
                egui::ScrollArea::vertical()
                    .id_salt("controls")
                    .show(ui, |ui| {
                        self.playing(ui, &status);
                        ui.separator();
                        self.controls(ui, &status);
                        ui.separator();
                        self.vary_panel(ui);
                        ui.separator();
                        self.model_status(ui, &status);
                    });
            });
        self.modes_panel(ui);
        egui::CentralPanel::default_margins().show(ui, |ui| self.motion_panel(ui, dt));
        // Redraw continuously while open: the window system paces the frames.
        ui.ctx().request_repaint();
    }

    fn editor_closed(&mut self) {
        self.gui = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nice_plug::prelude::{Param, PluginApi};
    use std::sync::Mutex;

    /// A host's side of the editor's context that records the parameter gestures.
    #[derive(Default)]
    struct Recorder {
        calls: Mutex<Vec<String>>,
        model_edits: Mutex<Option<nice_plug::params::internals::ParamPtr>>,
    }

    // SAFETY: the test touches the pointer only to compare it.
    unsafe impl Send for Recorder {}
    unsafe impl Sync for Recorder {}

    impl Recorder {
        fn name(&self, p: nice_plug::params::internals::ParamPtr) -> &'static str {
            if Some(p) == *self.model_edits.lock().unwrap() {
                "model_edits"
            } else {
                "other"
            }
        }
    }

    impl nice_plug::context::gui::GuiContextInner for Recorder {
        fn plugin_api(&self) -> PluginApi {
            PluginApi::Clap
        }
        unsafe fn raw_begin_set_parameter(&self, p: nice_plug::params::internals::ParamPtr) {
            let n = self.name(p);
            self.calls.lock().unwrap().push(format!("begin {n}"));
        }
        unsafe fn raw_set_parameter_normalized(
            &self,
            p: nice_plug::params::internals::ParamPtr,
            v: f32,
        ) {
            let n = self.name(p);
            self.calls.lock().unwrap().push(format!("set {n} {v:.4}"));
        }
        unsafe fn raw_end_set_parameter(&self, p: nice_plug::params::internals::ParamPtr) {
            let n = self.name(p);
            self.calls.lock().unwrap().push(format!("end {n}"));
        }
        fn get_state(&self) -> nice_plug::prelude::PluginState {
            nice_plug::prelude::PluginState {
                version: String::new(),
                params: Default::default(),
                fields: Default::default(),
            }
        }
        fn set_state(&self, _: nice_plug::prelude::PluginState) {}
        fn request_restart(&self) {}
    }

    #[test]
    fn a_model_change_in_the_editor_is_an_edit_the_host_records() {
        // Every model change the editor makes moves the hidden Model Edits parameter with a
        // full gesture, which hosts record as an edit of the project; a script with errors
        // changes nothing and records nothing.
        let store = Arc::new(ModelStore::default());
        let params = Arc::new(RessortParams::new(store.clone()));
        let recorder = Arc::new(Recorder::default());
        *recorder.model_edits.lock().unwrap() = Some(params.model_edits.as_ptr());
        let mut app = EditorApp::new(params, store.clone());
        app.gui = Some(GuiContext::new(recorder.clone()));
        let harmonic = Preset::find("harmonic-oscillator").unwrap();
        app.submit(harmonic.id.into(), harmonic.text.into());
        app.finish_loading();
        assert_eq!(
            *recorder.calls.lock().unwrap(),
            [
                "begin model_edits",
                "set model_edits 0.0039",
                "end model_edits"
            ]
        );
        recorder.calls.lock().unwrap().clear();
        app.submit("broken".into(), "@o osc 1. 0.1\n".into());
        app.finish_loading();
        assert!(
            recorder.calls.lock().unwrap().is_empty(),
            "a rejected script is no edit"
        );
    }

    #[test]
    fn diagnostics_split_into_position_and_message() {
        assert_eq!(
            Diagnostic::parse("12:4: error: undefined element `@x`"),
            Diagnostic {
                line: 12,
                col: 4,
                text: "error: undefined element `@x`".into()
            }
        );
        assert_eq!(Diagnostic::parse("odd").line, 1);
    }

    #[test]
    fn the_script_editor_follows_the_running_model_unless_edited() {
        let store = Arc::new(ModelStore::default());
        let params = Arc::new(RessortParams::new(store.clone()));
        let mut app = EditorApp::new(params, store.clone());
        let hammer = Preset::find("hammer-oscillator").unwrap();
        store
            .submit(ModelState::new(hammer.id, hammer.text))
            .unwrap();
        app.sync_script();
        assert_eq!(app.script, hammer.text);
        app.script.push_str("\n# my edit\n");
        let harmonic = Preset::find("harmonic-oscillator").unwrap();
        store
            .submit(ModelState::new(harmonic.id, harmonic.text))
            .unwrap();
        app.sync_script();
        assert!(app.script.ends_with("# my edit\n"), "edits are kept");
        // A rejected script stays in the editor with its diagnostics; the model stays.
        app.submit("bad".into(), "@m mass 1 0\n@x nothing".into());
        app.finish_loading();
        assert_eq!(store.running().name, "harmonic-oscillator");
        assert_eq!(app.tab, Tab::Script);
        assert!(!store.status().diagnostics.is_empty());
        assert!(app.script.contains("@x nothing"));
    }

    #[test]
    fn a_script_that_failed_to_load_opens_in_the_script_editor() {
        let store = Arc::new(ModelStore::default());
        let params = Arc::new(RessortParams::new(store.clone()));
        let bad = "@m mass 1 0 0\n@s spring @m @nowhere 0.1\n";
        assert!(store.submit(ModelState::new("broken", bad)).is_err());
        let app = EditorApp::new(params, store.clone());
        assert_eq!((app.tab, app.script.as_str()), (Tab::Script, bad));
        assert_eq!(
            Diagnostic::parse(&store.status().diagnostics[0]).line,
            2,
            "the diagnostic points at the line the editor highlights"
        );
        assert_eq!(store.running().name, crate::presets::DEFAULT_PRESET);
    }
}
