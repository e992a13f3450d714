//! Pass 3, group into kinds: sorts the elements into the engine's kinds (single masses, avatars,
//! one group per interaction law, inputs and outputs; macros stay as numbered), resolving every
//! endpoint and target to a point. A bracket endpoint creates a connection point, numbered after
//! the material points in the order met. Nothing is bound here: the rows keep their argument
//! expressions for the binding pass.
//! The next pass (`bands`) reorders each group's links into bands.

use super::context::Cx;
use super::errors::CompileErrorKind;
use super::labels::Params;
use super::points::Numbering;
use crate::laws::ArgClass;
use crate::laws::LawKind;
use crate::sim::engine::Route;
use crate::sim::info::{InputUse, OutputUse};
use crate::spec::expr::Expr;
use crate::spec::{ElementKind, Endpoint, Law};

/// A link (an interaction element) of one law: its two points and its argument expressions,
/// in the law's column order (the first [`LawKind::arity`] of `args`).
pub(super) struct Row<'a> {
    pub a: u32,
    pub b: u32,
    pub args: LawArgs<'a>,
    pub element: usize,
}

/// A law's argument expressions and their classes, padded with zeros to
/// [`LawKind::MAX_ARITY`].
pub(super) type LawArgs<'a> = [(&'a Expr, ArgClass); LawKind::MAX_ARITY];

/// The links of a model by law group, each group in script order (until `bands` reorders it).
#[derive(Default)]
pub(super) struct LinkGroups<'a> {
    pub groups: [Vec<Row<'a>>; LawKind::COUNT],
}

impl<'a> LinkGroups<'a> {
    fn push(&mut self, kind: LawKind, row: Row<'a>) {
        self.groups[kind.index()].push(row);
    }
}

/// The routes of force inputs and outputs, and what each channel carries.
#[derive(Default)]
pub(super) struct Io {
    pub force_inputs: Vec<Route>,
    pub pos_outputs: Vec<Route>,
    /// (output channel, first source, source count) of each force output.
    pub frc_outputs: Vec<(u32, u32, u32)>,
    /// The connection points (or the point) whose force each force output sums.
    pub frc_sources: Vec<u32>,
    /// Input channel → what it drives.
    pub inputs: Vec<Vec<InputUse>>,
    /// Output channel → what it reads.
    pub outputs: Vec<OutputUse>,
}

impl Io {
    fn use_input(&mut self, channel: u32, u: InputUse) {
        let c = channel as usize;
        if self.inputs.len() < c {
            self.inputs.resize(c, Vec::new());
        }
        self.inputs[c - 1].push(u);
    }
}

/// The elements of a model by kind.
pub(super) struct Kinds<'a> {
    /// Single masses (mass, osc, ground, massG) that have a point, in script order.
    pub singles: Vec<usize>,
    /// Avatars with a valid channel: element and route.
    pub avatars: Vec<(usize, Route)>,
    pub links: LinkGroups<'a>,
    pub io: Io,
    /// Interactions, macro links included.
    pub num_interactions: usize,
    /// The index of the first connection point (the number of material points).
    pub proxy_base: usize,
}

impl<'a> Cx<'a> {
    pub fn group_into_kinds(&mut self, params: &Params, numbering: &Numbering) -> Kinds<'a> {
        let spec = self.spec;
        let proxy_base = numbering.len();
        let has_point = |i: &usize| self.element_point[*i].is_some();
        let singles: Vec<usize> = (0..spec.elements.len())
            .filter(|&i| spec.elements[i].kind.is_single_mass())
            .filter(has_point)
            .collect();
        // Macros stay as they are numbered (`Numbering::macros`); their links count here.
        let mut num_interactions: usize = numbering
            .macros
            .iter()
            .map(|&(i, _)| match &spec.elements[i].kind {
                ElementKind::Macro(mac) => mac.num_links(),
                _ => 0,
            })
            .sum();

        // Avatars, then the audio-rate parameters' inputs.
        let mut io = Io::default();
        let mut avatars = Vec::new();
        for (i, e) in spec.elements.iter().enumerate() {
            let ElementKind::PosInput { channel, .. } = &e.kind else {
                continue;
            };
            let Some(point) = self.element_point[i] else {
                continue;
            };
            if *channel == 0 {
                self.error(Some(i), CompileErrorKind::InvalidChannel);
                continue;
            }
            let route = Route {
                channel: channel - 1,
                index: point,
            };
            avatars.push((i, route));
            io.use_input(*channel, InputUse::Position(e.label.to_string()));
        }
        for r in &params.audio {
            let name = spec.params[r.index as usize].name.clone();
            io.use_input(r.channel + 1, InputUse::Param(name));
        }

        // Interactions, in script order; connection points are created as endpoints appear.
        let mut links = LinkGroups::default();
        for (i, e) in spec.elements.iter().enumerate() {
            let ElementKind::Interaction { law, a, b } = &e.kind else {
                continue;
            };
            num_interactions += 1;
            let pa = self.endpoint(a, i, proxy_base);
            let pb = self.endpoint(b, i, proxy_base);
            let (kind, args) = law_row(law);
            if let (Some(a), Some(b)) = (pa, pb) {
                links.push(
                    kind,
                    Row {
                        a,
                        b,
                        args,
                        element: i,
                    },
                );
            }
        }

        // Then inputs and outputs, in script order.
        for (i, e) in spec.elements.iter().enumerate() {
            let (channel, target, is_input, is_force) = match &e.kind {
                ElementKind::FrcInput { channel, target } => (*channel, target, true, true),
                ElementKind::PosOutput { channel, target } => (*channel, target, false, false),
                ElementKind::FrcOutput { channel, target } => (*channel, target, false, true),
                _ => continue,
            };
            let point = self.endpoint(target, i, proxy_base);
            if channel == 0 {
                self.error(Some(i), CompileErrorKind::InvalidChannel);
                continue;
            }
            let Some(point) = point else { continue };
            let route = Route {
                channel: channel - 1,
                index: point,
            };
            let text = describe_endpoint(target);
            if is_input {
                io.force_inputs.push(route);
                io.use_input(channel, InputUse::Force(text));
                continue;
            }
            let c = channel as usize;
            if io.outputs.len() < c {
                io.outputs.resize(c, OutputUse::Unused);
            }
            if is_force {
                // Each bracket creates its own connection point (spec §2.8), so a force
                // output on a bracket reads the force applied at that location: the sum over
                // every connection point with the same macro and coordinates, its own included
                // (spec §3.12 e).
                let start = io.frc_sources.len() as u32;
                match target {
                    Endpoint::Label(_) => io.frc_sources.push(point),
                    _ => io.frc_sources.extend(
                        self.proxy_endpoints
                            .iter()
                            .enumerate()
                            .filter(|(_, ep)| **ep == target)
                            .map(|(i, _)| (proxy_base + i) as u32),
                    ),
                }
                let len = io.frc_sources.len() as u32 - start;
                io.frc_outputs.push((route.channel, start, len));
                io.outputs[c - 1] = OutputUse::Force(text);
            } else {
                io.pos_outputs.push(route);
                io.outputs[c - 1] = OutputUse::Position(text);
            }
        }

        Kinds {
            singles,
            avatars,
            links,
            io,
            num_interactions,
            proxy_base,
        }
    }
}

/// The law of a spec element and its argument expressions in the law's column order, with
/// the classes of the law's row (a missing column, the K of a `damper` or the Z of a `spring`,
/// is a zero).
fn law_row(law: &Law) -> (LawKind, LawArgs<'_>) {
    static ZERO: Expr = Expr::Num(0.0);
    let kind = law.kind();
    let exprs = law.columns(&ZERO);
    let columns = kind.row().columns;
    let args = std::array::from_fn(|c| {
        let class = columns.get(c).map_or(ArgClass::None, |col| col.class);
        (exprs[c], class)
    });
    (kind, args)
}

/// The text of an endpoint, for metadata (`@h`, `[@s 0.3]`).
pub(super) fn describe_endpoint(ep: &Endpoint) -> String {
    match ep {
        Endpoint::Label(l) => format!("@{l}"),
        Endpoint::Line { target, alpha } => format!("[@{target} {}]", bracket_coord(alpha)),
        Endpoint::Surface { target, u, w } => {
            format!("[@{target} {} {}]", bracket_coord(u), bracket_coord(w))
        }
        Endpoint::Volume { target, coords } => {
            let [u, v, w] = &**coords;
            let (u, v, w) = (bracket_coord(u), bracket_coord(v), bracket_coord(w));
            format!("[@{target} {u} {v} {w}]")
        }
    }
}

fn bracket_coord(e: &Expr) -> String {
    let text = e.to_string();
    if text.contains(' ') {
        format!("({text})")
    } else {
        text
    }
}
