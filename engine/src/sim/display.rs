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
