//! The editor's motion view: a motion frame (spec §6) drawn with egui's painter.
//!
//! 1-D selections (strings, chains, single masses) are drawn along their index as points and
//! lines, z vertical. Selections whose points have distinct x and y rendering coordinates
//! (meshes, triangles, hexagons, anything placed in a plane) are drawn in the plane, with z as
//! colour, as vertical displacement, or both. The vertical scale follows the largest |z| and
//! decays slowly, unless held. Inputs and outputs are marked where they act.

use crate::motion::MotionView;
use egui::{Color32, Mesh, Pos2, Rect, Sense, Shape, Stroke, Ui, Vec2};
use ressort_engine::{IoKind, PointKind};

/// How z appears in the plane view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ZMode {
    Colour,
    Displacement,
    Both,
}

impl ZMode {
    pub const ALL: [ZMode; 3] = [ZMode::Colour, ZMode::Displacement, ZMode::Both];

    pub fn name(self) -> &'static str {
        match self {
            ZMode::Colour => "Colour",
            ZMode::Displacement => "Displacement",
            ZMode::Both => "Colour + displacement",
        }
    }

    fn colour(self) -> bool {
        self != ZMode::Displacement
    }

    fn displacement(self) -> bool {
        self != ZMode::Colour
    }
}

/// Time constant of the auto-scale's release, in seconds.
const SCALE_RELEASE_S: f32 = 2.0;
/// The smallest scale: below it a frame counts as at rest.
const SCALE_FLOOR: f32 = 1e-9;

/// The motion view's settings and the state carried from frame to frame.
#[derive(Clone, Debug)]
pub struct PlotState {
    /// `None` for the generic buffer, else the index of a named buffer.
    pub buffer: Option<usize>,
    pub mode: ZMode,
    /// Keep the largest scale seen instead of following the motion down.
    pub hold: bool,
    pub scale: f32,
    /// The selection for `buffer` of the current view: generic indices, and whether it is
    /// drawn in the plane.
    selection: Vec<u32>,
    planar: bool,
    selection_key: Option<(usize, Option<usize>)>,
    /// Scratch: |z − rest| of the selection, and z − rest of every point.
    levels: Vec<f32>,
    deviation: Vec<f32>,
}

impl Default for PlotState {
    fn default() -> Self {
        PlotState {
            buffer: None,
            mode: ZMode::Both,
            hold: false,
            scale: SCALE_FLOOR,
            selection: Vec::new(),
            planar: false,
            selection_key: None,
            levels: Vec::new(),
            deviation: Vec::new(),
        }
    }
}

/// Blue below zero, orange above, dark at zero; `t` in −1 … 1.
pub fn diverging(t: f32) -> Color32 {
    let t = if t.is_finite() {
        t.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let a = t.abs().powf(0.6);
    let base = [34.0, 36.0, 44.0];
    let end = if t < 0.0 {
        [70.0, 150.0, 255.0]
    } else {
        [255.0, 150.0, 40.0]
    };
    let c = |i: usize| (base[i] + (end[i] - base[i]) * a) as u8;
    Color32::from_rgb(c(0), c(1), c(2))
}

impl PlotState {
    /// Rebuilds the selection when the view or the chosen buffer changed.
    fn select(&mut self, view: &MotionView) {
        let key = (view as *const MotionView as usize, self.buffer);
        if self.selection_key == Some(key) {
            return;
        }
        if self.buffer.is_some_and(|b| b >= view.named().len()) {
            self.buffer = None;
        }
        self.selection = match self.buffer {
            Some(b) => view.named()[b]
                .members
                .iter()
                .copied()
                .filter(|&m| (m as usize) < view.len())
                .collect(),
            None => (0..view.len() as u32).collect(),
        };
        let span = |v: &[f32]| {
            let (lo, hi) = self
                .selection
                .iter()
                .map(|&i| v[i as usize])
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(x), hi.max(x))
                });
            hi - lo
        };
        self.planar = self.selection.len() > 2 && span(&view.x) > 0.0 && span(&view.y) > 0.0;
        self.selection_key = Some((key.0, self.buffer));
        self.scale = SCALE_FLOOR;
    }

    /// Whether the current selection is drawn in the plane.
    pub fn planar(&self) -> bool {
        self.planar
    }

    /// Follows the frame's motion: attack at once, release over [`SCALE_RELEASE_S`]. The
    /// level is the largest |z| of a few points, or the 98th percentile of many, so that one
    /// hammer flying about does not flatten a membrane.
    fn follow(&mut self, dz: &[f32], dt: f32) {
        self.levels.clear();
        self.levels.extend(
            self.selection
                .iter()
                .filter_map(|&i| dz.get(i as usize))
                .map(|v| if v.is_finite() { v.abs() } else { 0.0 }),
        );
        let peak = if self.levels.len() < 20 {
            self.levels.iter().fold(0.0f32, |m, &v| m.max(v))
        } else {
            let k = (self.levels.len() as f32 * 0.98) as usize;
            let k = k.min(self.levels.len() - 1);
            *self.levels.select_nth_unstable_by(k, f32::total_cmp).1
        };
        if peak >= self.scale || !self.scale.is_finite() {
            self.scale = peak.max(SCALE_FLOOR);
        } else if !self.hold {
            let decayed = self.scale * (-dt / SCALE_RELEASE_S).exp();
            self.scale = decayed.max(peak).max(SCALE_FLOOR);
        }
    }

    /// Draws `z` (the generic buffer) into the remaining space of `ui`, as the motion around
    /// the rest positions. `dt` is the time since the previous frame. Returns the label and z
    /// of the point under the pointer.
    pub fn show(
        &mut self,
        ui: &mut Ui,
        view: &MotionView,
        z: &[f32],
        dt: f32,
    ) -> Option<(String, f32)> {
        self.select(view);
        let mut deviation = std::mem::take(&mut self.deviation);
        deviation.clear();
        deviation.extend(
            view.rest
                .iter()
                .enumerate()
                .map(|(i, r)| z.get(i).copied().unwrap_or(*r) - r),
        );
        self.follow(&deviation, dt);
        let shown = self.draw(ui, view, z, &deviation);
        self.deviation = deviation;
        shown
    }

    fn draw(
        &mut self,
        ui: &mut Ui,
        view: &MotionView,
        z: &[f32],
        deviation: &[f32],
    ) -> Option<(String, f32)> {
        let size = ui.available_size().max(Vec2::new(64.0, 64.0));
        let (response, painter) = ui.allocate_painter(size, Sense::hover());
        let rect = response.rect;
        let painter = painter.with_clip_rect(rect.intersect(ui.clip_rect()));
        painter.rect_filled(rect, 4.0, Color32::from_rgb(18, 19, 24));
        if self.selection.is_empty() {
            return None;
        }
        let inner = rect.shrink(18.0);
        let zs = |i: u32| deviation.get(i as usize).copied().unwrap_or(0.0) / self.scale;
        let positions: Vec<Pos2> = if self.planar {
            self.plane_positions(view, inner, &zs)
        } else {
            self.line_positions(inner, &zs)
        };
        // Index in `selection` of each generic point, for links and markers.
        let mut slot = vec![u32::MAX; view.len()];
        for (k, &i) in self.selection.iter().enumerate() {
            slot[i as usize] = k as u32;
        }
        let shapes = if self.planar {
            self.plane_shapes(view, &positions, &slot, &zs, inner)
        } else {
            self.line_shapes(view, &positions, &zs, inner)
        };
        painter.extend(shapes);

        // Inputs and outputs.
        let font = egui::FontId::monospace(11.0);
        for io in &view.io {
            let Some(&k) = slot.get(io.point as usize) else {
                continue;
            };
            if k == u32::MAX {
                continue;
            }
            let p = positions[k as usize];
            let (colour, name) = match io.kind {
                IoKind::ForceInput | IoKind::PositionInput => {
                    (Color32::from_rgb(120, 230, 140), "in")
                }
                IoKind::PositionOutput | IoKind::ForceOutput => {
                    (Color32::from_rgb(250, 220, 90), "out")
                }
            };
            painter.circle_stroke(p, 6.0, Stroke::new(2.0, colour));
            painter.text(
                p + Vec2::new(8.0, -8.0),
                egui::Align2::LEFT_BOTTOM,
                format!("{name}{}", io.channel),
                font.clone(),
                colour,
            );
        }
        painter.text(
            rect.right_top() + Vec2::new(-6.0, 4.0),
            egui::Align2::RIGHT_TOP,
            format!(
                "±{:.3e}{}",
                self.scale,
                if self.hold { " (held)" } else { "" }
            ),
            font,
            Color32::GRAY,
        );

        // The point under the pointer.
        let pointer = response.hover_pos()?;
        let (k, d2) = positions
            .iter()
            .enumerate()
            .map(|(k, p)| (k, p.distance_sq(pointer)))
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        if d2 > 144.0 {
            return None;
        }
        let i = self.selection[k] as usize;
        let (label, zi) = (view.label(i), z.get(i).copied().unwrap_or(0.0));
        painter.circle_stroke(positions[k], 5.0, Stroke::new(1.5, Color32::WHITE));
        painter.text(
            rect.left_bottom() + Vec2::new(6.0, -4.0),
            egui::Align2::LEFT_BOTTOM,
            format!(
                "{label}  z = {zi:.4e}  (rest {:.4e})",
                view.rest.get(i).copied().unwrap_or(0.0)
            ),
            egui::FontId::monospace(11.0),
            Color32::WHITE,
        );
        Some((label, zi))
    }

    fn line_positions(&self, inner: Rect, zs: &impl Fn(u32) -> f32) -> Vec<Pos2> {
        let n = self.selection.len();
        let half = inner.height() * 0.5;
        self.selection
            .iter()
            .enumerate()
            .map(|(k, &i)| {
                let x = if n == 1 {
                    inner.center().x
                } else {
                    inner.left() + inner.width() * k as f32 / (n - 1) as f32
                };
                Pos2::new(x, inner.center().y - zs(i).clamp(-1.2, 1.2) * half * 0.9)
            })
            .collect()
    }

    fn line_shapes(
        &self,
        view: &MotionView,
        positions: &[Pos2],
        zs: &impl Fn(u32) -> f32,
        inner: Rect,
    ) -> Vec<Shape> {
        let mut shapes = vec![Shape::line_segment(
            [
                Pos2::new(inner.left(), inner.center().y),
                Pos2::new(inner.right(), inner.center().y),
            ],
            Stroke::new(1.0, Color32::from_gray(60)),
        )];
        // Runs of consecutive points that belong together: nodes of one macro, or single
        // elements in a row.
        let joined = |a: u32, b: u32| {
            let (pa, pb) = (&view.info.points[a as usize], &view.info.points[b as usize]);
            let is_node =
                |p: &ressort_engine::PointInfo| matches!(p.kind, PointKind::MacroNode { .. });
            b == a + 1 && (pa.owner == pb.owner || !(is_node(pa) || is_node(pb)))
        };
        let line = Stroke::new(1.5, Color32::from_rgb(150, 170, 200));
        let mut run: Vec<Pos2> = Vec::new();
        for k in 0..positions.len() {
            if k > 0 && !joined(self.selection[k - 1], self.selection[k]) {
                if run.len() > 1 {
                    shapes.push(Shape::line(std::mem::take(&mut run), line));
                }
                run.clear();
            }
            run.push(positions[k]);
        }
        if run.len() > 1 {
            shapes.push(Shape::line(run, line));
        }
        let n = positions.len();
        let radius = (inner.width() / n as f32 * 0.3).clamp(1.0, 4.5);
        if n <= 4000 {
            for (k, p) in positions.iter().enumerate() {
                shapes.push(Shape::circle_filled(
                    *p,
                    radius,
                    diverging(zs(self.selection[k])),
                ));
            }
        }
        shapes
    }

    fn plane_positions(
        &self,
        view: &MotionView,
        inner: Rect,
        zs: &impl Fn(u32) -> f32,
    ) -> Vec<Pos2> {
        let (mut x0, mut x1, mut y0, mut y1) = (
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::INFINITY,
            f32::NEG_INFINITY,
        );
        for &i in &self.selection {
            let (x, y) = (view.x[i as usize], view.y[i as usize]);
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        let lift = if self.mode.displacement() {
            inner.height() * 0.12
        } else {
            0.0
        };
        let area = Rect::from_min_max(
            inner.min + Vec2::new(0.0, lift),
            inner.max - Vec2::new(0.0, lift),
        );
        let (w, h) = ((x1 - x0).max(1e-12), (y1 - y0).max(1e-12));
        let s = (area.width() / w).min(area.height() / h);
        let origin = area.center() - Vec2::new(w * s, h * s) * 0.5;
        self.selection
            .iter()
            .map(|&i| {
                let (x, y) = (view.x[i as usize], view.y[i as usize]);
                let dz = if self.mode.displacement() {
                    zs(i).clamp(-1.2, 1.2) * lift
                } else {
                    0.0
                };
                // y grows upwards in model space.
                Pos2::new(origin.x + (x - x0) * s, origin.y + (y1 - y) * s - dz)
            })
            .collect()
    }

    fn plane_shapes(
        &self,
        view: &MotionView,
        positions: &[Pos2],
        slot: &[u32],
        zs: &impl Fn(u32) -> f32,
        inner: Rect,
    ) -> Vec<Shape> {
        let mut shapes = Vec::new();
        let neutral = Color32::from_rgb(150, 170, 200);
        let colour_of = |i: u32| {
            if self.mode.colour() {
                diverging(zs(i))
            } else {
                neutral
            }
        };
        let at = |i: u32| -> Option<Pos2> {
            let k = *slot.get(i as usize)?;
            (k != u32::MAX).then(|| positions[k as usize])
        };
        let mut covered = vec![false; view.len()];
        // Meshes: a filled surface (colour) and/or a wireframe (displacement).
        for run in view.macros.iter().filter(|r| r.width > 1) {
            let (w, rows) = (run.width, run.count / run.width);
            if rows < 2 {
                continue;
            }
            let node = |r: u32, c: u32| run.first + r * w + c;
            if self.mode.colour() {
                let mut mesh = Mesh::default();
                let mut index = vec![u32::MAX; run.count as usize];
                for r in 0..rows {
                    for c in 0..w {
                        let i = node(r, c);
                        if let Some(p) = at(i) {
                            index[(r * w + c) as usize] = mesh.vertices.len() as u32;
                            mesh.colored_vertex(p, diverging(zs(i)));
                        }
                    }
                }
                for r in 0..rows - 1 {
                    for c in 0..w - 1 {
                        let q = [
                            index[(r * w + c) as usize],
                            index[(r * w + c + 1) as usize],
                            index[((r + 1) * w + c) as usize],
                            index[((r + 1) * w + c + 1) as usize],
                        ];
                        if q.iter().all(|&v| v != u32::MAX) {
                            mesh.add_triangle(q[0], q[1], q[2]);
                            mesh.add_triangle(q[1], q[3], q[2]);
                        }
                    }
                }
                shapes.push(Shape::mesh(mesh));
            }
            if self.mode.displacement() {
                let dense = rows.max(w) > 60;
                let step = if dense { rows.max(w).div_ceil(60) } else { 1 };
                let stroke = Stroke::new(
                    1.0,
                    if self.mode.colour() {
                        Color32::from_black_alpha(90)
                    } else {
                        neutral
                    },
                );
                for r in (0..rows).step_by(step as usize) {
                    let pts: Vec<Pos2> = (0..w).filter_map(|c| at(node(r, c))).collect();
                    shapes.push(Shape::line(pts, stroke));
                }
                for c in (0..w).step_by(step as usize) {
                    let pts: Vec<Pos2> = (0..rows).filter_map(|r| at(node(r, c))).collect();
                    shapes.push(Shape::line(pts, stroke));
                }
            }
            for k in run.first..run.first + run.count {
                if let Some(c) = covered.get_mut(k as usize) {
                    *c = true;
                }
            }
        }
        // Strings placed in the plane: their nodes in a line.
        for run in view.macros.iter().filter(|r| r.width == 0) {
            let pts: Vec<Pos2> = (run.first..run.first + run.count).filter_map(&at).collect();
            if pts.len() > 1 {
                shapes.push(Shape::line(pts, Stroke::new(1.5, neutral)));
            }
        }
        // Explicit interactions, then every point not drawn as part of a surface.
        let link = Stroke::new(1.0, Color32::from_gray(90));
        if view.links.len() <= 50_000 {
            for &(a, b) in &view.links {
                if let (Some(pa), Some(pb)) = (at(a), at(b)) {
                    shapes.push(Shape::line_segment([pa, pb], link));
                }
            }
        }
        let loose = self
            .selection
            .iter()
            .filter(|&&i| !covered[i as usize])
            .count()
            .max(1);
        let radius =
            (inner.width().min(inner.height()) / (loose as f32).sqrt() * 0.18).clamp(1.5, 6.0);
        for &i in &self.selection {
            if covered[i as usize] {
                continue;
            }
            if let Some(p) = at(i) {
                shapes.push(Shape::circle_filled(p, radius, colour_of(i)));
            }
        }
        shapes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_colour_map_is_symmetric_in_strength_and_safe() {
        let (neg, zero, pos) = (diverging(-1.0), diverging(0.0), diverging(1.0));
        assert_ne!(neg, pos);
        assert_eq!(diverging(f32::NAN), zero);
        assert_eq!(diverging(7.0), pos);
        assert!(neg.b() > neg.r() && pos.r() > pos.b());
    }

    #[test]
    fn the_scale_attacks_at_once_releases_slowly_and_holds() {
        let mut s = PlotState {
            selection: vec![0, 1],
            ..PlotState::default()
        };
        let mut many = PlotState {
            selection: (0..100).collect(),
            ..PlotState::default()
        };
        let mut dz = vec![0.01; 100];
        dz[7] = 5.0;
        many.follow(&dz, 0.016);
        assert_eq!(
            many.scale, 0.01,
            "one outlier among many does not set the scale"
        );
        s.follow(&[0.5, -2.0], 0.016);
        assert_eq!(s.scale, 2.0);
        s.follow(&[0.0, 0.1], 1.0);
        assert!(
            (s.scale - 2.0 * (-0.5f32).exp()).abs() < 1e-6,
            "{}",
            s.scale
        );
        s.hold = true;
        let held = s.scale;
        s.follow(&[0.0, 0.0], 10.0);
        assert_eq!(s.scale, held);
    }
}
