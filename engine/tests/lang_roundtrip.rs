//! Property tests of the printer: `parse(&print(&spec)) == spec` for generated specs (spans
//! aside), and `parse(print(parse(x))) == parse(x)` for generated script text.

use proptest::prelude::*;
use proptest::sample::{select, subsequence};
use ressort_engine::lang::{parse, print};
use ressort_engine::{
    BinOp, Element, ElementKind, Endpoint, Expr, Func, Law, LawKind, MacroKind, MacroSpec,
    ModelSpec, ParamDecl, ParamKind, SampleRateMode, Span, Vector,
};

/// Finite numbers of every magnitude, with a bias to ordinary values.
fn num() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -1000.0..1000.0f64,
        1 => any::<f64>().prop_filter("finite", |v| v.is_finite()),
        1 => select(vec![0.0, -0.0, 1.0, -2.0, 1e-5, 2.5e3]),
    ]
}

fn expr(names: Vec<String>) -> BoxedStrategy<Expr> {
    let leaf = if names.is_empty() {
        num().prop_map(Expr::Num).boxed()
    } else {
        prop_oneof![
            num().prop_map(Expr::Num),
            select(names).prop_map(|n| Expr::Name(n.into()))
        ]
        .boxed()
    };
    leaf.prop_recursive(4, 16, 3, |inner| {
        prop_oneof![
            inner.clone().prop_map(|e| Expr::Neg(Box::new(e))),
            (
                select(vec![BinOp::Add, BinOp::Sub, BinOp::Mul, BinOp::Div]),
                inner.clone(),
                inner.clone()
            )
                .prop_map(|(op, a, b)| Expr::Binary(op, Box::new(a), Box::new(b))),
            (
                select(Func::ALL.to_vec()),
                proptest::collection::vec(inner, 3)
            )
                .prop_map(|(f, mut args)| {
                    args.truncate(f.arity());
                    Expr::Call(f, args.into())
                }),
        ]
    })
    .boxed()
}

fn vector(names: Vec<String>) -> BoxedStrategy<Vector> {
    prop_oneof![
        expr(names.clone()).prop_map(Vector::Scalar),
        (expr(names.clone()), expr(names.clone()), expr(names))
            .prop_map(|(x, y, z)| Vector::Xyz(Box::new([x, y, z]))),
    ]
    .boxed()
}

/// Material elements: singles, macros and avatars (`None` = avatar placeholder kind).
fn point(names: Vec<String>) -> BoxedStrategy<ElementKind> {
    let e = || expr(names.clone());
    let v = || vector(names.clone());
    let macro_kind = select(vec![
        MacroKind::String,
        MacroKind::Chain,
        MacroKind::StiffString,
        MacroKind::Mesh,
        MacroKind::CornerMesh,
        MacroKind::ClosedMesh,
    ]);
    prop_oneof![
        (e(), e(), v(), v()).prop_map(|(m, gravity, pos, vel)| ElementKind::Mass {
            m,
            gravity,
            pos,
            vel
        }),
        (e(), e(), e(), e(), v(), v()).prop_map(|(m, k, z, gravity, pos, vel)| ElementKind::Osc {
            m,
            k,
            z,
            gravity,
            pos,
            vel
        }),
        v().prop_map(|pos| ElementKind::Ground { pos }),
        (e(), e(), v(), v()).prop_map(|(m, gravity, pos, delayed)| ElementKind::MassG {
            m,
            gravity,
            pos,
            delayed
        }),
        (
            macro_kind,
            2u32..40,
            2u32..10,
            e(),
            e(),
            e(),
            e(),
            e(),
            v(),
            v()
        )
            .prop_map(|(kind, length, width, m, k, k2, z, zo, pos, vel)| {
                ElementKind::Macro(Box::new(MacroSpec {
                    kind,
                    length,
                    width: if kind.is_2d() { width } else { 1 },
                    m,
                    k,
                    k2: (kind == MacroKind::StiffString).then_some(k2),
                    z,
                    zo,
                    pos,
                    vel,
                }))
            }),
        v().prop_map(|pos| ElementKind::PosInput { channel: 0, pos }),
    ]
    .boxed()
}

fn endpoint(
    names: Vec<String>,
    points: Vec<String>,
    macros: Vec<(String, bool)>,
) -> BoxedStrategy<Endpoint> {
    let label = select(points).prop_map(|l| Endpoint::Label(l.into()));
    if macros.is_empty() {
        return label.boxed();
    }
    let e = expr(names);
    let proxy = (select(macros), e.clone(), e).prop_map(|((target, is_2d), u, w)| {
        if is_2d {
            Endpoint::Surface {
                target: target.into(),
                u: Box::new(u),
                w: Box::new(w),
            }
        } else {
            Endpoint::Line {
                target: target.into(),
                alpha: Box::new(u),
            }
        }
    });
    prop_oneof![label, proxy].boxed()
}

fn law(names: Vec<String>) -> BoxedStrategy<Law> {
    let e = || expr(names.clone());
    // The short forms, and every law of the table under its own keyword with all its
    // columns (a law added to the table is covered here without a line more).
    let full = (
        0..LawKind::COUNT,
        proptest::collection::vec(e(), LawKind::MAX_ARITY),
    )
        .prop_map(|(k, args)| Law::new(LawKind::ALL[k], args));
    prop_oneof![e().prop_map(Law::spring), e().prop_map(Law::damper), full].boxed()
}

/// What an element connects to, before endpoints are drawn.
#[derive(Clone, Debug)]
enum Link {
    Interaction(Law),
    FrcInput,
    PosOutput,
    FrcOutput,
}

const PARAM_POOL: [&str; 6] = ["K", "Z", "p_0", "stiffness", "x1", "_y"];
const BUFFER_POOL: [&str; 4] = ["triangle", "string", "b2", "membrane"];

fn spec() -> impl Strategy<Value = ModelSpec> {
    let params = subsequence(PARAM_POOL.to_vec(), 0..=PARAM_POOL.len()).prop_flat_map(|names| {
        let n = names.len();
        (
            Just(names),
            proptest::collection::vec(
                prop_oneof![
                    num().prop_map(|value| ParamKind::Control { value }),
                    (1u32..9, prop_oneof![Just(0.0), num()])
                        .prop_map(|(input, default)| ParamKind::Audio { input, default }),
                ],
                n,
            ),
        )
    });
    (params, 0usize..=BUFFER_POOL.len(), any::<bool>())
        .prop_flat_map(|((names, kinds), nbuf, raw)| {
            let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
            let points = proptest::collection::vec(point(names.clone()), 1..6);
            (Just(names), Just(kinds), Just(nbuf), Just(raw), points)
        })
        .prop_flat_map(|(names, kinds, nbuf, raw, points)| {
            let mut avatar = 0;
            let mut labels = Vec::new();
            let mut point_labels = Vec::new();
            let mut macros = Vec::new();
            let mut elements = Vec::new();
            for (i, kind) in points.into_iter().enumerate() {
                let (label, kind) = match kind {
                    ElementKind::PosInput { pos, .. } => {
                        avatar += 1;
                        (
                            format!("in{avatar}"),
                            ElementKind::PosInput {
                                channel: avatar,
                                pos,
                            },
                        )
                    }
                    k => (format!("e{i}"), k),
                };
                match &kind {
                    ElementKind::Macro(m) => macros.push((label.clone(), m.kind.is_2d())),
                    _ => point_labels.push(label.clone()),
                }
                labels.push(label.clone());
                elements.push((label, kind));
            }
            if point_labels.is_empty() {
                point_labels.push("g".to_string());
                elements.push(("g".to_string(), ElementKind::Ground { pos: 0.0.into() }));
            }
            let link = prop_oneof![
                3 => law(names.clone()).prop_map(Link::Interaction),
                1 => Just(Link::FrcInput),
                1 => Just(Link::PosOutput),
                1 => Just(Link::FrcOutput),
            ];
            let links = proptest::collection::vec(
                (
                    link,
                    endpoint(names.clone(), point_labels.clone(), macros.clone()),
                    endpoint(names.clone(), point_labels, macros),
                ),
                0..6,
            );
            (
                Just(names),
                Just(kinds),
                Just(nbuf),
                Just(raw),
                Just((elements, avatar)),
                links,
            )
        })
        .prop_flat_map(|(names, kinds, nbuf, raw, (points, avatars), links)| {
            let mut elements = points;
            let (mut input, mut output) = (avatars, 0);
            for (i, (link, a, b)) in links.into_iter().enumerate() {
                let e = match link {
                    Link::Interaction(law) => {
                        (format!("i{i}"), ElementKind::Interaction { law, a, b })
                    }
                    Link::FrcInput => {
                        input += 1;
                        (
                            format!("in{input}"),
                            ElementKind::FrcInput {
                                channel: input,
                                target: a,
                            },
                        )
                    }
                    Link::PosOutput => {
                        output += 1;
                        (
                            format!("out{output}"),
                            ElementKind::PosOutput {
                                channel: output,
                                target: a,
                            },
                        )
                    }
                    Link::FrcOutput => {
                        output += 1;
                        (
                            format!("out{output}"),
                            ElementKind::FrcOutput {
                                channel: output,
                                target: a,
                            },
                        )
                    }
                };
                elements.push(e);
            }
            let n = elements.len();
            let membership = proptest::collection::vec(
                (
                    Just((0..nbuf as u32).collect::<Vec<u32>>()).prop_shuffle(),
                    0..=nbuf,
                    any::<bool>(),
                    -10.0..10.0f64,
                    -10.0..10.0f64,
                ),
                n,
            );
            (
                Just(names),
                Just(kinds),
                Just(nbuf),
                Just(raw),
                Just(elements).prop_shuffle(),
                membership,
            )
        })
        .prop_map(|(names, kinds, nbuf, raw, elements, membership)| {
            let params = names
                .into_iter()
                .zip(kinds)
                .map(|(name, kind)| ParamDecl {
                    name,
                    kind,
                    span: Span::default(),
                })
                .collect();
            let elements = elements
                .into_iter()
                .zip(membership)
                .map(|((label, kind), (order, count, tagged, x, y))| {
                    let buffers: Vec<u32> = order.into_iter().take(count).collect();
                    let tag_xy =
                        (tagged && kind.is_single_mass() && !buffers.is_empty()).then_some((x, y));
                    Element {
                        label: label.into(),
                        kind,
                        buffers,
                        tag_xy,
                        span: Span::default(),
                    }
                })
                .collect();
            ModelSpec {
                sample_rate_mode: if raw {
                    SampleRateMode::Raw
                } else {
                    SampleRateMode::Scaled
                },
                params,
                elements,
                buffers: BUFFER_POOL
                    .iter()
                    .take(nbuf)
                    .map(|s| s.to_string())
                    .collect(),
                host: Default::default(),
                space: None,
            }
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn print_then_parse_gives_the_spec(spec in spec()) {
        let text = print(&spec);
        let parsed = parse(&text);
        prop_assert!(parsed.diagnostics.is_empty(), "{:#?}\n{}", parsed.diagnostics, text);
        prop_assert_eq!(parsed.spec.as_ref(), Some(&spec), "{}", text);
        // Printing is canonical.
        prop_assert_eq!(print(parsed.spec.as_ref().unwrap()), text);
    }
}

/// Script-like text: lines from templates with random values, labels and scopes, so that a
/// good share of scripts is valid and the round trip is exercised on parsed text.
fn script() -> impl Strategy<Value = String> {
    let val = || {
        select(vec![
            "1",
            "0.",
            "-2",
            "2e+3",
            ".5",
            "K",
            "-K",
            "[K + 1]",
            "sqrt(K)",
            "[pow(K, 2)]",
            "[1 2 3]",
            "[(K + 1) 0 -2]",
            "'K * 2'",
            "-(2)",
            "[--2]",
            "[1 - (2 - 3)]",
        ])
    };
    let ep = || {
        select(vec![
            "@m",
            "@n",
            "[@s 0.5]",
            "[@me 0.2 0.3]",
            "[@s (K - 1)]",
            "@in1",
            "@gs_m1",
            "@gs_g0",
        ])
    };
    let buf = || select(vec!["a", "b", "c"]);
    // Commands are written without their label; the joiner labels line i `@l{i}` (inputs
    // `@in{i+2}`, outputs `@out{i+1}`), so labels never collide.
    let line = prop_oneof![
        (val(), val(), val()).prop_map(|(a, b, c)| format!("mass {a} {b} {c}")),
        (val(), val(), val(), val()).prop_map(|(a, b, c, d)| format!("mass {a} {b} {c} {d}")),
        (val(), val(), val()).prop_map(|(a, b, c)| format!("osc {a} {b} {c} 0 0")),
        val().prop_map(|a| format!("ground {a}")),
        (val(), buf()).prop_map(|(a, b)| format!("mass 1 {a} 0 {b} 0.5 -1")),
        (val(), val()).prop_map(|(a, b)| format!("massG 1 {a} {b} 0")),
        (val(), val()).prop_map(|(a, b)| format!("string 10 1 {a} {b} 0 0")),
        (val(), val()).prop_map(|(a, b)| format!("stiffString 10 1 {a} K {b} 0.001 0 0")),
        (val(), val()).prop_map(|(a, b)| format!("cornerMesh 4 5 1 {a} {b} 0 0")),
        (ep(), ep(), val(), val()).prop_map(|(a, b, c, d)| format!("springDamper {a} {b} {c} {d}")),
        (ep(), ep(), val(), val()).prop_map(|(a, b, c, d)| format!("spring {a} {b} {c} {d}")),
        (ep(), ep(), val()).prop_map(|(a, b, c)| format!("contact {a} {b} {c} 0.1 -1")),
        (ep(), ep(), val()).prop_map(|(a, b, c)| format!("nlPluck {a} {b} {c} 0.1")),
        ep().prop_map(|a| format!("in: frcInput {a}")),
        ep().prop_map(|a| format!("out: posOutput {a}")),
        val().prop_map(|a| format!("in: posInput {a}")),
        buf().prop_map(|b| format!("~begin {b}")),
        buf().prop_map(|b| format!("~end {b}")),
        Just("~samplerate raw".to_string()),
        (val(), val()).prop_map(|(a, b)| format!("~generate string G nodes=3 M=1 K={a} Z={b}")),
        (val(), select(vec!["none", "corners", "borders"])).prop_map(|(a, f)| format!(
            "~generate mesh G size=3,2 M=1 K={a} Z=0 Zo=1e-4 fixed={f} from=0,0,0 to=2,1,0"
        )),
        val().prop_map(|a| format!("~generate triangle G size=3 M={a} K=0.1 Z=0 fixed=corners")),
        val().prop_map(|a| format!("~generate hexagon G size=1 M=1 K=0.1 Z={a}")),
        val().prop_map(|a| format!("~generate ring G nodes=4 radius=0.5 M=1 K={a} Z=0")),
        val().prop_map(|a| format!(
            "~generate lattice G size=2,2,2 span=1 diagonals=on M=1 K={a} Z=0 fixed=zmax"
        )),
        val().prop_map(|a| format!("~generate polyline G points=0,0;1,0;1,1 M=1 K={a} Z=0")),
        val().prop_map(|a| format!("~generate stiffString G nodes=3 M=1 K=0.1 Ks={a} Z=0")),
        Just("# a comment".to_string()),
    ];
    proptest::collection::vec(line, 0..16).prop_map(|lines| {
        let mut text = String::from(
            "@K param 0.1\n@m mass 1 0 0\n@n ground 0\n@s string 10 1 K 0 0 0\n\
             @me cornerMesh 4 5 1 K 0 0 0\n@in1 posInput 0\n\
             ~generate string gs nodes=3 M=1 K=K Z=0\n",
        );
        for (i, l) in lines.iter().enumerate() {
            let l = if let Some(rest) = l.strip_prefix("in:") {
                format!("@in{}{rest}", i + 2)
            } else if let Some(rest) = l.strip_prefix("out:") {
                format!("@out{}{rest}", i + 1)
            } else if l.starts_with("~generate") {
                l.replacen(" G ", &format!(" g{i} "), 1)
            } else if l.starts_with(['~', '#']) {
                l.clone()
            } else {
                format!("@l{i} {l}")
            };
            text.push_str(&l);
            text.push('\n');
        }
        text
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn parsed_text_round_trips(text in script()) {
        let first = parse(&text);
        if let Some(spec) = &first.spec {
            let printed = print(spec);
            let second = parse(&printed);
            prop_assert!(second.errors().next().is_none(), "{:#?}\n{}", second.diagnostics, printed);
            prop_assert_eq!(second.spec.as_ref(), Some(spec), "{}\n---\n{}", text, printed);
        }
    }
}

/// The script generator must produce valid scripts often, or the round-trip property above
/// would hold vacuously.
#[test]
fn script_generator_reaches_valid_scripts() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let mut ok = 0;
    let mut with_generators = 0;
    for _ in 0..500 {
        let Ok(tree) = script().new_tree(&mut runner) else {
            continue;
        };
        let text = tree.current();
        if parse(&text).spec.is_some_and(|s| s.elements.len() > 6) {
            ok += 1;
            // A `~generate` line besides the prelude's.
            if text.matches("~generate").count() > 1 {
                with_generators += 1;
            }
        }
    }
    assert!(ok >= 50, "only {ok} of 500 generated scripts are valid");
    assert!(
        with_generators >= 20,
        "only {with_generators} valid scripts with `~generate` lines"
    );
}

/// The host directives survive printing: parse(print(parse(x))) == parse(x).
#[test]
fn host_directives_round_trip() {
    let text = "@K param 0.1\n@m osc 1 K 0.001 0 0\n@in1 frcInput @m\n@in2 frcInput @m\n\
                @out1 posOutput @m\n~pitch 261.625\n~key 60.5\n~note in2 -0.05\n\
                ~route in1 sidechain_right\n~route in2 none\n~macro K 0.05 2e-1\n~voices 8\n";
    let first = ressort_engine::parse(text).spec.expect("parses");
    assert_eq!(first.host.voices, Some(8));
    assert_eq!(first.host.pitch_hz, Some(261.625));
    assert_eq!(first.host.note_input, Some(2));
    assert_eq!(first.host.routes.len(), 2);
    let printed = ressort_engine::print(&first);
    let second = ressort_engine::parse(&printed)
        .spec
        .expect("printed text parses");
    assert_eq!(first.host, second.host, "{printed}");
    assert_eq!(first, second);
}

/// Routes reach the multichannel sidechain: `sidechain_3` … `sidechain_8`, with `sidechain_1`
/// and `sidechain_2` as the names of left and right; `sidechain_9` is an error.
#[test]
fn routes_name_every_sidechain_channel() {
    use ressort_engine::RouteSource;
    let text = "@m osc 1 0.1 0.001 0 0
@in1 frcInput @m
@in2 frcInput @m
@in3 frcInput @m
\
                @out1 posOutput @m
~route in1 sidechain_8
~route in2 sidechain_1
\
                ~route in3 sidechain_3
";
    let spec = ressort_engine::parse(text).spec.expect("parses");
    let sources: Vec<RouteSource> = spec.host.routes.iter().map(|r| r.source).collect();
    assert_eq!(
        sources,
        [
            RouteSource::Sidechain(8),
            RouteSource::SidechainLeft,
            RouteSource::Sidechain(3)
        ]
    );
    let printed = ressort_engine::print(&spec);
    assert!(printed.contains("~route in1 sidechain_8"), "{printed}");
    assert_eq!(
        ressort_engine::parse(&printed).spec.unwrap().host,
        spec.host
    );
    let bad =
        ressort_engine::parse("@m osc 1 0.1 0.001 0 0\n@in1 frcInput @m\n~route in1 sidechain_9\n");
    let errors: Vec<String> = bad.errors().map(|d| d.to_string()).collect();
    assert!(
        errors
            .iter()
            .any(|e| e.contains("unknown input source `sidechain_9`")),
        "{errors:?}"
    );
}

/// An `audioParam` default survives printing; a zero default prints as the MIMS4Max form.
#[test]
fn audio_param_defaults_round_trip() {
    let text = "@lX audioParam @in3 0.3\n@lY audioParam @in4 -2.5e-3\n@cX audioParam @in5 0\n\
                @cY audioParam @in6\n";
    let first = ressort_engine::parse(text).spec.expect("parses");
    let defaults: Vec<ParamKind> = first.params.iter().map(|p| p.kind.clone()).collect();
    assert_eq!(
        defaults,
        vec![
            ParamKind::Audio {
                input: 3,
                default: 0.3
            },
            ParamKind::Audio {
                input: 4,
                default: -2.5e-3
            },
            ParamKind::Audio {
                input: 5,
                default: 0.0
            },
            ParamKind::Audio {
                input: 6,
                default: 0.0
            },
        ]
    );
    let printed = print(&first);
    assert_eq!(
        printed,
        "@lX audioParam @in3 0.3\n@lY audioParam @in4 -0.0025\n@cX audioParam @in5\n\
         @cY audioParam @in6\n"
    );
    assert_eq!(ressort_engine::parse(&printed).spec, Some(first));
}

/// `~voices` takes a whole number from 1 to 1024, once.
#[test]
fn voice_counts_are_checked() {
    for bad in ["0", "1025", "2.5", "many"] {
        let p = ressort_engine::parse(&format!("@o osc 1 0.1 0.001 0 0\n~voices {bad}\n"));
        let errors: Vec<String> = p.errors().map(|d| d.to_string()).collect();
        assert!(
            errors
                .iter()
                .any(|e| e.contains("2:9") && e.contains("voice count")),
            "~voices {bad}: {errors:?}"
        );
    }
    let twice = ressort_engine::parse("@o osc 1 0.1 0.001 0 0\n~voices 4\n~voices 8\n");
    assert!(twice
        .errors()
        .any(|d| d.to_string().contains("a second `~voices`")));
}
