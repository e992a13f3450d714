//! Pass 2, number points: every material point gets its index in the state arrays, in the
//! order of spec §6.2: single masses, then macro nodes, then avatars, each in script order.
//! Connection points come after all of them; the grouping pass numbers those as it meets them.

use super::context::Cx;
use super::errors::CompileErrorKind;
use super::MAX_POINTS;
use crate::sim::info::{OwnerInfo, PointInfo, PointKind};
use crate::spec::{ElementKind, MacroKind, MacroSpec};

/// The points of a model and the elements that own them.
pub(super) struct Numbering {
    /// Point index → owner, node and kind.
    pub points: Vec<PointInfo>,
    /// The elements that own points, in point order.
    pub owners: Vec<OwnerInfo>,
    /// Owner → element index.
    pub owner_element: Vec<usize>,
    /// The fixed nodes of every macro (spec §2.7), by point index.
    pub fixed_points: Vec<u32>,
    /// The macros that have points, in script order: element index and local fixed nodes.
    pub macros: Vec<(usize, Vec<u32>)>,
}

impl Numbering {
    /// The number of material points (connection points excluded).
    pub fn len(&self) -> usize {
        self.points.len()
    }
}

impl Cx<'_> {
    /// Numbers the points and records each element's first point in `element_point`. A
    /// model with more than [`MAX_POINTS`] points is reported once, with its full count.
    pub fn number_points(&mut self) -> Numbering {
        let spec = self.spec;
        // Single masses first, then macros, then avatars, each in script order: one sweep of
        // the elements sorts them, and sizes the arrays of the points that are not macro nodes.
        let mut by_pass: [Vec<usize>; 3] = [
            Vec::with_capacity(spec.elements.len()),
            Vec::new(),
            Vec::new(),
        ];
        for (i, e) in spec.elements.iter().enumerate() {
            match &e.kind {
                k if k.is_single_mass() => by_pass[0].push(i),
                ElementKind::Macro(_) => by_pass[1].push(i),
                ElementKind::PosInput { .. } => by_pass[2].push(i),
                _ => {}
            }
        }
        let owner_count = by_pass.iter().map(Vec::len).sum();
        let mut owners = Vec::with_capacity(owner_count);
        let mut owner_element = Vec::with_capacity(owner_count);
        let mut points: Vec<PointInfo> = Vec::with_capacity(by_pass[0].len() + by_pass[2].len());
        let mut too_large = false;
        for elements in &by_pass {
            for &i in elements {
                let e = &spec.elements[i];
                let (count, kind, width) = match &e.kind {
                    ElementKind::Mass { .. } => (1, PointKind::Mass, 0),
                    ElementKind::Osc { .. } => (1, PointKind::Osc, 0),
                    ElementKind::Ground { .. } => (1, PointKind::Ground, 0),
                    ElementKind::MassG { .. } => (1, PointKind::MassG, 0),
                    ElementKind::Macro(m) => {
                        let sizes_ok = self.check_macro_sizes(m, i);
                        if !sizes_ok {
                            continue;
                        }
                        let w = if m.kind.is_2d() { m.width } else { 0 };
                        (m.num_nodes(), PointKind::MacroNode { fixed: false }, w)
                    }
                    ElementKind::PosInput { .. } => (1, PointKind::Avatar, 0),
                    _ => continue,
                };
                if points.len() + count > MAX_POINTS {
                    too_large = true;
                    continue;
                }
                let owner = owners.len() as u32;
                owners.push(OwnerInfo {
                    label: e.label.clone(),
                    keyword: e.kind.keyword(),
                    mesh_width: width,
                    sizes: Vec::new(),
                });
                owner_element.push(i);
                self.element_point[i] = Some(points.len() as u32);
                points.extend((0..count).map(|node| PointInfo {
                    owner,
                    node: node as u32,
                    kind,
                }));
            }
        }
        if too_large {
            let total: usize = spec
                .elements
                .iter()
                .map(|e| match &e.kind {
                    ElementKind::Macro(m) => m.num_nodes(),
                    k if k.is_single_mass() => 1,
                    ElementKind::PosInput { .. } => 1,
                    _ => 0,
                })
                .sum();
            self.error(None, CompileErrorKind::TooLarge { points: total });
        }

        // The macros' fixed nodes, in script order.
        let mut fixed_points = Vec::new();
        let mut macros = Vec::new();
        for &i in &by_pass[1] {
            let (ElementKind::Macro(mac), Some(base)) =
                (&spec.elements[i].kind, self.element_point[i])
            else {
                continue;
            };
            let fixed = fixed_nodes(mac);
            for &p in &fixed {
                fixed_points.push(base + p);
                points[(base + p) as usize].kind = PointKind::MacroNode { fixed: true };
            }
            macros.push((i, fixed));
        }
        Numbering {
            points,
            owners,
            owner_element,
            fixed_points,
            macros,
        }
    }

    /// Checks a macro's sizes (≥ 2; 1-D macros have width 1).
    fn check_macro_sizes(&mut self, m: &MacroSpec, element: usize) -> bool {
        let mut ok = true;
        if m.length < 2 {
            self.error(Some(element), CompileErrorKind::InvalidSize(m.length));
            ok = false;
        }
        if m.kind.is_2d() && m.width < 2 {
            self.error(Some(element), CompileErrorKind::InvalidSize(m.width));
            ok = false;
        }
        if ok && m.num_nodes() > MAX_POINTS {
            self.error(
                Some(element),
                CompileErrorKind::TooLarge {
                    points: m.num_nodes(),
                },
            );
            ok = false;
        }
        ok
    }
}

/// The local indices of a macro's fixed nodes (spec §2.7), in ascending order.
fn fixed_nodes(mac: &MacroSpec) -> Vec<u32> {
    let (l, w) = (mac.length, mac.width);
    match mac.kind {
        MacroKind::String | MacroKind::StiffString => vec![0, l - 1],
        MacroKind::Chain | MacroKind::Mesh => Vec::new(),
        MacroKind::CornerMesh => {
            let mut v = vec![0, w - 1, (l - 1) * w, (l - 1) * w + w - 1];
            v.dedup();
            v
        }
        // The border: the first and last rows whole, the ends of the rows between.
        MacroKind::ClosedMesh => {
            let mut v = Vec::with_capacity(2 * (l + w) as usize);
            v.extend(0..w);
            for i in 1..l.saturating_sub(1) {
                v.extend([i * w, i * w + w - 1]);
            }
            if l > 1 {
                v.extend((l - 1) * w..l * w);
            }
            v
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::expr::Expr;
    use crate::spec::Vector;

    #[test]
    fn a_closed_mesh_is_fixed_on_its_border() {
        for (l, w) in [(2, 2), (2, 5), (5, 2), (3, 3), (7, 4), (150, 150)] {
            let mac = MacroSpec {
                kind: MacroKind::ClosedMesh,
                length: l,
                width: w,
                m: Expr::Num(1.0),
                k: Expr::Num(0.1),
                k2: None,
                z: Expr::Num(0.0),
                zo: Expr::Num(0.0),
                pos: Vector::Scalar(Expr::Num(0.0)),
                vel: Vector::Scalar(Expr::Num(0.0)),
            };
            let border: Vec<u32> = (0..l * w)
                .filter(|n| {
                    let (i, j) = (n / w, n % w);
                    i == 0 || i == l - 1 || j == 0 || j == w - 1
                })
                .collect();
            assert_eq!(fixed_nodes(&mac), border, "{l}×{w}");
        }
    }
}
