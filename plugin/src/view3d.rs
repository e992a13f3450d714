//! The motion view of a 3-D model (issue 39): the points and links drawn in perspective or
//! orthographic projection with egui's painter, from an orbit camera ([`camera`]) the user
//! turns by dragging, zooms with the wheel and pans with the right or middle button (or
//! shift-drag). Points are coloured by speed or by displacement from rest; inputs and outputs
//! are ringed. The motion is exaggerated on request, so that the small vibrations of a sounding
//! model are seen against its size. Everything per frame goes into buffers kept between
//! frames, and big models are thinned ([`scene::MAX_LINKS`], [`scene::MAX_DOTS`]).

pub mod camera;
pub mod scene;

use crate::motion::MotionView;
use camera::{Bounds, Camera, Projector};
use egui::{
    Align2, Color32, FontId, Mesh, PointerButton, Pos2, Rect, Sense, Shape, Stroke, Ui, Vec2,
};
use scene::{MarkerKind, Scene};
use std::sync::Arc;

/// The exaggerated motion reaches this fraction of the model's radius.
const EXAGGERATION_TARGET: f32 = 0.08;
/// No point is drawn further than this fraction of the model's radius from its rest.
const EXAGGERATION_CAP: f32 = 0.3;
const MAX_GAIN: f32 = 1e6;
/// Time constant of the colour and exaggeration scales' release, in seconds.
const SCALE_RELEASE_S: f32 = 2.0;
const SCALE_FLOOR: f32 = 1e-12;
/// Zoom per pixel of wheel scrolling.
const ZOOM_PER_PX: f32 = 0.0015;
/// How near (pixels) the pointer must be to a point to name it.
const PICK_PX: f32 = 12.0;
/// The amplitude of an animated mode shape, as a fraction of the model's radius.
pub const SHAPE_AMPLITUDE: f32 = 0.1;

const BACKGROUND: Color32 = Color32::from_rgb(18, 19, 24);
pub const INPUT: Color32 = Color32::from_rgb(120, 230, 140);
pub const OUTPUT: Color32 = Color32::from_rgb(250, 220, 90);
const FIXED: Color32 = Color32::from_rgb(95, 98, 110);

/// What the points' colours say.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColourBy {
    Speed,
    Displacement,
}

impl ColourBy {
    pub fn name(self) -> &'static str {
        match self {
            ColourBy::Speed => "Colour: speed",
            ColourBy::Displacement => "Colour: displacement",
        }
    }
}

/// One frame of a 3-D model: every point's x, y and z in generic order, and a number that
/// changes when the frame does.
#[derive(Clone, Copy, Debug)]
pub struct Frame3<'a> {
    pub id: u64,
    pub x: &'a [f32],
    pub y: &'a [f32],
    pub z: &'a [f32],
}

/// The colour of a magnitude `t` in 0 … 1: slate blue at rest, through violet, to coral.
pub fn magnitude(t: f32) -> Color32 {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let t = t.powf(0.7);
    let stops = [
        [70.0, 95.0, 160.0],
        [175.0, 95.0, 220.0],
        [255.0, 120.0, 80.0],
    ];
    let (a, b, u) = if t < 0.5 {
        (stops[0], stops[1], t * 2.0)
    } else {
        (stops[1], stops[2], t * 2.0 - 1.0)
    };
    let c = |i: usize| (a[i] + (b[i] - a[i]) * u) as u8;
    Color32::from_rgb(c(0), c(1), c(2))
}

/// `c` faded towards the background by `f` (0 … 1): far things are darker.
fn fade(c: Color32, f: f32) -> Color32 {
    let mix = |a: u8, b: u8| (a as f32 + (b as f32 - a as f32) * f) as u8;
    Color32::from_rgb(
        mix(c.r(), BACKGROUND.r()),
        mix(c.g(), BACKGROUND.g()),
        mix(c.b(), BACKGROUND.b()),
    )
}

/// A robust level of `levels`: the largest of a few, the 98th percentile of many (one
/// hammer flying about does not set the scale of a membrane).
fn peak(levels: &mut [f32]) -> f32 {
    if levels.len() < 20 {
        levels.iter().fold(0.0f32, |m, &v| m.max(v))
    } else {
        let k = ((levels.len() as f32 * 0.98) as usize).min(levels.len() - 1);
        *levels.select_nth_unstable_by(k, f32::total_cmp).1
    }
}

/// Attack at once, release over [`SCALE_RELEASE_S`].
fn follow(scale: f32, level: f32, dt: f32) -> f32 {
    if level >= scale || !scale.is_finite() {
        level.max(SCALE_FLOOR)
    } else {
        (scale * (-dt / SCALE_RELEASE_S).exp())
            .max(level)
            .max(SCALE_FLOOR)
    }
}

fn length(v: [f32; 3]) -> f32 {
    camera::norm(v)
}

fn minus(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The 3-D motion view's settings and the buffers it keeps between frames.
#[derive(Debug)]
pub struct View3d {
    pub camera: Camera,
    pub colour_by: ColourBy,
    pub exaggerate: bool,
    /// Fit the camera to the model at the next draw.
    refit: bool,
    /// The view and buffer the scene was built for.
    key: Option<(usize, Option<usize>)>,
    scene: Scene,
    /// Per slot: this frame's positions, the previous frame's, speeds, drawn positions,
    /// screen positions with depth, colours.
    raw: Vec<[f32; 3]>,
    prev: Vec<[f32; 3]>,
    speed: Vec<f32>,
    drawn: Vec<[f32; 3]>,
    screen: Vec<(Pos2, f32)>,
    colours: Vec<Color32>,
    /// Scratch for the scales and the dots' drawing order.
    levels: Vec<f32>,
    order: Vec<u32>,
    last_id: Option<u64>,
    since_new: f32,
    disp_scale: f32,
    speed_scale: f32,
    gain: f32,
    /// The triangles of the links and dots, handed to the painter and reused once it lets go.
    mesh: Arc<Mesh>,
}

impl Default for View3d {
    fn default() -> View3d {
        View3d {
            camera: Camera::default(),
            colour_by: ColourBy::Speed,
            exaggerate: true,
            refit: true,
            key: None,
            scene: Scene::default(),
            raw: Vec::new(),
            prev: Vec::new(),
            speed: Vec::new(),
            drawn: Vec::new(),
            screen: Vec::new(),
            colours: Vec::new(),
            levels: Vec::new(),
            order: Vec::new(),
            last_id: None,
            since_new: 0.0,
            disp_scale: SCALE_FLOOR,
            speed_scale: SCALE_FLOOR,
            gain: 1.0,
            mesh: Arc::new(Mesh::default()),
        }
    }
}

impl View3d {
    /// Builds the scene when the view or the chosen buffer changed (and fits the camera to
    /// it). Returns the scene's radius, the size mode shapes are animated at.
    pub fn prepare(&mut self, view: &MotionView, buffer: Option<usize>) -> f32 {
        let key = (view as *const MotionView as usize, buffer);
        if self.key != Some(key) {
            let members = buffer
                .and_then(|b| view.named().get(b))
                .map(|b| b.members.as_slice());
            self.scene = Scene::build(view, members);
            self.key = Some(key);
            self.refit = true;
            self.last_id = None;
            self.disp_scale = SCALE_FLOOR;
            self.speed_scale = SCALE_FLOOR;
            self.speed.clear();
            self.speed.resize(self.scene.len(), 0.0);
        }
        self.scene.radius()
    }

    /// The scene being drawn.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Back to the default direction of view, fitted to the model.
    pub fn reset(&mut self) {
        self.camera = Camera {
            perspective: self.camera.perspective,
            ..Camera::default()
        };
        self.refit = true;
    }

    /// The view's own controls, for the motion panel's tool bar.
    pub fn controls(&mut self, ui: &mut Ui) {
        ui.checkbox(&mut self.camera.perspective, "Perspective")
            .on_hover_text("Perspective or orthographic projection");
        egui::ComboBox::from_id_salt("colour_by")
            .selected_text(self.colour_by.name())
            .show_ui(ui, |ui| {
                for c in [ColourBy::Speed, ColourBy::Displacement] {
                    ui.selectable_value(&mut self.colour_by, c, c.name());
                }
            });
        ui.checkbox(&mut self.exaggerate, "Exaggerate")
            .on_hover_text("Magnify the motion around rest so that small vibrations show");
        if ui
            .small_button("Reset view")
            .on_hover_text(
                "Drag: orbit · wheel: zoom · right/middle or shift-drag: pan · double-click: reset",
            )
            .clicked()
        {
            self.reset();
        }
    }

    /// Takes a frame: positions, speeds (from the previous frame), the scales and the drawn
    /// positions. `dt` is the time since the previous call.
    pub fn update(&mut self, frame: Frame3<'_>, dt: f32) {
        let scene = &self.scene;
        scene.positions(frame.x, frame.y, frame.z, &mut self.raw);
        self.since_new += dt;
        if self.last_id != Some(frame.id) {
            if self.last_id.is_some() && self.prev.len() == self.raw.len() {
                let elapsed = self.since_new.max(1e-4);
                for ((s, p), q) in self.speed.iter_mut().zip(&self.raw).zip(&self.prev) {
                    *s = length(minus(*p, *q)) / elapsed;
                }
            }
            self.prev.clone_from(&self.raw);
            self.last_id = Some(frame.id);
            self.since_new = 0.0;
        }
        // The scales follow the moving points.
        let moving = |k: &usize| !scene.fixed[*k];
        self.levels.clear();
        self.levels.extend(
            (0..scene.len())
                .filter(moving)
                .map(|k| length(minus(self.raw[k], scene.rest[k])))
                .map(|v| if v.is_finite() { v } else { 0.0 }),
        );
        self.disp_scale = follow(self.disp_scale, peak(&mut self.levels), dt);
        self.levels.clear();
        self.levels.extend(
            (0..scene.len())
                .filter(moving)
                .map(|k| self.speed[k])
                .map(|v| if v.is_finite() { v } else { 0.0 }),
        );
        self.speed_scale = follow(self.speed_scale, peak(&mut self.levels), dt);
        let radius = scene.radius();
        self.gain = if self.exaggerate {
            (EXAGGERATION_TARGET * radius / self.disp_scale).clamp(1.0, MAX_GAIN)
        } else {
            1.0
        };
        let (gain, cap) = (self.gain, EXAGGERATION_CAP * radius);
        self.drawn.clear();
        self.drawn
            .extend(self.raw.iter().zip(&scene.rest).map(|(p, r)| {
                if gain == 1.0 {
                    return *p;
                }
                let d = minus(*p, *r).map(|v| v * gain);
                let l = length(d);
                let s = if l > cap { cap / l } else { 1.0 };
                [r[0] + d[0] * s, r[1] + d[1] * s, r[2] + d[2] * s]
            }));
    }

    /// The magnitude the colour of slot `k` shows, 0 … 1.
    fn level(&self, k: usize) -> f32 {
        match self.colour_by {
            ColourBy::Speed => self.speed[k] / self.speed_scale,
            ColourBy::Displacement => {
                length(minus(self.raw[k], self.scene.rest[k])) / self.disp_scale
            }
        }
    }

    /// Draws `frame` of `view` (showing `buffer`, or every point) into the rest of `ui`.
    /// Returns the label of the point under the pointer.
    pub fn show(
        &mut self,
        ui: &mut Ui,
        view: &MotionView,
        buffer: Option<usize>,
        frame: Frame3<'_>,
        dt: f32,
    ) -> Option<String> {
        self.prepare(view, buffer);
        self.update(frame, dt);
        let size = ui.available_size().max(Vec2::new(64.0, 64.0));
        let (response, painter) = ui.allocate_painter(size, Sense::click_and_drag());
        let rect = response.rect;
        let painter = painter.with_clip_rect(rect.intersect(ui.clip_rect()));
        painter.rect_filled(rect, 4.0, BACKGROUND);
        self.navigate(ui, &response, rect);
        if self.scene.is_empty() {
            return None;
        }
        if self.refit {
            let b = self.scene.bounds.unwrap_or(Bounds {
                min: [-1.0; 3],
                max: [1.0; 3],
            });
            self.camera.fit(&b, rect);
            self.refit = false;
        }
        let p = self.camera.projector(rect);
        self.project(&p);
        let mesh = self.triangles(&p, rect);
        painter.add(Shape::mesh(mesh));
        self.markers(&painter);
        self.legend(&painter, rect);
        axes_gizmo(&painter, &self.camera, rect);
        self.hover(&painter, &response, view, rect)
    }

    /// Orbit, pan, zoom and reset from the pointer.
    fn navigate(&mut self, ui: &Ui, response: &egui::Response, rect: Rect) {
        let shift = ui.input(|i| i.modifiers.shift);
        let delta = response.drag_delta();
        if response.dragged_by(PointerButton::Primary) && !shift {
            self.camera.orbit(delta);
        } else if response.dragged_by(PointerButton::Secondary)
            || response.dragged_by(PointerButton::Middle)
            || response.dragged_by(PointerButton::Primary)
        {
            self.camera.pan(delta, rect);
        }
        if response.hovered() {
            let (scroll, zoom) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
            if scroll != 0.0 {
                self.camera.zoom((-scroll * ZOOM_PER_PX).exp());
            }
            if zoom != 1.0 {
                self.camera.zoom(1.0 / zoom);
            }
        }
        if response.double_clicked() {
            self.reset();
        }
    }

    /// Screen positions, depths and colours of every slot.
    fn project(&mut self, p: &Projector) {
        let hidden = (Pos2::new(f32::NAN, f32::NAN), f32::NAN);
        self.screen.clear();
        self.screen
            .extend(self.drawn.iter().map(|&v| p.project(v).unwrap_or(hidden)));
        // Depth cue: the far side of the model's sphere fades towards the background.
        let r = self.scene.radius() * 1.2;
        let near = self.camera.distance - r;
        self.colours.clear();
        for k in 0..self.scene.len() {
            let base = if self.scene.fixed[k] {
                FIXED
            } else {
                magnitude(self.level(k))
            };
            let f = ((self.screen[k].1 - near) / (2.0 * r)).clamp(0.0, 1.0) * 0.55;
            self.colours.push(fade(base, f));
        }
    }

    /// Links as thin quads and dots as octagons, far dots first, in one mesh.
    fn triangles(&mut self, p: &Projector, rect: Rect) -> Arc<Mesh> {
        if Arc::get_mut(&mut self.mesh).is_none() {
            self.mesh = Arc::new(Mesh::default());
        }
        let mesh = Arc::get_mut(&mut self.mesh).expect("the mesh was just made unique");
        mesh.clear();
        let outside = rect.expand(8.0);
        let half_width = 0.6;
        for &[a, b] in &self.scene.links {
            let ((pa, _), (pb, _)) = (self.screen[a as usize], self.screen[b as usize]);
            if !(pa.x.is_finite() && pb.x.is_finite()) {
                continue;
            }
            // Both ends beyond one edge: nothing of it shows.
            if (pa.x < outside.left() && pb.x < outside.left())
                || (pa.x > outside.right() && pb.x > outside.right())
                || (pa.y < outside.top() && pb.y < outside.top())
                || (pa.y > outside.bottom() && pb.y > outside.bottom())
            {
                continue;
            }
            let d = pb - pa;
            let l = d.length();
            if l < 1e-3 {
                continue;
            }
            let n = Vec2::new(-d.y, d.x) * (half_width / l);
            let (ca, cb) = (dim(self.colours[a as usize]), dim(self.colours[b as usize]));
            let i = mesh.vertices.len() as u32;
            mesh.colored_vertex(pa + n, ca);
            mesh.colored_vertex(pa - n, ca);
            mesh.colored_vertex(pb + n, cb);
            mesh.colored_vertex(pb - n, cb);
            mesh.add_triangle(i, i + 1, i + 2);
            mesh.add_triangle(i + 1, i + 3, i + 2);
        }
        self.order.clear();
        self.order.extend(
            self.scene
                .dots
                .iter()
                .copied()
                .filter(|&k| outside.contains(self.screen[k as usize].0)),
        );
        let screen = &self.screen;
        self.order
            .sort_unstable_by(|a, b| screen[*b as usize].1.total_cmp(&screen[*a as usize].1));
        let world = self.scene.radius() * 0.012;
        const RIM: [(f32, f32); 8] = [
            (1.0, 0.0),
            (0.707, 0.707),
            (0.0, 1.0),
            (-0.707, 0.707),
            (-1.0, 0.0),
            (-0.707, -0.707),
            (0.0, -1.0),
            (0.707, -0.707),
        ];
        for &k in &self.order {
            let (c, z) = screen[k as usize];
            let r = (world * p.pixels_per_unit(z)).clamp(1.5, 5.0);
            let colour = self.colours[k as usize];
            let i = mesh.vertices.len() as u32;
            mesh.colored_vertex(c, colour);
            for (x, y) in RIM {
                mesh.colored_vertex(c + Vec2::new(x * r, y * r), colour);
            }
            for j in 0..8 {
                mesh.add_triangle(i, i + 1 + j, i + 1 + (j + 1) % 8);
            }
        }
        self.mesh.clone()
    }

    fn markers(&self, painter: &egui::Painter) {
        let font = FontId::monospace(11.0);
        for m in &self.scene.markers {
            let (at, _) = self.screen[m.slot as usize];
            if !at.x.is_finite() {
                continue;
            }
            let (colour, name, r) = match m.kind {
                MarkerKind::Input => (INPUT, "in", 7.0),
                MarkerKind::Output => (OUTPUT, "out", 9.5),
            };
            painter.circle_stroke(at, r, Stroke::new(2.0, colour));
            painter.text(
                at + Vec2::new(r + 2.0, -r),
                Align2::LEFT_BOTTOM,
                format!("{name}{}", m.channel),
                font.clone(),
                colour,
            );
        }
    }

    /// What the colours and rings mean, the scale, and how the model is thinned.
    fn legend(&self, painter: &egui::Painter, rect: Rect) {
        let font = FontId::monospace(11.0);
        let mut y = rect.top() + 8.0;
        let x = rect.left() + 10.0;
        for (colour, text, r) in [(INPUT, "input", 5.0), (OUTPUT, "output", 6.5)] {
            painter.circle_stroke(Pos2::new(x + 6.0, y + 6.0), r, Stroke::new(2.0, colour));
            painter.text(
                Pos2::new(x + 18.0, y),
                Align2::LEFT_TOP,
                text,
                font.clone(),
                colour,
            );
            y += 16.0;
        }
        // The colour ramp, 0 … the current scale.
        let (what, scale, unit) = match self.colour_by {
            ColourBy::Speed => ("speed", self.speed_scale, "/s"),
            ColourBy::Displacement => ("displacement", self.disp_scale, ""),
        };
        let ramp = Rect::from_min_size(Pos2::new(x, y + 2.0), Vec2::new(90.0, 8.0));
        let mut mesh = Mesh::default();
        for j in 0..=8 {
            let t = j as f32 / 8.0;
            let px = ramp.left() + t * ramp.width();
            mesh.colored_vertex(Pos2::new(px, ramp.top()), magnitude(t));
            mesh.colored_vertex(Pos2::new(px, ramp.bottom()), magnitude(t));
            if j > 0 {
                let i = 2 * j as u32;
                mesh.add_triangle(i - 2, i - 1, i);
                mesh.add_triangle(i - 1, i + 1, i);
            }
        }
        painter.add(Shape::mesh(mesh));
        painter.text(
            Pos2::new(ramp.right() + 6.0, ramp.center().y),
            Align2::LEFT_CENTER,
            format!("{what} 0 … {scale:.2e}{unit}"),
            font.clone(),
            Color32::GRAY,
        );
        y += 16.0;
        let mut notes = Vec::new();
        if self.gain > 1.0 {
            notes.push(format!("motion ×{:.3}", self.gain));
        }
        if self.scene.links.len() < self.scene.links_total {
            notes.push(format!(
                "{} of {} links",
                self.scene.links.len(),
                self.scene.links_total
            ));
        }
        if self.scene.dots.len() < self.scene.len() {
            notes.push(format!(
                "{} of {} points",
                self.scene.dots.len(),
                self.scene.len()
            ));
        }
        notes.push(if self.camera.perspective {
            "perspective".into()
        } else {
            "orthographic".into()
        });
        painter.text(
            Pos2::new(x, y),
            Align2::LEFT_TOP,
            notes.join(" · "),
            font,
            Color32::GRAY,
        );
    }

    /// The point under the pointer, named at the bottom of the view.
    fn hover(
        &self,
        painter: &egui::Painter,
        response: &egui::Response,
        view: &MotionView,
        rect: Rect,
    ) -> Option<String> {
        let pointer = response.hover_pos()?;
        let (k, d2) = self
            .screen
            .iter()
            .enumerate()
            .filter(|(_, (s, _))| s.x.is_finite())
            .map(|(k, (s, _))| (k, s.distance_sq(pointer)))
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        if d2 > PICK_PX * PICK_PX {
            return None;
        }
        let label = view.label(self.scene.points[k] as usize);
        let [x, y, z] = self.raw[k];
        painter.circle_stroke(self.screen[k].0, 5.0, Stroke::new(1.5, Color32::WHITE));
        painter.text(
            rect.left_bottom() + Vec2::new(6.0, -4.0),
            Align2::LEFT_BOTTOM,
            format!(
                "{label}  [{x:.4} {y:.4} {z:.4}]  speed {:.3e}/s",
                self.speed[k]
            ),
            FontId::monospace(11.0),
            Color32::WHITE,
        );
        Some(label)
    }
}

/// Links are drawn a little darker than their points.
fn dim(c: Color32) -> Color32 {
    Color32::from_rgb(
        (c.r() as f32 * 0.8) as u8,
        (c.g() as f32 * 0.8) as u8,
        (c.b() as f32 * 0.8) as u8,
    )
}

/// The x, y and z axes' directions in the bottom right corner.
fn axes_gizmo(painter: &egui::Painter, camera: &Camera, rect: Rect) {
    let origin = rect.right_bottom() + Vec2::new(-34.0, -34.0);
    let view = Camera {
        target: [0.0; 3],
        distance: 1.0,
        perspective: false,
        ..*camera
    };
    // Orthographic at unit distance: an axis of length tan(fov/2) spans half the box, 20 px.
    let box_ = Rect::from_center_size(origin, Vec2::splat(40.0));
    let reach = (0.5 * view.fov).tan();
    let p = view.projector(box_);
    let font = FontId::monospace(10.0);
    for (axis, name, colour) in [
        ([1.0, 0.0, 0.0], "x", Color32::from_rgb(230, 90, 90)),
        ([0.0, 1.0, 0.0], "y", Color32::from_rgb(140, 210, 90)),
        ([0.0, 0.0, 1.0], "z", Color32::from_rgb(100, 150, 255)),
    ] {
        let Some((end, _)) = p.project(axis.map(|v: f32| v * reach)) else {
            continue;
        };
        painter.line_segment([origin, end], Stroke::new(1.5, colour));
        painter.text(
            end + (end - origin) * 0.4,
            Align2::CENTER_CENTER,
            name,
            font.clone(),
            colour,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(text: &str) -> MotionView {
        let spec = ressort_engine::parse(text).spec.unwrap();
        let e =
            ressort_engine::compile(&spec, &ressort_engine::CompileOptions::at(48_000.0)).unwrap();
        MotionView::of(&e)
    }

    const STRING: &str = "~dim 3
@s string3 12 1. 0.3 0.001 [0 0 0] [11 0 0] [0.9*auto]
@in1 frcInput @s_m3 [0 1 0]
@out1 posOutput @s_m8 [0 1 0]
";

    #[test]
    fn the_colour_ramp_rises_and_is_safe() {
        assert_eq!(magnitude(f32::NAN), magnitude(0.0));
        assert_eq!(magnitude(4.0), magnitude(1.0));
        assert!(magnitude(1.0).r() > magnitude(0.0).r());
        assert!(magnitude(0.0).b() > magnitude(0.0).r());
        assert_eq!(fade(INPUT, 1.0), BACKGROUND);
        assert_eq!(fade(INPUT, 0.0), INPUT);
    }

    #[test]
    fn speeds_come_from_successive_frames_and_the_motion_is_exaggerated_within_bounds() {
        let v = view(STRING);
        let mut v3 = View3d::default();
        let radius = v3.prepare(&v, None);
        assert!((radius - 5.5).abs() < 1e-4, "{radius}");
        let n = v.len();
        let (x, z) = (v.rest_x.clone(), v.rest.clone());
        let mut y = v.rest_y.clone();
        v3.update(
            Frame3 {
                id: 1,
                x: &x,
                y: &y,
                z: &z,
            },
            0.01,
        );
        assert!(v3.speed.iter().all(|&s| s == 0.0));
        // Node 5 moves 1e-3 along y over 0.02 s: 0.05 units/s.
        let m5 = (0..n).find(|&i| v.label(i) == "@s_m5").unwrap();
        y[m5] += 1e-3;
        v3.update(
            Frame3 {
                id: 1,
                x: &x,
                y: &y,
                z: &z,
            },
            0.01,
        );
        assert!(
            v3.speed.iter().all(|&s| s == 0.0),
            "the same frame again: no news"
        );
        v3.update(
            Frame3 {
                id: 2,
                x: &x,
                y: &y,
                z: &z,
            },
            0.01,
        );
        assert!((v3.speed[m5] - 0.05).abs() < 1e-4, "{}", v3.speed[m5]);
        assert_eq!(v3.level(m5), 1.0, "the fastest point sets the speed scale");
        // Exaggerated: the millimetre becomes 8 % of the radius; plain, it stays.
        let shown = v3.drawn[m5][1] - v.rest_y[m5];
        assert!(
            (shown - EXAGGERATION_TARGET * radius).abs() < 1e-3,
            "{shown}"
        );
        assert!(v3.gain > 100.0);
        v3.exaggerate = false;
        v3.update(
            Frame3 {
                id: 2,
                x: &x,
                y: &y,
                z: &z,
            },
            0.01,
        );
        assert!((v3.drawn[m5][1] - v.rest_y[m5] - 1e-3).abs() < 1e-6);
        // The ends are grounds: drawn grey whatever they do.
        assert!(v3.scene.fixed[0] && v3.scene.fixed[11]);
    }

    #[test]
    fn one_point_flung_away_does_not_set_the_exaggeration_and_stays_near_its_rest() {
        let v = view(
            &STRING
                .replace("12 1.", "62 1.")
                .replace("[11 0 0]", "[61 0 0]"),
        );
        let mut v3 = View3d::default();
        let radius = v3.prepare(&v, None);
        let (x, z) = (v.rest_x.clone(), v.rest.clone());
        let mut y = v.rest_y.clone();
        for (k, y) in y.iter_mut().enumerate() {
            *y += 1e-4 * (k as f32 * 0.3).sin();
        }
        let m5 = (0..v.len()).find(|&i| v.label(i) == "@s_m5").unwrap();
        y[m5] += 100.0;
        v3.update(
            Frame3 {
                id: 1,
                x: &x,
                y: &y,
                z: &z,
            },
            0.01,
        );
        assert!(v3.gain > 1000.0, "{}", v3.gain);
        let shown = length(minus(v3.drawn[m5], v3.scene.rest[m5]));
        assert!((shown - EXAGGERATION_CAP * radius).abs() < 1e-3, "{shown}");
        assert_eq!(v3.level(m5), 0.0, "no speed before a second frame");
        v3.colour_by = ColourBy::Displacement;
        assert_eq!(v3.level(m5).min(1.0), 1.0);
    }
}
