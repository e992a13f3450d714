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
//! 0.25 s of wall time each after a warm-up; the median run gives ns per sample.

use ressort_engine::{compile, reference, CompileOptions, Engine, InputUse, ModelSpec};
use std::time::{Duration, Instant};

const SAMPLE_RATE_HZ: f64 = 48_000.0;
const BLOCK_FRAMES: usize = 64;
const COMPILE_RUNS: usize = 9;
const TIMED_RUNS: usize = 7;
const RUN_WALL_TIME: Duration = Duration::from_millis(250);

struct Row {
    name: &'static str,
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

fn measure(name: &'static str, spec: &ModelSpec) -> Row {
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
    e.process(BLOCK_FRAMES, &first, &mut out);

    // Calibrate the number of blocks per run to about RUN_WALL_TIME.
    let t = Instant::now();
    let mut blocks = 0usize;
    while t.elapsed() < RUN_WALL_TIME / 2 {
        e.process(BLOCK_FRAMES, &rest, &mut out);
        blocks += 1;
    }
    let blocks_per_run = (blocks * 2).max(1);
    let runs: Vec<f64> = (0..TIMED_RUNS)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..blocks_per_run {
                e.process(BLOCK_FRAMES, &rest, &mut out);
            }
            t.elapsed().as_secs_f64() * 1e9 / (blocks_per_run * BLOCK_FRAMES) as f64
        })
        .collect();
    assert!(
        !e.is_tripped(),
        "{name}: the guard tripped during the benchmark: {:?}",
        e.guard_event()
    );
    Row {
        name,
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
        ratios.push_str(&format!(
            "- The string macro runs {:.1}× faster than the same string as 1000 single masses \
             and 1001 spring-dampers.\n",
            x.ns_per_sample / m.ns_per_sample
        ));
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
    println!("{table}");
    print!("{ratios}");

    if save {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/RESULTS.md");
        let text = format!(
            "# Reference-model benchmark\n\n\
             Produced by `cargo bench -p ressort-engine --bench reference_models -- --save` \
             (also `bash scripts/main.sh --save`).\n\n\
             Machine: {} ({} logical cores). Sample rate {} Hz, blocks of {} frames, median of \
             {} runs; compile time is the median of {} compiles of the builder spec.\n\n\
             {table}\n{ratios}",
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
