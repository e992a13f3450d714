//! Benchmark of three-dimensional models (issue 39 point 9): what a `~dim 3` model costs
//! against its 1-D twin, a large 3-D model, a bank of 3-D voices and a large mesh file's load,
//! all measured in one run.
//!
//! ```text
//! cargo bench -p ressort-engine --bench space_models            # print the table
//! cargo bench -p ressort-engine --bench space_models -- --save  # also write SPACE.md
//! cargo bench -p ressort-engine --bench space_models -- string  # only rows containing "string"
//! ```
//!
//! The rows, with the goals they are held to:
//!
//! 1. **string1000 in 1-D and in 3-D**: the faust-mi `string1000.mdl` (ground, 1000 masses,
//!    ground, 1001 spring-dampers written one per line), generated here as the load-time
//!    benchmark generates it, and the same topology with `~dim 3`: the nodes along x one unit
//!    apart, spring-dampers of rest length 0.9 (a pre-tensioned string), the force input and
//!    the output along z (transverse). Goal: the 3-D string within 3× the 1-D one's time.
//! 2. **icosphere 5**: a geodesic shell of 10,242 nodes and 30,720 spring-dampers (V = 3E − 6
//!    exactly; the 10,000-mass, 30,000-spring model). Goal: within one core's real-time budget
//!    at 48 kHz, 20.8 µs per sample.
//! 3. **16 voices of the bell**: the shipped `bell.obj` (200 moving vertices and a fixed crown)
//!    with hinges, played by the [`Instrument`] as the plugin plays it, 16 notes held. Goal: a
//!    real-time factor (seconds of audio per second of the thread's time) of at least 1.
//! 4. **a 10,000-vertex OBJ file**: a 100 × 100 height-field grid of triangles written into a
//!    temporary folder, loaded by `objMesh` from the script's folder: file read, OBJ parse and
//!    the rest of the script (parse), then compile. Goal: parse plus compile within 10 ms.
//!
//! Engines are timed as in the reference-model benchmark (`reference_models.rs`): 64-sample
//! blocks at 48 kHz, an impulse on in1, the model reset and struck again at the start of every
//! simulated second, a warm-up, then 7 runs of about 0.25 s each; the median run gives ns per
//! sample. The voice bank renders blocks of 256 frames in 7 runs of about 0.5 s after a
//! warm-up, all 16 voices sounding throughout (checked). A load is timed as in the load-time
//! benchmark: one warm-up, then as many runs as fit in about 0.2 s (at least 21); the median.
//!
//! Each engine row also prints a checksum of its output bits over a fixed render (one second
//! from reset; the voice bank's first 0.5 s of 16 notes), so that an optimisation of the 3-D
//! kernels can show it leaves every render bit-identical.

use ressort_engine::instrument::{
    self, Controls, Conventions, Event, Instrument, Timed, MAX_HOST_INPUTS,
};
use ressort_engine::lang::folder_files;
use ressort_engine::lang::parse_with_files;
use ressort_engine::{compile, parse, CompileOptions, Engine, InputUse};
use std::path::Path;
use std::time::{Duration, Instant};

const SAMPLE_RATE_HZ: f64 = 48_000.0;
const BLOCK_FRAMES: usize = 64;
const TIMED_RUNS: usize = 7;
const RUN_WALL_TIME: Duration = Duration::from_millis(250);
/// The voice bank's block and run length.
const BANK_BLOCK: usize = 256;
const BANK_RUN_WALL_TIME: Duration = Duration::from_millis(500);
const VOICES: usize = 16;
/// Loads: at least this many runs, as many as fit in LOAD_WALL_TIME.
const LOAD_MIN_RUNS: usize = 21;
const LOAD_WALL_TIME: Duration = Duration::from_millis(200);

/// The goals of issue 39 point 9.
const GOAL_RATIO: f64 = 3.0;
const GOAL_LARGE_US: f64 = 1e6 / SAMPLE_RATE_HZ;
const GOAL_BANK_FACTOR: f64 = 1.0;
const GOAL_LOAD_MS: f64 = 10.0;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// FNV-1a over the bits of `values`.
fn checksum(hash: &mut u64, bits: impl Iterator<Item = u64>) {
    for b in bits {
        for byte in b.to_le_bytes() {
            *hash ^= byte as u64;
            *hash = hash.wrapping_mul(0x100_0000_01b3);
        }
    }
}

const FNV_START: u64 = 0xcbf2_9ce4_8422_2325;

/// The faust-mi `string1000.mdl` (the load-time benchmark's generator, same bytes): ground,
/// `n` masses, ground, `n + 1` spring-dampers, a force input at a third and a position output
/// at two thirds.
fn string_1d(n: usize) -> String {
    let mut s = format!(
        "# oracle twin of string{n}: string: ground -- {n} masses (M=1) -- ground, {} \
         springDampers (K=0.1, Z=0.001) between consecutive nodes; unit force impulse on node \
         {} (= mass #{} from the left), output = position of node {}\n~samplerate raw\n",
        n + 1,
        n / 3,
        n / 3,
        2 * n / 3
    );
    s.push_str("@n0 ground 0.0\n");
    for k in 1..=n {
        s.push_str(&format!("@n{k} mass 1.0 0.0 0.0 0.0\n"));
    }
    s.push_str(&format!("@n{} ground 0.0\n", n + 1));
    for k in 0..=n {
        s.push_str(&format!("@l{k} springDamper @n{k} @n{} 0.1 0.001\n", k + 1));
    }
    s.push_str(&format!(
        "@in1 frcInput @n{}\n@out1 posOutput @n{}\n",
        n / 3,
        2 * n / 3
    ));
    s
}

/// [`string_1d`]'s topology in 3-D: node k at (k, 0, 0), spring-dampers of rest length 0.9
/// (the string is pre-tensioned, so it has transverse waves), the input and output along z.
fn string_3d(n: usize) -> String {
    let mut s = format!(
        "# string{n} in 3-D: ground -- {n} masses (M=1) -- ground along x, {} springDampers \
         (K=0.1, Z=0.001, L=0.9 against a spacing of 1), force on node {} and position of \
         node {} along z\n~dim 3\n~samplerate raw\n",
        n + 1,
        n / 3,
        2 * n / 3
    );
    s.push_str("@n0 ground [0 0 0]\n");
    for k in 1..=n {
        s.push_str(&format!("@n{k} mass 1.0 [{k} 0 0] [0 0 0]\n"));
    }
    s.push_str(&format!("@n{0} ground [{0} 0 0]\n", n + 1));
    for k in 0..=n {
        s.push_str(&format!(
            "@l{k} springDamper @n{k} @n{} 0.1 0.001 0.9\n",
            k + 1
        ));
    }
    s.push_str(&format!(
        "@in1 frcInput @n{}\n@out1 posOutput @n{}\n",
        n / 3,
        2 * n / 3
    ));
    s
}

/// The 10,242-node, 30,720-link geodesic shell, pinned at its crown, struck along z.
const ICOSPHERE: &str = "\
~dim 3
@b icosphere 5 1. 0.1 0.00002 [0 0 0] 10 auto 'fix=crown'
@in1 frcInput @b_m1000
@out1 posOutput @b_m5000 [1 0 0]
";

/// The shipped bell (`models/bell.obj`: 10 rings of 20 vertices and a crown), fixed at its
/// crown, with hinges; struck along x, heard along x.
const BELL: &str = "\
~dim 3
~unpitched
@bell objMesh 'bell.obj' 1. 0.1 0.00002 5 [0 0 0] auto 'hinge=0.01 fix=200'
@in1 frcInput @bell_m5 [1 0 0]
@out1 posOutput @bell_m15 [1 0 0]
";

/// A `side` × `side` height-field grid as a Wavefront OBJ: vertex (i, j) at (i, j,
/// 0.5·sin(0.3 i)·cos(0.2 j)), two triangles per cell.
fn grid_obj(side: usize) -> String {
    let mut s = format!("# a {side} x {side} height-field grid, written by space_models.rs\n");
    for i in 0..side {
        for j in 0..side {
            let z = 0.5 * (0.3 * i as f64).sin() * (0.2 * j as f64).cos();
            s.push_str(&format!("v {i} {j} {z:.6}\n"));
        }
    }
    let v = |i: usize, j: usize| i * side + j + 1;
    for i in 0..side - 1 {
        for j in 0..side - 1 {
            s.push_str(&format!(
                "f {} {} {}\n",
                v(i, j),
                v(i + 1, j),
                v(i + 1, j + 1)
            ));
            s.push_str(&format!(
                "f {} {} {}\n",
                v(i, j),
                v(i + 1, j + 1),
                v(i, j + 1)
            ));
        }
    }
    s
}

const GRID_SIDE: usize = 100;

/// The script that loads the grid, fixed at its corners.
fn grid_script(side: usize) -> String {
    let last = side * side - 1;
    format!(
        "~dim 3\n@g objMesh 'grid.obj' 1. 0.1 0.001 1 [0 0 0] [0.95*auto] 'fix=0,{},{},{last}'\n\
         @in1 frcInput @g_m{}\n@out1 posOutput @g_m{}\n",
        side - 1,
        last - (side - 1),
        side * side / 2 + side / 3,
        side * side / 3
    )
}

/// Input blocks: a −0.01 impulse on in1 at the first sample (as `reference_models.rs`).
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

struct EngineRow {
    name: &'static str,
    points: usize,
    interactions: usize,
    ns_per_sample: f64,
    checksum: u64,
}

/// Times `script`'s engine (see the module documentation).
fn measure_engine(name: &'static str, script: &str) -> EngineRow {
    let parsed = parse(script);
    let spec = parsed.spec.unwrap_or_else(|| {
        let errors: Vec<String> = parsed.diagnostics.iter().map(|d| d.to_string()).collect();
        panic!("{name} does not parse: {errors:?}")
    });
    let mut e = compile(&spec, &CompileOptions::at(SAMPLE_RATE_HZ))
        .unwrap_or_else(|err| panic!("{name}: {err}"));
    let first = inputs(&e, BLOCK_FRAMES, true);
    let rest = inputs(&e, BLOCK_FRAMES, false);
    let mut out = vec![0.0; e.info().num_outputs() * BLOCK_FRAMES];
    let restrike = (SAMPLE_RATE_HZ as usize).div_ceil(BLOCK_FRAMES);
    let mut run = |e: &mut Engine, blocks: usize, hash: &mut Option<u64>| {
        for b in 0..blocks {
            if b % restrike == 0 {
                e.reset();
                e.process(BLOCK_FRAMES, &first, &mut out);
            } else {
                e.process(BLOCK_FRAMES, &rest, &mut out);
            }
            if let Some(h) = hash {
                checksum(h, out.iter().map(|v| v.to_bits()));
            }
        }
    };

    // The checksum: one simulated second from reset.
    let mut hash = Some(FNV_START);
    run(&mut e, restrike, &mut hash);

    // Warm up, and calibrate the number of blocks per run to about RUN_WALL_TIME.
    run(&mut e, 16, &mut None);
    let t = Instant::now();
    let mut blocks = 0usize;
    while t.elapsed() < RUN_WALL_TIME / 2 {
        run(&mut e, 16, &mut None);
        blocks += 16;
    }
    let blocks_per_run = (blocks * 2).max(1);
    let runs: Vec<f64> = (0..TIMED_RUNS)
        .map(|_| {
            let t = Instant::now();
            run(&mut e, blocks_per_run, &mut None);
            t.elapsed().as_secs_f64() * 1e9 / (blocks_per_run * BLOCK_FRAMES) as f64
        })
        .collect();
    assert!(
        !e.is_tripped(),
        "{name}: the guard tripped during the benchmark: {:?}",
        e.guard_event()
    );
    EngineRow {
        name,
        points: e.info().num_points,
        interactions: e.info().num_interactions,
        ns_per_sample: median(runs),
        checksum: hash.unwrap_or_default(),
    }
}

struct BankRow {
    points: usize,
    interactions: usize,
    /// Seconds of audio per second of wall time, one thread.
    realtime_factor: f64,
    ns_per_sample: f64,
    checksum: u64,
}

/// Plays [`VOICES`] held notes of the bell on the instrument (see the module documentation).
fn measure_bank() -> BankRow {
    let mut model = instrument::prepare_with("bell", BELL, SAMPLE_RATE_HZ, Conventions::Musical)
        .unwrap_or_else(|e| panic!("the bell does not prepare: {e:?}"));
    let (points, interactions) = {
        let info = model.engine.info();
        (info.num_points, info.num_interactions)
    };
    model.set_voices(VOICES);
    let controls = Controls::DEFAULT;
    let mut inst = Instrument::new(SAMPLE_RATE_HZ, controls);
    inst.set_model(Box::new(model));
    let (mut left, mut right) = (vec![0.0f32; BANK_BLOCK], vec![0.0f32; BANK_BLOCK]);
    let notes: Vec<Timed> = (0..VOICES as u8)
        .map(|k| {
            Timed::new(
                u32::from(k) * 3,
                Event::NoteOn {
                    note: 48 + k,
                    velocity: 0.8,
                    channel: 0,
                    voice_id: None,
                },
            )
        })
        .collect();
    let host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
    let mut block = |inst: &mut Instrument, events: &[Timed], hash: &mut Option<u64>| {
        let mut ev = events.iter().copied();
        let mut out: [&mut [f32]; 2] = [&mut left, &mut right];
        inst.process(BANK_BLOCK, &host, false, &mut ev, &controls, &mut out);
        if let Some(h) = hash {
            checksum(h, left.iter().chain(&right).map(|v| u64::from(v.to_bits())));
        }
    };

    // The checksum: the first 0.5 s of the notes.
    let mut hash = Some(FNV_START);
    block(&mut inst, &notes, &mut hash);
    let half_second = (SAMPLE_RATE_HZ as usize / 2).div_ceil(BANK_BLOCK);
    for _ in 1..half_second {
        block(&mut inst, &[], &mut hash);
    }

    let t = Instant::now();
    let mut blocks = 0usize;
    while t.elapsed() < BANK_RUN_WALL_TIME / 2 {
        block(&mut inst, &[], &mut None);
        blocks += 1;
    }
    let blocks_per_run = (blocks * 2).max(1);
    let runs: Vec<f64> = (0..TIMED_RUNS)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..blocks_per_run {
                block(&mut inst, &[], &mut None);
            }
            t.elapsed().as_secs_f64() * 1e9 / (blocks_per_run * BANK_BLOCK) as f64
        })
        .collect();
    let sounding = inst.voice_count().0;
    assert_eq!(
        sounding, VOICES,
        "the bell's voices must all sound through the benchmark"
    );
    let ns = median(runs);
    BankRow {
        points,
        interactions,
        realtime_factor: 1e9 / SAMPLE_RATE_HZ / ns,
        ns_per_sample: ns,
        checksum: hash.unwrap_or_default(),
    }
}

struct LoadRow {
    vertices: usize,
    bytes: usize,
    points: usize,
    interactions: usize,
    parse_ms: f64,
    compile_ms: f64,
    total_ms: f64,
    runs: usize,
}

/// Sorted timings of `f` in ms: one warm-up run, then as many as fit in LOAD_WALL_TIME.
fn time_runs<T>(mut f: impl FnMut() -> T) -> Vec<f64> {
    let mut once = || {
        let t = Instant::now();
        let r = f();
        let ms = t.elapsed().as_secs_f64() * 1e3;
        drop(r);
        ms
    };
    let first = once();
    let runs =
        ((LOAD_WALL_TIME.as_secs_f64() * 1e3 / first.max(1e-6)) as usize).max(LOAD_MIN_RUNS) | 1;
    let mut v: Vec<f64> = (0..runs).map(|_| once()).collect();
    v.sort_by(f64::total_cmp);
    v
}

/// Writes the grid OBJ into a temporary folder and times its load.
fn measure_load() -> LoadRow {
    let dir = std::env::temp_dir().join(format!("ressort-space-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("create the temporary folder");
    let obj = grid_obj(GRID_SIDE);
    std::fs::write(dir.join("grid.obj"), &obj).expect("write grid.obj");
    let script = grid_script(GRID_SIDE);
    let files = folder_files(&dir);
    let options = CompileOptions::at(SAMPLE_RATE_HZ);
    let parse_ok = || {
        let parsed = parse_with_files(&script, &files);
        parsed.spec.unwrap_or_else(|| {
            let errors: Vec<String> = parsed.diagnostics.iter().map(|d| d.to_string()).collect();
            panic!("the grid script does not parse: {errors:?}")
        })
    };
    let spec = parse_ok();
    let engine = compile(&spec, &options).unwrap_or_else(|e| panic!("the grid: {e}"));
    let (points, interactions) = (engine.info().num_points, engine.info().num_interactions);
    drop(engine);
    let parse_runs = time_runs(&parse_ok);
    let compile_runs = time_runs(|| compile(&spec, &options));
    let total = time_runs(|| compile(&parse_ok(), &options));
    let _ = std::fs::remove_dir_all(&dir);
    LoadRow {
        vertices: GRID_SIDE * GRID_SIDE,
        bytes: obj.len(),
        points,
        interactions,
        parse_ms: median(parse_runs),
        compile_ms: median(compile_runs),
        runs: total.len(),
        total_ms: median(total),
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

/// Today's date (UTC), as YYYY-MM-DD: days since 1970 to the civil calendar.
fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let z = (secs / 86_400) as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

fn verdict(met: bool) -> &'static str {
    if met {
        "met"
    } else {
        "NOT MET"
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let save = args.iter().any(|a| a == "--save");
    let filters: Vec<&String> = args.iter().filter(|a| !a.starts_with("--")).collect();
    let wanted =
        |name: &str| filters.is_empty() || filters.iter().any(|f| name.contains(f.as_str()));

    // The faust-mi script, when at hand, is the generated 1-D string byte for byte.
    let faust_mi = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/bench/faust-mi/scripts/string1000.mdl");
    if let Ok(text) = std::fs::read_to_string(&faust_mi) {
        eprintln!(
            "generated 1-D string1000 {} {}",
            if text == string_1d(1000) {
                "is byte for byte"
            } else {
                "DIFFERS from"
            },
            faust_mi.display()
        );
    }

    let mut engines = Vec::new();
    let s1 = string_1d(1000);
    let s3 = string_3d(1000);
    let engine_models: [(&'static str, &str); 3] = [
        ("string1000 (1-D)", &s1),
        ("string1000 (3-D)", &s3),
        ("icosphere 5 (3-D)", ICOSPHERE),
    ];
    for (name, script) in engine_models {
        if !wanted(name) {
            continue;
        }
        let row = measure_engine(name, script);
        eprintln!(
            "{:<20} {:>6} points {:>6} interactions {:>10.1} ns/sample  checksum {:016x}",
            row.name, row.points, row.interactions, row.ns_per_sample, row.checksum
        );
        engines.push(row);
    }
    let bank = wanted("bell voices").then(|| {
        let row = measure_bank();
        eprintln!(
            "bell voices ×{VOICES}      {:>6} points {:>6} interactions {:>10.1} ns/sample  \
             real-time factor {:.2}  checksum {:016x}",
            row.points, row.interactions, row.ns_per_sample, row.realtime_factor, row.checksum
        );
        row
    });
    let load = wanted("obj load").then(|| {
        let row = measure_load();
        eprintln!(
            "obj load {} vertices: parse {:.3} ms  compile {:.3} ms  parse+compile {:.3} ms",
            row.vertices, row.parse_ms, row.compile_ms, row.total_ms
        );
        row
    });

    // The table: one row per goal.
    let mut table = String::from(
        "| measurement | model | points | interactions | figure | goal | verdict |\n\
         |---|---|---:|---:|---:|---:|---|\n",
    );
    let find = |n: &str| engines.iter().find(|r| r.name == n);
    if let (Some(one), Some(three)) = (find("string1000 (1-D)"), find("string1000 (3-D)")) {
        let ratio = three.ns_per_sample / one.ns_per_sample;
        for r in [one, three] {
            table.push_str(&format!(
                "| 1. element-by-element string | {} | {} | {} | {:.1} ns/sample | | |\n",
                r.name, r.points, r.interactions, r.ns_per_sample
            ));
        }
        table.push_str(&format!(
            "| 1. 3-D / 1-D | | | | {ratio:.2}× | ≤ {GOAL_RATIO}× | {} |\n",
            verdict(ratio <= GOAL_RATIO)
        ));
    }
    if let Some(r) = find("icosphere 5 (3-D)") {
        let us = r.ns_per_sample / 1e3;
        table.push_str(&format!(
            "| 2. large 3-D model | {} | {} | {} | {us:.1} µs/sample | ≤ {GOAL_LARGE_US:.1} µs/sample | {} |\n",
            r.name,
            r.points,
            r.interactions,
            verdict(us <= GOAL_LARGE_US)
        ));
    }
    if let Some(b) = &bank {
        table.push_str(&format!(
            "| 3. voice bank | {VOICES} voices of bell.obj (hinges) | {} per voice | {} per voice | \
             real-time factor {:.2} ({:.1} µs/sample) | ≥ {GOAL_BANK_FACTOR} | {} |\n",
            b.points,
            b.interactions,
            b.realtime_factor,
            b.ns_per_sample / 1e3,
            verdict(b.realtime_factor >= GOAL_BANK_FACTOR)
        ));
    }
    if let Some(l) = &load {
        table.push_str(&format!(
            "| 4. OBJ load | {} vertices, {} bytes | {} | {} | {:.2} ms (parse {:.2} + compile {:.2}, {} runs) | ≤ {GOAL_LOAD_MS} ms | {} |\n",
            l.vertices,
            l.bytes,
            l.points,
            l.interactions,
            l.total_ms,
            l.parse_ms,
            l.compile_ms,
            l.runs,
            verdict(l.total_ms <= GOAL_LOAD_MS)
        ));
    }
    let mut sums = String::from("Render checksums (FNV-1a of the output bits):\n\n");
    for r in &engines {
        sums.push_str(&format!("- {}: `{:016x}`\n", r.name, r.checksum));
    }
    if let Some(b) = &bank {
        sums.push_str(&format!("- bell voices: `{:016x}`\n", b.checksum));
    }
    println!("{table}\n{sums}");

    if save {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/SPACE.md");
        let text = format!(
            "# Three-dimensional models benchmark\n\n\
             Produced by `cargo bench -p ressort-engine --bench space_models -- --save` \
             (`engine/benches/space_models.rs`; its module documentation describes each row), \
             {}. Earlier figures and what changed between them are in \
             `docs/performance-history.md`.\n\n\
             Machine: {} ({} logical cores). Engines: sample rate {} Hz, blocks of {} frames, \
             median of {} runs of about 0.25 s, struck from rest by an impulse of −0.01 on in1 \
             at the start of every simulated second. Voice bank: the instrument, blocks of {} \
             frames, median of {} runs of about 0.5 s, {} notes held and sounding. Load: the \
             median of at least {} runs, the OBJ file read from a temporary folder in each.\n\n\
             {table}\n{sums}",
            today(),
            cpu_model(),
            std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1),
            SAMPLE_RATE_HZ,
            BLOCK_FRAMES,
            TIMED_RUNS,
            BANK_BLOCK,
            TIMED_RUNS,
            VOICES,
            LOAD_MIN_RUNS,
        );
        std::fs::write(path, text).expect("write SPACE.md");
        eprintln!("wrote {path}");
    }
}
