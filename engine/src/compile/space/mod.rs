//! Compiles a 3-D model (3-D spec): the spec's elements become the runs, law groups,
//! connection points, inputs and outputs of [`crate::sim::space`]. The passes, in order:
//!
//! 1. **number points** (`number`, here): explicit mass-type elements and structure nodes in
//!    script order (each structure generated from its constant geometry, §4), then the
//!    avatars; every material point's initial position, for `auto` and the motion layout;
//! 2. **bind elements** (`bind`): each element's arguments to slots, in script order: the
//!    runs of the mass phase, the links of each law (a structure's, an adder's, an explicit
//!    line's, with `auto` bound to each link's initial length, §1.7), the connection points
//!    (`endpoints`), the inputs and outputs;
//!
//! then `assemble` builds the engine: the shared [`SpaceModel`], the metadata, the controls.

use super::context::Cx;
use super::errors::{CompileErrorKind, CompileErrors};
use super::labels::Params;
use super::{CompileOptions, Rate};
use crate::sim::info::{OwnerInfo, PointInfo, PointKind};
use crate::spec::expr::Expr;
use crate::spec::space::structures::{self, Geometry, Shape};
use crate::spec::space::{Body, SpaceKind, SpaceSpec, StructureKind};
use crate::spec::Vector;
use std::collections::HashMap;

mod assemble;
mod bind;
mod endpoints;

/// A structure's place in the numbering.
pub(super) struct Placed {
    pub kind: StructureKind,
    pub sizes: Vec<u32>,
    /// Its first node.
    pub first: u32,
    pub geometry: Geometry,
}

/// What numbering the points found.
pub(super) struct Numbering {
    pub points: Vec<PointInfo>,
    pub owners: Vec<OwnerInfo>,
    /// Each point's initial position with the declared parameter values.
    pub x0: Vec<[f64; 3]>,
    /// Each element's first point (explicit points, avatars, a structure's first node).
    pub element_point: Vec<Option<u32>>,
    /// The structures, by label.
    pub structures: HashMap<String, Placed>,
    /// Each labelled element by label: its index.
    pub labels: HashMap<String, usize>,
}

impl Numbering {
    pub fn len(&self) -> usize {
        self.points.len()
    }
}

/// The value of a constant expression at the declared parameter values (NaN where a name is
/// unknown).
pub(super) fn value(e: &Expr, names: &HashMap<&str, f64>) -> f64 {
    e.eval(&|n| names.get(n).copied())
}

/// A position or vector's value: a scalar s is (0, 0, s) (3-D spec §1.7).
pub(super) fn vector_value(v: &Vector, names: &HashMap<&str, f64>) -> [f64; 3] {
    match v {
        Vector::Scalar(z) => [0.0, 0.0, value(z, names)],
        Vector::Xyz(c) => [
            value(&c[0], names),
            value(&c[1], names),
            value(&c[2], names),
        ],
    }
}

/// The three expressions of a vector.
pub(super) fn vector_exprs(v: &Vector) -> [Expr; 3] {
    match v {
        Vector::Scalar(z) => [Expr::Num(0.0), Expr::Num(0.0), z.clone()],
        Vector::Xyz(c) => (**c).clone(),
    }
}

impl<'a> Cx<'a> {
    /// Compiles a 3-D model (`self.spec.space`).
    pub(super) fn compile_space(
        mut self,
        options: &CompileOptions,
        rate: Rate,
        params: Params,
    ) -> Result<crate::Engine, CompileErrors> {
        let Some(space) = self.spec.space.as_deref() else {
            return Err(CompileErrors(self.errors));
        };
        let names: HashMap<&str, f64> = self
            .spec
            .params
            .iter()
            .zip(&params.values)
            .map(|(p, v)| (p.name.as_str(), *v))
            .collect();
        let numbering = self.number_space(space, &names);
        let bound = self.bind_space(space, &numbering, &names, rate);
        self.assemble_space(options, rate, params, numbering, bound)
    }

    /// Pass 1: the points, in script order, then the avatars (3-D spec §1.5, §4.0).
    fn number_space(&mut self, space: &'a SpaceSpec, names: &HashMap<&str, f64>) -> Numbering {
        let mut n = Numbering {
            points: Vec::new(),
            owners: Vec::new(),
            x0: Vec::new(),
            element_point: vec![None; space.elements.len()],
            structures: HashMap::new(),
            labels: HashMap::with_capacity(space.elements.len()),
        };
        for (i, e) in space.elements.iter().enumerate() {
            if n.labels.insert(e.label.to_string(), i).is_some() {
                let first = space.elements[n.labels[e.label.as_str()]].span;
                self.error(Some(i), CompileErrorKind::DuplicateLabel { first });
            }
        }
        let mut owner = |n: &mut Numbering,
                         label: &crate::spec::Label,
                         keyword: &'static str,
                         sizes: Vec<u32>| {
            n.owners.push(OwnerInfo {
                label: label.clone(),
                keyword,
                mesh_width: 0,
                sizes,
            });
            (n.owners.len() - 1) as u32
        };
        for pass in [false, true] {
            for (i, e) in space.elements.iter().enumerate() {
                let (kind, pos) = match &e.kind {
                    SpaceKind::Mass { pos, .. } if !pass => (PointKind::Mass, pos),
                    SpaceKind::Osc { pos, .. } if !pass => (PointKind::Osc, pos),
                    SpaceKind::Ground { pos } if !pass => (PointKind::Ground, pos),
                    SpaceKind::PosInput { pos, .. } | SpaceKind::PosInputXyz { pos, .. }
                        if pass =>
                    {
                        (PointKind::Avatar, pos)
                    }
                    SpaceKind::Structure(s) if !pass => {
                        self.place_structure(i, s, names, &mut n, &mut owner);
                        continue;
                    }
                    _ => continue,
                };
                let o = owner(&mut n, &e.label, e.kind.keyword(), Vec::new());
                n.element_point[i] = Some(n.points.len() as u32);
                n.points.push(PointInfo {
                    owner: o,
                    node: 0,
                    kind,
                });
                n.x0.push(vector_value(pos, names));
            }
        }
        if n.points.len() > super::MAX_POINTS {
            self.error(
                None,
                CompileErrorKind::TooLarge {
                    points: n.points.len(),
                },
            );
        }
        n
    }

    /// Generates a structure from its constant geometry and numbers its nodes.
    fn place_structure(
        &mut self,
        i: usize,
        s: &'a crate::spec::space::Structure,
        names: &HashMap<&str, f64>,
        n: &mut Numbering,
        owner: &mut impl FnMut(&mut Numbering, &crate::spec::Label, &'static str, Vec<u32>) -> u32,
    ) {
        let label = &self
            .spec
            .space
            .as_ref()
            .map(|sp| sp.elements[i].label.clone())
            .unwrap_or_default();
        let points: Vec<[f64; 3]> = s.points.iter().map(|p| vector_value(p, names)).collect();
        let radius = s.radius.as_ref().map_or(1.0, |r| value(r, names));
        let fix = s.fix();
        let shape = Shape {
            kind: s.kind,
            sizes: &s.sizes,
            points: &points,
            radius,
            fix: &fix,
            diag: s.diag(),
            span: s.span(),
            second: s.k2().is_some(),
            hinge: s.hinge().is_some(),
            mesh: s.mesh.as_deref(),
        };
        let geometry = match structures::generate(&shape) {
            Ok(g) => g,
            Err(e) => {
                self.error(Some(i), CompileErrorKind::Structure(e.to_string()));
                return;
            }
        };
        let first = n.points.len() as u32;
        let o = owner(n, label, s.kind.keyword(), s.sizes.clone());
        n.element_point[i] = Some(first);
        for (k, (p, fixed)) in geometry.nodes.iter().zip(&geometry.fixed).enumerate() {
            n.points.push(PointInfo {
                owner: o,
                node: k as u32,
                kind: PointKind::MacroNode { fixed: *fixed },
            });
            n.x0.push(*p);
        }
        n.structures.insert(
            label.to_string(),
            Placed {
                kind: s.kind,
                sizes: s.sizes.clone(),
                first,
                geometry,
            },
        );
    }
}

/// The axes a body (and a structure's `lock=`) moves along.
pub(super) fn axes_of(body: Body) -> [bool; 3] {
    [0, 1, 2].map(|c| body.moves(c))
}
