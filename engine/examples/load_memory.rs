//! What thousands of model loads leave behind: prepares scripts as the plugin does on every
//! model change (parse, compile, native code for small models, analyses, level calibration)
//! and drops them, over and over, printing the live heap (a counting allocator) and the
//! resident memory (after glibc's `malloc_trim`) every thousand loads:
//! `cargo run --release -p ressort-engine --example load_memory -- 10000 harmonic-oscillator
//! plucked-oscillator mesh-15x15` (a count, then names of scripts in `models/`, run from the
//! workspace root). A flat column means nothing leaks: not the heap, not the native code's
//! executable pages.
use ressort_engine::instrument::prepare;
#[path = "common/counting.rs"]
mod counting;
use counting::{Counting, LIVE};
use std::sync::atomic::Ordering;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Resident memory in MiB, after handing free heap pages back to the system.
fn resident_mib() -> f64 {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only releases free memory of glibc's heap.
    unsafe {
        libc::malloc_trim(0);
    }
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap_or_default();
    let pages: f64 = statm
        .split_whitespace()
        .nth(1)
        .and_then(|p| p.parse().ok())
        .unwrap_or(0.0);
    pages * 4096.0 / (1024.0 * 1024.0)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let count: usize = args
        .next()
        .and_then(|c| c.parse().ok())
        .expect("usage: load_memory COUNT NAME…");
    let names: Vec<String> = args.collect();
    let scripts: Vec<(String, String)> = names
        .iter()
        .map(|n| {
            let path = format!("models/{n}.mdl");
            let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
            (n.clone(), text)
        })
        .collect();
    assert!(!scripts.is_empty(), "name at least one script of models/");
    let mut native_loads = 0;
    let mut first: Option<(f64, f64)> = None;
    let started = std::time::Instant::now();
    println!("loads   live heap MiB   resident MiB   native loads   seconds");
    for i in 1..=count {
        let (name, text) = &scripts[i % scripts.len()];
        let prepared = prepare(name, text, 48_000.0).expect("the preset prepares");
        native_loads += prepared.engine.native_code_bytes().is_some() as usize;
        drop(prepared);
        if i % 1000 == 0 || i == 100 {
            let live = LIVE.load(Ordering::Relaxed) as f64 / (1024.0 * 1024.0);
            let rss = resident_mib();
            if i == 100 {
                first = Some((live, rss));
            }
            println!(
                "{i:>6}   {live:>13.3}   {rss:>12.1}   {native_loads:>12}   {:>7.1}",
                started.elapsed().as_secs_f64()
            );
        }
    }
    if let Some((live0, rss0)) = first {
        println!(
            "after {count} loads: live heap {:+.3} MiB, resident {:+.1} MiB since load 100",
            LIVE.load(Ordering::Relaxed) as f64 / (1024.0 * 1024.0) - live0,
            resident_mib() - rss0
        );
    }
}
