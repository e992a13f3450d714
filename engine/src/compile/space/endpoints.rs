//! A 3-D endpoint or target resolved to a point (3-D spec §1.2, §2.6): an explicit point's
//! label, a structure node's generated label (`s_m12`), or a connection point on a structure
//! (`[@s α]`, `[@me u w]`, `[@c u v w]`, `[@r α]`), created with its coordinates bound to
//! argument slots.

use super::{value, Numbering, Placed};
use crate::compile::context::Cx;
use crate::compile::errors::CompileErrorKind;
use crate::laws::ArgClass;
use crate::sim::space::proxies::{Along, ProxyDef};
use crate::spec::expr::Expr;
use crate::spec::space::{structures, SpaceKind, StructureKind};
use crate::spec::Endpoint;
use std::collections::HashMap;

/// The connection points made so far and what they read.
#[derive(Default)]
pub(super) struct ProxyList {
    pub defs: Vec<ProxyDef>,
    /// Each one's initial position (at the declared parameter values).
    pub x0: Vec<[f64; 3]>,
    /// Connection points whose coordinates read an audio-rate parameter.
    pub audio: Vec<u32>,
}

/// The structure and node a generated label names (`s_m12` → (s, 12)).
fn generated_node<'n>(numbering: &'n Numbering, label: &str) -> Option<(&'n Placed, u32)> {
    for (i, _) in label.char_indices().filter(|&(_, c)| c == '_') {
        let (owner, suffix) = (&label[..i], &label[i + 1..]);
        let Some(p) = numbering.structures.get(owner) else {
            continue;
        };
        let Some(node) = suffix.strip_prefix('m') else {
            continue;
        };
        let nodes = p.geometry.nodes.len() as u64;
        if let Some(k) = structures::parse_node(p.kind, &p.sizes, nodes, node) {
            return Some((p, k as u32));
        }
    }
    None
}

impl<'a> Cx<'a> {
    /// The point an endpoint names and its initial position, or an error on `element`. A
    /// bracket creates a connection point (its index is `proxy_base` + its number).
    pub(super) fn endpoint3(
        &mut self,
        ep: &Endpoint,
        element: usize,
        numbering: &Numbering,
        proxies: &mut ProxyList,
        names: &HashMap<&str, f64>,
    ) -> Option<(u32, [f64; 3])> {
        let space = self.spec.space.as_deref()?;
        let target = ep.target();
        let proxy_base = numbering.len() as u32;
        if let Endpoint::Label(l) = ep {
            if let Some(&j) = numbering.labels.get(l.as_str()) {
                let e = &space.elements[j];
                return match (&e.kind, numbering.element_point[j]) {
                    (
                        SpaceKind::Mass { .. }
                        | SpaceKind::Osc { .. }
                        | SpaceKind::Ground { .. }
                        | SpaceKind::PosInput { .. }
                        | SpaceKind::PosInputXyz { .. },
                        Some(p),
                    ) => Some((p, numbering.x0[p as usize])),
                    (SpaceKind::Structure(_), _) => {
                        self.error(
                            Some(element),
                            CompileErrorKind::BareMacroReference(target.to_string()),
                        );
                        None
                    }
                    _ => {
                        self.error(
                            Some(element),
                            CompileErrorKind::NotAPoint {
                                target: target.to_string(),
                                found: "not a point",
                            },
                        );
                        None
                    }
                };
            }
            return match generated_node(numbering, l) {
                Some((p, k)) => {
                    let point = p.first + k;
                    Some((point, numbering.x0[point as usize]))
                }
                None => {
                    self.error(
                        Some(element),
                        CompileErrorKind::UndefinedElement(target.to_string()),
                    );
                    None
                }
            };
        }
        let Some(p) = numbering.structures.get(target) else {
            self.error(
                Some(element),
                CompileErrorKind::NotAMacro(target.to_string()),
            );
            return None;
        };
        let coords: Vec<&Expr> = match ep {
            Endpoint::Line { alpha, .. } => vec![alpha],
            Endpoint::Surface { u, w, .. } => vec![u, w],
            Endpoint::Volume { coords, .. } => coords.iter().collect(),
            Endpoint::Label(_) => return None,
        };
        let (along, expected) = match p.kind {
            StructureKind::String3 => (Along::Line { n: p.sizes[0] }, 1),
            StructureKind::Ring3 => (Along::Ring { n: p.sizes[0] }, 1),
            StructureKind::Mesh3 => (
                Along::Surface {
                    nx: p.sizes[0],
                    ny: p.sizes[1],
                },
                2,
            ),
            StructureKind::Lattice3 => (
                Along::Volume {
                    nx: p.sizes[0],
                    ny: p.sizes[1],
                    nz: p.sizes[2],
                },
                3,
            ),
            StructureKind::Icosphere | StructureKind::ObjMesh => (Along::Line { n: 1 }, 0),
        };
        if coords.len() != expected {
            self.error(
                Some(element),
                CompileErrorKind::WrongCoordinateCount {
                    target: target.to_string(),
                    expected,
                    found: coords.len(),
                },
            );
            return None;
        }
        let mut slots = [0u32; 3];
        let mut audio = false;
        let zero = Expr::Num(0.0);
        for (k, slot) in slots.iter_mut().enumerate() {
            let e = coords.get(k).copied().unwrap_or(&zero);
            let (s, a) = self.slot(e, ArgClass::None, element);
            *slot = s as u32;
            audio |= a;
            e.for_each_name(&mut |n| {
                if let Some(crate::compile::context::Symbol::Param(id)) =
                    self.symbols.get(&crate::spec::label_map::LabelKey(n))
                {
                    self.param_is_coordinate[*id as usize] = true;
                }
            });
        }
        let def = ProxyDef {
            along,
            base: p.first,
            coords: slots,
        };
        // The initial position: the weights at the declared values.
        let values: Vec<f64> = coords.iter().map(|e| value(e, names)).collect();
        let mut args = vec![0.0; 3];
        args[..values.len()].copy_from_slice(&values);
        let probe = ProxyDef {
            coords: [0, 1, 2],
            ..def
        };
        let (mut nodes, mut weights) = ([0u32; 8], [0.0; 8]);
        probe.derive(&args, &mut nodes, &mut weights);
        let mut x0 = [0.0; 3];
        for (c, v) in x0.iter_mut().enumerate() {
            let axis: Vec<f64> = (0..probe.width())
                .map(|k| numbering.x0[nodes[k] as usize][c])
                .collect();
            let mut pos = weights[0] * axis[0];
            for k in 1..probe.width() {
                pos += weights[k] * axis[k];
            }
            *v = pos;
        }
        let index = proxies.defs.len() as u32;
        if audio {
            proxies.audio.push(index);
        }
        proxies.defs.push(def);
        proxies.x0.push(x0);
        Some((proxy_base + index, x0))
    }
}
