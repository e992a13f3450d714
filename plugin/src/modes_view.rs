//! The editor's Modes view (issue 14): the modes of the running model as a spectrum of stems,
//! frequency (log) against the modal gain from a chosen input to a chosen output, recomputed
//! on a worker thread ([`crate::modes_worker`]) whenever the model, Stiffness, Damping, Tune or
//! a macro changes. The reference pitch (the strongest mode the first output hears from the
//! note input, the mode MIDI notes and Tune are tuned by) is marked. Clicking a stem selects
//! its mode: its frequency, note and T60 are shown, and the motion view animates its shape.

use crate::modes_worker::{ModesResult, ModesWorker};
use egui::{Align2, Color32, FontId, Pos2, Rect, Sense, Stroke, Ui, Vec2};
use ressort_engine::instrument::{Controls, ModalModel};
use ressort_engine::modes::{note_name, Mode, Solver};
use std::sync::Arc;
use std::time::Instant;

/// The gain axis spans this many decibels below the strongest mode.
const FLOOR_DB: f32 = 60.0;
/// How close (in pixels) a click must be to a stem to select it.
const PICK_PX: f32 = 8.0;
/// The frequency a selected mode's shape is animated at in the motion view.
const SHAPE_RATE_HZ: f32 = 0.7;

/// Not the motion view's background, so that the two are told apart on screen.
const BACKGROUND: Color32 = Color32::from_rgb(22, 24, 31);
const STEM: Color32 = Color32::from_rgb(110, 170, 255);
const MUTED: Color32 = Color32::from_rgb(80, 84, 96);
const SELECTED: Color32 = Color32::from_rgb(255, 165, 60);
const REFERENCE: Color32 = Color32::from_rgb(120, 220, 130);

/// The Modes view's state between frames.
#[derive(Debug, Default)]
pub struct ModesView {
    worker: Option<ModesWorker>,
    /// The newest analysis.
    result: Option<ModesResult>,
    /// The model and controls of the last request.
    requested: Option<(Arc<ModalModel>, Controls)>,
    /// 1-based input and output whose gains the stems show.
    pub input: usize,
    pub output: usize,
    /// The selected mode (an index into the result's modes).
    pub selected: Option<usize>,
    phase: f32,
    /// No new request before this: the worker rests at least as long as its last analysis
    /// took, so that automating a control on a large model keeps it below half a core.
    rest_until: Option<Instant>,
    /// Scratch for the animated shape (z, and x and y of a 3-D model).
    animated: Vec<f32>,
    animated_x: Vec<f32>,
    animated_y: Vec<f32>,
}

/// Where mode frequencies sit on the horizontal axis: log frequency between `lo` and `hi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrequencyAxis {
    pub lo: f32,
    pub hi: f32,
}

impl FrequencyAxis {
    /// From a decade below the lowest mode (at most 20 Hz) to half the sample rate.
    pub fn of(modes: &[Mode], sample_rate: f64) -> FrequencyAxis {
        let lowest = modes
            .iter()
            .map(|m| m.frequency_hz)
            .filter(|f| *f > 0.0)
            .fold(f64::INFINITY, f64::min);
        let lo = if lowest.is_finite() {
            (lowest * 0.7).clamp(1.0, 20.0)
        } else {
            20.0
        };
        FrequencyAxis {
            lo: lo as f32,
            hi: (sample_rate * 0.5) as f32,
        }
    }

    /// The x of `f` in `rect` (frequencies outside the axis sit on its ends).
    pub fn x(&self, f: f32, rect: Rect) -> f32 {
        let t = ((f.max(self.lo).min(self.hi) / self.lo).ln() / (self.hi / self.lo).ln())
            .clamp(0.0, 1.0);
        rect.left() + t * rect.width()
    }
}

/// A gain in decibels below `max`, clamped to the axis (−[`FLOOR_DB`] … 0); None for a mode
/// the pair does not hear.
pub fn relative_db(gain: f64, max: f64) -> Option<f32> {
    if gain > 0.0 && max > 0.0 && gain.is_finite() {
        Some(((20.0 * (gain / max).log10()) as f32).clamp(-FLOOR_DB, 0.0))
    } else {
        None
    }
}

/// The stem nearest to `x` within [`PICK_PX`], by index.
pub fn pick(xs: &[f32], x: f32) -> Option<usize> {
    xs.iter()
        .enumerate()
        .map(|(i, &s)| (i, (s - x).abs()))
        .filter(|&(_, d)| d <= PICK_PX)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// `1.234 kHz`, `523.3 Hz`.
pub fn format_hz(f: f64) -> String {
    if f >= 1000.0 {
        format!("{:.3} kHz", f / 1000.0)
    } else if f >= 100.0 {
        format!("{f:.1} Hz")
    } else {
        format!("{f:.2} Hz")
    }
}

/// A mode in one line: `523.3 Hz · C5 +1 ct · T60 2.31 s`.
pub fn describe(m: &Mode) -> String {
    let note = note_name(m.frequency_hz)
        .map(|(n, c)| format!(" · {n} {c:+.0} ct"))
        .unwrap_or_default();
    let t60 = if m.t60_s.is_finite() {
        if m.t60_s >= 10.0 {
            format!("{:.0} s", m.t60_s)
        } else if m.t60_s >= 0.1 {
            format!("{:.2} s", m.t60_s)
        } else {
            format!("{:.1} ms", m.t60_s * 1000.0)
        }
    } else {
        "∞".to_string()
    };
    format!("{}{note} · T60 {t60}", format_hz(m.frequency_hz))
}

impl ModesView {
    /// Follows the running model and the controls: asks the worker for new modes when either
    /// changed, and takes the newest result. Called once per frame.
    pub fn update(&mut self, model: Option<Arc<ModalModel>>, controls: Controls) {
        let Some(model) = model else {
            return;
        };
        if let Some(r) = self.worker.as_mut().and_then(|w| w.poll()) {
            self.rest_until = Some(Instant::now() + r.elapsed);
            let same_model = self
                .result
                .as_ref()
                .is_some_and(|old| Arc::ptr_eq(&old.model, &r.model));
            if !same_model
                || self
                    .selected
                    .is_some_and(|k| k >= r.modes.analysis.modes.len())
            {
                self.selected = None;
            }
            self.result = Some(r);
        }
        // A worker that went idle has ended; a request it had not answered is asked again.
        if self.worker.as_ref().is_some_and(|w| w.finished()) {
            if self.busy() {
                self.requested = None;
            }
            self.worker = None;
        }
        let new_model = !matches!(&self.requested, Some((m, _)) if Arc::ptr_eq(m, &model));
        let changed = new_model || !matches!(&self.requested, Some((_, c)) if *c == controls);
        let resting = self.rest_until.is_some_and(|t| Instant::now() < t);
        // A new model goes at once; a control change waits for the worker and its rest.
        if !changed || !(new_model || !(self.busy() || resting)) {
            return;
        }
        if self.worker.is_none() {
            self.worker = ModesWorker::start();
        }
        let Some(worker) = self.worker.as_mut() else {
            return;
        };
        if new_model
            && !self
                .result
                .as_ref()
                .is_some_and(|r| Arc::ptr_eq(&r.model, &model))
        {
            self.input = model.note_input.unwrap_or(1);
            self.output = 1;
            self.selected = None;
        }
        worker.request(model.clone(), controls);
        self.requested = Some((model, controls));
    }

    /// Whether an analysis is running.
    pub fn busy(&self) -> bool {
        self.worker.as_ref().is_some_and(|w| w.busy())
    }

    /// The newest analysis, if any.
    pub fn result(&self) -> Option<&ModesResult> {
        self.result.as_ref()
    }

    /// The selected mode.
    pub fn selected_mode(&self) -> Option<(usize, &Mode)> {
        let k = self.selected?;
        Some((k, self.result.as_ref()?.modes.analysis.modes.get(k)?))
    }

    /// The index of the reference mode: the strongest mode above 20 Hz from the note input
    /// (or `@in1`) to `@out1`, as the instrument tunes notes.
    pub fn reference(&self) -> Option<usize> {
        let r = self.result.as_ref()?;
        let a = &r.modes.analysis;
        let input = r.model.note_input.unwrap_or(1);
        let m = a.strongest(input, 1, 20.0)?;
        a.modes.iter().position(|x| std::ptr::eq(x, m))
    }

    /// The motion frame that shows the selected mode's shape, moving at [`SHAPE_RATE_HZ`]
    /// around `rest`; None when no mode is selected or its shape does not fit the view.
    pub fn shape_frame(&mut self, rest: &[f32], dt: f32) -> Option<&[f32]> {
        let phase =
            (self.phase + std::f32::consts::TAU * SHAPE_RATE_HZ * dt) % std::f32::consts::TAU;
        let k = self.selected?;
        let m = self.result.as_ref()?.modes.analysis.modes.get(k)?;
        if m.shape.len() != rest.len() {
            return None;
        }
        let s = phase.sin();
        self.animated.clear();
        self.animated
            .extend(rest.iter().zip(&m.shape).map(|(r, v)| r + s * *v as f32));
        self.phase = phase;
        Some(&self.animated)
    }

    /// The 3-D counterpart of [`ModesView::shape_frame`]: the selected mode's shape (x, y
    /// and z of every point, [`Mode::shape`]'s layout for 3-D models) moving around the
    /// static equilibrium the analysis linearised it at (a chain hanging under gravity, a
    /// ball resting on its drum), or around `rest` (x, y, z) when the analysis gives none,
    /// its largest component `amplitude` long. None when no mode is selected or its shape is
    /// not a 3-D one of this many points.
    pub fn shape_frame_3d(
        &mut self,
        rest: [&[f32]; 3],
        amplitude: f32,
        dt: f32,
    ) -> Option<[&[f32]; 3]> {
        let phase =
            (self.phase + std::f32::consts::TAU * SHAPE_RATE_HZ * dt) % std::f32::consts::TAU;
        let k = self.selected?;
        let analysis = &self.result.as_ref()?.modes.analysis;
        let m = analysis.modes.get(k)?;
        let n = rest[2].len();
        if m.shape.len() != 3 * n || rest[0].len() != n || rest[1].len() != n {
            return None;
        }
        let equilibrium = (analysis.rest.len() == 3 * n).then_some(&analysis.rest);
        let s = phase.sin() * amplitude;
        for (c, out) in [
            &mut self.animated_x,
            &mut self.animated_y,
            &mut self.animated,
        ]
        .into_iter()
        .enumerate()
        {
            out.clear();
            out.extend(rest[c].iter().enumerate().map(|(i, r)| {
                let at = equilibrium.map_or(*r, |e| e[3 * i + c] as f32);
                at + s * m.shape[3 * i + c] as f32
            }));
        }
        self.phase = phase;
        Some([&self.animated_x, &self.animated_y, &self.animated])
    }

    /// The button that opens and closes the view; closing it deselects the mode.
    fn toggle(&mut self, ui: &mut Ui, open: &mut bool) {
        if ui
            .selectable_label(*open, "Modes")
            .on_hover_text("Show or hide the model's modes: frequency, decay and gain")
            .clicked()
        {
            *open = !*open;
            if !*open {
                self.selected = None;
            }
        }
    }

    /// Draws the view into `ui`: its button, and while `open` the header and the spectrum.
    pub fn show(&mut self, ui: &mut Ui, open: &mut bool) {
        if !*open {
            ui.horizontal(|ui| self.toggle(ui, open));
            return;
        }
        let Some(r) = self.result.as_ref() else {
            ui.horizontal(|ui| {
                self.toggle(ui, open);
                if self.busy() {
                    ui.spinner();
                    ui.label("analysing the model…");
                } else {
                    ui.label("The modes appear when the plugin is active.");
                }
            });
            // Fill the panel, so that it opens at its full height.
            ui.allocate_space(ui.available_size());
            return;
        };
        let (n_in, n_out, note) = (r.model.num_inputs, r.model.num_outputs, r.model.note_input);
        let analysis_line = {
            let a = &r.modes.analysis;
            let which = match a.solver {
                Solver::Sparse => format!("lowest {} modes (sparse)", a.modes.len()),
                Solver::Companion => format!("{} modes (companion)", a.modes.len()),
                Solver::Dense => format!("{} modes", a.modes.len()),
            };
            format!(
                "{which} of {} moving points · {:.0} ms",
                a.degrees_of_freedom,
                r.elapsed.as_secs_f64() * 1000.0
            )
        };
        let clamped = r.modes.gains.clamped.then(|| {
            format!(
                "Stiffness clamped to ×{:.3} (asked ×{:.3})",
                r.modes.gains.stiffness, r.modes.gains.requested_stiffness
            )
        });
        ui.horizontal(|ui| {
            self.toggle(ui, open);
            if n_in > 0 && n_out > 0 {
                let name = |i: usize| {
                    if Some(i) == note {
                        format!("in{i} (notes)")
                    } else {
                        format!("in{i}")
                    }
                };
                egui::ComboBox::from_id_salt("modes_input")
                    .selected_text(format!("from {}", name(self.input)))
                    .show_ui(ui, |ui| {
                        for i in 1..=n_in {
                            ui.selectable_value(&mut self.input, i, name(i));
                        }
                    });
                egui::ComboBox::from_id_salt("modes_output")
                    .selected_text(format!("to out{}", self.output))
                    .show_ui(ui, |ui| {
                        for o in 1..=n_out {
                            ui.selectable_value(&mut self.output, o, format!("out{o}"));
                        }
                    });
            }
            if self.busy() {
                ui.spinner();
            }
            if let Some(c) = clamped {
                ui.colored_label(SELECTED, egui::RichText::new(c).small());
            }
        });
        ui.horizontal(|ui| match self.selected_mode() {
            Some((k, m)) => {
                let db = self.max_gain().and_then(|max| {
                    relative_db(self.gain_of(k), max).map(|d| format!(" · {d:.1} dB"))
                });
                ui.colored_label(
                    SELECTED,
                    format!("Mode {}: {}{}", k + 1, describe(m), db.unwrap_or_default()),
                );
                if ui
                    .small_button("×")
                    .on_hover_text("Back to the live motion")
                    .clicked()
                {
                    self.selected = None;
                }
            }
            None => {
                let text = match self.reference().and_then(|k| {
                    let m = &self.result.as_ref()?.modes.analysis.modes[k];
                    Some(format!("Reference pitch: mode {}, {}", k + 1, describe(m)))
                }) {
                    Some(t) => t,
                    None => "No mode links the note input to out1.".to_string(),
                };
                ui.colored_label(REFERENCE, text);
            }
        });
        self.spectrum(ui, &analysis_line);
    }

    fn gain_of(&self, k: usize) -> f64 {
        self.result
            .as_ref()
            .map_or(0.0, |r| r.modes.analysis.gain(k, self.input, self.output))
    }

    /// The largest gain of the chosen pair.
    fn max_gain(&self) -> Option<f64> {
        let r = self.result.as_ref()?;
        let max = (0..r.modes.analysis.modes.len())
            .map(|k| self.gain_of(k))
            .filter(|g| g.is_finite())
            .fold(0.0, f64::max);
        (max > 0.0).then_some(max)
    }

    /// The stems; `caption` (what was analysed) goes in the top left corner.
    fn spectrum(&mut self, ui: &mut Ui, caption: &str) {
        let size = ui.available_size().max(Vec2::new(120.0, 60.0));
        let (response, painter) = ui.allocate_painter(size, Sense::click());
        let response = response.on_hover_text_at_pointer("Click a stem to see the mode's shape");
        let rect = response.rect;
        let painter = painter.with_clip_rect(rect.intersect(ui.clip_rect()));
        painter.rect_filled(rect, 4.0, BACKGROUND);
        let Some(r) = self.result.as_ref() else {
            return;
        };
        let modes = &r.modes.analysis.modes;
        let plot = Rect::from_min_max(
            rect.min + Vec2::new(34.0, 8.0),
            rect.max - Vec2::new(10.0, 18.0),
        );
        let axis = FrequencyAxis::of(modes, r.model.sample_rate());
        let font = FontId::monospace(10.0);
        let grid = Color32::from_rgb(44, 46, 56);
        // Frequency grid: 1-2-5 per decade.
        let mut decade = 10f32.powf(axis.lo.log10().floor());
        while decade <= axis.hi {
            for m in [1.0, 2.0, 5.0] {
                let f = decade * m;
                if f < axis.lo || f > axis.hi {
                    continue;
                }
                let x = axis.x(f, plot);
                painter.line_segment(
                    [Pos2::new(x, plot.top()), Pos2::new(x, plot.bottom())],
                    Stroke::new(1.0, grid),
                );
                let label = if f >= 1000.0 {
                    format!("{}k", f / 1000.0)
                } else {
                    format!("{f}")
                };
                painter.text(
                    Pos2::new(x, plot.bottom() + 2.0),
                    Align2::CENTER_TOP,
                    label,
                    font.clone(),
                    Color32::GRAY,
                );
            }
            decade *= 10.0;
        }
        // Gain grid every 20 dB.
        let y_of = |db: f32| plot.top() + (-db / FLOOR_DB) * plot.height();
        for db in [0.0, -20.0, -40.0, -60.0] {
            let y = y_of(db);
            painter.line_segment(
                [Pos2::new(plot.left(), y), Pos2::new(plot.right(), y)],
                Stroke::new(1.0, grid),
            );
            painter.text(
                Pos2::new(plot.left() - 4.0, y),
                Align2::RIGHT_CENTER,
                if db == 0.0 {
                    "0 dB".to_string()
                } else {
                    format!("{db:.0}")
                },
                font.clone(),
                Color32::GRAY,
            );
        }
        painter.text(
            Pos2::new(rect.right() - 4.0, rect.bottom() - 2.0),
            Align2::RIGHT_BOTTOM,
            "Hz",
            font.clone(),
            Color32::GRAY,
        );

        let max = self.max_gain();
        let reference = self.reference();
        let xs: Vec<f32> = modes
            .iter()
            .map(|m| axis.x(m.frequency_hz as f32, plot))
            .collect();
        if let Some(k) = reference {
            let x = xs[k];
            painter.line_segment(
                [Pos2::new(x, plot.top()), Pos2::new(x, plot.bottom())],
                Stroke::new(1.5, REFERENCE),
            );
            painter.text(
                Pos2::new(x + 3.0, plot.top() + 14.0),
                Align2::LEFT_TOP,
                "reference",
                font.clone(),
                REFERENCE,
            );
        }
        for (k, &x) in xs.iter().enumerate() {
            let db = max.and_then(|max| relative_db(self.gain_of(k), max));
            let selected = self.selected == Some(k);
            let (top, colour) = match db {
                Some(db) => (y_of(db), if selected { SELECTED } else { STEM }),
                // A mode this pair does not hear: a short tick at the floor.
                None => (plot.bottom() - 6.0, if selected { SELECTED } else { MUTED }),
            };
            painter.line_segment(
                [Pos2::new(x, plot.bottom()), Pos2::new(x, top)],
                Stroke::new(if selected { 2.5 } else { 1.5 }, colour),
            );
            painter.circle_filled(Pos2::new(x, top), if selected { 4.0 } else { 2.5 }, colour);
        }

        // Hover and click. The top right corner says what was analysed, or which mode is under
        // the pointer.
        let hovered = response.hover_pos().and_then(|p| pick(&xs, p.x));
        if hovered.is_none() {
            painter.text(
                Pos2::new(plot.right(), plot.top()),
                Align2::RIGHT_TOP,
                caption,
                font.clone(),
                Color32::GRAY,
            );
        }
        {
            if let Some(k) = hovered {
                let m = &modes[k];
                let db = max
                    .and_then(|max| relative_db(self.gain_of(k), max))
                    .map(|d| format!(" · {d:.1} dB"))
                    .unwrap_or_else(|| " · not heard".to_string());
                painter.text(
                    Pos2::new(plot.right(), plot.top()),
                    Align2::RIGHT_TOP,
                    format!("mode {}: {}{db}", k + 1, describe(m)),
                    FontId::monospace(11.0),
                    Color32::WHITE,
                );
            }
        }
        if response.clicked() {
            if let Some(p) = response.interact_pointer_pos() {
                let hit = pick(&xs, p.x);
                self.selected = if hit == self.selected { None } else { hit };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mode(f: f64) -> Mode {
        Mode {
            frequency_hz: f,
            t60_s: 1.5,
            radius: 0.9999,
            lambda: 0.01,
            gains: vec![1.0],
            residues: vec![(0.0, 1.0)],
            shape: vec![0.0, 1.0, -0.5],
        }
    }

    #[test]
    fn the_frequency_axis_is_logarithmic_from_below_the_lowest_mode_to_nyquist() {
        let axis = FrequencyAxis::of(&[mode(100.0), mode(1000.0)], 48_000.0);
        assert_eq!(axis.lo, 20.0);
        assert_eq!(axis.hi, 24_000.0);
        let rect = Rect::from_min_max(Pos2::new(0.0, 0.0), Pos2::new(300.0, 10.0));
        // Equal ratios are equal distances.
        let d1 = axis.x(200.0, rect) - axis.x(100.0, rect);
        let d2 = axis.x(2000.0, rect) - axis.x(1000.0, rect);
        assert!((d1 - d2).abs() < 1e-3, "{d1} {d2}");
        assert_eq!(axis.x(1.0, rect), 0.0);
        assert_eq!(axis.x(1e6, rect), 300.0);
        // A 5 Hz mode widens the axis down to it.
        let low = FrequencyAxis::of(&[mode(5.0)], 44_100.0);
        assert!(low.lo <= 5.0 && low.lo >= 1.0, "{}", low.lo);
    }

    #[test]
    fn gains_read_in_decibels_below_the_strongest_and_clicks_pick_the_nearest_stem() {
        assert_eq!(relative_db(1.0, 1.0), Some(0.0));
        assert!((relative_db(0.1, 1.0).unwrap() + 20.0).abs() < 1e-4);
        assert_eq!(relative_db(1e-9, 1.0), Some(-FLOOR_DB));
        assert_eq!(relative_db(0.0, 1.0), None);
        assert_eq!(relative_db(f64::NAN, 1.0), None);
        let xs = [10.0, 50.0, 54.0, 200.0];
        assert_eq!(pick(&xs, 12.0), Some(0));
        assert_eq!(pick(&xs, 53.0), Some(2));
        assert_eq!(pick(&xs, 100.0), None);
    }

    #[test]
    fn a_selected_mode_moves_the_points_by_its_shape() {
        use ressort_engine::instrument::prepare;
        let text = "@s string 6 1. 0.1 0. 0. 0.\n@in1 frcInput @s 0.3\n@out1 posOutput @s 0.7\n";
        let model = Arc::new(ModalModel::of(&prepare("s", text, 48_000.0).unwrap()));
        let modes = (*model).clone().modes(&Controls::DEFAULT, None);
        let mut v = ModesView::default();
        let rest = vec![0.25f32; 6];
        assert!(v.shape_frame(&rest, 0.01).is_none(), "nothing selected");
        v.result = Some(ModesResult {
            id: 1,
            model,
            controls: Controls::DEFAULT,
            modes,
            elapsed: std::time::Duration::ZERO,
        });
        v.selected = Some(1);
        let shape: Vec<f32> = v
            .selected_mode()
            .unwrap()
            .1
            .shape
            .iter()
            .map(|&x| x as f32)
            .collect();
        // A quarter of the animation's period: the points sit at rest + shape.
        let frame = v.shape_frame(&rest, 0.25 / SHAPE_RATE_HZ).unwrap().to_vec();
        for ((z, r), s) in frame.iter().zip(&rest).zip(&shape) {
            assert!((z - (r + s)).abs() < 1e-5, "{z} {r} {s}");
        }
        // The second mode of a string has a node in the middle and ends that never move.
        assert_eq!(shape[0], 0.0);
        assert!(shape[1] * shape[4] < 0.0, "{shape:?}");
        // A view of another model does not get a frame.
        assert!(v.shape_frame(&rest[..5], 0.01).is_none());
    }

    #[test]
    fn a_3d_mode_moves_the_points_along_x_y_and_z() {
        use ressort_engine::instrument::prepare;
        let text = "~dim 3\n@s string3 6 1. 0.1 0.001 [0 0 0] [5 0 0] [0.9*auto]\n@in1 frcInput @s_m2 [0 1 0]\n@out1 posOutput @s_m3 [0 1 0]\n";
        let model = Arc::new(ModalModel::of(&prepare("s", text, 48_000.0).unwrap()));
        let modes = (*model).clone().modes(&Controls::DEFAULT, None);
        let mut v = ModesView::default();
        v.result = Some(ModesResult {
            id: 1,
            model,
            controls: Controls::DEFAULT,
            modes,
            elapsed: std::time::Duration::ZERO,
        });
        v.selected = Some(0);
        let rest_x: Vec<f32> = (0..6).map(|i| i as f32).collect();
        let (rest_y, rest_z) = (vec![0.0f32; 6], vec![0.5f32; 6]);
        let shape = v.selected_mode().unwrap().1.shape.clone();
        assert_eq!(shape.len(), 18, "x, y and z of each of the 6 points");
        assert!(
            v.shape_frame(&rest_z, 0.01).is_none(),
            "a 3-D shape is no 1-D frame"
        );
        // The shape moves around the string's equilibrium, its declared line (z = 0), not
        // around the positions the view was handed.
        let eq = v.result.as_ref().unwrap().modes.analysis.rest.clone();
        assert_eq!(eq.len(), 18);
        let [x, y, z] = v
            .shape_frame_3d([&rest_x, &rest_y, &rest_z], 2.0, 0.25 / SHAPE_RATE_HZ)
            .unwrap();
        for i in 0..6 {
            for (c, axis) in [x, y, z].into_iter().enumerate() {
                let line = if c == 0 { i as f64 } else { 0.0 };
                assert!((eq[3 * i + c] - line).abs() < 1e-9, "point {i} axis {c}");
                let want = eq[3 * i + c] as f32 + 2.0 * shape[3 * i + c] as f32;
                assert!((axis[i] - want).abs() < 1e-5, "point {i} axis {c}");
            }
        }
        // The string's fixed ends do not move; something in between does.
        assert_eq!((x[0], y[0], z[0]), (0.0, 0.0, 0.0));
        assert!(shape.iter().any(|v| v.abs() > 0.5));
        assert!(v
            .shape_frame_3d([&rest_x[..5], &rest_y[..5], &rest_z[..5]], 2.0, 0.01)
            .is_none());
    }

    /// A bob hanging from a soft spring is drawn swinging around where gravity holds it, below
    /// its declared place: the mode shapes animate at the static equilibrium (3-D spec §6.1).
    #[test]
    fn a_3d_mode_moves_around_the_static_equilibrium() {
        use ressort_engine::instrument::prepare;
        let text = "~dim 3\n~gravity 9.81\n@g ground [0 0 0]\n@m mass 1. [0 0 -1] [0 0 0]\n\
            @l spring @g @m 0.000001 auto\n@in1 frcInput @m [1 0 0]\n@out1 posOutput @m [1 0 0]\n";
        let model = Arc::new(ModalModel::of(&prepare("s", text, 48_000.0).unwrap()));
        let modes = (*model).clone().modes(&Controls::DEFAULT, None);
        let mut v = ModesView::default();
        v.result = Some(ModesResult {
            id: 1,
            model,
            controls: Controls::DEFAULT,
            modes,
            elapsed: std::time::Duration::ZERO,
        });
        v.selected = Some(0);
        let declared = [vec![0.0f32, 0.0], vec![0.0f32, 0.0], vec![0.0f32, -1.0]];
        // At a zero of the swing the frame is the equilibrium itself.
        let [x, y, z] = v
            .shape_frame_3d([&declared[0], &declared[1], &declared[2]], 2.0, 0.0)
            .unwrap();
        // The stretch that holds the bob: M·g over K, per step at any rate (K is written as
        // at 44.1 kHz, gravity in units/s²): 9.81 / (10⁻⁶ · 44 100²) ≈ 5.0e-3 units.
        let sag = 9.81 / (0.000001 * 44_100.0f64 * 44_100.0);
        assert_eq!((x[0], y[0], z[0]), (0.0, 0.0, 0.0), "the ground");
        assert!((x[1], y[1]) == (0.0, 0.0));
        assert!(
            (z[1] as f64 - (-1.0 - sag)).abs() < 1e-4 * sag,
            "the bob hangs at {} (declared −1, sag {sag:.3e})",
            z[1]
        );
    }

    #[test]
    fn the_view_asks_again_when_a_control_or_the_model_changes_and_only_then() {
        use ressort_engine::instrument::prepare;
        let text = "@s string 8 1. 0.1 0.001 0. 0.\n@in1 frcInput @s 0.3\n@out1 posOutput @s 0.7\n";
        let model = || Arc::new(ModalModel::of(&prepare("s", text, 48_000.0).unwrap()));
        let (a, b) = (model(), model());
        let mut v = ModesView::default();
        let settle = |v: &mut ModesView, m: &Arc<ModalModel>, c: Controls| {
            let start = std::time::Instant::now();
            loop {
                v.update(Some(m.clone()), c);
                let done = v.result().is_some_and(|r| {
                    Arc::ptr_eq(&r.model, m)
                        && r.controls == c
                        && r.id == v.worker.as_ref().unwrap().sent
                });
                if done {
                    return v.worker.as_ref().unwrap().sent;
                }
                assert!(start.elapsed().as_secs() < 30, "no result");
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
        };
        let mut c = Controls::DEFAULT;
        let first = settle(&mut v, &a, c);
        let f0 = v.result().unwrap().modes.analysis.modes[0].frequency_hz;
        // Nothing changed: no new request.
        assert_eq!(settle(&mut v, &a, c), first);
        // Damping, Tune and a macro each ask again.
        c.damping_octaves = 1.0;
        let second = settle(&mut v, &a, c);
        assert!(second > first);
        c.tune_st = 12.0;
        assert!(settle(&mut v, &a, c) > second);
        let f1 = v.result().unwrap().modes.analysis.modes[0].frequency_hz;
        assert!((f1 / f0 - 2.0).abs() < 1e-3, "{f0} {f1}");
        // Another model (a new preparation) asks again and clears the selection.
        v.selected = Some(0);
        settle(&mut v, &b, c);
        assert_eq!(v.selected, None);
        assert_eq!(v.input, 1);
    }

    #[test]
    fn modes_read_with_their_note_and_decay() {
        assert_eq!(describe(&mode(440.0)), "440.0 Hz · A4 +0 ct · T60 1.50 s");
        let mut m = mode(1234.5);
        m.t60_s = f64::INFINITY;
        assert!(
            describe(&m).starts_with("1.234 kHz · D#6"),
            "{}",
            describe(&m)
        );
        assert!(describe(&m).ends_with("T60 ∞"));
    }
}
