//! What a display needs of a compiled model: where its inputs and outputs sit and which points
//! its interactions join, on material points (connection points shown at their nearest node).

use crate::sim::compiled::Compiled;
use crate::sim::kernels::links::Interactions;
use crate::sim::kernels::proxies::Proxies;

/// What an [`IoPoint`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IoKind {
    ForceInput,
    PositionInput,
    PositionOutput,
    ForceOutput,
}

/// A model input or output located on a material point (see `Engine::io_points`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct IoPoint {
    pub kind: IoKind,
    /// The 1-based channel (`@in1` / `@out1` is 1).
    pub channel: u32,
    /// Index in the generic motion buffer.
    pub point: u32,
}

/// The material point a point index stands for in a display: itself for a material
/// point, the node with the largest weight for a connection point (spec §2.8).
fn display_point(model: &Compiled, proxies: &Proxies, index: u32) -> Option<u32> {
    let i = index as usize;
    if i < model.info.num_points {
        return Some(index);
    }
    let p = i.checked_sub(proxies.base)?;
    let (nodes, weights) = (proxies.nodes.get(p)?, proxies.weights.get(p)?);
    let best = (0..4).max_by(|&a, &b| weights[a].total_cmp(&weights[b]))?;
    Some(nodes[best])
}

/// Where the model's inputs and outputs sit, for displays (spec §6): one entry per force
/// input, position input (its avatar), position output and force output, located on a
/// material point of the generic motion buffer.
pub(crate) fn io_points(model: &Compiled, proxies: &Proxies) -> Vec<IoPoint> {
    let mut out = Vec::new();
    let mut push = |kind: IoKind, channel: u32, index: u32| {
        if let Some(point) = display_point(model, proxies, index) {
            out.push(IoPoint {
                kind,
                channel: channel + 1,
                point,
            });
        }
    };
    for r in &model.force_inputs {
        push(IoKind::ForceInput, r.channel, r.index);
    }
    for r in &model.avatars {
        push(IoKind::PositionInput, r.channel, r.index);
    }
    for r in &model.pos_outputs {
        push(IoKind::PositionOutput, r.channel, r.index);
    }
    for &(channel, start, len) in &model.frc_outputs {
        if let Some(&first) = model
            .frc_sources
            .get(start as usize..(start + len) as usize)
            .and_then(|s| s.first())
        {
            push(IoKind::ForceOutput, channel, first);
        }
    }
    out
}

/// The explicit interactions as pairs of material points (connection points replaced by
/// their heaviest node), for drawing a structure. Macro-internal links are not listed:
/// they join consecutive nodes of a string and neighbours of a mesh (spec §2.7).
pub(crate) fn links(
    model: &Compiled,
    proxies: &Proxies,
    interactions: &Interactions,
) -> Vec<(u32, u32)> {
    interactions
        .groups
        .iter()
        .flat_map(|g| g.a.iter().zip(&g.b))
        .filter_map(|(&a, &b)| {
            Some((
                display_point(model, proxies, a)?,
                display_point(model, proxies, b)?,
            ))
        })
        .filter(|(a, b)| a != b)
        .collect()
}

/// A 3-D model's point for a display: a connection point's heaviest node.
fn space_point(space: &crate::sim::space::Space, num_points: usize, index: u32) -> Option<u32> {
    let i = index as usize;
    if i < num_points {
        return Some(index);
    }
    let p = i - num_points;
    let def = space.model.proxies.get(p)?;
    let w = space.proxy_weights.get(p)?;
    let best = (0..def.width()).max_by(|&a, &b| w[a].total_cmp(&w[b]))?;
    space.proxy_nodes.get(p).map(|n| n[best])
}

/// A 3-D model's inputs and outputs on material points (3-D spec §3), as [`io_points`].
pub(crate) fn space_io_points(space: &crate::sim::space::Space, num_points: usize) -> Vec<IoPoint> {
    use crate::sim::space::{Avatar, ForceInput, Output3, Probe3};
    let m = &space.model;
    let mut out = Vec::new();
    let mut push = |kind: IoKind, channel: u32, index: u32| {
        if let Some(point) = space_point(space, num_points, index) {
            out.push(IoPoint {
                kind,
                channel: channel + 1,
                point,
            });
        }
    };
    for fi in &m.force_inputs {
        let (ForceInput::Line { point, channel, .. } | ForceInput::Xyz { point, channel }) = *fi;
        push(IoKind::ForceInput, channel, point);
    }
    for av in &m.avatars {
        let (Avatar::Line { point, channel, .. } | Avatar::Xyz { point, channel }) = *av;
        push(IoKind::PositionInput, channel, point);
    }
    for o in &m.outputs {
        match *o {
            Output3::Point {
                channel,
                probe: Probe3::Force,
                point,
                ..
            } => push(IoKind::ForceOutput, channel, point),
            Output3::Point { channel, point, .. } => push(IoKind::PositionOutput, channel, point),
            Output3::Distance { channel, a, .. } => push(IoKind::PositionOutput, channel, a),
            Output3::Mic { channel, mic } => {
                if let Some(&p) = m.mics[mic as usize].members.first() {
                    push(IoKind::PositionOutput, channel, p);
                }
            }
        }
    }
    out
}

/// Every link of a 3-D model, structures' included, as pairs of material points.
pub(crate) fn space_links(space: &crate::sim::space::Space, num_points: usize) -> Vec<(u32, u32)> {
    space
        .model
        .groups
        .iter()
        .flat_map(|g| g.a.iter().zip(&g.b))
        .filter_map(|(&a, &b)| {
            Some((
                space_point(space, num_points, a)?,
                space_point(space, num_points, b)?,
            ))
        })
        .filter(|(a, b)| a != b)
        .collect()
}
