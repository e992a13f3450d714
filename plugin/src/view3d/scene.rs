//! What the 3-D motion view draws of a model, built once per model (and buffer choice) from
//! its [`MotionView`]: the points, their rest positions, which of them never move, the links
//! between them (thinned out to [`MAX_LINKS`] on big models), which points get a dot
//! ([`MAX_DOTS`] at most) and where the inputs and outputs act.

use super::camera::Bounds;
use crate::motion::MotionView;
use ressort_engine::{IoKind, PointKind};

/// The most links drawn per frame; a model with more draws every k-th.
pub const MAX_LINKS: usize = 12_000;
/// The most points drawn as dots per frame; a model with more draws every k-th (the links
/// still show its shape).
pub const MAX_DOTS: usize = 3_000;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MarkerKind {
    Input,
    Output,
}

/// An input or output of the model, on the point it acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Marker {
    /// Index into [`Scene::points`].
    pub slot: u32,
    pub kind: MarkerKind,
    /// 1-based channel.
    pub channel: u32,
}

/// The static part of the 3-D drawing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// The generic motion-buffer index of each drawn point ("slot").
    pub points: Vec<u32>,
    /// Each slot's position at rest (stage 0).
    pub rest: Vec<[f32; 3]>,
    /// Grounds and fixed structure nodes: drawn, but not coloured by motion.
    pub fixed: Vec<bool>,
    /// Links as slot pairs, each pair once, thinned to [`MAX_LINKS`].
    pub links: Vec<[u32; 2]>,
    /// How many distinct links the selection has before thinning.
    pub links_total: usize,
    /// The slots drawn as dots.
    pub dots: Vec<u32>,
    pub markers: Vec<Marker>,
    /// The box around the rest positions.
    pub bounds: Option<Bounds>,
}

impl Scene {
    /// The scene of `view`'s points, or of `members` (generic indices) only.
    pub fn build(view: &MotionView, members: Option<&[u32]>) -> Scene {
        let n = view.len();
        let points: Vec<u32> = match members {
            Some(m) => m.iter().copied().filter(|&i| (i as usize) < n).collect(),
            None => (0..n as u32).collect(),
        };
        let mut slot = vec![u32::MAX; n];
        for (k, &i) in points.iter().enumerate() {
            slot[i as usize] = k as u32;
        }
        let at = |v: &[f32], i: usize| v.get(i).copied().unwrap_or(0.0);
        let rest: Vec<[f32; 3]> = points
            .iter()
            .map(|&i| {
                let i = i as usize;
                [at(&view.rest_x, i), at(&view.rest_y, i), at(&view.rest, i)]
            })
            .collect();
        let fixed = points
            .iter()
            .map(|&i| {
                matches!(
                    view.info.points[i as usize].kind,
                    PointKind::Ground | PointKind::MacroNode { fixed: true }
                )
            })
            .collect();
        let slot_of = |i: u32| slot.get(i as usize).copied().filter(|&s| s != u32::MAX);
        let mut all: Vec<[u32; 2]> = view
            .links
            .iter()
            .filter_map(|&(a, b)| {
                let (a, b) = (slot_of(a)?, slot_of(b)?);
                (a != b).then(|| [a.min(b), a.max(b)])
            })
            .collect();
        // A spring and the damper beside it are one line.
        all.sort_unstable();
        all.dedup();
        let links_total = all.len();
        let links = if links_total > MAX_LINKS {
            let step = links_total.div_ceil(MAX_LINKS);
            all.into_iter().step_by(step).collect()
        } else {
            all
        };
        let step = points.len().div_ceil(MAX_DOTS).max(1);
        let dots = (0..points.len() as u32).step_by(step).collect();
        let markers = view
            .io
            .iter()
            .filter_map(|io| {
                Some(Marker {
                    slot: slot_of(io.point)?,
                    kind: match io.kind {
                        IoKind::ForceInput | IoKind::PositionInput => MarkerKind::Input,
                        IoKind::PositionOutput | IoKind::ForceOutput => MarkerKind::Output,
                    },
                    channel: io.channel,
                })
            })
            .collect();
        let bounds = Bounds::of(rest.iter().copied());
        Scene {
            points,
            rest,
            fixed,
            links,
            links_total,
            dots,
            markers,
            bounds,
        }
    }

    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The radius of the rest positions' bounding sphere (1 for an empty or point-like
    /// scene, so that the view has a size to work with).
    pub fn radius(&self) -> f32 {
        match self.bounds {
            Some(b) if b.radius() > 1e-9 => b.radius(),
            _ => 1.0,
        }
    }

    /// Fills `out` with each slot's position in a frame of the generic buffer (`x`, `y`, `z`
    /// by generic index); a frame that lacks an axis (none published yet) reads the rest.
    pub fn positions(&self, x: &[f32], y: &[f32], z: &[f32], out: &mut Vec<[f32; 3]>) {
        out.clear();
        let n = self
            .points
            .iter()
            .map(|&i| i as usize + 1)
            .max()
            .unwrap_or(0);
        if x.len() < n || y.len() < n || z.len() < n {
            out.extend_from_slice(&self.rest);
            return;
        }
        out.extend(self.points.iter().map(|&i| {
            let i = i as usize;
            [x[i], y[i], z[i]]
        }));
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

    /// LANGUAGE.md §19.7's membrane with a ball, plus an input on the ball.
    const MEMBRANE: &str = "~dim 3
~gravity [0 0 -20]
@mem mesh3 15 15 1. 0.2 0.001 [0 0 0] [14 0 0] [0 14 0] [0.9*auto] 'fix=borders'
@mv vdampers @mem 0.0002
@ball mass 20. [6.3 7.1 3] [0 0 0]
@hit contactSet @ball @mem 0.05 0.002 0.5
@in1 frcInput @ball
@out1 posOutput @mem_m4_9
";

    #[test]
    fn a_membrane_and_its_ball_become_points_links_and_markers() {
        let v = view(MEMBRANE);
        assert!(v.is_3d());
        let s = Scene::build(&v, None);
        assert_eq!(s.len(), v.len());
        // The membrane's nodes lie in z = 0 on a 14 × 14 square, the ball above it.
        let b = s.bounds.unwrap();
        assert_eq!((b.min, b.max), ([0.0, 0.0, 0.0], [14.0, 14.0, 3.0]));
        let ball = (0..v.len()).find(|&i| v.label(i) == "@ball").unwrap();
        assert_eq!(s.rest[ball], [6.3, 7.1, 3.0]);
        // Its rows and columns: 2 · 15 · 14 links (the vector dampers lie on the same lines),
        // and the contacts to the ball when the engine lists them.
        let grid = 2 * 15 * 14;
        assert!(s.links_total >= grid, "{}", s.links_total);
        assert!(s
            .links
            .iter()
            .all(|&[a, b]| a < b && (b as usize) < s.len()));
        let node = |label: &str| (0..v.len()).find(|&i| v.label(i) == label).unwrap() as u32;
        let (m00, m01) = (node("@mem_m0_0"), node("@mem_m0_1"));
        assert!(s.links.contains(&[m00.min(m01), m00.max(m01)]));
        // Borders are fixed, the middle and the ball move.
        assert!(s.fixed[m00 as usize]);
        assert!(!s.fixed[node("@mem_m7_7") as usize] && !s.fixed[ball]);
        assert_eq!(s.dots.len(), s.len(), "a small model draws every point");
        let mut markers = s.markers.clone();
        markers.sort_by_key(|m| m.channel);
        assert_eq!(
            markers,
            [
                Marker {
                    slot: ball as u32,
                    kind: MarkerKind::Input,
                    channel: 1
                },
                Marker {
                    slot: node("@mem_m4_9"),
                    kind: MarkerKind::Output,
                    channel: 1
                }
            ]
        );
    }

    #[test]
    fn a_selection_keeps_its_own_points_links_and_markers() {
        let v = view(MEMBRANE);
        let node = |label: &str| (0..v.len()).find(|&i| v.label(i) == label).unwrap() as u32;
        let row: Vec<u32> = (0..15).map(|j| node(&format!("@mem_m4_{j}"))).collect();
        let s = Scene::build(&v, Some(&row));
        assert_eq!(s.points, row);
        assert_eq!(s.links_total, 14, "only the links inside the row");
        assert_eq!(s.markers.len(), 1);
        assert_eq!(s.markers[0].slot, 9);
        // Positions follow the frame, slot by slot; a frame without axes reads the rest.
        let n = v.len();
        let (x, y, z) = (vec![1.0; n], vec![2.0; n], vec![3.0; n]);
        let mut out = Vec::new();
        s.positions(&x, &y, &z, &mut out);
        assert_eq!(out, vec![[1.0, 2.0, 3.0]; 15]);
        s.positions(&[], &[], &z, &mut out);
        assert_eq!(out, s.rest);
    }

    #[test]
    fn big_models_are_thinned_to_the_drawing_limits() {
        let v = view(
            "~dim 3\n@mem mesh3 80 80 1. 0.2 0.001 [0 0 0] [79 0 0] [0 79 0] auto 'fix=borders diag'\n@out1 posOutput @mem_m4_9\n",
        );
        let s = Scene::build(&v, None);
        assert_eq!(s.len(), 6400);
        assert!(s.links_total > MAX_LINKS, "{}", s.links_total);
        assert!(s.links.len() <= MAX_LINKS && s.links.len() > MAX_LINKS / 2);
        assert!(s.dots.len() <= MAX_DOTS && s.dots.len() > MAX_DOTS / 2);
    }
}
