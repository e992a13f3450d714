//! The spec of a 3-D model (3-D spec `mass-interaction-3d.md`, cited as "3-D spec §N"): a
//! script with `~dim 3` (§1.1). Its points move in three dimensions; every coordinate is
//! physical. The parser fills [`SpaceSpec`] instead of [`super::ModelSpec::elements`]; the
//! parameters, buffer scopes, sample-rate mode and host directives stay in the
//! [`super::ModelSpec`] around it.
//!
//! This folder owns the 3-D elements as the spec keeps them ([`SpaceKind`]), the structure
//! generators of §4 and their geometry (`structures`), and the import of a Wavefront OBJ
//! mesh (`obj`).

use super::expr::Expr;
use super::{Endpoint, Label, Span, Vector};
use crate::laws::space::SpaceLawKind;
use std::sync::Arc;

pub mod obj;
pub mod structures;

pub use obj::{MeshData, ObjError};

/// The most nodes one structure may have: 1 048 576 (the compiler's point limit).
pub const MAX_STRUCTURE_NODES: u64 = 1 << 20;
pub use structures::{Fix, Geometry, LinkFamily, Lock, StructureError};

/// The elements and the medium of a 3-D model, in script order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SpaceSpec {
    /// `~gravity`: a uniform acceleration of every moving point (3-D spec §1.10, class Acc):
    /// a vector is the acceleration, a scalar g means (0, 0, −g).
    pub gravity: Option<Vector>,
    /// `~friction Za`: a uniform air friction of every moving point (§1.10, class Z).
    pub friction: Option<Expr>,
    pub elements: Vec<SpaceElement>,
}

impl SpaceSpec {
    /// The element labelled `label`.
    pub fn element(&self, label: &str) -> Option<&SpaceElement> {
        self.elements.iter().find(|e| e.label == label)
    }
}

/// One line of a 3-D model: a labelled element.
#[derive(Clone, Debug, PartialEq)]
pub struct SpaceElement {
    /// The label without `@` (`in3`, `out1` for inputs and outputs).
    pub label: Label,
    pub kind: SpaceKind,
    /// The named motion buffers (indices into [`super::ModelSpec::buffers`]) open at its line.
    pub buffers: Vec<u32>,
    pub span: Span,
}

/// Which axes a mass moves along (3-D spec §2.1.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Body {
    /// `mass`: all three.
    Free,
    /// `massZ`: z only (miPhysics's `Mass1D`).
    Z,
    /// `massXY`: x and y.
    Xy,
}

impl Body {
    /// The script keyword.
    pub fn keyword(self) -> &'static str {
        match self {
            Body::Free => "mass",
            Body::Z => "massZ",
            Body::Xy => "massXY",
        }
    }

    /// Whether axis `c` (0 x, 1 y, 2 z) moves.
    pub fn moves(self, c: usize) -> bool {
        match self {
            Body::Free => true,
            Body::Z => c == 2,
            Body::Xy => c != 2,
        }
    }
}

/// What a point output reads (3-D spec §3.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Probe {
    /// `posOutput`: x·â.
    Position,
    /// `frcOutput`: F·â at the end of stage 4.
    Force,
    /// `velOutput`: (x − x̃)·â, units per step.
    Velocity,
}

impl Probe {
    pub fn keyword(self) -> &'static str {
        match self {
            Probe::Position => "posOutput",
            Probe::Force => "frcOutput",
            Probe::Velocity => "velOutput",
        }
    }
}

/// What a 3-D element is.
#[derive(Clone, Debug, PartialEq)]
pub enum SpaceKind {
    /// `mass`, `massZ`, `massXY`: `M {gravity} pos vel` (3-D spec §2.1.1, §2.1.3). A scalar
    /// gravity g is the force (0, 0, −g), a vector the force itself.
    Mass {
        body: Body,
        m: Expr,
        gravity: Vector,
        pos: Vector,
        vel: Vector,
    },
    /// `osc M K Z {gravity} pos vel` (§2.1.4): rests at its initial position.
    Osc {
        m: Expr,
        k: Expr,
        z: Expr,
        gravity: Vector,
        pos: Vector,
        vel: Vector,
    },
    /// `ground pos` (§2.1.2).
    Ground { pos: Vector },
    /// An interaction of the 3-D table (§2.2–§2.5): its argument slots in
    /// [`crate::laws::space::SpaceRow::slots`] order (a direction takes three), and its
    /// endpoints (`b` is `None` for a one-endpoint law, `planeContact`).
    Interaction {
        law: SpaceLawKind,
        args: Vec<Expr>,
        a: Endpoint,
        b: Option<Endpoint>,
    },
    /// A structure generator (§4): expanded by the compiler into nodes and links.
    Structure(Box<Structure>),
    /// `contactSet m1 @struct K Z D {Zt} {mu}` (§4.7): one sphere contact from `a` to every
    /// node of the structure `set`; `args` are the `contact` row's slots.
    ContactSet {
        a: Endpoint,
        set: Label,
        args: Vec<Expr>,
    },
    /// `vdampers @struct Zv` (§4.7): a vector damper in parallel with every link of `set`.
    Vdampers { set: Label, z: Expr },
    /// `@inN posInput pos {dir}` (§3.1): an avatar moving along `dir` (z by default).
    PosInput {
        channel: u32,
        pos: Vector,
        dir: Option<Vector>,
    },
    /// `@inN posInputXYZ pos` (§3.1): an avatar on channels N, N+1, N+2.
    PosInputXyz { channel: u32, pos: Vector },
    /// `@inN frcInput target {dir}` (§3.2).
    FrcInput {
        channel: u32,
        target: Endpoint,
        dir: Option<Vector>,
    },
    /// `@inN frcInputXYZ target` (§3.2): channels N, N+1, N+2.
    FrcInputXyz { channel: u32, target: Endpoint },
    /// `@outN posOutput|frcOutput|velOutput target {dir}` (§3.3).
    Output {
        channel: u32,
        probe: Probe,
        target: Endpoint,
        dir: Option<Vector>,
    },
    /// `@outN distOutput m1 m2` (§3.3): ℓ = |x₁ − x₂|.
    DistOutput {
        channel: u32,
        a: Endpoint,
        b: Endpoint,
    },
    /// `@outN mic SET P DIR q r0` (§3.4): a velocity pickup over the points of a structure or
    /// a buffer scope; `dir` `None` is `radial`.
    Mic {
        channel: u32,
        set: Label,
        at: Vector,
        dir: Option<Vector>,
        q: Expr,
        r0: Expr,
    },
}

impl SpaceKind {
    /// The script keyword.
    pub fn keyword(&self) -> &'static str {
        match self {
            SpaceKind::Mass { body, .. } => body.keyword(),
            SpaceKind::Osc { .. } => "osc",
            SpaceKind::Ground { .. } => "ground",
            SpaceKind::Interaction { law, .. } => law.row().keyword,
            SpaceKind::Structure(s) => s.kind.keyword(),
            SpaceKind::ContactSet { .. } => "contactSet",
            SpaceKind::Vdampers { .. } => "vdampers",
            SpaceKind::PosInput { .. } => "posInput",
            SpaceKind::PosInputXyz { .. } => "posInputXYZ",
            SpaceKind::FrcInput { .. } => "frcInput",
            SpaceKind::FrcInputXyz { .. } => "frcInputXYZ",
            SpaceKind::Output { probe, .. } => probe.keyword(),
            SpaceKind::DistOutput { .. } => "distOutput",
            SpaceKind::Mic { .. } => "mic",
        }
    }
}

/// The structure generators of 3-D spec §4.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StructureKind {
    /// `string3 N M K Z A B L {opts}` (§4.1).
    String3,
    /// `mesh3 NX NY M K Z A B C L {opts}` (§4.2).
    Mesh3,
    /// `lattice3 NX NY NZ M K Z A H L {opts}` (§4.3).
    Lattice3,
    /// `ring3 N M K Z C R NRM L {opts}` (§4.4).
    Ring3,
    /// `icosphere S M K Z C R L {opts}` (§4.5).
    Icosphere,
    /// `objMesh 'path' M K Z S T L {opts}` (§4.6).
    ObjMesh,
}

impl StructureKind {
    pub const ALL: [StructureKind; 6] = [
        StructureKind::String3,
        StructureKind::Mesh3,
        StructureKind::Lattice3,
        StructureKind::Ring3,
        StructureKind::Icosphere,
        StructureKind::ObjMesh,
    ];

    pub fn keyword(self) -> &'static str {
        match self {
            StructureKind::String3 => "string3",
            StructureKind::Mesh3 => "mesh3",
            StructureKind::Lattice3 => "lattice3",
            StructureKind::Ring3 => "ring3",
            StructureKind::Icosphere => "icosphere",
            StructureKind::ObjMesh => "objMesh",
        }
    }

    pub fn from_keyword(keyword: &str) -> Option<StructureKind> {
        StructureKind::ALL
            .into_iter()
            .find(|k| k.keyword() == keyword)
    }

    /// How many size literals lead its arguments (an OBJ mesh has a path instead).
    pub fn num_sizes(self) -> usize {
        match self {
            StructureKind::String3 | StructureKind::Ring3 | StructureKind::Icosphere => 1,
            StructureKind::Mesh3 => 2,
            StructureKind::Lattice3 => 3,
            StructureKind::ObjMesh => 0,
        }
    }

    /// The coordinates a connection point on it takes (3-D spec §2.6): 1 for strings and
    /// rings, 2 for membranes, 3 for lattices, 0 where nodes are addressed by label only.
    pub fn coordinates(self) -> u8 {
        match self {
            StructureKind::String3 | StructureKind::Ring3 => 1,
            StructureKind::Mesh3 => 2,
            StructureKind::Lattice3 => 3,
            StructureKind::Icosphere | StructureKind::ObjMesh => 0,
        }
    }

    /// The signature, for messages.
    pub fn signature(self) -> &'static str {
        match self {
            StructureKind::String3 => "N M K Z A B L {opts}",
            StructureKind::Mesh3 => "NX NY M K Z A B C L {opts}",
            StructureKind::Lattice3 => "NX NY NZ M K Z A H L {opts}",
            StructureKind::Ring3 => "N M K Z C R NRM L {opts}",
            StructureKind::Icosphere => "S M K Z C R L {opts}",
            StructureKind::ObjMesh => "'path' M K Z S T L {opts}",
        }
    }
}

/// A structure statement (3-D spec §4): the generator, its sizes, its physical arguments, its
/// geometry and its options, as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Structure {
    pub kind: StructureKind,
    /// The size literals: N (string3, ring3), NX NY (mesh3), NX NY NZ (lattice3), the
    /// subdivision level S (icosphere); empty for objMesh.
    pub sizes: Vec<u32>,
    pub m: Expr,
    pub k: Expr,
    pub z: Expr,
    /// The geometry vectors in argument order: A B (string3), A B C (mesh3), A H (lattice3),
    /// C NRM (ring3), C (icosphere), T (objMesh).
    pub points: Vec<Vector>,
    /// The radius R (ring3, icosphere) or the scale S (objMesh).
    pub radius: Option<Expr>,
    /// The rest length L of every link, an expression that may use `auto` (§1.7).
    pub rest: Expr,
    /// The options group (§4.0), item by item as written.
    pub options: Vec<StructOption>,
    /// objMesh: the file as written and its contents, read when the script was parsed.
    pub mesh: Option<Arc<MeshData>>,
}

/// One item of a structure's options group (3-D spec §4.0): `key=value` or a flag.
#[derive(Clone, Debug, PartialEq)]
pub enum StructOption {
    /// `Zo=expr` (per-node air friction, class Z).
    Zo(Expr),
    /// `fix=…`.
    Fix(Fix),
    /// `lock=z`, `lock=xy`.
    Lock(Lock),
    /// `diag` (mesh3, lattice3).
    Diag,
    /// `span=s` (lattice3).
    Span(u32),
    /// `K2=expr` (ring3: second-neighbour links).
    K2(Expr),
    /// `hinge=expr` (icosphere, objMesh: links across edges).
    Hinge(Expr),
}

impl Structure {
    /// The `Zo=` option.
    pub fn zo(&self) -> Option<&Expr> {
        self.options.iter().find_map(|o| match o {
            StructOption::Zo(e) => Some(e),
            _ => None,
        })
    }

    /// The `fix=` option, or the generator's default.
    pub fn fix(&self) -> Fix {
        self.options
            .iter()
            .find_map(|o| match o {
                StructOption::Fix(f) => Some(f.clone()),
                _ => None,
            })
            .unwrap_or_else(|| Fix::default_for(self.kind))
    }

    /// The `lock=` option.
    pub fn lock(&self) -> Option<Lock> {
        self.options.iter().find_map(|o| match o {
            StructOption::Lock(l) => Some(*l),
            _ => None,
        })
    }

    /// Whether the `diag` flag is set.
    pub fn diag(&self) -> bool {
        self.options.iter().any(|o| matches!(o, StructOption::Diag))
    }

    /// The `span=` option (1 by default).
    pub fn span(&self) -> u32 {
        self.options
            .iter()
            .find_map(|o| match o {
                StructOption::Span(s) => Some(*s),
                _ => None,
            })
            .unwrap_or(1)
    }

    /// The `K2=` option.
    pub fn k2(&self) -> Option<&Expr> {
        self.options.iter().find_map(|o| match o {
            StructOption::K2(e) => Some(e),
            _ => None,
        })
    }

    /// The `hinge=` option.
    pub fn hinge(&self) -> Option<&Expr> {
        self.options.iter().find_map(|o| match o {
            StructOption::Hinge(e) => Some(e),
            _ => None,
        })
    }
}
