//! The `~generate` directive: every topology generator of spec §4 from a script, with node
//! counts, link counts, fixed nodes and connectivity checked against §4 and against the Rust
//! API (`ressort_engine::generators`), the §4.1 equivalence with the `string` macro, addressable
//! nodes, generated parameters and the printer round trip.

mod common;

use common::{clean_spec, engine, impulse, render};
use ressort_engine::generators::{generate, Fixed, Generator, LatticeFixed, Topology};
use ressort_engine::lang::{parse, print};
use ressort_engine::{ElementKind, Endpoint, Expr, LawKind, ModelBuilder, ModelSpec, Vector};
use std::collections::{HashMap, HashSet};

/// The generated structure as found in a parsed spec: nodes (with fixedness and position) and
/// links (node index pairs, and whether the link is an undamped `Ks` stiffness link).
struct Graph {
    nodes: Vec<String>,
    fixed: Vec<bool>,
    pos: Vec<[f64; 3]>,
    links: Vec<(usize, usize)>,
    stiff: Vec<bool>,
}

impl Graph {
    fn of(spec: &ModelSpec, name: &str) -> Graph {
        let prefix = format!("{name}_");
        let mut g = Graph {
            nodes: Vec::new(),
            fixed: Vec::new(),
            pos: Vec::new(),
            links: Vec::new(),
            stiff: Vec::new(),
        };
        let xyz = |v: &Vector| match v {
            Vector::Xyz(c) => (**c).clone().map(|e| e.as_number().unwrap()),
            Vector::Scalar(z) => [0.0, 0.0, z.as_number().unwrap()],
        };
        let mut index = HashMap::new();
        for e in spec
            .elements
            .iter()
            .filter(|e| e.label.starts_with(&prefix))
        {
            let (fixed, pos) = match &e.kind {
                ElementKind::Ground { pos } => (true, pos),
                ElementKind::Mass { m, pos, vel, .. } => {
                    assert_eq!(m, &Expr::param(&format!("{name}_M")));
                    assert_eq!(vel, &Vector::from(0.0));
                    (false, pos)
                }
                ElementKind::Osc { m, k, z, pos, .. } => {
                    assert_eq!(m, &Expr::param(&format!("{name}_M")));
                    assert_eq!(k, &Expr::Num(0.0));
                    assert_eq!(z, &Expr::param(&format!("{name}_Zo")));
                    (false, pos)
                }
                _ => continue,
            };
            index.insert(e.label.clone(), g.nodes.len());
            g.nodes.push(e.label.to_string());
            g.fixed.push(fixed);
            g.pos.push(xyz(pos));
        }
        for e in spec
            .elements
            .iter()
            .filter(|e| e.label.starts_with(&prefix))
        {
            let ElementKind::Interaction { law, a, b } = &e.kind else {
                continue;
            };
            let (LawKind::SpringDamper, [k, z]) = (law.kind(), law.args()) else {
                panic!("{}: links are springDampers", e.label);
            };
            let stiff = k == &Expr::param(&format!("{name}_Ks"));
            if stiff {
                assert_eq!(z, &Expr::Num(0.0), "stiffness links are undamped");
            } else {
                assert_eq!(k, &Expr::param(&format!("{name}_K")));
                assert_eq!(z, &Expr::param(&format!("{name}_Z")));
            }
            let at = |ep: &Endpoint| index[ep.target()];
            g.links.push((at(a), at(b)));
            g.stiff.push(stiff);
        }
        g
    }

    fn index(&self, label: &str) -> usize {
        self.nodes
            .iter()
            .position(|n| n == label)
            .unwrap_or_else(|| panic!("no node {label}"))
    }

    fn degree(&self, node: usize) -> usize {
        self.links
            .iter()
            .filter(|(a, b)| *a == node || *b == node)
            .count()
    }

    /// Link pairs as unordered label pairs.
    fn label_pairs(&self) -> HashSet<(String, String)> {
        self.links
            .iter()
            .map(|&(a, b)| {
                let (a, b) = (self.nodes[a].clone(), self.nodes[b].clone());
                if a < b {
                    (a, b)
                } else {
                    (b, a)
                }
            })
            .collect()
    }

    fn connected(&self) -> bool {
        let mut seen = vec![false; self.nodes.len()];
        let mut stack = vec![0];
        seen[0] = true;
        while let Some(n) = stack.pop() {
            for &(a, b) in &self.links {
                for (x, y) in [(a, b), (b, a)] {
                    if x == n && !seen[y] {
                        seen[y] = true;
                        stack.push(y);
                    }
                }
            }
        }
        seen.iter().all(|s| *s)
    }
}

fn pair(a: &str, b: &str) -> (String, String) {
    if a < b {
        (a.to_string(), b.to_string())
    } else {
        (b.to_string(), a.to_string())
    }
}

/// The integer coordinates in a node label `<name>_m<a>_<b>…`.
fn coords(label: &str) -> Vec<i64> {
    let rest = &label[label.rfind("_m").unwrap() + 2..];
    rest.split('_').map(|s| s.parse().unwrap()).collect()
}

/// Parses `directive` (one `~generate` line) and checks it against the Rust API with the same
/// topology and values, against the counts of spec §4, against the compiled model, for
/// connectivity and for the printer round trip. Returns the structure for further checks.
#[track_caller]
fn check(
    directive: &str,
    topology: Topology,
    generator: Generator,
    points: usize,
    links: usize,
    fixed: usize,
) -> Graph {
    let spec = clean_spec(directive);
    let mut b = ModelBuilder::new();
    let out = generate(&mut b, &generator, &topology).unwrap();
    assert_eq!(spec, b.build(), "{directive}: differs from the Rust API");
    let g = Graph::of(&spec, &generator.name);
    assert_eq!(g.nodes, out.nodes, "{directive}: node order");
    assert_eq!(g.links, out.pairs, "{directive}: link pairs");
    assert_eq!(g.nodes.len(), points, "{directive}: points (§4)");
    assert_eq!(g.links.len(), links, "{directive}: links (§4)");
    assert_eq!(
        g.fixed.iter().filter(|f| **f).count(),
        fixed,
        "{directive}: fixed nodes (§4)"
    );
    assert!(g.connected(), "{directive}: not connected");
    let e = engine(&spec, 44_100.0);
    assert_eq!(e.info().num_points, points);
    assert_eq!(e.info().num_interactions, links);
    // Parameters of §4: <name>_M, _K, _Z, _Zo (and _Ks).
    let names: Vec<&str> = spec.params.iter().map(|p| p.name.as_str()).collect();
    let n = &generator.name;
    let mut expected = vec![
        format!("{n}_M"),
        format!("{n}_K"),
        format!("{n}_Z"),
        format!("{n}_Zo"),
    ];
    if matches!(topology, Topology::StiffString { .. }) {
        expected.push(format!("{n}_Ks"));
    }
    assert_eq!(names, expected);
    assert_eq!(
        parse(&print(&spec)).spec,
        Some(spec),
        "{directive}: round trip"
    );
    g
}

fn gen(name: &str, m: f64, k: f64, z: f64, first: [f64; 3], last: [f64; 3]) -> Generator {
    Generator {
        name: name.to_string(),
        m,
        k,
        z,
        zo: 0.0,
        ks: 0.0,
        first,
        last,
    }
}

const BOX: ([f64; 3], [f64; 3]) = ([0.0, 0.0, 0.0], [1.0, 1.0, 0.0]);

#[test]
fn string_generator() {
    // §4.1: n + 2 points (2 end grounds) / n + 1 links; g0–m0, m_k–m_{k+1}, m_{n−1}–g1.
    let mut g = gen("str", 1.0, 0.2, 1e-3, [0.0, 0.5, 0.0], [2.0, 0.5, 0.0]);
    g.zo = 1e-4;
    let s = check(
        "~generate string str nodes=10 M=1 K=0.2 Z=1e-3 Zo=1e-4 from=0,0.5,0 to=2,0.5,0",
        Topology::String { nodes: 10 },
        g,
        12,
        11,
        2,
    );
    let mut expected: HashSet<_> = (0..9)
        .map(|k| pair(&format!("str_m{k}"), &format!("str_m{}", k + 1)))
        .collect();
    expected.insert(pair("str_g0", "str_m0"));
    expected.insert(pair("str_m9", "str_g1"));
    assert_eq!(s.label_pairs(), expected);
    assert!(s.fixed[s.index("str_g0")] && s.fixed[s.index("str_g1")]);
    // Nodes equally spaced over n + 1 intervals between the box ends.
    for (i, p) in s.pos.iter().enumerate() {
        assert!((p[0] - 2.0 * i as f64 / 11.0).abs() < 1e-12, "{p:?}");
        assert_eq!(p[1], 0.5);
    }
}

#[test]
fn stiff_string_generator() {
    // §4.2: n + 2 points / (n + 1) + (n + 2) = 2n + 3 links. Chain numbering 0 = g0,
    // k = m_{k−1}, n+1 = g1: K links (k, k+1); Ks links (0, 1), (k, k+2), (n, n+1).
    let n = 8;
    let mut g = gen("ss", 1.0, 0.2, 1e-3, BOX.0, BOX.1);
    g.ks = 0.05;
    let s = check(
        "~generate stiffString ss nodes=8 M=1 K=0.2 Ks=0.05 Z=1e-3",
        Topology::StiffString { nodes: n },
        g,
        n + 2,
        2 * n + 3,
        2,
    );
    let chain = |k: usize| match k {
        0 => "ss_g0".to_string(),
        k if k == n + 1 => "ss_g1".to_string(),
        k => format!("ss_m{}", k - 1),
    };
    let mut k_links = Vec::new();
    let mut ks_links = Vec::new();
    for (&(a, b), &stiff) in s.links.iter().zip(&s.stiff) {
        let p = pair(&s.nodes[a], &s.nodes[b]);
        if stiff {
            ks_links.push(p);
        } else {
            k_links.push(p);
        }
    }
    let expected_k: Vec<_> = (0..=n).map(|k| pair(&chain(k), &chain(k + 1))).collect();
    let mut expected_ks = vec![pair(&chain(0), &chain(1))];
    expected_ks.extend((0..n).map(|k| pair(&chain(k), &chain(k + 2))));
    expected_ks.push(pair(&chain(n), &chain(n + 1)));
    assert_eq!(k_links, expected_k);
    assert_eq!(ks_links, expected_ks);
}

#[test]
fn chain_generator() {
    // §4.3: n points / n − 1 links, no fixed node.
    let c = check(
        "~generate chain ch nodes=10 M=2 K=0.1 Z=0",
        Topology::Chain { nodes: 10 },
        gen("ch", 2.0, 0.1, 0.0, BOX.0, BOX.1),
        10,
        9,
        0,
    );
    let expected: HashSet<_> = (0..9)
        .map(|k| pair(&format!("ch_m{k}"), &format!("ch_m{}", k + 1)))
        .collect();
    assert_eq!(c.label_pairs(), expected);
}

#[test]
fn mesh_generator() {
    // §4.4: L·W points / L(W−1) + (L−1)W links; fixed none 0, corners 4, borders 2(L+W) − 4.
    let (l, w) = (7usize, 5usize);
    let links = l * (w - 1) + (l - 1) * w;
    for (word, fixed, count) in [
        ("none", Fixed::None, 0),
        ("corners", Fixed::Corners, 4),
        ("borders", Fixed::Borders, 2 * (l + w) - 4),
    ] {
        let m = check(
            &format!("~generate mesh me size=7,5 M=1 K=0.1 Z=0.001 fixed={word} to=3,2,0"),
            Topology::Mesh {
                length: l,
                width: w,
                fixed,
            },
            gen("me", 1.0, 0.1, 0.001, BOX.0, [3.0, 2.0, 0.0]),
            l * w,
            links,
            count,
        );
        // 4-neighbour links (i,j)–(i,j+1) and (i,j)–(i+1,j), every one of them.
        let mut expected = HashSet::new();
        for i in 0..l {
            for j in 0..w {
                if j + 1 < w {
                    expected.insert(pair(&format!("me_m{i}_{j}"), &format!("me_m{i}_{}", j + 1)));
                }
                if i + 1 < l {
                    expected.insert(pair(&format!("me_m{i}_{j}"), &format!("me_m{}_{j}", i + 1)));
                }
            }
        }
        assert_eq!(m.label_pairs(), expected);
        // Fixed nodes are where §4.4 puts them; positions span the box.
        for (k, label) in m.nodes.iter().enumerate() {
            let c = coords(label);
            let (on_i, on_j) = (
                c[0] == 0 || c[0] == l as i64 - 1,
                c[1] == 0 || c[1] == w as i64 - 1,
            );
            let want = match fixed {
                Fixed::None => false,
                Fixed::Corners => on_i && on_j,
                Fixed::Borders => on_i || on_j,
            };
            assert_eq!(m.fixed[k], want, "{label}");
            assert!((m.pos[k][0] - 3.0 * c[0] as f64 / 6.0).abs() < 1e-12);
            assert!((m.pos[k][1] - 2.0 * c[1] as f64 / 4.0).abs() < 1e-12);
        }
    }
}

#[test]
fn triangle_generator() {
    // §4.5: s(s+1)/2 points / 3s(s−1)/2 links; s = 10 gives 55 / 135. Corners 3, borders
    // 3(s−1). Links: rows (j,i)–(j,i+1), diagonals (j,i)–(j+1,i), anti-diagonals
    // (j,i+1)–(j+1,i).
    let s = 10usize;
    for (word, fixed, count) in [
        ("none", Fixed::None, 0),
        ("corners", Fixed::Corners, 3),
        ("borders", Fixed::Borders, 3 * (s - 1)),
    ] {
        let t = check(
            &format!(
                "~generate triangle tri size=10 M=1 K=0.3 Z=1e-4 fixed={word} from=0,0,0 to=1,1,0"
            ),
            Topology::Triangle { size: s, fixed },
            gen("tri", 1.0, 0.3, 1e-4, BOX.0, BOX.1),
            55,
            135,
            count,
        );
        let mut expected = HashSet::new();
        for j in 0..s {
            for i in 0..s - j {
                let n = |j: usize, i: usize| format!("tri_m{j}_{i}");
                if i + 1 < s - j {
                    expected.insert(pair(&n(j, i), &n(j, i + 1)));
                }
                if j + 1 < s && i < s - 1 - j {
                    expected.insert(pair(&n(j, i), &n(j + 1, i)));
                    expected.insert(pair(&n(j, i + 1), &n(j + 1, i)));
                }
            }
        }
        assert_eq!(t.label_pairs(), expected);
        // Interior nodes have 6 neighbours; regular geometry: every link has the same length.
        assert_eq!(t.degree(t.index("tri_m2_2")), 6);
        for &(a, b) in &t.links {
            let d =
                ((t.pos[a][0] - t.pos[b][0]).powi(2) + (t.pos[a][1] - t.pos[b][1]).powi(2)).sqrt();
            assert!((d - 1.0 / 9.0).abs() < 1e-12, "link length {d}");
        }
    }
}

#[test]
fn hexagon_generator() {
    // §4.6: 1 + 3s(s+1) points / 9s² + 3s links; s = 1 gives 7 / 12. Corners 6, borders 6s.
    check(
        "~generate hexagon hx size=1 M=1 K=0.1 Z=0",
        Topology::Hexagon {
            rings: 1,
            fixed: Fixed::None,
        },
        gen("hx", 1.0, 0.1, 0.0, BOX.0, BOX.1),
        7,
        12,
        0,
    );
    for (word, fixed, count) in [
        ("none", Fixed::None, 0),
        ("corners", Fixed::Corners, 6),
        ("borders", Fixed::Borders, 18),
    ] {
        let h = check(
            &format!(
                "~generate hexagon hx size=3 M=1 K=0.1 Z=0 fixed={word} from=-1,-1,0 to=1,1,0"
            ),
            Topology::Hexagon { rings: 3, fixed },
            gen("hx", 1.0, 0.1, 0.0, [-1.0, -1.0, 0.0], [1.0, 1.0, 0.0]),
            37,
            90,
            count,
        );
        // Links join exactly the nodes at lattice distance 1 (spacing 2/(2s) = 1/3), and
        // every such pair is linked: a complete triangulation.
        let spacing = 1.0 / 3.0;
        let dist = |a: usize, b: usize| {
            ((h.pos[a][0] - h.pos[b][0]).powi(2) + (h.pos[a][1] - h.pos[b][1]).powi(2)).sqrt()
        };
        for &(a, b) in &h.links {
            assert!((dist(a, b) - spacing).abs() < 1e-9);
        }
        let mut neighbours = 0;
        for a in 0..h.nodes.len() {
            for b in a + 1..h.nodes.len() {
                if (dist(a, b) - spacing).abs() < 1e-9 {
                    neighbours += 1;
                }
            }
        }
        assert_eq!(neighbours, 90);
        // The centre has 6 neighbours; ring k holds 6k nodes named <name>_m<k>_<index>.
        assert_eq!(h.nodes[0], "hx_m0_0");
        assert_eq!(h.degree(0), 6);
        for k in 1..=3 {
            let ring = h.nodes.iter().filter(|n| coords(n)[0] == k).count();
            assert_eq!(ring, 6 * k as usize);
        }
        // Borders are the outer ring.
        if fixed == Fixed::Borders {
            for (label, f) in h.nodes.iter().zip(&h.fixed) {
                assert_eq!(*f, coords(label)[0] == 3, "{label}");
            }
        }
    }
}

#[test]
fn ring_generator() {
    // §4.7: n points / n links, a closed loop on a circle of radius r about the centre.
    let r = check(
        "~generate ring rg nodes=12 radius=0.5 centre=1,2,0 M=1 K=0.1 Z=0.001",
        Topology::Ring {
            nodes: 12,
            radius: 0.5,
        },
        gen("rg", 1.0, 0.1, 0.001, [1.0, 2.0, 0.0], BOX.1),
        12,
        12,
        0,
    );
    let expected: HashSet<_> = (0..12)
        .map(|k| pair(&format!("rg_m{k}"), &format!("rg_m{}", (k + 1) % 12)))
        .collect();
    assert_eq!(r.label_pairs(), expected);
    for (k, p) in r.pos.iter().enumerate() {
        assert_eq!(r.degree(k), 2);
        let d = ((p[0] - 1.0).powi(2) + (p[1] - 2.0).powi(2)).sqrt();
        assert!((d - 0.5).abs() < 1e-12);
    }
}

#[test]
fn lattice_generator() {
    let size = [2usize, 3, 4];
    let axis = (size[0] - 1) * size[1] * size[2]
        + size[0] * (size[1] - 1) * size[2]
        + size[0] * size[1] * (size[2] - 1);
    let lattice = |span, diagonals, fixed| Topology::Lattice {
        size,
        span,
        diagonals,
        fixed,
    };
    let g = || gen("cu", 1.0, 0.1, 0.001, BOX.0, [1.0, 1.0, 0.0]);
    // §4.8, s = 1 without diagonals: the 6-neighbour lattice.
    let l = check(
        "~generate lattice cu size=2,3,4 M=1 K=0.1 Z=0.001",
        lattice(1, false, LatticeFixed::None),
        g(),
        24,
        axis,
        0,
    );
    for &(a, b) in &l.links {
        let (ca, cb) = (coords(&l.nodes[a]), coords(&l.nodes[b]));
        let diff: Vec<i64> = (0..3).map(|k| (ca[k] - cb[k]).abs()).collect();
        assert_eq!(diff.iter().sum::<i64>(), 1, "{:?} {:?}", ca, cb);
    }
    // `cube` is the same generator.
    assert_eq!(
        parse("~generate cube cu size=2,3,4 M=1 K=0.1 Z=0.001").spec,
        parse("~generate lattice cu size=2,3,4 M=1 K=0.1 Z=0.001").spec
    );
    // Fixed nodes: corners 8, borders N − Π(N_a − 2)+, a face, the centre.
    check(
        "~generate lattice cu size=2,3,4 M=1 K=0.1 Z=0.001 fixed=corners",
        lattice(1, false, LatticeFixed::Corners),
        g(),
        24,
        axis,
        8,
    );
    check(
        "~generate lattice cu size=2,3,4 M=1 K=0.1 Z=0.001 fixed=borders",
        lattice(1, false, LatticeFixed::Borders),
        g(),
        24,
        axis,
        24,
    );
    check(
        "~generate lattice cu size=2,3,4 M=1 K=0.1 Z=0.001 fixed=ymax",
        lattice(
            1,
            false,
            LatticeFixed::Face {
                axis: 1,
                high: true,
            },
        ),
        g(),
        24,
        axis,
        8,
    );
    check(
        "~generate lattice cu size=2,3,4 M=1 K=0.1 Z=0.001 fixed=zmin",
        lattice(
            1,
            false,
            LatticeFixed::Face {
                axis: 2,
                high: false,
            },
        ),
        g(),
        24,
        axis,
        6,
    );
    check(
        "~generate lattice cu size=2,3,4 M=1 K=0.1 Z=0.001 fixed=centre",
        lattice(1, false, LatticeFixed::Centre),
        g(),
        24,
        axis,
        1,
    );
    // Span 2 without diagonals: Σ_a Σ_{d=1..s} (N_a − d)+ Π_{b≠a} N_b.
    let span2: usize = (0..3)
        .map(|a| {
            let others: usize = (0..3).filter(|b| *b != a).map(|b| size[b]).product();
            (1..=2).map(|d| size[a].saturating_sub(d)).sum::<usize>() * others
        })
        .sum();
    check(
        "~generate lattice cu size=2,3,4 M=1 K=0.1 Z=0.001 span=2",
        lattice(2, false, LatticeFixed::None),
        g(),
        24,
        span2,
        0,
    );
    // Diagonals: every pair within Chebyshev distance s, counted by brute force.
    for span in [1usize, 2] {
        let cells: Vec<[i64; 3]> = (0..2)
            .flat_map(|x| (0..3).flat_map(move |y| (0..4).map(move |z| [x, y, z])))
            .collect();
        let cheb = cells
            .iter()
            .enumerate()
            .flat_map(|(i, a)| cells[i + 1..].iter().map(move |b| (a, b)))
            .filter(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).max().unwrap() <= span as i64)
            .count();
        check(
            &format!("~generate lattice cu size=2,3,4 M=1 K=0.1 Z=0.001 span={span} diagonals=on"),
            lattice(span, true, LatticeFixed::None),
            g(),
            24,
            cheb,
            0,
        );
    }
}

#[test]
fn polyline_generator() {
    // §4.9: n points / n links closed (the default, as the original), n − 1 open. The points
    // are rescaled into the box.
    let pts = vec![(0.0, 0.0), (4.0, 0.0), (4.0, 2.0), (0.0, 2.0)];
    let g = || gen("pl", 1.0, 0.1, 0.001, BOX.0, [2.0, 1.0, 0.0]);
    let closed = check(
        "~generate polyline pl points=0,0;4,0;4,2;0,2 M=1 K=0.1 Z=0.001 to=2,1,0",
        Topology::Polyline {
            points: pts.clone(),
            closed: true,
        },
        g(),
        4,
        4,
        0,
    );
    assert!(closed.label_pairs().contains(&pair("pl_m3", "pl_m0")));
    assert_eq!(closed.pos[2][..2], [2.0, 1.0]);
    let open = check(
        "~generate polyline pl points=0,0;4,0;4,2;0,2 closed=off M=1 K=0.1 Z=0.001 to=2,1,0",
        Topology::Polyline {
            points: pts,
            closed: false,
        },
        g(),
        4,
        3,
        0,
    );
    assert!(!open.label_pairs().contains(&pair("pl_m3", "pl_m0")));
}

/// Spec §4.1: a generated string of n nodes has the dynamics of the macro `string (n+2)` with
/// the same M, K, Z, Zo. Excited and observed at nodes the macro reaches exactly (α = k/(N−1)
/// with a power-of-two denominator), the two agree to rounding at every sample; likewise the
/// stiff string (§4.2) and the pinned meshes (§4.4).
#[test]
fn generated_string_equals_the_string_macro() {
    let cases = [
        (
            "~generate string s nodes=7 M=1 K=0.3 Z=0.001 Zo=1e-4\n\
             @in1 frcInput @s_m3\n@out1 posOutput @s_m1\n@out2 posOutput @s_m5\n",
            "@s string 9 1 0.3 0.001 1e-4 0 0\n\
             @in1 frcInput [@s 0.5]\n@out1 posOutput [@s 0.25]\n@out2 posOutput [@s 0.75]\n",
        ),
        (
            "~generate string s nodes=15 M=1 K=0.2 Z=0.0005\n\
             @in1 frcInput @s_m1\n@out1 posOutput @s_m11\n",
            "@s string 17 1 0.2 0.0005 0 0\n\
             @in1 frcInput [@s 0.125]\n@out1 posOutput [@s 0.75]\n",
        ),
        (
            "~generate stiffString s nodes=7 M=1 K=0.2 Ks=0.05 Z=0.001\n\
             @in1 frcInput @s_m3\n@out1 posOutput @s_m1\n",
            "@s stiffString 9 1 0.2 0.05 0.001 0 0\n\
             @in1 frcInput [@s 0.5]\n@out1 posOutput [@s 0.25]\n",
        ),
        (
            "~generate mesh s size=5,5 M=1 K=0.1 Z=0.001 fixed=corners\n\
             @in1 frcInput @s_m2_1\n@out1 posOutput @s_m1_3\n",
            "@s cornerMesh 5 5 1 0.1 0.001 0 0\n\
             @in1 frcInput [@s 0.5 0.25]\n@out1 posOutput [@s 0.25 0.75]\n",
        ),
        (
            "~generate mesh s size=5,5 M=1 K=0.1 Z=0.001 Zo=2e-4 fixed=borders\n\
             @in1 frcInput @s_m2_1\n@out1 posOutput @s_m1_3\n",
            "@s closedMesh 5 5 1 0.1 0.001 2e-4 0 0\n\
             @in1 frcInput [@s 0.5 0.25]\n@out1 posOutput [@s 0.25 0.75]\n",
        ),
    ];
    for (generated, macro_text) in cases {
        for sr in [44_100.0, 96_000.0] {
            let input = [impulse(0.01, 4000)];
            let a = render(&mut engine(&clean_spec(generated), sr), 4000, 64, &input);
            let m = render(&mut engine(&clean_spec(macro_text), sr), 4000, 64, &input);
            for (ch, (x, y)) in a.iter().zip(&m).enumerate() {
                let peak = x.iter().fold(0.0f64, |p, v| p.max(v.abs()));
                assert!(peak > 1e-6, "{generated}: channel {ch} silent");
                for (i, (u, v)) in x.iter().zip(y).enumerate() {
                    assert!(
                        (u - v).abs() <= 1e-12 * peak,
                        "{generated} at {sr} Hz: out{} sample {i}: generated {u} vs macro {v}",
                        ch + 1
                    );
                }
            }
        }
    }
}

/// Generated nodes are ordinary labels: later lines (and earlier ones, names resolve over the
/// whole script) address them as endpoints and output targets; generated points join the open
/// buffer scopes with the generator's x/y; the generated parameters are real parameters.
#[test]
fn generated_nodes_are_addressable() {
    let text = "\
@hM param 1
@kStr param 0.2
@out3 posOutput @late_m0
~begin strings
~generate string str nodes=20 M=1 K=kStr Z=[kStr / 200] from=0,0,0 to=2,0,0
~end strings
@in1 posInput 0.1
@p nlPluck @str_m10 @in1 0.5 0.1
@out1 posOutput @str_m5
~begin plate
~generate triangle tri size=5 M=hM K=0.3 Z=1e-4 fixed=corners
@c springDamper @tri_m0_2 @str_m19 [tri_K / 10] 0
@out2 posOutput @tri_m3_1
~end plate
~generate chain late nodes=3 M=1 K=0.1 Z=0
@l springDamper @late_m2 @str_g1 0.01 0
";
    let spec = clean_spec(text);
    // Values are evaluated once, from parameters declared above.
    let value = |n: &str| match spec.param(n).unwrap().kind {
        ressort_engine::ParamKind::Control { value } => value,
        _ => panic!(),
    };
    assert_eq!(value("str_K"), 0.2);
    assert_eq!(value("str_Z"), 0.001);
    assert_eq!(value("tri_M"), 1.0);
    // Endpoints name generated nodes.
    let ElementKind::Interaction { a, .. } = &spec.element("p").unwrap().kind else {
        panic!()
    };
    assert_eq!(a, &Endpoint::label("str_m10"));
    let e = engine(&spec, 48_000.0);
    let info = e.info();
    // 22 + 15 + 3 generated points and the avatar.
    assert_eq!(info.num_points, 22 + 15 + 3 + 1);
    // Buffer scopes hold the generated points, with the generator's x/y.
    let strings = info.motion.named("strings").unwrap();
    assert_eq!(strings.members.len(), 22);
    let xs: Vec<f64> = strings
        .members
        .iter()
        .map(|&m| info.motion.x[m as usize])
        .collect();
    for (i, x) in xs.iter().enumerate() {
        assert!((x - 2.0 * i as f64 / 21.0).abs() < 1e-12);
    }
    assert_eq!(info.motion.named("plate").unwrap().members.len(), 15);
    // Outputs on generated nodes, all three.
    assert_eq!(info.num_outputs(), 3);
    // The generated parameters are controllable: a stiffer string sounds different.
    let mut input = vec![0.0; 2000];
    for (n, v) in input.iter_mut().enumerate() {
        *v = 0.1 - 0.2 * n as f64 / 2000.0; // the plectrum sweeps down through the string
    }
    let run = |k: Option<f64>| {
        let mut e = engine(&spec, 48_000.0);
        if let Some(k) = k {
            let id = e.param_id("str_K").unwrap();
            e.set_param(id, k).unwrap();
        }
        render(&mut e, 2000, 64, &[input.clone()])
    };
    let base = run(None);
    let stiffer = run(Some(0.4));
    assert!(
        base[0].iter().any(|v| v.abs() > 1e-6),
        "the pluck moves the string"
    );
    assert_ne!(base[0], stiffer[0]);
}

/// The printer writes the expanded elements and their parameters; the text parses back to the
/// same model, including buffer scopes and x/y (spec §3, round trip).
#[test]
fn printed_generators_round_trip() {
    let text = "\
@k param 0.25
~begin a
~generate hexagon h size=2 M=[1 + k] K=k Z=1e-4 Zo=1e-5 fixed=corners from=[-1 -1 0] to=[1 1 0]
~begin b
~generate ring r nodes=5 radius=2.5 centre=0,0,0.1 M=1 K=0.1 Z=0
~end a
~generate polyline p points=0,0;1,0.5;2,-1 closed=off M=1 K=0.1 Z=0
@c springDamper @h_m2_0 @r_m4 0.1 0
";
    let spec = clean_spec(text);
    let printed = print(&spec);
    assert!(printed.contains("@h_M param 1.25\n"), "{printed}");
    assert!(
        printed.contains("@h_m0_0 osc h_M 0 h_Zo [0 0 0]"),
        "{printed}"
    );
    let again = parse(&printed);
    assert!(again.diagnostics.is_empty(), "{:#?}", again.diagnostics);
    assert_eq!(again.spec.as_ref(), Some(&spec));
    assert_eq!(print(again.spec.as_ref().unwrap()), printed);
    let h = spec.element("h_m0_0").unwrap();
    let r = spec.element("r_m0").unwrap();
    let p = spec.element("p_m0").unwrap();
    let name = |e: &ressort_engine::Element| -> Vec<&str> {
        e.buffers
            .iter()
            .map(|&b| spec.buffers[b as usize].as_str())
            .collect()
    };
    assert_eq!(name(h), ["a"]);
    assert_eq!(name(r), ["a", "b"]);
    assert_eq!(name(p), ["b"]);
}

/// A directive with an error creates nothing, and references to its labels are not reported
/// a second time.
#[test]
fn errors_do_not_cascade() {
    for bad in [
        "~generate string s nodes=0 M=1 K=0.1 Z=0",
        "~generate strin s nodes=3 M=1 K=0.1 Z=0",
        "~generate string s nodes=[3 M=1 K=0.1 Z=0",
        "~generate string s nodes=3 M=1 K=0.1 Z=0 span=2",
        "~generate string s nodes=3 M=1 K=0.1",
    ] {
        let text = format!("{bad}\n@out1 posOutput @s_m1\n@c spring @s_m0 @s_g1 s_K\n");
        let p = parse(&text);
        assert_eq!(p.diagnostics.len(), 1, "{text}\n{:#?}", p.diagnostics);
        assert!(p.spec.is_none());
    }
}
