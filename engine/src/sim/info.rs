//! Cold metadata of a compiled model: counts, labels, parameters, channels and the motion
//! layout. Never read by the sample loop.

use crate::sim::motion::MotionLayout;
use crate::spec::SampleRateMode;

/// What kind of material point a point is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PointKind {
    Mass,
    Osc,
    Ground,
    MassG,
    /// A node of a macro structure; `fixed` for string ends and pinned mesh nodes.
    MacroNode {
        fixed: bool,
    },
    /// A `posInput` avatar.
    Avatar,
}

/// One material point, in generic motion-buffer order (spec §6.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointInfo {
    /// Index into [`ModelInfo::owners`].
    pub owner: u32,
    /// Node index inside a macro (0 for single points).
    pub node: u32,
    pub kind: PointKind,
}

/// An element that owns points: a single mass-type element, a macro or an avatar.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnerInfo {
    pub label: crate::spec::Label,
    pub keyword: &'static str,
    /// For meshes, the width W (nodes are i·W + j); 0 for everything else.
    pub mesh_width: u32,
    /// A 3-D structure's sizes (3-D spec §4), whose nodes are labelled `s_m12`, `me_m3_4`,
    /// `c_m1_0_2`; empty for everything else.
    pub sizes: Vec<u32>,
}

/// A declared parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamInfo {
    pub name: String,
    /// The declared value of a control-rate parameter, or the default of an audio-rate one
    /// (its value while its input is silent).
    pub default: f64,
    /// The 1-based input channel of an audio-rate parameter.
    pub audio_input: Option<u32>,
    /// True when the parameter is named in a connection-point coordinate (`[@m lX lY]`): it
    /// places a point along a macro, so its useful values are 0 … 1.
    pub coordinate: bool,
}

/// What an input channel drives.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum InputUse {
    /// The position of the avatar with this label.
    Position(String),
    /// A force on this target (label or connection point text).
    Force(String),
    /// The audio-rate parameter with this name.
    Param(String),
}

/// What an output channel carries.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OutputUse {
    Position(String),
    Force(String),
    /// A channel number below the highest one that nothing uses: it outputs 0.
    Unused,
}

/// Metadata of a compiled model.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModelInfo {
    pub sample_rate_hz: f64,
    pub sample_rate_mode: SampleRateMode,
    /// Material points (single elements, macro nodes and avatars): the generic buffer length.
    pub num_points: usize,
    /// Connection points created by bracket references.
    pub num_connection_points: usize,
    /// Explicit interactions plus macro-internal links (spec §7.0).
    pub num_interactions: usize,
    pub points: Vec<PointInfo>,
    pub owners: Vec<OwnerInfo>,
    pub params: Vec<ParamInfo>,
    /// What each input channel drives (index = channel − 1). Its length is the highest
    /// channel used (spec §3.9).
    pub inputs: Vec<Vec<InputUse>>,
    /// What each output channel carries (index = channel − 1).
    pub outputs: Vec<OutputUse>,
    pub motion: MotionLayout,
}

impl ModelInfo {
    /// The number of input channels.
    pub fn num_inputs(&self) -> usize {
        self.inputs.len()
    }

    /// The number of output channels.
    pub fn num_outputs(&self) -> usize {
        self.outputs.len()
    }

    /// The point [`ModelInfo::point_label`] names `label`, the first one if several do.
    /// Formats only the labels of the owners, and of the nodes of a macro whose label starts
    /// `label` (a state load of the 22,500-mass plate spent 3.7 ms formatting every point's).
    pub fn find_point(&self, label: &str) -> Option<usize> {
        let owners: Vec<String> = self.owners.iter().map(|o| o.label.to_string()).collect();
        self.points.iter().position(|p| {
            let owner = &owners[p.owner as usize];
            match p.kind {
                PointKind::MacroNode { .. } => {
                    label.len() > owner.len()
                        && label.starts_with(owner.as_str())
                        && label.as_bytes()[owner.len()] == b'['
                        && self.point_label_of(p) == label
                }
                _ => owner == label,
            }
        })
    }

    /// A readable name for point `i`: `m1`, `s[12]`, `mesh[3,4]`.
    pub fn point_label(&self, i: usize) -> String {
        let Some(p) = self.points.get(i) else {
            return format!("connection point {}", i - self.points.len());
        };
        self.point_label_of(p)
    }

    fn point_label_of(&self, p: &PointInfo) -> String {
        let owner = &self.owners[p.owner as usize];
        let structure = crate::spec::space::StructureKind::from_keyword(owner.keyword);
        if let (Some(kind), PointKind::MacroNode { .. }) = (structure, p.kind) {
            return crate::spec::space::structures::node_label(
                &owner.label,
                kind,
                &owner.sizes,
                p.node as usize,
            );
        }
        match p.kind {
            PointKind::MacroNode { .. } if owner.mesh_width > 0 => format!(
                "{}[{},{}]",
                owner.label,
                p.node / owner.mesh_width,
                p.node % owner.mesh_width
            ),
            PointKind::MacroNode { .. } => format!("{}[{}]", owner.label, p.node),
            _ => owner.label.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::compile::{compile, CompileOptions};

    /// `find_point` agrees with formatting every label, for single points, avatars, string
    /// and mesh nodes, and names nothing else.
    #[test]
    fn find_point_names_the_point_its_label_names() {
        let text = "@m1 mass 1. 0. 0.\n@in1 posInput 1.\n@s string 5 1. 0.1 0.001 0. 0.\n\
                    @mesh mesh 3 4 1. 0.1 0.001 0. 0.\n@r1 spring @m1 @in1 0.1\n";
        let spec = crate::parse(text).spec.expect("it parses");
        let engine = compile(&spec, &CompileOptions::at(48000.0)).expect("it compiles");
        let info = engine.info();
        for i in 0..info.points.len() {
            let label = info.point_label(i);
            let first = (0..info.points.len()).find(|&j| info.point_label(j) == label);
            assert_eq!(info.find_point(&label), first, "{label}");
        }
        for missing in ["m2", "s[9]", "mesh[", "mesh[3,0]", "", "s"] {
            let brute = (0..info.points.len()).find(|&j| info.point_label(j) == missing);
            assert_eq!(info.find_point(missing), brute, "{missing}");
        }
    }
}
