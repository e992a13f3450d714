//! The 3-D motion view's camera: an orbit camera around a target point (yaw, pitch, distance,
//! vertical field of view), perspective or orthographic, and the projection of model points
//! onto the view's rectangle. z is up, as in the model (3-D spec §1.3: gravity along −z).

use egui::{Pos2, Rect, Vec2};

/// Points closer to the eye than this fraction of the camera distance are not drawn.
const NEAR: f32 = 1e-3;
/// The pitch stays this far from the poles, so the view's up direction is always defined.
const PITCH_LIMIT: f32 = 1.55;
/// Radians per pixel of an orbit drag.
pub const ORBIT_PER_PX: f32 = 0.008;
/// The fitted view leaves this margin around the model's bounding sphere.
const FIT_MARGIN: f32 = 1.15;

/// An axis-aligned box around a set of points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

impl Bounds {
    /// The box of the finite points among `points`; None when there is none.
    pub fn of(points: impl IntoIterator<Item = [f32; 3]>) -> Option<Bounds> {
        let mut b: Option<Bounds> = None;
        for p in points {
            if !p.iter().all(|v| v.is_finite()) {
                continue;
            }
            let bb = b.get_or_insert(Bounds { min: p, max: p });
            for c in 0..3 {
                bb.min[c] = bb.min[c].min(p[c]);
                bb.max[c] = bb.max[c].max(p[c]);
            }
        }
        b
    }

    pub fn centre(&self) -> [f32; 3] {
        [0, 1, 2].map(|c| 0.5 * (self.min[c] + self.max[c]))
    }

    /// Half the box's diagonal: the radius of a sphere around it.
    pub fn radius(&self) -> f32 {
        0.5 * norm(sub(self.max, self.min))
    }
}

/// The orbit camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Angle of the eye around the target in the xy plane, from +x towards +y (radians).
    pub yaw: f32,
    /// Elevation of the eye above the target's xy plane (radians).
    pub pitch: f32,
    /// Distance from the eye to the target.
    pub distance: f32,
    pub target: [f32; 3],
    /// Vertical field of view (radians); the orthographic view shows the same height at the
    /// target's distance.
    pub fov: f32,
    pub perspective: bool,
}

impl Default for Camera {
    /// Looking at the origin from the front-left, a little from above.
    fn default() -> Camera {
        Camera {
            yaw: -2.2,
            pitch: 0.55,
            distance: 10.0,
            target: [0.0; 3],
            fov: 0.7,
            perspective: true,
        }
    }
}

/// A camera set up for one rectangle: projects points without recomputing the basis.
#[derive(Clone, Copy, Debug)]
pub struct Projector {
    eye: [f32; 3],
    right: [f32; 3],
    up: [f32; 3],
    forward: [f32; 3],
    centre: Pos2,
    /// Pixels per unit at unit depth (perspective) or everywhere (orthographic).
    focal: f32,
    perspective: bool,
    near: f32,
}

impl Camera {
    /// The eye's position.
    pub fn eye(&self) -> [f32; 3] {
        let (cp, sp) = (self.pitch.cos(), self.pitch.sin());
        let dir = [cp * self.yaw.cos(), cp * self.yaw.sin(), sp];
        add(self.target, scale(dir, self.distance))
    }

    /// The projector for `rect`.
    pub fn projector(&self, rect: Rect) -> Projector {
        let eye = self.eye();
        let forward = normalise(sub(self.target, eye));
        let right = normalise(cross(forward, [0.0, 0.0, 1.0]));
        let up = cross(right, forward);
        let half = 0.5 * rect.height().max(1.0);
        let tan = (0.5 * self.fov).tan();
        let focal = if self.perspective {
            half / tan
        } else {
            half / (self.distance * tan)
        };
        Projector {
            eye,
            right,
            up,
            forward,
            centre: rect.center(),
            focal,
            perspective: self.perspective,
            near: NEAR * self.distance,
        }
    }

    /// Turns the eye around the target by a drag of `delta` pixels: right turns the model
    /// to the right, down raises the eye. The distance stays.
    pub fn orbit(&mut self, delta: Vec2) {
        self.yaw = (self.yaw - delta.x * ORBIT_PER_PX) % std::f32::consts::TAU;
        self.pitch = (self.pitch + delta.y * ORBIT_PER_PX).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Moves the eye towards the target (`factor` < 1) or away from it.
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance * factor).clamp(1e-6, 1e9);
        }
    }

    /// Moves the target so that the model follows a drag of `delta` pixels in `rect`.
    pub fn pan(&mut self, delta: Vec2, rect: Rect) {
        let p = self.projector(rect);
        // Units per pixel in the target's plane, for both projections.
        let unit = if self.perspective {
            self.distance / p.focal
        } else {
            1.0 / p.focal
        };
        let shift = add(scale(p.right, -delta.x * unit), scale(p.up, delta.y * unit));
        self.target = add(self.target, shift);
    }

    /// Aims at the centre of `bounds` from a distance that shows all of it in `rect`, keeping
    /// the direction of view.
    pub fn fit(&mut self, bounds: &Bounds, rect: Rect) {
        self.target = bounds.centre();
        let radius = bounds.radius().max(1e-6) * FIT_MARGIN;
        // The narrower of the two fields of view decides.
        let aspect = (rect.width() / rect.height().max(1.0)).clamp(0.05, 20.0);
        let half_v = 0.5 * self.fov;
        let half_h = (half_v.tan() * aspect).atan();
        let half = half_v.min(half_h);
        self.distance = radius / half.sin();
    }
}

impl Projector {
    /// Where `p` appears on screen and its depth along the view (None behind the eye, in
    /// perspective).
    #[inline]
    pub fn project(&self, p: [f32; 3]) -> Option<(Pos2, f32)> {
        let d = sub(p, self.eye);
        let (x, y, z) = (dot(d, self.right), dot(d, self.up), dot(d, self.forward));
        let s = if self.perspective {
            if z < self.near || !z.is_finite() {
                return None;
            }
            self.focal / z
        } else {
            self.focal
        };
        let pos = Pos2::new(self.centre.x + x * s, self.centre.y - y * s);
        (pos.x.is_finite() && pos.y.is_finite()).then_some((pos, z))
    }

    /// Pixels per unit length at depth `z`.
    pub fn pixels_per_unit(&self, z: f32) -> f32 {
        if self.perspective {
            self.focal / z.max(self.near)
        } else {
            self.focal
        }
    }
}

fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: [f32; 3], s: f32) -> [f32; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn norm(a: [f32; 3]) -> f32 {
    dot(a, a).sqrt()
}

fn normalise(a: [f32; 3]) -> [f32; 3] {
    let n = norm(a);
    if n > 0.0 {
        scale(a, 1.0 / n)
    } else {
        [1.0, 0.0, 0.0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect() -> Rect {
        Rect::from_min_size(Pos2::new(0.0, 0.0), Vec2::new(400.0, 200.0))
    }

    /// Looking along −x at the origin from (10, 0, 0).
    fn front(perspective: bool) -> Camera {
        Camera {
            yaw: 0.0,
            pitch: 0.0,
            distance: 10.0,
            target: [0.0; 3],
            fov: 2.0 * (0.1f32).atan(),
            perspective,
        }
    }

    fn close(a: Pos2, b: Pos2) -> bool {
        (a - b).length() < 1e-3
    }

    #[test]
    fn known_points_project_where_the_geometry_says() {
        // tan(fov/2) = 0.1 and half the height is 100 px: 1000 px per unit at unit depth.
        let p = front(true).projector(rect());
        let (centre, depth) = p.project([0.0; 3]).unwrap();
        assert!(close(centre, Pos2::new(200.0, 100.0)), "{centre:?}");
        assert!((depth - 10.0).abs() < 1e-5);
        // From +x looking at the origin, +y is to the right and +z up (a right-handed view,
        // not a mirror; y grows downwards on screen): 1 unit at depth 10 is 100 px.
        let (right, _) = p.project([0.0, 1.0, 0.0]).unwrap();
        assert!(close(right, Pos2::new(300.0, 100.0)), "{right:?}");
        let (top, _) = p.project([0.0, 0.0, 1.0]).unwrap();
        assert!(close(top, Pos2::new(200.0, 0.0)), "{top:?}");
        // Nearer points spread further from the centre; points behind the eye vanish.
        let (near, d) = p.project([5.0, 0.0, 1.0]).unwrap();
        assert!(close(near, Pos2::new(200.0, -100.0)), "{near:?}");
        assert!((d - 5.0).abs() < 1e-5);
        assert!(p.project([11.0, 0.0, 0.0]).is_none());
    }

    #[test]
    fn orthographic_keeps_sizes_with_depth_and_agrees_at_the_target() {
        let (persp, ortho) = (
            front(true).projector(rect()),
            front(false).projector(rect()),
        );
        let at = |p: &Projector, v| p.project(v).unwrap().0;
        // In the target's plane both show the same picture.
        assert!(close(
            at(&persp, [0.0, 1.0, 0.5]),
            at(&ortho, [0.0, 1.0, 0.5])
        ));
        // Off it, only the perspective one changes size with depth.
        assert!(close(
            at(&ortho, [5.0, 0.0, 1.0]),
            at(&ortho, [-5.0, 0.0, 1.0])
        ));
        assert!(close(at(&ortho, [5.0, 0.0, 1.0]), Pos2::new(200.0, 0.0)));
        assert!(!close(
            at(&persp, [5.0, 0.0, 1.0]),
            at(&persp, [-5.0, 0.0, 1.0])
        ));
        // Orthographic draws what is behind the eye too (it has none).
        assert!(ortho.project([20.0, 0.0, 0.0]).is_some());
        assert_eq!(ortho.pixels_per_unit(1.0), ortho.pixels_per_unit(100.0));
    }

    #[test]
    fn orbiting_keeps_the_distance_and_the_target() {
        let mut c = Camera {
            target: [1.0, -2.0, 3.0],
            ..Camera::default()
        };
        let before = norm(sub(c.eye(), c.target));
        for d in [
            Vec2::new(40.0, 10.0),
            Vec2::new(-300.0, 500.0),
            Vec2::new(7.0, -900.0),
        ] {
            c.orbit(d);
            let now = norm(sub(c.eye(), c.target));
            assert!((now - before).abs() < 1e-4 * before, "{now} vs {before}");
            assert_eq!(c.target, [1.0, -2.0, 3.0]);
            assert!(c.pitch.abs() <= PITCH_LIMIT);
        }
        // A drag to the right moves the eye clockwise seen from above (the model turns right).
        let mut c = front(true);
        c.orbit(Vec2::new(10.0, 0.0));
        assert!(c.eye()[1] < 0.0);
        // The target still projects onto the centre after any orbit.
        let (centre, _) = c.projector(rect()).project(c.target).unwrap();
        assert!(close(centre, rect().center()));
    }

    #[test]
    fn zoom_and_pan_move_the_camera_as_the_pointer_says() {
        let mut c = front(true);
        c.zoom(0.5);
        assert!((c.distance - 5.0).abs() < 1e-6);
        c.zoom(f32::NAN);
        c.zoom(0.0);
        assert!((c.distance - 5.0).abs() < 1e-6, "bad factors do nothing");
        // A point in the target's plane follows the pointer exactly, in both projections.
        for perspective in [true, false] {
            let mut c = front(perspective);
            let point = [0.0, 0.5, 0.25];
            let before = c.projector(rect()).project(point).unwrap().0;
            c.pan(Vec2::new(30.0, -12.0), rect());
            let after = c.projector(rect()).project(point).unwrap().0;
            assert!(
                close(after, before + Vec2::new(30.0, -12.0)),
                "{before:?} → {after:?}"
            );
        }
    }

    #[test]
    fn fitting_shows_the_whole_box_from_any_direction() {
        let b = Bounds::of([
            [0.0, 0.0, 0.0],
            [14.0, 0.0, 0.0],
            [0.0, 14.0, -2.0],
            [f32::NAN; 3],
        ])
        .unwrap();
        assert_eq!(b.min, [0.0, 0.0, -2.0]);
        assert_eq!(b.max, [14.0, 14.0, 0.0]);
        assert_eq!(b.centre(), [7.0, 7.0, -1.0]);
        assert!(Bounds::of([[f32::INFINITY, 0.0, 0.0]]).is_none());
        for (yaw, pitch, perspective) in [(0.3, 0.2, true), (-2.0, 1.2, true), (1.0, -0.5, false)] {
            for r in [
                rect(),
                Rect::from_min_size(Pos2::ZERO, Vec2::new(150.0, 600.0)),
            ] {
                let mut c = Camera {
                    yaw,
                    pitch,
                    perspective,
                    ..Camera::default()
                };
                c.fit(&b, r);
                assert_eq!(c.target, b.centre());
                let p = c.projector(r);
                for corner in 0..8 {
                    let v = [0, 1, 2].map(|k| {
                        if corner >> k & 1 == 1 {
                            b.max[k]
                        } else {
                            b.min[k]
                        }
                    });
                    let (s, _) = p.project(v).unwrap();
                    assert!(r.contains(s), "corner {v:?} at {s:?} outside {r:?}");
                }
                // And not lost in the middle: the box spans a good part of the view.
                let (a, _) = p.project(b.min).unwrap();
                let (z, _) = p.project(b.max).unwrap();
                assert!((a - z).length() > 0.25 * r.width().min(r.height()));
            }
        }
    }
}
