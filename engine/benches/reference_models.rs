//! Benchmark of the reference models of spec §7: time per sample, share of one core's real-time
//! budget at 48 kHz, and compile time, all measured in one run.
//!
//! ```text
//! cargo bench -p ressort-engine --bench reference_models            # print the table
//! cargo bench -p ressort-engine --bench reference_models -- --save  # also write RESULTS.md
//! cargo bench -p ressort-engine --bench reference_models -- mesh    # only names containing "mesh"
//! ```
//!
//! Each model is compiled 9 times (the median is reported); then it renders 64-sample blocks at
//! 48 kHz with an impulse on in1 and slow signals on its other inputs, in 7 timed runs of about
//! 0.25 s of wall time each after a warm-up; the median run gives ns per sample. The model is reset
//! and struck again at the start of every simulated second (the reset is timed; it costs one
//! pass over the state), so a run never measures a model held at its fixed point.
//!
//! Then the element-by-element twins of compiled Faust `mi.lib` (the scripts of
//! `../shared/bench/faust-mi/scripts`, or `$FAUST_MI_SCRIPTS`) are measured the same way and,
//! when Faust's renderer has been built (`bash ../shared/bench/faust-mi/compare.sh` builds
//! `target/faust-mi/build/render-native`; or `$FAUST_MI_RENDER`), set against Faust's best of
//! five runs, measured in the same process run.

use ressort_engine::{compile, parse, reference, CompileOptions, Engine, InputUse, ModelSpec};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

const SAMPLE_RATE_HZ: f64 = 48_000.0;
const BLOCK_FRAMES: usize = 64;
const COMPILE_RUNS: usize = 9;
const TIMED_RUNS: usize = 7;
const RUN_WALL_TIME: Duration = Duration::from_millis(250);

struct Row {
    name: String,
    points: usize,
    interactions: usize,
    compile_ms: f64,
    ns_per_sample: f64,
}

impl Row {
    /// Share of one core's real-time budget at 48 kHz, in percent.
    fn percent_of_core(&self) -> f64 {
        self.ns_per_sample / (1e9 / SAMPLE_RATE_HZ) * 100.0
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Input blocks: a −0.01 impulse on in1 at the first sample, slow sines on position inputs,
/// mid-range values on audio-rate parameters.
fn inputs(e: &Engine, block: usize, first: bool) -> Vec<f64> {
    let mut v = Vec::new();
    for (c, uses) in e.info().inputs.iter().enumerate() {
        for n in 0..block {
            v.push(match uses.first() {
                Some(InputUse::Force(_)) if c == 0 && first && n == 0 => -0.01,
                Some(InputUse::Position(_)) => 0.01 * (n as f64 * 0.01).sin(),
                Some(InputUse::Param(_)) => 0.5,
                _ => 0.0,
            });
        }
    }
    v
}

fn measure(name: &str, spec: &ModelSpec) -> Row {
    let options = CompileOptions::at(SAMPLE_RATE_HZ);
    let compile_ms = median(
        (0..COMPILE_RUNS)
            .map(|_| {
                let t = Instant::now();
                let e = compile(spec, &options).expect("reference models compile");
                let ms = t.elapsed().as_secs_f64() * 1e3;
                drop(e);
                ms
            })
            .collect(),
    );
    let mut e = compile(spec, &options).expect("reference models compile");
    let first = inputs(&e, BLOCK_FRAMES, true);
    let rest = inputs(&e, BLOCK_FRAMES, false);
    let mut out = vec![0.0; e.info().num_outputs() * BLOCK_FRAMES];
    // The model is struck from rest at the start of every simulated second, so that it sounds
    // throughout: a run of a small model simulates minutes, in which a damped model reaches
    // its fixed point, and the engine then holds it instead of stepping (engine/src/sim/rest.rs).
    let restrike = (SAMPLE_RATE_HZ as usize).div_ceil(BLOCK_FRAMES);
    let mut run = |e: &mut Engine, blocks: usize| {
        for b in 0..blocks {
            if b % restrike == 0 {
                e.reset();
                e.process(BLOCK_FRAMES, &first, &mut out);
            } else {
                e.process(BLOCK_FRAMES, &rest, &mut out);
            }
        }
    };

    // Warm up, and calibrate the number of blocks per run to about RUN_WALL_TIME.
    run(&mut e, 16);
    let t = Instant::now();
    let mut blocks = 0usize;
    while t.elapsed() < RUN_WALL_TIME / 2 {
        run(&mut e, 16);
        blocks += 16;
    }
    let blocks_per_run = (blocks * 2).max(1);
    let runs: Vec<f64> = (0..TIMED_RUNS)
        .map(|_| {
            let t = Instant::now();
            run(&mut e, blocks_per_run);
            t.elapsed().as_secs_f64() * 1e9 / (blocks_per_run * BLOCK_FRAMES) as f64
        })
        .collect();
    assert!(
        !e.is_tripped(),
        "{name}: the guard tripped during the benchmark: {:?}",
        e.guard_event()
    );
    Row {
        name: name.to_string(),
        points: e.info().num_points,
        interactions: e.info().num_interactions,
        compile_ms,
        ns_per_sample: median(runs),
    }
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".to_string())
}

/// The faust-mi twin scripts, by name (`osc`, `string1000`, …), sorted.
fn twin_scripts() -> Vec<(String, PathBuf)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let dir = std::env::var_os("FAUST_MI_SCRIPTS")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("../shared/bench/faust-mi/scripts"));
    let mut found: Vec<(String, PathBuf)> = std::fs::read_dir(&dir)
        .map(|d| {
            d.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "mdl"))
                .filter_map(|p| Some((p.file_stem()?.to_str()?.to_string(), p)))
                .collect()
        })
        .unwrap_or_default();
    found.sort();
    found
}

/// Faust's renderer, if built.
fn faust_renderer() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let path = std::env::var_os("FAUST_MI_RENDER")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target/faust-mi/build/render-native"));
    path.is_file().then_some(path)
}

/// Faust's best ns/sample on `model` (or its `_cg` build, as compare.sh picks it): one
/// warm-up, then the best of five runs of 200,000 samples.
fn faust_ns(render: &Path, model: &str) -> Option<f64> {
    let list = Command::new(render).arg("--list").output().ok()?;
    let list = String::from_utf8_lossy(&list.stdout);
    let has = |m: &str| list.lines().any(|l| l.split_whitespace().next() == Some(m));
    let name = if has(model) {
        model.to_string()
    } else if has(&format!("{model}_cg")) {
        format!("{model}_cg")
    } else {
        return None;
    };
    let out = std::env::temp_dir().join(format!("ressort-faust-{}.f64", std::process::id()));
    let run = Command::new(render)
        .args([name.as_str(), "200000"])
        .arg(&out)
        .args(["--runs", "5"])
        .output()
        .ok()?;
    let _ = std::fs::remove_file(&out);
    let text = String::from_utf8_lossy(&run.stdout);
    text.split_whitespace()
        .find_map(|w| w.strip_prefix("ns_per_sample_best="))
        .and_then(|v| v.parse().ok())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let save = args.iter().any(|a| a == "--save");
    let filters: Vec<&String> = args.iter().filter(|a| !a.starts_with("--")).collect();

    let mut rows = Vec::new();
    for (name, spec) in reference::all() {
        if !filters.is_empty() && !filters.iter().any(|f| name.contains(f.as_str())) {
            continue;
        }
        let row = measure(name, &spec);
        eprintln!(
            "{:<22} {:>8.1} ns/sample  {:>6.2} % of a core  compile {:.3} ms",
            row.name,
            row.ns_per_sample,
            row.percent_of_core(),
            row.compile_ms
        );
        rows.push(row);
    }

    // The element-by-element twins of compiled Faust.
    let render = faust_renderer();
    let mut twins = Vec::new();
    for (name, path) in twin_scripts() {
        let row_name = format!("faust_mi_{name}");
        if !filters.is_empty() && !filters.iter().any(|f| row_name.contains(f.as_str())) {
            continue;
        }
        let text = std::fs::read_to_string(&path).expect("read a faust-mi script");
        let spec = parse(&text).spec.expect("the faust-mi scripts parse");
        let row = measure(&row_name, &spec);
        let faust = render.as_deref().and_then(|r| faust_ns(r, &name));
        eprintln!(
            "{:<22} {:>8.1} ns/sample  Faust {}",
            row.name,
            row.ns_per_sample,
            faust.map_or("not built".to_string(), |f| format!(
                "{f:.1} ns/sample, {:.2}×",
                f / row.ns_per_sample
            ))
        );
        twins.push((name, row, faust));
    }

    let mut table = String::new();
    table.push_str(
        "| model | points | interactions | ns/sample | % of one core at 48 kHz | real-time factor | compile ms |\n",
    );
    table.push_str("|---|---:|---:|---:|---:|---:|---:|\n");
    for r in &rows {
        table.push_str(&format!(
            "| {} | {} | {} | {:.1} | {:.2} | {:.0}× | {:.3} |\n",
            r.name,
            r.points,
            r.interactions,
            r.ns_per_sample,
            r.percent_of_core(),
            100.0 / r.percent_of_core(),
            r.compile_ms
        ));
    }
    let find = |n: &str| rows.iter().find(|r| r.name == n);
    let mut ratios = String::new();
    if let (Some(m), Some(x)) = (find("string_1000"), find("string_1000_expanded")) {
        let ratio = x.ns_per_sample / m.ns_per_sample;
        ratios.push_str(&if ratio >= 1.0 {
            format!(
                "- The string macro runs {ratio:.2}× faster than the same string as 1000 single \
                 masses and 1001 spring-dampers.\n"
            )
        } else {
            format!(
                "- The same string as 1000 single masses and 1001 spring-dampers runs {:.2}× \
                 faster than the string macro (chains, uniform arguments and plain masses).\n",
                1.0 / ratio
            )
        });
    }
    if let Some(m) = find("mesh_25x20") {
        ratios.push_str(&format!(
            "- Mesh 25×20 uses {:.2} % of a core at 48 kHz against 67 % for the original \
             toolbox at 44.1 kHz (SMC'19 Table 1, another machine), and compiles in {:.3} ms \
             against 3 minutes.\n",
            m.percent_of_core(),
            m.compile_ms
        ));
    }
    if let Some(m) = find("string_1000") {
        ratios.push_str(&format!(
            "- The 1000-mass string, which the original toolbox could not compile, compiles in \
             {:.3} ms and uses {:.2} % of a core.\n",
            m.compile_ms,
            m.percent_of_core()
        ));
    }
    let mut twin_table = String::new();
    if !twins.is_empty() {
        twin_table.push_str(
            "## Element by element, against compiled Faust mi.lib\n\n\
             The faust-mi scripts (`../shared/bench/faust-mi/scripts`: what MIMS4Max and \
             `~generate` write, one `mass` and one `springDamper` per line) on the engine as \
             above, and Faust's renderer (`-O3 -march=native`, double; built by `bash \
             ../shared/bench/faust-mi/compare.sh`) on the same models, best of five runs of \
             200,000 samples, in the same run. Ratio = Faust ns / Ressort ns.\n\n\
             | model | points | interactions | Faust ns/sample | Ressort ns/sample | ratio |\n\
             |---|---:|---:|---:|---:|---:|\n",
        );
        for (name, r, faust) in &twins {
            let (f, ratio) = match faust {
                Some(f) => (format!("{f:.1}"), format!("{:.2}×", f / r.ns_per_sample)),
                None => ("not built".to_string(), "–".to_string()),
            };
            twin_table.push_str(&format!(
                "| {name} | {} | {} | {f} | {:.1} | {ratio} |\n",
                r.points, r.interactions, r.ns_per_sample
            ));
        }
    }
    println!("{table}");
    print!("{ratios}");
    if !twin_table.is_empty() {
        println!("\n{twin_table}");
    }

    if save {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/RESULTS.md");
        let text = format!(
            "# Reference-model benchmark\n\n\
             Produced by `cargo bench -p ressort-engine --bench reference_models -- --save` \
             (also `bash scripts/main.sh --save`).\n\n\
             Machine: {} ({} logical cores). Sample rate {} Hz, blocks of {} frames, median of \
             {} runs of about 0.25 s, the model struck from rest by an impulse of −0.01 on in1 at \
             the start of every simulated second (it sounds throughout); compile time is the median of {} compiles of the builder spec.\n\n\
             {table}\n{ratios}\n{twin_table}",
            cpu_model(),
            std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1),
            SAMPLE_RATE_HZ,
            BLOCK_FRAMES,
            TIMED_RUNS,
            COMPILE_RUNS
        );
        std::fs::write(path, text).expect("write RESULTS.md");
        eprintln!("wrote {path}");
    }
}
