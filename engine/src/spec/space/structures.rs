//! The structure generators of 3-D spec §4: each statement's nodes (positions and which are
//! fixed) and links (endpoints and family, in generation order), their labels, and their
//! counts. The parser uses the counts and labels (pass 1: labels a structure creates,
//! collisions); the compiler expands the geometry into points and links.
//!
//! Every generator follows its section's normative order: node index order, then link order
//! family by family as the section lists them (§4.0: "Links … in generation order").

use super::obj::MeshData;
use super::StructureKind;

/// A family of links, with its label prefix (3-D spec §4.0): `_r` (first neighbours), `_d`
/// (mesh3 diagonals), `_s` (ring3 second neighbours), `_h` (hinges).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LinkFamily {
    Ring,
    Diagonal,
    Second,
    Hinge,
}

impl LinkFamily {
    pub const ALL: [LinkFamily; 4] = [
        LinkFamily::Ring,
        LinkFamily::Diagonal,
        LinkFamily::Second,
        LinkFamily::Hinge,
    ];

    /// The label letter: `r`, `d`, `s`, `h`.
    pub fn letter(self) -> char {
        match self {
            LinkFamily::Ring => 'r',
            LinkFamily::Diagonal => 'd',
            LinkFamily::Second => 's',
            LinkFamily::Hinge => 'h',
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// `lock=z` / `lock=xy` (3-D spec §4.0): free nodes are `massZ` / `massXY`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Lock {
    Z,
    Xy,
}

impl Lock {
    pub fn word(self) -> &'static str {
        match self {
            Lock::Z => "z",
            Lock::Xy => "xy",
        }
    }
}

/// A lattice's fixed set item (3-D spec §4.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LatticeFix {
    Corners,
    Borders,
    Centre,
    /// A face: axis (0 x, 1 y, 2 z) and side (false: index 0, true: the maximum).
    Face(u8, bool),
}

impl LatticeFix {
    const WORDS: [(&'static str, LatticeFix); 9] = [
        ("corners", LatticeFix::Corners),
        ("borders", LatticeFix::Borders),
        ("centre", LatticeFix::Centre),
        ("x-", LatticeFix::Face(0, false)),
        ("x+", LatticeFix::Face(0, true)),
        ("y-", LatticeFix::Face(1, false)),
        ("y+", LatticeFix::Face(1, true)),
        ("z-", LatticeFix::Face(2, false)),
        ("z+", LatticeFix::Face(2, true)),
    ];

    fn word(self) -> &'static str {
        Self::WORDS
            .iter()
            .find(|(_, f)| *f == self)
            .map_or("", |(w, _)| w)
    }
}

/// Which nodes of a structure are grounds (`fix=`, 3-D spec §4.1–§4.6).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Fix {
    None,
    /// string3: both ends (the default), the first, the last.
    Both,
    First,
    Last,
    /// mesh3: the 4 corners, or the border (1D §4.4).
    Corners,
    Borders,
    /// lattice3: a list of sets.
    Lattice(Vec<LatticeFix>),
    /// ring3, objMesh: 0-based node indices.
    Indices(Vec<u32>),
    /// icosphere: the pole v₀, or the pole and its neighbours.
    Pole,
    Crown,
    /// objMesh: every vertex at the lowest z (within 10⁻⁹ of the bounding-box diagonal).
    Zmin,
}

impl Fix {
    /// The generator's default (3-D spec §4): both ends of a string, none elsewhere.
    pub fn default_for(kind: StructureKind) -> Fix {
        match kind {
            StructureKind::String3 => Fix::Both,
            _ => Fix::None,
        }
    }

    /// Reads the value of `fix=` for a generator of `kind`.
    pub fn parse(kind: StructureKind, text: &str) -> Result<Fix, String> {
        let expected = match kind {
            StructureKind::String3 => "`both`, `first`, `last` or `none`",
            StructureKind::Mesh3 => "`none`, `corners` or `borders`",
            StructureKind::Lattice3 => {
                "a comma-separated list of `corners`, `borders`, `centre`, `x-`, `x+`, `y-`, \
                 `y+`, `z-`, `z+`, or `none`"
            }
            StructureKind::Ring3 => "`none` or a comma-separated list of node indices",
            StructureKind::Icosphere => "`none`, `pole` or `crown`",
            StructureKind::ObjMesh => "`none`, `zmin` or a comma-separated list of node indices",
        };
        let bad = || {
            Err(format!(
                "`fix={text}` for `{}`: expected {expected}",
                kind.keyword()
            ))
        };
        if text == "none" {
            return Ok(Fix::None);
        }
        let indices = || -> Option<Vec<u32>> {
            text.split(',')
                .map(|w| w.trim().parse::<u32>().ok())
                .collect()
        };
        match kind {
            StructureKind::String3 => match text {
                "both" => Ok(Fix::Both),
                "first" => Ok(Fix::First),
                "last" => Ok(Fix::Last),
                _ => bad(),
            },
            StructureKind::Mesh3 => match text {
                "corners" => Ok(Fix::Corners),
                "borders" => Ok(Fix::Borders),
                _ => bad(),
            },
            StructureKind::Lattice3 => {
                let mut sets = Vec::new();
                for w in text.split(',') {
                    match LatticeFix::WORDS.iter().find(|(word, _)| *word == w.trim()) {
                        Some((_, f)) => sets.push(*f),
                        None => return bad(),
                    }
                }
                Ok(Fix::Lattice(sets))
            }
            StructureKind::Ring3 => indices().map(Fix::Indices).map_or_else(bad, Ok),
            StructureKind::Icosphere => match text {
                "pole" => Ok(Fix::Pole),
                "crown" => Ok(Fix::Crown),
                _ => bad(),
            },
            StructureKind::ObjMesh => match text {
                "zmin" => Ok(Fix::Zmin),
                _ => indices().map(Fix::Indices).map_or_else(bad, Ok),
            },
        }
    }

    /// The value as a script writes it.
    pub fn text(&self) -> String {
        match self {
            Fix::None => "none".into(),
            Fix::Both => "both".into(),
            Fix::First => "first".into(),
            Fix::Last => "last".into(),
            Fix::Corners => "corners".into(),
            Fix::Borders => "borders".into(),
            Fix::Lattice(sets) => sets.iter().map(|s| s.word()).collect::<Vec<_>>().join(","),
            Fix::Indices(ix) => ix
                .iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(","),
            Fix::Pole => "pole".into(),
            Fix::Crown => "crown".into(),
            Fix::Zmin => "zmin".into(),
        }
    }
}

/// Why a structure cannot be generated.
#[derive(Clone, Debug, PartialEq)]
pub enum StructureError {
    /// A geometry value is not finite.
    NonFinite(&'static str),
    /// The ring's normal is the zero vector.
    ZeroNormal,
    /// A `fix=` node index beyond the structure.
    FixOutOfRange { index: u32, nodes: usize },
    /// More nodes than the compiler's limit.
    TooLarge(u64),
    /// An OBJ file without a vertex.
    EmptyMesh,
}

impl std::fmt::Display for StructureError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StructureError::NonFinite(what) => write!(f, "{what} is not finite"),
            StructureError::ZeroNormal => write!(f, "the ring's normal NRM is the zero vector"),
            StructureError::FixOutOfRange { index, nodes } => write!(
                f,
                "`fix=` names node {index}, but the structure has {nodes} nodes (0 … {})",
                nodes.saturating_sub(1)
            ),
            StructureError::TooLarge(n) => write!(
                f,
                "the structure would have {n} nodes, more than the limit of {}",
                super::MAX_STRUCTURE_NODES
            ),
            StructureError::EmptyMesh => write!(f, "the OBJ file has no vertex"),
        }
    }
}

/// What a generator needs to build its geometry: the statement's constants evaluated.
#[derive(Clone, Copy, Debug)]
pub struct Shape<'a> {
    pub kind: StructureKind,
    pub sizes: &'a [u32],
    /// The geometry vectors, evaluated, in argument order (see [`super::Structure::points`]).
    pub points: &'a [[f64; 3]],
    /// R (ring3, icosphere) or S (objMesh).
    pub radius: f64,
    pub fix: &'a Fix,
    pub diag: bool,
    pub span: u32,
    /// `K2=` given (ring3 second neighbours).
    pub second: bool,
    /// `hinge=` given.
    pub hinge: bool,
    pub mesh: Option<&'a MeshData>,
}

/// A generated structure: its nodes and links, in generation order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Geometry {
    /// Initial node positions, in node index order.
    pub nodes: Vec<[f64; 3]>,
    /// Which nodes are grounds.
    pub fixed: Vec<bool>,
    /// (node a, node b, family), in generation order.
    pub links: Vec<(u32, u32, LinkFamily)>,
    /// Non-fatal findings (a non-manifold edge without a hinge, …), for warnings.
    pub warnings: Vec<String>,
}

/// How many nodes and links of each family a structure has, from its topology alone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub nodes: u64,
    pub links: [u64; 4],
}

impl Counts {
    /// Links of `family`.
    pub fn links_of(&self, family: LinkFamily) -> u64 {
        self.links[family.index()]
    }

    /// Every link.
    pub fn total_links(&self) -> u64 {
        self.links.iter().sum()
    }
}

/// The lattice's allowed forward offsets, in lexicographic order (3-D spec §4.3).
fn lattice_offsets(span: u32, diag: bool) -> Vec<[i64; 3]> {
    let s = span as i64;
    let mut out = Vec::new();
    for di in -s..=s {
        for dj in -s..=s {
            for dk in -s..=s {
                let d = [di, dj, dk];
                let Some(first) = d.iter().find(|c| **c != 0) else {
                    continue;
                };
                if *first < 0 {
                    continue;
                }
                let nonzero = d.iter().filter(|c| **c != 0).count();
                if diag || nonzero == 1 {
                    out.push(d);
                }
            }
        }
    }
    out
}

/// The counts of a structure from its kind, sizes and options (and an OBJ mesh's topology).
pub fn counts(
    kind: StructureKind,
    sizes: &[u32],
    diag: bool,
    span: u32,
    second: bool,
    hinge: bool,
    mesh: Option<&MeshData>,
) -> Counts {
    let n = |i: usize| sizes.get(i).copied().unwrap_or(1) as u64;
    let mut c = Counts::default();
    match kind {
        StructureKind::String3 => {
            c.nodes = n(0);
            c.links[0] = n(0).saturating_sub(1);
        }
        StructureKind::Mesh3 => {
            let (x, y) = (n(0), n(1));
            c.nodes = x * y;
            c.links[0] = x * y.saturating_sub(1) + x.saturating_sub(1) * y;
            if diag {
                c.links[1] = 2 * x.saturating_sub(1) * y.saturating_sub(1);
            }
        }
        StructureKind::Lattice3 => {
            let dims = [n(0), n(1), n(2)];
            c.nodes = dims.iter().product();
            c.links[0] = lattice_offsets(span, diag)
                .iter()
                .map(|d| {
                    (0..3)
                        .map(|a| dims[a].saturating_sub(d[a].unsigned_abs()))
                        .product::<u64>()
                })
                .sum();
        }
        StructureKind::Ring3 => {
            c.nodes = n(0);
            c.links[0] = n(0);
            if second {
                c.links[2] = match n(0) {
                    0..=3 => 0,
                    4 => 2,
                    m => m,
                };
            }
        }
        StructureKind::Icosphere => {
            let four = 4u64.saturating_pow(sizes.first().copied().unwrap_or(0));
            c.nodes = 10 * four + 2;
            c.links[0] = 30 * four;
            if hinge {
                c.links[3] = 30 * four;
            }
        }
        StructureKind::ObjMesh => {
            if let Some(m) = mesh {
                c.nodes = m.vertices.len() as u64;
                c.links[0] = m.edges.len() as u64;
                if hinge {
                    c.links[3] = m.hinges().0.len() as u64;
                }
            }
        }
    }
    c
}

/// The label of node `k` of the structure `name` (3-D spec §4.0): `name_m<i>`,
/// `name_m<i>_<j>` (mesh3) or `name_m<i>_<j>_<k>` (lattice3).
pub fn node_label(name: &str, kind: StructureKind, sizes: &[u32], k: usize) -> String {
    match kind {
        StructureKind::Mesh3 => {
            let ny = sizes.get(1).copied().unwrap_or(1).max(1) as usize;
            format!("{name}_m{}_{}", k / ny, k % ny)
        }
        StructureKind::Lattice3 => {
            let (ny, nz) = (
                sizes.get(1).copied().unwrap_or(1).max(1) as usize,
                sizes.get(2).copied().unwrap_or(1).max(1) as usize,
            );
            format!("{name}_m{}_{}_{}", k / (ny * nz), (k / nz) % ny, k % nz)
        }
        _ => format!("{name}_m{k}"),
    }
}

/// The node a label suffix names (the text after `name_m`), if it is one of the structure's.
pub fn parse_node(kind: StructureKind, sizes: &[u32], nodes: u64, suffix: &str) -> Option<u64> {
    let parts: Option<Vec<u64>> = suffix.split('_').map(plain_index).collect();
    let parts = parts?;
    let dims: Vec<u64> = match kind {
        StructureKind::Mesh3 => sizes.iter().map(|&s| s as u64).collect(),
        StructureKind::Lattice3 => sizes.iter().map(|&s| s as u64).collect(),
        _ => vec![nodes],
    };
    if parts.len() != dims.len() || parts.iter().zip(&dims).any(|(p, d)| p >= d) {
        return None;
    }
    Some(parts.iter().zip(&dims).fold(0, |acc, (p, d)| acc * d + p))
}

/// A decimal index without sign or leading zeros (but `0`).
fn plain_index(s: &str) -> Option<u64> {
    let ok =
        !s.is_empty() && s.chars().all(|c| c.is_ascii_digit()) && (s == "0" || !s.starts_with('0'));
    if ok {
        s.parse().ok()
    } else {
        None
    }
}

/// Whether `suffix` (the text after `name_`) is a link label the structure creates:
/// `r<k>`, `d<k>`, `s<k>` or `h<k>` within its counts.
pub fn is_link_label(counts: &Counts, suffix: &str) -> bool {
    let mut chars = suffix.chars();
    let Some(letter) = chars.next() else {
        return false;
    };
    let Some(family) = LinkFamily::ALL.into_iter().find(|f| f.letter() == letter) else {
        return false;
    };
    plain_index(chars.as_str()).is_some_and(|k| k < counts.links_of(family))
}

/// Generates a structure (3-D spec §4.1–§4.6).
pub fn generate(s: &Shape<'_>) -> Result<Geometry, StructureError> {
    for p in s.points {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(StructureError::NonFinite("a geometry vector"));
        }
    }
    let counts = counts(s.kind, s.sizes, s.diag, s.span, s.second, s.hinge, s.mesh);
    if counts.nodes > super::MAX_STRUCTURE_NODES {
        return Err(StructureError::TooLarge(counts.nodes));
    }
    let mut g = match s.kind {
        StructureKind::String3 => string3(s),
        StructureKind::Mesh3 => mesh3(s),
        StructureKind::Lattice3 => lattice3(s),
        StructureKind::Ring3 => ring3(s)?,
        StructureKind::Icosphere => icosphere(s)?,
        StructureKind::ObjMesh => obj_mesh(s)?,
    };
    if let Fix::Indices(ix) = s.fix {
        for &i in ix {
            match g.fixed.get_mut(i as usize) {
                Some(f) => *f = true,
                None => {
                    return Err(StructureError::FixOutOfRange {
                        index: i,
                        nodes: g.nodes.len(),
                    })
                }
            }
        }
    }
    Ok(g)
}

fn point(s: &Shape<'_>, i: usize) -> [f64; 3] {
    s.points.get(i).copied().unwrap_or([0.0; 3])
}

/// `string3` (§4.1): nodes at A + i/(N−1)·(B − A), links (i, i+1).
fn string3(s: &Shape<'_>) -> Geometry {
    let n = s.sizes[0] as usize;
    let (a, b) = (point(s, 0), point(s, 1));
    let last = (n - 1).max(1) as f64;
    let nodes: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let t = i as f64 / last;
            [0, 1, 2].map(|c| a[c] + t * (b[c] - a[c]))
        })
        .collect();
    let mut fixed = vec![false; n];
    match s.fix {
        Fix::Both => {
            fixed[0] = true;
            fixed[n - 1] = true;
        }
        Fix::First => fixed[0] = true,
        Fix::Last => fixed[n - 1] = true,
        _ => {}
    }
    let links = (0..n.saturating_sub(1))
        .map(|i| (i as u32, i as u32 + 1, LinkFamily::Ring))
        .collect();
    Geometry {
        nodes,
        fixed,
        links,
        warnings: Vec::new(),
    }
}

/// `mesh3` (§4.2): node (i, j) at A + i/(NX−1)(B − A) + j/(NY−1)(C − A), flat index i·NY + j;
/// links (i, j)–(i, j+1), then (i, j)–(i+1, j), then with `diag` each cell's two diagonals.
fn mesh3(s: &Shape<'_>) -> Geometry {
    let (nx, ny) = (s.sizes[0] as usize, s.sizes[1] as usize);
    let (a, b, c) = (point(s, 0), point(s, 1), point(s, 2));
    let (lx, ly) = ((nx - 1).max(1) as f64, (ny - 1).max(1) as f64);
    let mut nodes = Vec::with_capacity(nx * ny);
    for i in 0..nx {
        for j in 0..ny {
            let (ti, tj) = (i as f64 / lx, j as f64 / ly);
            nodes.push([0, 1, 2].map(|k| a[k] + ti * (b[k] - a[k]) + tj * (c[k] - a[k])));
        }
    }
    let idx = |i: usize, j: usize| (i * ny + j) as u32;
    let border = |i: usize, j: usize| i == 0 || j == 0 || i == nx - 1 || j == ny - 1;
    let corner = |i: usize, j: usize| (i == 0 || i == nx - 1) && (j == 0 || j == ny - 1);
    let fixed = (0..nx * ny)
        .map(|k| {
            let (i, j) = (k / ny, k % ny);
            match s.fix {
                Fix::Corners => corner(i, j),
                Fix::Borders => border(i, j),
                _ => false,
            }
        })
        .collect();
    let mut links = Vec::new();
    for i in 0..nx {
        for j in 0..ny.saturating_sub(1) {
            links.push((idx(i, j), idx(i, j + 1), LinkFamily::Ring));
        }
    }
    for i in 0..nx.saturating_sub(1) {
        for j in 0..ny {
            links.push((idx(i, j), idx(i + 1, j), LinkFamily::Ring));
        }
    }
    if s.diag {
        for i in 0..nx.saturating_sub(1) {
            for j in 0..ny.saturating_sub(1) {
                links.push((idx(i, j), idx(i + 1, j + 1), LinkFamily::Diagonal));
                links.push((idx(i, j + 1), idx(i + 1, j), LinkFamily::Diagonal));
            }
        }
    }
    Geometry {
        nodes,
        fixed,
        links,
        warnings: Vec::new(),
    }
}

/// `lattice3` (§4.3): node (i, j, k) at A + (i·hx, j·hy, k·hz), flat index (i·NY + j)·NZ + k;
/// for each node in order, a link to each neighbour at an allowed forward offset.
fn lattice3(s: &Shape<'_>) -> Geometry {
    let dims = [
        s.sizes[0] as usize,
        s.sizes[1] as usize,
        s.sizes[2] as usize,
    ];
    let (a, h) = (point(s, 0), point(s, 1));
    let n = dims[0] * dims[1] * dims[2];
    let flat = |i: usize, j: usize, k: usize| (i * dims[1] + j) * dims[2] + k;
    let mut nodes = Vec::with_capacity(n);
    let mut fixed = Vec::with_capacity(n);
    let sets: &[LatticeFix] = match s.fix {
        Fix::Lattice(sets) => sets,
        _ => &[],
    };
    for i in 0..dims[0] {
        for j in 0..dims[1] {
            for k in 0..dims[2] {
                let ix = [i, j, k];
                nodes.push([
                    a[0] + i as f64 * h[0],
                    a[1] + j as f64 * h[1],
                    a[2] + k as f64 * h[2],
                ]);
                let at_end = |c: usize| ix[c] == 0 || ix[c] == dims[c] - 1;
                let fix = sets.iter().any(|set| match set {
                    LatticeFix::Corners => (0..3).all(at_end),
                    LatticeFix::Borders => (0..3).any(at_end),
                    LatticeFix::Centre => (0..3).all(|c| ix[c] == dims[c] / 2),
                    LatticeFix::Face(axis, max) => {
                        let c = *axis as usize;
                        ix[c] == if *max { dims[c] - 1 } else { 0 }
                    }
                });
                fixed.push(fix);
            }
        }
    }
    let offsets = lattice_offsets(s.span, s.diag);
    let mut links = Vec::new();
    for i in 0..dims[0] {
        for j in 0..dims[1] {
            for k in 0..dims[2] {
                for d in &offsets {
                    let to = [i as i64 + d[0], j as i64 + d[1], k as i64 + d[2]];
                    if (0..3).all(|c| to[c] >= 0 && (to[c] as usize) < dims[c]) {
                        links.push((
                            flat(i, j, k) as u32,
                            flat(to[0] as usize, to[1] as usize, to[2] as usize) as u32,
                            LinkFamily::Ring,
                        ));
                    }
                }
            }
        }
    }
    Geometry {
        nodes,
        fixed,
        links,
        warnings: Vec::new(),
    }
}

/// `ring3` (§4.4): node k at C + R(cos θ_k e₁ + sin θ_k e₂), θ_k = 2πk/N, with the frame
/// from the normal; ring links (k, k+1 mod N), then with `K2=` second neighbours.
fn ring3(s: &Shape<'_>) -> Result<Geometry, StructureError> {
    let n = s.sizes[0] as usize;
    let (c, nrm) = (point(s, 0), point(s, 1));
    if !s.radius.is_finite() {
        return Err(StructureError::NonFinite("the radius R"));
    }
    let len = (nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]).sqrt();
    if !(len > 0.0) {
        return Err(StructureError::ZeroNormal);
    }
    let nh = nrm.map(|v| v / len);
    let g = if nh[0].abs() > 0.9 {
        [0.0, 1.0, 0.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let gn = g[0] * nh[0] + g[1] * nh[1] + g[2] * nh[2];
    let e1 = [0, 1, 2].map(|k| g[k] - gn * nh[k]);
    let e1l = (e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]).sqrt();
    let e1 = e1.map(|v| v / e1l);
    let e2 = [
        nh[1] * e1[2] - nh[2] * e1[1],
        nh[2] * e1[0] - nh[0] * e1[2],
        nh[0] * e1[1] - nh[1] * e1[0],
    ];
    let nodes = (0..n)
        .map(|k| {
            let th = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            let (sn, cs) = th.sin_cos();
            [0, 1, 2].map(|i| c[i] + s.radius * (cs * e1[i] + sn * e2[i]))
        })
        .collect();
    let mut links: Vec<(u32, u32, LinkFamily)> = (0..n)
        .map(|k| (k as u32, ((k + 1) % n) as u32, LinkFamily::Ring))
        .collect();
    if s.second {
        let ks: Vec<usize> = match n {
            0..=3 => vec![],
            4 => vec![0, 1],
            _ => (0..n).collect(),
        };
        links.extend(
            ks.into_iter()
                .map(|k| (k as u32, ((k + 2) % n) as u32, LinkFamily::Second)),
        );
    }
    Ok(Geometry {
        nodes,
        fixed: vec![false; n],
        links,
        warnings: Vec::new(),
    })
}

/// `icosphere` (§4.5): the base icosahedron (normative vertex and face order), subdivided S
/// times by edge midpoints pushed to the unit sphere, mapped to C + R·v; links from the faces'
/// edges in first-seen order; hinges across edges with `hinge=`.
fn icosphere(s: &Shape<'_>) -> Result<Geometry, StructureError> {
    if !s.radius.is_finite() {
        return Err(StructureError::NonFinite("the radius R"));
    }
    let (verts, faces) = icosphere_unit(s.sizes[0]);
    let c = point(s, 0);
    let nodes: Vec<[f64; 3]> = verts
        .iter()
        .map(|v| [0, 1, 2].map(|k| c[k] + s.radius * v[k]))
        .collect();
    let n = nodes.len();
    let mut fixed = vec![false; n];
    let edges = face_edges(&faces);
    match s.fix {
        Fix::Pole => fixed[0] = true,
        Fix::Crown => {
            fixed[0] = true;
            for &(a, b) in &edges {
                if a == 0 {
                    fixed[b as usize] = true;
                } else if b == 0 {
                    fixed[a as usize] = true;
                }
            }
        }
        _ => {}
    }
    let mut links: Vec<(u32, u32, LinkFamily)> = edges
        .iter()
        .map(|&(a, b)| (a, b, LinkFamily::Ring))
        .collect();
    let mut warnings = Vec::new();
    if s.hinge {
        let (hinges, non_manifold) = hinges_of(&faces, &edges);
        links.extend(hinges.into_iter().map(|(a, b)| (a, b, LinkFamily::Hinge)));
        if non_manifold > 0 {
            warnings.push(format!(
                "{non_manifold} edges are not shared by exactly two faces: no hinge there"
            ));
        }
    }
    Ok(Geometry {
        nodes,
        fixed,
        links,
        warnings,
    })
}

/// The unit icosphere of subdivision level `level`: vertices and counter-clockwise faces.
pub fn icosphere_unit(level: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    use std::f64::consts::PI;
    let r = 2.0 / 5f64.sqrt();
    let h = 1.0 / 5f64.sqrt();
    let mut v: Vec<[f64; 3]> = vec![[0.0, 0.0, 1.0]];
    for k in 0..5 {
        let t = 2.0 * PI * k as f64 / 5.0;
        v.push([r * t.cos(), r * t.sin(), h]);
    }
    for k in 0..5 {
        let t = 2.0 * PI * k as f64 / 5.0 + PI / 5.0;
        v.push([r * t.cos(), r * t.sin(), -h]);
    }
    v.push([0.0, 0.0, -1.0]);
    let mut f: Vec<[u32; 3]> = Vec::with_capacity(20);
    for k in 0..5u32 {
        let k1 = (k + 1) % 5;
        f.push([0, 1 + k, 1 + k1]);
    }
    for k in 0..5u32 {
        let k1 = (k + 1) % 5;
        f.push([1 + k, 6 + k, 1 + k1]);
        f.push([1 + k1, 6 + k, 6 + k1]);
    }
    for k in 0..5u32 {
        let k1 = (k + 1) % 5;
        f.push([11, 6 + k1, 6 + k]);
    }
    for _ in 0..level {
        let mut mid: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(f.len() * 4);
        for &[a, b, c] in &f {
            let mut m = |x: u32, y: u32, v: &mut Vec<[f64; 3]>| -> u32 {
                let key = (x.min(y), x.max(y));
                *mid.entry(key).or_insert_with(|| {
                    let (p, q) = (v[x as usize], v[y as usize]);
                    let s = [0, 1, 2].map(|i| (p[i] + q[i]) / 2.0);
                    let l = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
                    v.push(s.map(|c| c / l));
                    (v.len() - 1) as u32
                })
            };
            let mab = m(a, b, &mut v);
            let mbc = m(b, c, &mut v);
            let mca = m(c, a, &mut v);
            next.push([a, mab, mca]);
            next.push([b, mbc, mab]);
            next.push([c, mca, mbc]);
            next.push([mab, mbc, mca]);
        }
        f = next;
    }
    (v, f)
}

/// The edges of faces (each face's (a,b), (b,c), (c,a)), the first time each unordered edge is
/// seen, endpoints in first-seen order.
fn face_edges(faces: &[[u32; 3]]) -> Vec<(u32, u32)> {
    let mut seen = std::collections::HashSet::with_capacity(faces.len() * 2);
    let mut edges = Vec::with_capacity(faces.len() * 3 / 2);
    for &[a, b, c] in faces {
        for (x, y) in [(a, b), (b, c), (c, a)] {
            if seen.insert((x.min(y), x.max(y))) {
                edges.push((x, y));
            }
        }
    }
    edges
}

/// The hinges of a triangulated surface (3-D spec §4.5 `hinge=`): for each edge in `edges`
/// order shared by exactly two triangles (a, b, c) and (b, a, d), the link c–d. Returns them
/// and the number of edges shared by more than two triangles.
pub(crate) fn hinges_of(faces: &[[u32; 3]], edges: &[(u32, u32)]) -> (Vec<(u32, u32)>, usize) {
    let mut opposite: std::collections::HashMap<(u32, u32), Vec<u32>> =
        std::collections::HashMap::with_capacity(edges.len());
    for &[a, b, c] in faces {
        for (x, y, z) in [(a, b, c), (b, c, a), (c, a, b)] {
            opposite.entry((x.min(y), x.max(y))).or_default().push(z);
        }
    }
    let mut hinges = Vec::new();
    let mut non_manifold = 0;
    for &(a, b) in edges {
        match opposite.get(&(a.min(b), a.max(b))).map(Vec::as_slice) {
            Some([c, d]) => hinges.push((*c, *d)),
            Some(o) if o.len() > 2 => non_manifold += 1,
            _ => {}
        }
    }
    (hinges, non_manifold)
}

/// `objMesh` (§4.6): vertex k at S·v + T; the file's edges; fixed nodes by `fix=`.
fn obj_mesh(s: &Shape<'_>) -> Result<Geometry, StructureError> {
    let Some(mesh) = s.mesh else {
        return Err(StructureError::EmptyMesh);
    };
    if mesh.vertices.is_empty() {
        return Err(StructureError::EmptyMesh);
    }
    if !s.radius.is_finite() {
        return Err(StructureError::NonFinite("the scale S"));
    }
    let t = point(s, 0);
    let nodes: Vec<[f64; 3]> = mesh
        .vertices
        .iter()
        .map(|v| [0, 1, 2].map(|k| s.radius * v[k] + t[k]))
        .collect();
    let n = nodes.len();
    let mut fixed = vec![false; n];
    if *s.fix == Fix::Zmin {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &nodes {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let diag =
            ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
        for (f, p) in fixed.iter_mut().zip(&nodes) {
            *f = p[2] <= lo[2] + 1e-9 * diag;
        }
    }
    let mut links: Vec<(u32, u32, LinkFamily)> = mesh
        .edges
        .iter()
        .map(|&(a, b)| (a, b, LinkFamily::Ring))
        .collect();
    let mut warnings = Vec::new();
    if s.hinge {
        let (hinges, non_manifold) = mesh.hinges();
        links.extend(hinges.into_iter().map(|(a, b)| (a, b, LinkFamily::Hinge)));
        if non_manifold > 0 {
            warnings.push(format!(
                "{non_manifold} edges are shared by more than two faces (non-manifold): no hinge there"
            ));
        }
    }
    Ok(Geometry {
        nodes,
        fixed,
        links,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape<'a>(
        kind: StructureKind,
        sizes: &'a [u32],
        points: &'a [[f64; 3]],
        fix: &'a Fix,
    ) -> Shape<'a> {
        Shape {
            kind,
            sizes,
            points,
            radius: 1.0,
            fix,
            diag: false,
            span: 1,
            second: false,
            hinge: false,
            mesh: None,
        }
    }

    #[test]
    fn a_string_spans_its_ends_and_fixes_both() {
        let g = generate(&shape(
            StructureKind::String3,
            &[5],
            &[[0.0; 3], [4.0, 0.0, 0.0]],
            &Fix::Both,
        ))
        .unwrap();
        assert_eq!(g.nodes[2], [2.0, 0.0, 0.0]);
        assert_eq!(g.fixed, [true, false, false, false, true]);
        assert_eq!(g.links.len(), 4);
    }

    /// Icosphere counts (3-D spec §4.5): V = 10·4^S + 2, E = 30·4^S, E = 3V − 6; every edge
    /// is shared by two faces, every face counter-clockwise seen from outside.
    #[test]
    fn icosphere_counts_and_orientation() {
        for level in 0..4 {
            let (v, f) = icosphere_unit(level);
            let e = face_edges(&f);
            let four = 4usize.pow(level);
            assert_eq!(v.len(), 10 * four + 2);
            assert_eq!(e.len(), 30 * four);
            assert_eq!(f.len(), 20 * four);
            assert_eq!(e.len(), 3 * v.len() - 6);
            let (hinges, non_manifold) = hinges_of(&f, &e);
            assert_eq!((hinges.len(), non_manifold), (e.len(), 0));
            for &[a, b, c] in &f {
                let (p, q, r) = (v[a as usize], v[b as usize], v[c as usize]);
                let u = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                let w = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
                let n = [
                    u[1] * w[2] - u[2] * w[1],
                    u[2] * w[0] - u[0] * w[2],
                    u[0] * w[1] - u[1] * w[0],
                ];
                let out = n[0] * p[0] + n[1] * p[1] + n[2] * p[2];
                assert!(out > 0.0, "face ({a}, {b}, {c}) turns inward");
            }
            let c = counts(
                StructureKind::Icosphere,
                &[level],
                false,
                1,
                false,
                true,
                None,
            );
            assert_eq!(c.nodes as usize, v.len());
            assert_eq!(c.links_of(LinkFamily::Hinge) as usize, e.len());
        }
        // The crown: the pole and its five neighbours.
        let fix = Fix::Crown;
        let g = generate(&Shape {
            radius: 10.0,
            ..shape(StructureKind::Icosphere, &[2], &[[0.0; 3]], &fix)
        })
        .unwrap();
        assert_eq!(g.fixed.iter().filter(|f| **f).count(), 6);
    }

    /// The lattice's links follow its counts; the 2×2×N beam with diagonals has 6N + 16(N − 1)
    /// links (3-D spec §4.3).
    #[test]
    fn lattice_links_match_the_counts() {
        for (sizes, diag, span) in [
            ([2, 2, 5], true, 1),
            ([3, 4, 2], false, 1),
            ([4, 3, 3], true, 2),
            ([5, 1, 1], false, 3),
        ] {
            let s = Shape {
                diag,
                span,
                ..shape(
                    StructureKind::Lattice3,
                    &sizes,
                    &[[0.0; 3], [1.0, 1.0, 1.0]],
                    &Fix::None,
                )
            };
            let g = generate(&s).unwrap();
            let c = counts(
                StructureKind::Lattice3,
                &sizes,
                diag,
                span,
                false,
                false,
                None,
            );
            assert_eq!(g.links.len() as u64, c.total_links(), "{sizes:?}");
            assert_eq!(g.nodes.len() as u64, c.nodes);
        }
        let c = counts(
            StructureKind::Lattice3,
            &[2, 2, 7],
            true,
            1,
            false,
            false,
            None,
        );
        assert_eq!(c.total_links(), 6 * 7 + 16 * 6);
    }

    #[test]
    fn mesh_and_ring_counts() {
        let s = Shape {
            diag: true,
            ..shape(
                StructureKind::Mesh3,
                &[4, 3],
                &[[0.0; 3], [3.0, 0.0, 0.0], [0.0, 2.0, 0.0]],
                &Fix::Borders,
            )
        };
        let g = generate(&s).unwrap();
        let c = counts(StructureKind::Mesh3, &[4, 3], true, 1, false, false, None);
        assert_eq!(g.links.len() as u64, c.total_links());
        assert_eq!(g.fixed.iter().filter(|f| !**f).count(), 2);
        assert_eq!(g.nodes[1 * 3 + 2], [1.0, 2.0, 0.0]);
        for n in [3u32, 4, 5, 9] {
            let sizes = [n];
            let s = Shape {
                second: true,
                radius: 2.0,
                ..shape(
                    StructureKind::Ring3,
                    &sizes,
                    &[[0.0; 3], [0.0, 0.0, 1.0]],
                    &Fix::None,
                )
            };
            let g = generate(&s).unwrap();
            let c = counts(StructureKind::Ring3, &[n], false, 1, true, false, None);
            assert_eq!(g.links.len() as u64, c.total_links(), "ring of {n}");
            for p in &g.nodes {
                assert!(((p[0] * p[0] + p[1] * p[1]).sqrt() - 2.0).abs() < 1e-12 && p[2] == 0.0);
            }
        }
        let s = Shape {
            radius: 2.0,
            ..shape(
                StructureKind::Ring3,
                &[5],
                &[[0.0; 3], [0.0; 3]],
                &Fix::None,
            )
        };
        assert_eq!(generate(&s), Err(StructureError::ZeroNormal));
    }

    #[test]
    fn labels_round_trip() {
        for (kind, sizes, nodes) in [
            (StructureKind::String3, vec![40u32], 40u64),
            (StructureKind::Mesh3, vec![15, 12], 180),
            (StructureKind::Lattice3, vec![2, 3, 4], 24),
        ] {
            for k in 0..nodes as usize {
                let l = node_label("s", kind, &sizes, k);
                let suffix = l.strip_prefix("s_m").unwrap();
                assert_eq!(
                    parse_node(kind, &sizes, nodes, suffix),
                    Some(k as u64),
                    "{l}"
                );
            }
        }
        assert_eq!(parse_node(StructureKind::String3, &[40], 40, "40"), None);
        assert_eq!(parse_node(StructureKind::String3, &[40], 40, "07"), None);
        assert_eq!(parse_node(StructureKind::Mesh3, &[4, 4], 16, "3"), None);
        let c = counts(StructureKind::String3, &[40], false, 1, false, false, None);
        assert!(is_link_label(&c, "r38") && !is_link_label(&c, "r39") && !is_link_label(&c, "d0"));
    }

    #[test]
    fn fix_words_round_trip() {
        for (kind, text) in [
            (StructureKind::String3, "first"),
            (StructureKind::Mesh3, "borders"),
            (StructureKind::Lattice3, "corners,z-,centre"),
            (StructureKind::Ring3, "0,3"),
            (StructureKind::Icosphere, "crown"),
            (StructureKind::ObjMesh, "zmin"),
            (StructureKind::ObjMesh, "1,2,5"),
        ] {
            let f = Fix::parse(kind, text).unwrap();
            assert_eq!(f.text(), text);
        }
        assert!(Fix::parse(StructureKind::String3, "borders").is_err());
        assert!(Fix::parse(StructureKind::Lattice3, "corners,q").is_err());
    }
}
