//! What a script no table knows costs at the analyses' peak (issue 40): each named preset with
//! a comment added (as `tests/tests/instance_memory.rs` edits one) is prepared, as
//! the plugin prepares a pasted script, and then its lowest modes are analysed alone
//! (`Engine::modes`, the reference pitch's count). Printed per script and step: the time, the
//! heap's peak above its level before the step (a counting allocator: bytes reserved, touched
//! or not) and the resident high-water mark's rise (the kernel's, reset before the step:
//! pages touched). `cargo run --release -p ressort-engine --example analysis_peak --
//! chladni-150x150 string-1000` (names of scripts in `models/`, run from the workspace root;
//! `--rate HZ` first for another rate than 48 kHz).
use ressort_engine::instrument::prepare;
#[path = "common/counting.rs"]
mod counting;
use counting::{Counting, LIVE, PEAK};
use std::sync::atomic::Ordering;
use std::time::Instant;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn mib(bytes: usize) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

/// A line of /proc/self/status in MiB (`VmRSS`, `VmHWM`).
fn status_mib(key: &str) -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kib: f64 = status
        .lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|v| v.split_whitespace().next()?.parse().ok())
        .unwrap_or(0.0);
    kib / 1024.0
}

/// Runs `step`, printing its time, its heap peak and its resident rise under `label`.
fn measure<T>(label: &str, step: impl FnOnce() -> T) -> T {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only releases free memory of glibc's heap.
    unsafe {
        libc::malloc_trim(0);
    }
    // Writing 5 resets the high-water mark to the resident set (Linux ≥ 4.0).
    let _ = std::fs::write("/proc/self/clear_refs", "5");
    let resident = status_mib("VmRSS:");
    let before = LIVE.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    let t = Instant::now();
    let out = step();
    let secs = t.elapsed().as_secs_f64();
    let peak = PEAK.load(Ordering::Relaxed).saturating_sub(before);
    println!(
        "  {label:<34} {secs:>7.3} s   heap peak {:>7.1} MiB   resident peak +{:>6.1} MiB",
        mib(peak),
        status_mib("VmHWM:") - resident
    );
    out
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut rate = 48_000.0;
    if args.first().is_some_and(|a| a == "--rate") && args.len() > 1 {
        rate = args[1].parse().expect("--rate HZ");
        args.drain(..2);
    }
    for name in args {
        let path = format!("models/{name}.mdl");
        let mut text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        text.push_str("\n# edited\n");
        println!("{name} (edited) at {rate} Hz");
        let prepared = measure("prepare (every analysis)", || {
            prepare(&name, &text, rate).expect("the script prepares")
        });
        let mut engine = prepared.engine.clone();
        drop(prepared);
        let analysis = measure("modes (the reference pitch's)", || engine.modes(None));
        println!(
            "  {} modes of {} moving masses ({:?})",
            analysis.modes.len(),
            analysis.degrees_of_freedom,
            analysis.solver
        );
    }
}
