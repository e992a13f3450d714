//! Motion frames for the editor (spec §6): the positions of the material points leave the audio
//! thread through a lock-free triple buffer, and only while the editor is open.
//!
//! Each prepared model owns the writing end ([`MotionWriter`]); the reading end
//! ([`MotionReader`]) goes to the [`crate::model::ModelStore`], where the editor picks it up
//! together with the model's static [`MotionView`] (coordinates, named buffers, where the
//! inputs and outputs are, which points are linked). The audio thread copies the generic
//! buffer at most [`MOTION_FRAME_RATE`] times per second: a copy of every point's z into a
//! preallocated frame and a publish, no allocation and no lock.

use ressort_engine::{Engine, IoPoint, ModelInfo, NamedBuffer, PointKind};
use std::sync::Arc;
use triple_buffer::{Input, Output};

/// The most frames per second the audio thread publishes; displays refresh at 30–60 Hz.
pub const MOTION_FRAME_RATE: f64 = 120.0;

/// One snapshot of the generic motion buffer.
#[derive(Clone, Debug, Default)]
pub struct MotionFrame {
    /// Counts published frames from 1; 0 means nothing was published yet.
    pub number: u64,
    /// The z of every material point, in generic order.
    pub z: Vec<f32>,
    /// A 3-D model's x and y of every material point (empty for a 1-D model).
    pub x: Vec<f32>,
    pub y: Vec<f32>,
}

/// A macro structure's nodes in the generic buffer: strings are runs of `count` nodes,
/// meshes `count / width` rows of `width`.
#[derive(Clone, Debug, PartialEq)]
pub struct MacroRun {
    pub first: u32,
    pub count: u32,
    /// 0 for 1-D macros.
    pub width: u32,
}

/// What a motion frame means, made once per model off the audio thread.
#[derive(Clone, Debug, Default)]
pub struct MotionView {
    /// Display coordinates of every point, generic order: the rendering coordinates of spec
    /// §2.7 where the script gives them, grid coordinates for meshes without them, and the
    /// mean of its linked neighbours for a single point without them.
    pub x: Vec<f32>,
    pub y: Vec<f32>,
    /// Every point's position at rest: the view shows the motion around it.
    pub rest: Vec<f32>,
    /// A 3-D model's rest positions on x and y (empty for a 1-D model; z is `rest`).
    pub rest_x: Vec<f32>,
    pub rest_y: Vec<f32>,
    /// The model's metadata: points, owners, named buffers (`info.motion.named`).
    pub info: ModelInfo,
    pub io: Vec<IoPoint>,
    /// Explicit interactions as point pairs.
    pub links: Vec<(u32, u32)>,
    pub macros: Vec<MacroRun>,
}

impl MotionView {
    /// The view of a compiled model.
    pub fn of(engine: &Engine) -> MotionView {
        let info = engine.info();
        let mut macros: Vec<MacroRun> = Vec::new();
        for (i, p) in info.points.iter().enumerate() {
            if let PointKind::MacroNode { .. } = p.kind {
                match macros.last_mut() {
                    Some(run)
                        if info.points[run.first as usize].owner == p.owner
                            && (run.first + run.count) as usize == i =>
                    {
                        run.count += 1
                    }
                    _ => macros.push(MacroRun {
                        first: i as u32,
                        count: 1,
                        width: info.owners[p.owner as usize].mesh_width,
                    }),
                }
            }
        }
        let (x, y) = display_coordinates(engine, &macros);
        MotionView {
            x,
            y,
            rest: engine.positions()[..info.num_points]
                .iter()
                .map(|&v| v as f32)
                .collect(),
            rest_x: engine
                .axis(0)
                .iter()
                .take(info.num_points)
                .map(|&v| v as f32)
                .collect(),
            rest_y: engine
                .axis(1)
                .iter()
                .take(info.num_points)
                .map(|&v| v as f32)
                .collect(),
            info: info.clone(),
            io: engine.io_points(),
            links: engine.links(),
            macros,
        }
    }

    /// The number of points of the generic buffer.
    pub fn len(&self) -> usize {
        self.info.points.len()
    }

    /// Whether the model is three-dimensional (its frames carry x and y too).
    pub fn is_3d(&self) -> bool {
        !self.rest_x.is_empty()
    }

    pub fn is_empty(&self) -> bool {
        self.info.points.is_empty()
    }

    /// The named buffers (spec §6.3).
    pub fn named(&self) -> &[NamedBuffer] {
        &self.info.motion.named
    }

    /// A readable name for point `i`: `@m1`, `@s[12]`, `@mesh[3,4]`.
    pub fn label(&self, i: usize) -> String {
        if i < self.len() {
            format!("@{}", self.info.point_label(i))
        } else {
            String::new()
        }
    }
}

/// Display coordinates (see [`MotionView::x`]).
fn display_coordinates(engine: &Engine, macros: &[MacroRun]) -> (Vec<f32>, Vec<f32>) {
    let info = engine.info();
    let n = info.num_points;
    let mut x: Vec<f32> = info.motion.x.iter().map(|&v| v as f32).collect();
    let mut y: Vec<f32> = info.motion.y.iter().map(|&v| v as f32).collect();
    // An element is placed when any of its points has a non-zero coordinate.
    let mut placed_owner = vec![false; info.owners.len()];
    for (i, p) in info.points.iter().enumerate() {
        if x[i] != 0.0 || y[i] != 0.0 {
            placed_owner[p.owner as usize] = true;
        }
    }
    let mut placed: Vec<bool> = info
        .points
        .iter()
        .map(|p| placed_owner[p.owner as usize])
        .collect();
    // Meshes without coordinates: row i along x, column j along y, as placed meshes are.
    for run in macros.iter().filter(|r| r.width > 1) {
        if placed[run.first as usize] {
            continue;
        }
        for k in 0..run.count {
            let i = (run.first + k) as usize;
            x[i] = (k / run.width) as f32;
            y[i] = (k % run.width) as f32;
            placed[i] = true;
        }
    }
    // Single points without coordinates sit at the mean of their placed neighbours, so a
    // hammer shows where it strikes (a few passes reach along short chains).
    let links = engine.links();
    if placed.iter().any(|&p| p) {
        for _ in 0..3 {
            let mut sum = vec![(0.0f32, 0.0f32, 0u32); n];
            for &(a, b) in &links {
                let (a, b) = (a as usize, b as usize);
                if a >= n || b >= n {
                    continue;
                }
                for (from, to) in [(a, b), (b, a)] {
                    if placed[from] && !placed[to] {
                        sum[to].0 += x[from];
                        sum[to].1 += y[from];
                        sum[to].2 += 1;
                    }
                }
            }
            for (i, &(sx, sy, c)) in sum.iter().enumerate() {
                let single = !matches!(info.points[i].kind, PointKind::MacroNode { .. });
                if c > 0 && single {
                    x[i] = sx / c as f32;
                    y[i] = sy / c as f32;
                    placed[i] = true;
                }
            }
        }
    }
    (x, y)
}

/// The audio thread's end: publishes frames at most [`MOTION_FRAME_RATE`] times a second.
pub struct MotionWriter {
    input: Input<MotionFrame>,
    /// Samples between frames.
    interval: u64,
    /// Samples since the last frame.
    elapsed: u64,
    published: u64,
}

impl std::fmt::Debug for MotionWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MotionWriter")
            .field("interval", &self.interval)
            .field("published", &self.published)
            .finish()
    }
}

impl ressort_engine::instrument::Watcher for MotionWriter {
    fn tick(&mut self, frames: usize, axes: [&[f64]; 3], watching: bool) {
        MotionWriter::tick(self, frames, axes, watching);
    }
}

impl MotionWriter {
    /// Called after every chunk of `frames` samples. When the editor is open and a frame is
    /// due, copies the material points' positions and publishes them. Realtime-safe.
    #[inline]
    pub fn tick(&mut self, frames: usize, axes: [&[f64]; 3], editor_open: bool) {
        self.elapsed += frames as u64;
        if !editor_open || self.elapsed < self.interval {
            return;
        }
        self.elapsed = 0;
        self.published += 1;
        let frame = self.input.input_buffer_mut();
        frame.number = self.published;
        let copy = |to: &mut [f32], from: &[f64]| {
            for (v, p) in to.iter_mut().zip(from) {
                *v = if p.is_finite() { *p as f32 } else { 0.0 };
            }
        };
        copy(&mut frame.z, axes[2]);
        copy(&mut frame.x, axes[0]);
        copy(&mut frame.y, axes[1]);
        self.input.publish();
    }

    /// Frames published so far.
    pub fn published(&self) -> u64 {
        self.published
    }
}

/// The editor's end: the model's view and its latest frame.
pub struct MotionReader {
    pub view: Arc<MotionView>,
    output: Output<MotionFrame>,
}

impl std::fmt::Debug for MotionReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MotionReader")
            .field("points", &self.view.len())
            .finish()
    }
}

impl MotionReader {
    /// The latest published frame (frame number 0 before the first one).
    pub fn latest(&mut self) -> &MotionFrame {
        self.output.read()
    }
}

/// A writer and reader for a compiled model, at `sample_rate`.
pub fn motion_channel(engine: &Engine, sample_rate: f64) -> (MotionWriter, MotionReader) {
    let view = MotionView::of(engine);
    let planar = if view.is_3d() { view.len() } else { 0 };
    let frame = MotionFrame {
        number: 0,
        z: vec![0.0; view.len()],
        x: vec![0.0; planar],
        y: vec![0.0; planar],
    };
    let (input, output) = triple_buffer::triple_buffer(&frame);
    let interval = (sample_rate / MOTION_FRAME_RATE).round().max(1.0) as u64;
    (
        MotionWriter {
            input,
            interval,
            elapsed: 0,
            published: 0,
        },
        MotionReader {
            view: Arc::new(view),
            output,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn engine(text: &str) -> Engine {
        let spec = ressort_engine::parse(text).spec.unwrap();
        ressort_engine::compile(&spec, &ressort_engine::CompileOptions::at(48_000.0)).unwrap()
    }

    #[test]
    fn frames_flow_only_while_the_editor_is_open() {
        let e = engine(crate::presets::Preset::find("mesh-15x15").unwrap().text);
        let (mut w, mut r) = motion_channel(&e, 48_000.0);
        assert_eq!(r.view.macros.len(), 1);
        assert_eq!(
            r.view.macros[0],
            MacroRun {
                first: 2,
                count: 225,
                width: 15
            }
        );
        assert_eq!(r.view.label(2 + 16), "@mesh[1,1]");
        // The mesh has no rendering coordinates: grid coordinates (row along x). The hammer
        // sits where it strikes ([@mesh 0.3 0.2] → node (4, 3)), its ground above it.
        assert_eq!((r.view.x[2 + 16], r.view.y[2 + 16]), (1.0, 1.0));
        let h = (0..r.view.len())
            .find(|&i| r.view.label(i) == "@h")
            .unwrap();
        let gh = (0..r.view.len())
            .find(|&i| r.view.label(i) == "@gh")
            .unwrap();
        assert_eq!((r.view.x[h], r.view.y[h]), (4.0, 3.0));
        assert_eq!((r.view.x[gh], r.view.y[gh]), (4.0, 3.0));
        assert_eq!(r.view.rest[h], 0.1, "the hammer rests at 0.1");
        let mut positions = vec![0.25; e.positions().len()];
        for _ in 0..100 {
            w.tick(16, [&[], &[], &positions], false);
        }
        assert_eq!(r.latest().number, 0, "closed editor: nothing published");
        // 400 samples per frame at 48 kHz: 25 chunks of 16.
        for _ in 0..25 {
            w.tick(16, [&[], &[], &positions], true);
        }
        let f = r.latest();
        assert_eq!(f.number, 1);
        assert_eq!(f.z.len(), 227);
        assert!(f.z.iter().all(|&z| z == 0.25));
        positions[3] = f64::NAN;
        for _ in 0..25 {
            w.tick(16, [&[], &[], &positions], true);
        }
        let f = r.latest();
        assert_eq!((f.number, f.z[3], f.z[4]), (2, 0.0, 0.25));
    }
}
