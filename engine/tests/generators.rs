//! Topology generators (spec §4): node counts, link counts, fixed nodes and connectivity, and
//! equivalence with the macros they expand.

mod common;

use common::{engine, impulse, render};
use ressort_engine::generators::{
    generate, Fixed, Generated, Generator, GeneratorError, LatticeFixed, Topology,
};
use ressort_engine::{Endpoint, MacroKind, MacroSpec, ModelBuilder};

fn gen(t: Topology) -> (Generated, ressort_engine::ModelSpec) {
    let mut b = ModelBuilder::new();
    let mut g = Generator::new("t");
    g.ks = 0.05;
    let out = generate(&mut b, &g, &t).unwrap();
    (out, b.build())
}

/// Checks points, links and fixed nodes, that the model compiles with those counts, that every
/// node is reachable from node 0, and that no pair is linked twice.
#[track_caller]
fn check(t: Topology, points: usize, links: usize, fixed: usize) -> Generated {
    let (out, spec) = gen(t.clone());
    assert_eq!(out.nodes.len(), points, "{t:?}: points");
    assert_eq!(out.links.len(), links, "{t:?}: links");
    assert_eq!(out.num_fixed(), fixed, "{t:?}: fixed nodes");
    let e = engine(&spec, 44_100.0);
    assert_eq!(e.info().num_points, points);
    assert_eq!(e.info().num_interactions, links);
    let mut seen = vec![false; points];
    let mut stack = vec![0];
    seen[0] = true;
    while let Some(n) = stack.pop() {
        for &(a, b) in &out.pairs {
            for (x, y) in [(a, b), (b, a)] {
                if x == n && !seen[y] {
                    seen[y] = true;
                    stack.push(y);
                }
            }
        }
    }
    assert!(seen.iter().all(|s| *s), "{t:?}: not connected");
    let mut pairs: Vec<(usize, usize)> = out
        .pairs
        .iter()
        .map(|&(a, b)| (a.min(b), a.max(b)))
        .collect();
    pairs.sort();
    let before = pairs.len();
    pairs.dedup();
    // The stiff string's end segments carry a K and a K₂ link on purpose (spec §4.2).
    if !matches!(t, Topology::StiffString { .. }) {
        assert_eq!(pairs.len(), before, "{t:?}: a pair is linked twice");
    }
    out
}

fn degree(out: &Generated, node: usize) -> usize {
    out.pairs
        .iter()
        .filter(|(a, b)| *a == node || *b == node)
        .count()
}

#[test]
fn one_dimensional_counts() {
    // String: n + 2 points / n + 1 links; stiff string 2n + 3 links; chain n / n − 1.
    let s = check(Topology::String { nodes: 10 }, 12, 11, 2);
    assert_eq!(s.nodes[0], "t_g0");
    assert_eq!(s.nodes[1], "t_m0");
    assert_eq!(s.nodes[11], "t_g1");
    check(Topology::StiffString { nodes: 10 }, 12, 23, 2);
    check(Topology::Chain { nodes: 10 }, 10, 9, 0);
    check(
        Topology::Ring {
            nodes: 12,
            radius: 0.5,
        },
        12,
        12,
        0,
    );
    let pts = vec![(0.0, 0.0), (1.0, 0.0), (1.0, 2.0), (0.0, 1.0)];
    check(
        Topology::Polyline {
            points: pts.clone(),
            closed: true,
        },
        4,
        4,
        0,
    );
    check(
        Topology::Polyline {
            points: pts,
            closed: false,
        },
        4,
        3,
        0,
    );
}

#[test]
fn mesh_counts_and_pinning() {
    let (l, w) = (7, 5);
    let links = l * (w - 1) + (l - 1) * w;
    let none = check(
        Topology::Mesh {
            length: l,
            width: w,
            fixed: Fixed::None,
        },
        35,
        links,
        0,
    );
    check(
        Topology::Mesh {
            length: l,
            width: w,
            fixed: Fixed::Corners,
        },
        35,
        links,
        4,
    );
    check(
        Topology::Mesh {
            length: l,
            width: w,
            fixed: Fixed::Borders,
        },
        35,
        links,
        2 * (l + w) - 4,
    );
    // Interior nodes have 4 neighbours; node (i, j) is named t_m<i>_<j>.
    assert_eq!(degree(&none, 2 * w + 2), 4);
    assert_eq!(none.nodes[2 * w + 3], "t_m2_3");
}

#[test]
fn triangle_counts() {
    // s = 10: 55 points / 135 links (spec §4.5); corners 3, borders 3(s − 1).
    let t = check(
        Topology::Triangle {
            size: 10,
            fixed: Fixed::None,
        },
        55,
        135,
        0,
    );
    check(
        Topology::Triangle {
            size: 10,
            fixed: Fixed::Corners,
        },
        55,
        135,
        3,
    );
    check(
        Topology::Triangle {
            size: 10,
            fixed: Fixed::Borders,
        },
        55,
        135,
        27,
    );
    // An interior node of a triangular lattice has 6 neighbours: row 2, i = 2.
    let idx = t.nodes.iter().position(|n| n == "t_m2_2").unwrap();
    assert_eq!(degree(&t, idx), 6);
}

#[test]
fn hexagon_counts() {
    // 1 + 3s(s+1) points / 9s² + 3s links; corners 6; borders 6s.
    check(
        Topology::Hexagon {
            rings: 1,
            fixed: Fixed::None,
        },
        7,
        12,
        0,
    );
    let h = check(
        Topology::Hexagon {
            rings: 3,
            fixed: Fixed::None,
        },
        37,
        90,
        0,
    );
    check(
        Topology::Hexagon {
            rings: 3,
            fixed: Fixed::Corners,
        },
        37,
        90,
        6,
    );
    check(
        Topology::Hexagon {
            rings: 3,
            fixed: Fixed::Borders,
        },
        37,
        90,
        18,
    );
    // The centre has 6 neighbours; ring 1 starts at polar angle 0.
    assert_eq!(degree(&h, 0), 6);
    assert_eq!(h.nodes[0], "t_m0_0");
    assert_eq!(h.nodes[1], "t_m1_0");
}

#[test]
fn lattice_counts() {
    // Without diagonals and span 1: (Nx−1)NyNz + Nx(Ny−1)Nz + NxNy(Nz−1).
    let size = [2usize, 3, 4];
    // (Nx−1)·Ny·Nz + Nx·(Ny−1)·Nz + Nx·Ny·(Nz−1) with (2, 3, 4).
    let axis = 3 * 4 + 2 * 2 * 4 + 2 * 3 * 3;
    let corners = 8;
    // N − (Nx−2)+(Ny−2)+(Nz−2)+ = 24 − 0: with Nx = 2 every node is on the boundary.
    let borders = 24;
    check(
        Topology::Lattice {
            size,
            span: 1,
            diagonals: false,
            fixed: LatticeFixed::None,
        },
        24,
        axis,
        0,
    );
    check(
        Topology::Lattice {
            size,
            span: 1,
            diagonals: false,
            fixed: LatticeFixed::Corners,
        },
        24,
        axis,
        corners,
    );
    check(
        Topology::Lattice {
            size,
            span: 1,
            diagonals: false,
            fixed: LatticeFixed::Borders,
        },
        24,
        axis,
        borders,
    );
    // Span 2 without diagonals: Σ_a Σ_d (N_a − d)+ Π_{b≠a} N_b.
    let span2: usize = (0..3)
        .map(|a| {
            let others: usize = (0..3).filter(|b| *b != a).map(|b| size[b]).product();
            (1..=2).map(|d| size[a].saturating_sub(d)).sum::<usize>() * others
        })
        .sum();
    check(
        Topology::Lattice {
            size,
            span: 2,
            diagonals: false,
            fixed: LatticeFixed::None,
        },
        24,
        span2,
        0,
    );
    // With diagonals: every pair within Chebyshev distance s, counted by brute force.
    let size = [3usize, 4, 3];
    let coords: Vec<[i64; 3]> = (0..3)
        .flat_map(|x| (0..4).flat_map(move |y| (0..3).map(move |z| [x, y, z])))
        .collect();
    let cheb = coords
        .iter()
        .enumerate()
        .flat_map(|(i, a)| coords[i + 1..].iter().map(move |b| (a, b)))
        .filter(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).max().unwrap() <= 1)
        .count();
    check(
        Topology::Lattice {
            size,
            span: 1,
            diagonals: true,
            fixed: LatticeFixed::None,
        },
        36,
        cheb,
        0,
    );
    // Faces and centre.
    check(
        Topology::Lattice {
            size,
            span: 1,
            diagonals: false,
            fixed: LatticeFixed::Face {
                axis: 1,
                high: true,
            },
        },
        36,
        (2 * 4 * 3) + (3 * 3 * 3) + (3 * 4 * 2),
        9,
    );
    check(
        Topology::Lattice {
            size,
            span: 1,
            diagonals: false,
            fixed: LatticeFixed::Centre,
        },
        36,
        (2 * 4 * 3) + (3 * 3 * 3) + (3 * 4 * 2),
        1,
    );
}

#[test]
fn bad_sizes_are_errors() {
    let mut b = ModelBuilder::new();
    let g = Generator::new("x");
    assert!(matches!(
        generate(
            &mut b,
            &g,
            &Topology::Ring {
                nodes: 2,
                radius: 1.0
            }
        ),
        Err(GeneratorError::TooSmall { .. })
    ));
    assert!(matches!(
        generate(
            &mut b,
            &g,
            &Topology::Mesh {
                length: 100_000,
                width: 100_000,
                fixed: Fixed::None
            }
        ),
        Err(GeneratorError::TooLarge { .. })
    ));
    let mut bad = Generator::new("x");
    bad.m = 0.0;
    assert!(generate(&mut b, &bad, &Topology::Chain { nodes: 4 }).is_err());
}

/// Renders a generated string/mesh and the macro it mirrors with the same force input and
/// listening node, and compares them (spec §4.1, §4.2, §4.4 equivalences).
#[test]
fn generated_structures_equal_their_macros() {
    let cases: Vec<(Topology, MacroKind, u32, u32)> = vec![
        (Topology::String { nodes: 20 }, MacroKind::String, 22, 1),
        (
            Topology::StiffString { nodes: 20 },
            MacroKind::StiffString,
            22,
            1,
        ),
        (Topology::Chain { nodes: 20 }, MacroKind::Chain, 20, 1),
        (
            Topology::Mesh {
                length: 6,
                width: 5,
                fixed: Fixed::Borders,
            },
            MacroKind::ClosedMesh,
            6,
            5,
        ),
        (
            Topology::Mesh {
                length: 6,
                width: 5,
                fixed: Fixed::Corners,
            },
            MacroKind::CornerMesh,
            6,
            5,
        ),
    ];
    for (topology, kind, length, width) in cases {
        let mut g = Generator::new("t");
        g.k = 0.3;
        g.ks = 0.1;
        g.zo = 1e-4;
        g.first = [0.0, 0.0, 0.0];
        g.last = [1.0, 1.0, 0.0];
        let n = (length * width) as usize;
        // Interior nodes, so that no case strikes or listens at a pinned node.
        let (hit, listen) = if kind.is_2d() {
            (2 * width as usize + 2, 3 * width as usize + 1)
        } else {
            (3usize, n - 3)
        };

        let mut b = ModelBuilder::new();
        let out = generate(&mut b, &g, &topology).unwrap();
        b.frc_input(1, Endpoint::label(&out.nodes[hit]));
        b.pos_output(1, Endpoint::label(&out.nodes[listen]));
        let generated = b.build();

        let mut b = ModelBuilder::new();
        b.macro_spec(
            "s",
            MacroSpec {
                kind,
                length,
                width,
                m: 1.0.into(),
                k: 0.3.into(),
                k2: (kind == MacroKind::StiffString).then(|| 0.1.into()),
                z: 0.001.into(),
                zo: 1e-4.into(),
                pos: 0.0.into(),
                vel: 0.0.into(),
            },
        );
        let at = |node: usize| {
            if kind.is_2d() {
                let (i, j) = (node / width as usize, node % width as usize);
                Endpoint::at2(
                    "s",
                    i as f64 / (length - 1) as f64,
                    j as f64 / (width - 1) as f64,
                )
            } else {
                Endpoint::at("s", node as f64 / (length - 1) as f64)
            }
        };
        b.frc_input(1, at(hit));
        b.pos_output(1, at(listen));
        let macro_model = b.build();

        let input = [impulse(0.01, 3000)];
        let a = render(&mut engine(&generated, 44_100.0), 3000, 128, &input);
        let m = render(&mut engine(&macro_model, 44_100.0), 3000, 128, &input);
        let peak = a[0].iter().fold(0.0f64, |p, v| p.max(v.abs()));
        assert!(peak > 1e-6, "{topology:?}: silent");
        for (i, (x, y)) in a[0].iter().zip(&m[0]).enumerate() {
            assert!(
                (x - y).abs() <= 1e-12 * peak,
                "{topology:?}: sample {i}: generated {x} vs macro {y}"
            );
        }
    }
}

/// `Topology::counts` and `plan` agree with what `generate` builds, so callers can refuse a
/// request before anything is allocated.
#[test]
fn counts_and_plan_match_generate() {
    let topologies = vec![
        Topology::String { nodes: 7 },
        Topology::StiffString { nodes: 7 },
        Topology::Chain { nodes: 7 },
        Topology::Mesh {
            length: 4,
            width: 3,
            fixed: Fixed::Corners,
        },
        Topology::Triangle {
            size: 5,
            fixed: Fixed::Borders,
        },
        Topology::Hexagon {
            rings: 4,
            fixed: Fixed::None,
        },
        Topology::Ring {
            nodes: 9,
            radius: 2.0,
        },
        Topology::Lattice {
            size: [3, 4, 2],
            span: 2,
            diagonals: true,
            fixed: LatticeFixed::None,
        },
        Topology::Lattice {
            size: [3, 1, 5],
            span: 9,
            diagonals: false,
            fixed: LatticeFixed::Centre,
        },
        Topology::Polyline {
            points: vec![(0.0, 0.0), (1.0, 0.0), (0.5, 1.0)],
            closed: true,
        },
    ];
    for t in topologies {
        let (out, spec) = gen(t.clone());
        assert_eq!(
            t.counts().unwrap(),
            (out.nodes.len(), out.links.len()),
            "{t:?}"
        );
        assert_eq!(
            ressort_engine::generators::plan("t", &t).unwrap(),
            out,
            "{t:?}"
        );
        assert_eq!(spec.params.len(), out.params.len());
        for (p, name) in spec.params.iter().zip(&out.params) {
            assert_eq!(&p.name, name);
        }
    }
}

#[test]
fn absurd_requests_fail_fast() {
    use std::time::Instant;
    let start = Instant::now();
    // A wide span is clamped to the lattice's extent; too many links is refused up front.
    let t = Topology::Lattice {
        size: [1 << 20, 1, 1],
        span: usize::MAX,
        diagonals: true,
        fixed: LatticeFixed::None,
    };
    assert!(matches!(
        t.counts(),
        Err(GeneratorError::TooManyLinks { .. })
    ));
    let t = Topology::Lattice {
        size: [100, 100, 100],
        span: 3,
        diagonals: true,
        fixed: LatticeFixed::None,
    };
    assert!(matches!(
        t.counts(),
        Err(GeneratorError::TooManyLinks { .. })
    ));
    for t in [
        Topology::String { nodes: usize::MAX },
        Topology::Hexagon {
            rings: usize::MAX,
            fixed: Fixed::None,
        },
        Topology::Triangle {
            size: usize::MAX,
            fixed: Fixed::None,
        },
        Topology::Lattice {
            size: [usize::MAX, usize::MAX, 2],
            span: 1,
            diagonals: false,
            fixed: LatticeFixed::None,
        },
    ] {
        assert!(
            matches!(t.counts(), Err(GeneratorError::TooLarge { .. })),
            "{t:?}"
        );
    }
    assert!(start.elapsed().as_secs() < 5, "{:?}", start.elapsed());
    // Positions that overflow are refused.
    let mut g = Generator::new("x");
    g.first = [-1e308, 0.0, 0.0];
    g.last = [1e308, 0.0, 0.0];
    let mut b = ModelBuilder::new();
    let t = Topology::Hexagon {
        rings: 2,
        fixed: Fixed::None,
    };
    assert!(matches!(
        generate(&mut b, &g, &t),
        Err(GeneratorError::InvalidValue { .. })
    ));
}

/// Hexagon labels follow the regular geometry, whatever the box: a mirrored or flat box gives
/// the same node order (spec §4.6).
#[test]
fn hexagon_order_does_not_depend_on_the_box() {
    let t = Topology::Hexagon {
        rings: 3,
        fixed: Fixed::None,
    };
    let run = |first: [f64; 3], last: [f64; 3]| {
        let mut g = Generator::new("h");
        g.first = first;
        g.last = last;
        let mut b = ModelBuilder::new();
        generate(&mut b, &g, &t).unwrap()
    };
    let normal = run([0.0, 0.0, 0.0], [1.0, 1.0, 0.0]);
    assert_eq!(run([1.0, 1.0, 0.0], [0.0, 0.0, 0.0]), normal);
    assert_eq!(run([0.5, 0.5, 0.0], [0.5, 0.5, 0.0]), normal);
}
