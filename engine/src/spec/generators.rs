//! Topology generators (spec §4): expand a structure into explicit elements, for structures that
//! need per-node access, irregular shapes or replaced nodes.
//!
//! Common rules (§4):
//! * each generator declares the parameters `<name>_M`, `<name>_K`, `<name>_Z` and `<name>_Zo`
//!   (the stiff string also `<name>_Ks`);
//! * nodes are `mass <name>_M` when Zo = 0, otherwise `osc <name>_M 0 <name>_Zo`;
//! * links are `springDamper <name>_K <name>_Z`, the stiffness springs `springDamper <name>_Ks 0`;
//! * fixed nodes become `ground`s;
//! * nodes are named `<name>_m<k>` (1-D) or `<name>_m<a>_<b>` (2-D, `_<c>` more in 3-D), end
//!   grounds `<name>_g0` / `<name>_g1`, links `<name>_r<k>`;
//! * positions interpolate linearly between a first and a last point (the box); x and y serve
//!   rendering and named buffers only.

use crate::spec::expr::Expr;
use crate::spec::{Endpoint, ModelBuilder, Vector};

/// Which nodes of a generated structure are fixed (spec §4.4–§4.8).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Fixed {
    #[default]
    None,
    Corners,
    Borders,
}

/// Fixed nodes of a 3-D lattice (spec §4.8).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum LatticeFixed {
    #[default]
    None,
    Corners,
    Borders,
    /// One face: axis 0 = x, 1 = y, 2 = z; `high` for the + face.
    Face {
        axis: u8,
        high: bool,
    },
    Centre,
}

/// The shape to generate.
#[derive(Clone, Debug, PartialEq)]
pub enum Topology {
    /// n moving nodes between two end grounds (§4.1): n + 2 points, n + 1 links.
    String { nodes: usize },
    /// n moving nodes with second-neighbour springs (§4.2): n + 2 points, 2n + 3 links.
    StiffString { nodes: usize },
    /// n free nodes (§4.3): n points, n − 1 links.
    Chain { nodes: usize },
    /// L × W 4-neighbour grid (§4.4).
    Mesh {
        length: usize,
        width: usize,
        fixed: Fixed,
    },
    /// Triangular lattice of `size` rows (§4.5): s(s+1)/2 points, 3s(s−1)/2 links.
    Triangle { size: usize, fixed: Fixed },
    /// Hexagon of `rings` rings (§4.6): 1 + 3s(s+1) points, 9s² + 3s links.
    Hexagon { rings: usize, fixed: Fixed },
    /// n ≥ 3 nodes on a circle in the x–y plane (§4.7): n points, n links.
    Ring { nodes: usize, radius: f64 },
    /// Nx × Ny × Nz lattice (§4.8) linking neighbours up to `span` apart, along axes only or
    /// within Chebyshev distance (`diagonals`).
    Lattice {
        size: [usize; 3],
        span: usize,
        diagonals: bool,
        fixed: LatticeFixed,
    },
    /// A polyline through (x, y) points rescaled into the box (§4.9): n links closed, n − 1 open.
    Polyline {
        points: Vec<(f64, f64)>,
        closed: bool,
    },
}

/// The physical values and placement of a generated structure.
#[derive(Clone, Debug, PartialEq)]
pub struct Generator {
    /// Prefix of every label and parameter.
    pub name: String,
    pub m: f64,
    pub k: f64,
    pub z: f64,
    /// Ground friction ("friction (optional)"): nodes become `osc M 0 Zo` when ≠ 0.
    pub zo: f64,
    /// Stiff string second-neighbour stiffness.
    pub ks: f64,
    /// First corner of the box (x, y, z); the ring's centre.
    pub first: [f64; 3],
    /// Last corner of the box.
    pub last: [f64; 3],
}

impl Generator {
    /// A generator named `name` with M = 1, K = 0.1, Z = 0.001, no friction, in the unit box at
    /// z = 0.
    pub fn new(name: &str) -> Generator {
        Generator {
            name: name.to_string(),
            m: 1.0,
            k: 0.1,
            z: 0.001,
            zo: 0.0,
            ks: 0.0,
            first: [0.0, 0.0, 0.0],
            last: [1.0, 1.0, 0.0],
        }
    }
}

/// What a generator produced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Generated {
    /// Node labels in node order (fixed ones included).
    pub nodes: Vec<String>,
    /// Which nodes are grounds.
    pub fixed: Vec<bool>,
    /// Link labels in order.
    pub links: Vec<String>,
    /// Node pairs of each link (indices into `nodes`).
    pub pairs: Vec<(usize, usize)>,
    /// The parameters the generator declared, in order: `<name>_M`, `<name>_K`, `<name>_Z`,
    /// `<name>_Zo`, and `<name>_Ks` for the stiff string.
    pub params: Vec<String>,
}

impl Generated {
    /// The label of node `i`.
    pub fn node(&self, i: usize) -> Option<&str> {
        self.nodes.get(i).map(String::as_str)
    }

    /// The number of fixed nodes.
    pub fn num_fixed(&self) -> usize {
        self.fixed.iter().filter(|f| **f).count()
    }
}

/// The largest structure a generator builds, in nodes.
pub const MAX_GENERATED_NODES: usize = 1 << 20;

/// The most links a generator builds. Without it a 3-D lattice with a wide neighbour span and
/// diagonals could ask for billions of links from a handful of nodes.
pub const MAX_GENERATED_LINKS: usize = 1 << 22;

/// Why a generator refused.
#[derive(Clone, Debug, PartialEq)]
pub enum GeneratorError {
    /// A size below the minimum for the shape.
    TooSmall { what: &'static str, min: usize },
    /// More than [`MAX_GENERATED_NODES`] nodes.
    TooLarge { nodes: usize },
    /// More than [`MAX_GENERATED_LINKS`] links.
    TooManyLinks { links: usize },
    /// A non-finite or non-positive value where one is required.
    InvalidValue { what: &'static str, value: f64 },
}

impl std::fmt::Display for GeneratorError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GeneratorError::TooSmall { what, min } => write!(f, "{what} must be at least {min}"),
            GeneratorError::TooLarge { nodes } => write!(
                f,
                "{nodes} nodes is more than the limit of {MAX_GENERATED_NODES}"
            ),
            GeneratorError::TooManyLinks { links } => write!(
                f,
                "{links} links is more than the limit of {MAX_GENERATED_LINKS}"
            ),
            GeneratorError::InvalidValue { what, value } => write!(f, "invalid {what}: {value}"),
        }
    }
}

impl std::error::Error for GeneratorError {}

/// A node before emission: its 2-D or 3-D name suffix, position and fixedness.
struct Node {
    suffix: String,
    pos: [f64; 3],
    fixed: bool,
}

fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

fn box_point(g: &Generator, t: [f64; 3]) -> [f64; 3] {
    [
        lerp(g.first[0], g.last[0], t[0]),
        lerp(g.first[1], g.last[1], t[1]),
        lerp(g.first[2], g.last[2], t[2]),
    ]
}

fn frac(i: usize, n: usize) -> f64 {
    if n <= 1 {
        0.0
    } else {
        i as f64 / (n - 1) as f64
    }
}

fn check_min(value: usize, min: usize, what: &'static str) -> Result<(), GeneratorError> {
    if value < min {
        Err(GeneratorError::TooSmall { what, min })
    } else {
        Ok(())
    }
}

fn check_size(nodes: usize) -> Result<(), GeneratorError> {
    if nodes > MAX_GENERATED_NODES {
        Err(GeneratorError::TooLarge { nodes })
    } else {
        Ok(())
    }
}

/// The lattice neighbour offsets in the positive half-space (first non-zero component > 0), so
/// that each pair is linked once. Offsets longer than an axis can never link two nodes, so the
/// span is clamped per axis: the loop stays within the lattice's own extent whatever the span.
fn lattice_offsets(size: [usize; 3], span: usize, diagonals: bool) -> Vec<[i64; 3]> {
    let reach = size.map(|n| span.min(n.saturating_sub(1)) as i64);
    let mut offsets = Vec::new();
    for dx in -reach[0]..=reach[0] {
        for dy in -reach[1]..=reach[1] {
            for dz in -reach[2]..=reach[2] {
                let d = [dx, dy, dz];
                let first_nonzero = d.iter().find(|v| **v != 0);
                if first_nonzero.is_none_or(|v| *v < 0) {
                    continue;
                }
                let nonzero = d.iter().filter(|v| **v != 0).count();
                if diagonals || nonzero == 1 {
                    offsets.push(d);
                }
            }
        }
    }
    offsets
}

impl Topology {
    /// The number of nodes (fixed ones included) and links the topology generates, computed
    /// without building anything. Fails as [`generate`] would on a size below the shape's
    /// minimum or a structure above [`MAX_GENERATED_NODES`] or [`MAX_GENERATED_LINKS`], so a
    /// caller can refuse an absurd request before anything is allocated.
    pub fn counts(&self) -> Result<(usize, usize), GeneratorError> {
        let (nodes, links) = match self {
            Topology::String { nodes: n } | Topology::StiffString { nodes: n } => {
                check_min(*n, 1, "the number of moving nodes")?;
                let points = n.saturating_add(2);
                check_size(points)?;
                let links = if matches!(self, Topology::StiffString { .. }) {
                    2 * n + 3
                } else {
                    n + 1
                };
                (points, links)
            }
            Topology::Chain { nodes: n } => {
                check_min(*n, 2, "the number of chain nodes")?;
                check_size(*n)?;
                (*n, n - 1)
            }
            Topology::Mesh { length, width, .. } => {
                let (l, w) = (*length, *width);
                check_min(l, 2, "the mesh length")?;
                check_min(w, 2, "the mesh width")?;
                check_size(l.saturating_mul(w))?;
                (l * w, l * (w - 1) + (l - 1) * w)
            }
            Topology::Triangle { size, .. } => {
                let s = *size;
                check_min(s, 2, "the triangle size")?;
                check_size(s.saturating_mul(s.saturating_add(1)) / 2)?;
                (s * (s + 1) / 2, 3 * s * (s - 1) / 2)
            }
            Topology::Hexagon { rings, .. } => {
                let s = *rings;
                check_min(s, 1, "the number of hexagon rings")?;
                let points = s
                    .saturating_mul(s.saturating_add(1))
                    .saturating_mul(3)
                    .saturating_add(1);
                check_size(points)?;
                (points, 9 * s * s + 3 * s)
            }
            Topology::Ring { nodes: n, .. } => {
                check_min(*n, 3, "the number of ring nodes")?;
                check_size(*n)?;
                (*n, *n)
            }
            Topology::Lattice {
                size,
                span,
                diagonals,
                ..
            } => {
                for n in size {
                    check_min(*n, 1, "each lattice size")?;
                }
                check_min(*span, 1, "the neighbour span")?;
                let points = size.iter().fold(1usize, |p, n| p.saturating_mul(*n));
                check_size(points)?;
                let links = lattice_offsets(*size, *span, *diagonals)
                    .iter()
                    .map(|d| {
                        (0..3).fold(1usize, |p, a| {
                            p.saturating_mul(size[a] - d[a].unsigned_abs() as usize)
                        })
                    })
                    .fold(0usize, usize::saturating_add);
                (points, links)
            }
            Topology::Polyline { points, closed } => {
                let n = points.len();
                check_min(n, 2, "the number of polyline points")?;
                check_size(n)?;
                (n, if *closed && n > 2 { n } else { n - 1 })
            }
        };
        if links > MAX_GENERATED_LINKS {
            return Err(GeneratorError::TooManyLinks { links });
        }
        Ok((nodes, links))
    }
}

/// Expands `topology` into `builder` with the values of `g`. Returns the labels of what it
/// created, for addressing nodes afterwards.
pub fn generate(
    builder: &mut ModelBuilder,
    g: &Generator,
    topology: &Topology,
) -> Result<Generated, GeneratorError> {
    for (what, v) in [
        ("M", g.m),
        ("K", g.k),
        ("Z", g.z),
        ("Zo", g.zo),
        ("Ks", g.ks),
    ] {
        if !v.is_finite() {
            return Err(GeneratorError::InvalidValue { what, value: v });
        }
    }
    if !(g.m > 0.0) {
        return Err(GeneratorError::InvalidValue {
            what: "M",
            value: g.m,
        });
    }
    if let Some(&v) = g.first.iter().chain(&g.last).find(|v| !v.is_finite()) {
        return Err(GeneratorError::InvalidValue {
            what: "box coordinate",
            value: v,
        });
    }
    let (nodes, links, stiff_links) = layout(g, topology)?;
    // A finite box can still overflow (a box from -1e308 to 1e308, a huge ring radius).
    if let Some(&v) = nodes.iter().flat_map(|n| &n.pos).find(|v| !v.is_finite()) {
        return Err(GeneratorError::InvalidValue {
            what: "node position",
            value: v,
        });
    }
    let out = labels(&g.name, topology, &nodes, &links, &stiff_links);
    emit(builder, g, &nodes, &out, links.len());
    Ok(out)
}

/// The labels and link pairs [`generate`] would create for a structure named `name`, without
/// building anything. Labels depend only on the name and the topology (not on the values or
/// the box), so a parser can learn them before it evaluates anything.
pub fn plan(name: &str, topology: &Topology) -> Result<Generated, GeneratorError> {
    let (nodes, links, stiff_links) = layout(&Generator::new(name), topology)?;
    Ok(labels(name, topology, &nodes, &links, &stiff_links))
}

/// Node list and link pairs of a topology. Stiffness links (stiff string) come separately.
#[allow(clippy::type_complexity)]
fn layout(
    g: &Generator,
    topology: &Topology,
) -> Result<(Vec<Node>, Vec<(usize, usize)>, Vec<(usize, usize)>), GeneratorError> {
    let (num_nodes, num_links) = topology.counts()?;
    let mut nodes = Vec::with_capacity(num_nodes);
    let mut links = Vec::with_capacity(num_links);
    let mut stiff = Vec::new();
    match topology {
        Topology::String { nodes: n } | Topology::StiffString { nodes: n } => {
            // Grounds at the box ends, n nodes equally spaced (n + 1 intervals).
            let t = |k: usize| k as f64 / (n + 1) as f64;
            nodes.push(Node {
                suffix: "g0".into(),
                pos: box_point(g, [0.0; 3]),
                fixed: true,
            });
            for k in 0..*n {
                let tk = t(k + 1);
                nodes.push(Node {
                    suffix: format!("m{k}"),
                    pos: box_point(g, [tk; 3]),
                    fixed: false,
                });
            }
            nodes.push(Node {
                suffix: "g1".into(),
                pos: box_point(g, [1.0; 3]),
                fixed: true,
            });
            // Chain numbering: 0 = g0, k = m_{k−1}, n+1 = g1.
            links.extend((0..=*n).map(|k| (k, k + 1)));
            if matches!(topology, Topology::StiffString { .. }) {
                stiff.push((0, 1));
                stiff.extend((0..*n).map(|k| (k, k + 2)));
                stiff.push((*n, n + 1));
            }
        }
        Topology::Chain { nodes: n } => {
            for k in 0..*n {
                let tk = frac(k, *n);
                nodes.push(Node {
                    suffix: format!("m{k}"),
                    pos: box_point(g, [tk; 3]),
                    fixed: false,
                });
            }
            links.extend((0..n - 1).map(|k| (k, k + 1)));
        }
        Topology::Mesh {
            length,
            width,
            fixed,
        } => {
            let (l, w) = (*length, *width);
            for i in 0..l {
                for j in 0..w {
                    let border = i == 0 || i == l - 1 || j == 0 || j == w - 1;
                    let corner = (i == 0 || i == l - 1) && (j == 0 || j == w - 1);
                    let (ti, tj) = (frac(i, l), frac(j, w));
                    nodes.push(Node {
                        suffix: format!("m{i}_{j}"),
                        pos: box_point(g, [ti, tj, ti]),
                        fixed: match fixed {
                            Fixed::None => false,
                            Fixed::Corners => corner,
                            Fixed::Borders => border,
                        },
                    });
                }
            }
            let id = |i: usize, j: usize| i * w + j;
            for i in 0..l {
                for j in 0..w - 1 {
                    links.push((id(i, j), id(i, j + 1)));
                }
            }
            for i in 0..l - 1 {
                for j in 0..w {
                    links.push((id(i, j), id(i + 1, j)));
                }
            }
        }
        Topology::Triangle { size, fixed } => {
            let s = *size;
            let spacing_x = (g.last[0] - g.first[0]) / (s - 1) as f64;
            let mut index = vec![vec![0usize; s]; s];
            for j in 0..s {
                for i in 0..s - j {
                    index[j][i] = nodes.len();
                    let corner = (j == 0 && (i == 0 || i == s - 1)) || (j == s - 1 && i == 0);
                    let border = i == 0 || i == s - 1 - j || j == 0;
                    nodes.push(Node {
                        suffix: format!("m{j}_{i}"),
                        pos: [
                            g.first[0] + spacing_x * (i as f64 + j as f64 / 2.0),
                            g.first[1] + spacing_x * j as f64 * 3f64.sqrt() / 2.0,
                            g.first[2],
                        ],
                        fixed: match fixed {
                            Fixed::None => false,
                            Fixed::Corners => corner,
                            Fixed::Borders => border,
                        },
                    });
                }
            }
            for j in 0..s {
                for i in 0..s - j - 1 {
                    links.push((index[j][i], index[j][i + 1]));
                }
            }
            for j in 0..s - 1 {
                for i in 0..s - 1 - j {
                    links.push((index[j][i], index[j + 1][i]));
                }
            }
            for j in 0..s - 1 {
                for i in 0..s - 1 - j {
                    links.push((index[j][i + 1], index[j + 1][i]));
                }
            }
        }
        Topology::Hexagon { rings, fixed } => {
            let s = *rings as i64;
            let spacing = (g.last[0] - g.first[0]) / (2 * s) as f64;
            let centre = [
                (g.first[0] + g.last[0]) / 2.0,
                (g.first[1] + g.last[1]) / 2.0,
                g.first[2],
            ];
            let geometry = |q: i64, r: i64| {
                (
                    spacing * (q as f64 + r as f64 / 2.0),
                    spacing * r as f64 * 3f64.sqrt() / 2.0,
                )
            };
            // Axial coordinates, centre then ring by ring by increasing polar angle from 0 of
            // the regular geometry (unit spacing, so the order and hence the labels do not
            // depend on the box, even a mirrored or flat one).
            let mut axial: Vec<(i64, i64)> = vec![(0, 0)];
            for ring in 1..=s {
                // Distance ≤ ring means r ∈ [max(−ring, −q−ring), min(ring, ring−q)]; the
                // distance is exactly `ring` on the two ends of that range, and all along it
                // for |q| = ring: 6·ring cells.
                let mut cells: Vec<(i64, i64)> = Vec::with_capacity(6 * ring as usize);
                for q in -ring..=ring {
                    let (lo, hi) = ((-ring).max(-q - ring), ring.min(ring - q));
                    if q.abs() == ring {
                        cells.extend((lo..=hi).map(|r| (q, r)));
                    } else {
                        cells.push((q, lo));
                        cells.push((q, hi));
                    }
                }
                let angle = |&(q, r): &(i64, i64)| {
                    let (x, y) = (q as f64 + r as f64 / 2.0, r as f64 * 3f64.sqrt() / 2.0);
                    y.atan2(x).rem_euclid(2.0 * std::f64::consts::PI)
                };
                cells.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
                axial.extend(cells);
            }
            let mut lookup = std::collections::HashMap::new();
            let mut ring_index = vec![0usize; s as usize + 1];
            for (k, &(q, r)) in axial.iter().enumerate() {
                lookup.insert((q, r), k);
                let ring = q.abs().max(r.abs()).max((q + r).abs());
                let within = ring_index[ring as usize];
                ring_index[ring as usize] += 1;
                let (x, y) = geometry(q, r);
                let outer = ring == s;
                let vertex = outer && (q == 0 || r == 0 || q + r == 0);
                nodes.push(Node {
                    suffix: format!("m{ring}_{within}"),
                    pos: [centre[0] + x, centre[1] + y, centre[2]],
                    fixed: match fixed {
                        Fixed::None => false,
                        Fixed::Corners => vertex,
                        Fixed::Borders => outer,
                    },
                });
            }
            for (k, &(q, r)) in axial.iter().enumerate() {
                for n in [(q + 1, r), (q, r + 1), (q - 1, r + 1)] {
                    if let Some(&other) = lookup.get(&n) {
                        links.push((k, other));
                    }
                }
            }
        }
        Topology::Ring { nodes: n, radius } => {
            if !radius.is_finite() {
                return Err(GeneratorError::InvalidValue {
                    what: "radius",
                    value: *radius,
                });
            }
            for k in 0..*n {
                let a = 2.0 * std::f64::consts::PI * k as f64 / *n as f64;
                nodes.push(Node {
                    suffix: format!("m{k}"),
                    pos: [
                        g.first[0] + radius * a.cos(),
                        g.first[1] + radius * a.sin(),
                        g.first[2],
                    ],
                    fixed: false,
                });
            }
            links.extend((0..*n).map(|k| (k, (k + 1) % n)));
        }
        Topology::Lattice {
            size,
            span,
            diagonals,
            fixed,
        } => {
            let [nx, ny, nz] = *size;
            let id = |x: usize, y: usize, z: usize| (x * ny + y) * nz + z;
            for x in 0..nx {
                for y in 0..ny {
                    for z in 0..nz {
                        let c = [x, y, z];
                        let on_low = |a: usize| c[a] == 0;
                        let on_high = |a: usize| c[a] + 1 == size[a];
                        let is_fixed = match fixed {
                            LatticeFixed::None => false,
                            LatticeFixed::Corners => (0..3).all(|a| on_low(a) || on_high(a)),
                            LatticeFixed::Borders => (0..3).any(|a| on_low(a) || on_high(a)),
                            LatticeFixed::Face { axis, high } => {
                                let a = (*axis as usize).min(2);
                                if *high {
                                    on_high(a)
                                } else {
                                    on_low(a)
                                }
                            }
                            LatticeFixed::Centre => (0..3).all(|a| c[a] == size[a] / 2),
                        };
                        nodes.push(Node {
                            suffix: format!("m{x}_{y}_{z}"),
                            pos: box_point(g, [frac(x, nx), frac(y, ny), frac(z, nz)]),
                            fixed: is_fixed,
                        });
                    }
                }
            }
            let offsets = lattice_offsets(*size, *span, *diagonals);
            for x in 0..nx as i64 {
                for y in 0..ny as i64 {
                    for z in 0..nz as i64 {
                        for d in &offsets {
                            let (x2, y2, z2) = (x + d[0], y + d[1], z + d[2]);
                            if (0..nx as i64).contains(&x2)
                                && (0..ny as i64).contains(&y2)
                                && (0..nz as i64).contains(&z2)
                            {
                                links.push((
                                    id(x as usize, y as usize, z as usize),
                                    id(x2 as usize, y2 as usize, z2 as usize),
                                ));
                            }
                        }
                    }
                }
            }
        }
        Topology::Polyline { points, closed } => {
            if let Some(&(x, y)) = points
                .iter()
                .find(|(x, y)| !x.is_finite() || !y.is_finite())
            {
                return Err(GeneratorError::InvalidValue {
                    what: "polyline point",
                    value: if x.is_finite() { y } else { x },
                });
            }
            let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
            for &(x, y) in points {
                lo = [lo[0].min(x), lo[1].min(y)];
                hi = [hi[0].max(x), hi[1].max(y)];
            }
            let unit = |v: f64, a: usize| {
                if hi[a] > lo[a] {
                    (v - lo[a]) / (hi[a] - lo[a])
                } else {
                    0.0
                }
            };
            for (k, &(x, y)) in points.iter().enumerate() {
                let (tx, ty) = (unit(x, 0), unit(y, 1));
                nodes.push(Node {
                    suffix: format!("m{k}"),
                    pos: box_point(g, [tx, ty, tx]),
                    fixed: false,
                });
            }
            let n = points.len();
            links.extend((0..n - 1).map(|k| (k, k + 1)));
            if *closed && n > 2 {
                links.push((n - 1, 0));
            }
        }
    }
    Ok((nodes, links, stiff))
}

/// The labels of a laid-out structure (spec §4 naming).
fn labels(
    name: &str,
    topology: &Topology,
    nodes: &[Node],
    links: &[(usize, usize)],
    stiff: &[(usize, usize)],
) -> Generated {
    let p = |suffix: &str| format!("{name}_{suffix}");
    let mut params = vec![p("M"), p("K"), p("Z"), p("Zo")];
    if matches!(topology, Topology::StiffString { .. }) {
        params.push(p("Ks"));
    }
    let pairs: Vec<(usize, usize)> = links.iter().chain(stiff).copied().collect();
    Generated {
        nodes: nodes.iter().map(|n| p(&n.suffix)).collect(),
        fixed: nodes.iter().map(|n| n.fixed).collect(),
        links: (0..pairs.len()).map(|r| p(&format!("r{r}"))).collect(),
        pairs,
        params,
    }
}

/// Declares the parameters and appends the elements: nodes in order, then the (K, Z) links,
/// then the undamped stiffness links (the pairs from index `num_damped` on).
fn emit(b: &mut ModelBuilder, g: &Generator, nodes: &[Node], out: &Generated, num_damped: usize) {
    let p = |suffix: &str| format!("{}_{suffix}", g.name);
    for (param, value) in out.params.iter().zip([g.m, g.k, g.z, g.zo, g.ks]) {
        b.param(param, value);
    }
    for (node, label) in nodes.iter().zip(&out.nodes) {
        let pos = Vector::Xyz(Box::new(node.pos.map(Expr::Num)));
        if node.fixed {
            b.ground(label, pos);
        } else if g.zo == 0.0 {
            b.mass(label, Expr::param(&p("M")), pos, 0.0);
        } else {
            b.osc(
                label,
                Expr::param(&p("M")),
                0.0,
                Expr::param(&p("Zo")),
                pos,
                0.0,
            );
        }
    }
    for (r, (&(a, bb), label)) in out.pairs.iter().zip(&out.links).enumerate() {
        let (k, z) = if r >= num_damped {
            (Expr::param(&p("Ks")), Expr::Num(0.0))
        } else {
            (Expr::param(&p("K")), Expr::param(&p("Z")))
        };
        b.spring_damper(
            label,
            Endpoint::label(&out.nodes[a]),
            Endpoint::label(&out.nodes[bb]),
            k,
            z,
        );
    }
}
