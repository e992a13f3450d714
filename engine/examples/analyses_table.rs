//! Writes or checks the table of the presets' analyses (`models/analyses.txt`,
//! [`ressort_engine::instrument::analyses`]), run from the workspace root:
//!
//! - `cargo run --release -p ressort-engine --example analyses_table -- --write` analyses every
//!   script of `models/` at every shipped rate (the macro units without a time budget) and
//!   writes the table: after changing a preset, a law or an analysis.
//! - Without `--write` it prints what differs from the shipped table.
use ressort_engine::instrument::analyses::{self, Analyses, Table, SHIPPED_RATES};
use ressort_engine::instrument::{prepare_analysed, Conventions};
use std::time::Instant;

fn main() {
    let write = std::env::args().any(|a| a == "--write");
    let mut names: Vec<String> = std::fs::read_dir("models")
        .expect("run from the workspace root")
        .filter_map(|e| {
            let p = e.ok()?.path();
            (p.extension()? == "mdl").then(|| p.file_stem()?.to_str().map(String::from))?
        })
        .collect();
    names.sort();
    let jobs: Vec<(String, String, f64)> = names
        .iter()
        .flat_map(|n| {
            let text = std::fs::read_to_string(format!("models/{n}.mdl")).expect("a script");
            SHIPPED_RATES.map(|r| (n.clone(), text.clone(), r))
        })
        .collect();
    let started = Instant::now();
    // Two workers, one job at a time each, results in the jobs' order.
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<std::sync::Mutex<Option<Analyses>>> =
        jobs.iter().map(|_| std::sync::Mutex::new(None)).collect();
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some((name, text, rate)) = jobs.get(i) else {
                    break;
                };
                let t = Instant::now();
                let p = prepare_analysed(name, text, *rate, Conventions::Musical, f64::INFINITY)
                    .unwrap_or_else(|e| panic!("{name} prepares: {e:?}"));
                eprintln!(
                    "{name:<24} {rate:>8} Hz {:7.3} s",
                    t.elapsed().as_secs_f64()
                );
                *results[i].lock().unwrap() = Some(Analyses::of(p.facts()));
            });
        }
    });
    let mut table = Table::default();
    for ((name, text, rate), a) in jobs.iter().zip(results) {
        table.push(
            name,
            text,
            *rate,
            a.into_inner().unwrap().expect("analysed"),
        );
    }
    eprintln!(
        "{} entries in {:.1} s",
        table.entries.len(),
        started.elapsed().as_secs_f64()
    );
    if write {
        let header = "The analyses of every script of models/ at the shipped sample rates, under today's\n\
                      conventions (engine/src/instrument/analyses.rs). Generated: do not edit; after changing a\n\
                      preset, a law or an analysis, run\n\
                      cargo run --release -p ressort-engine --example analyses_table -- --write";
        std::fs::write("models/analyses.txt", table.to_text(header)).expect("writes the table");
        println!(
            "wrote models/analyses.txt ({} entries)",
            table.entries.len()
        );
        return;
    }
    let shipped = analyses::shipped();
    let (mut differ, mut exact) = (0, 0);
    for e in &table.entries {
        let distance = shipped
            .entries
            .iter()
            .find(|s| s.hash == e.hash && s.sample_rate == e.sample_rate)
            .ok_or_else(|| "no entry".to_string())
            .and_then(|s| s.analyses.distance(&e.analyses));
        match distance {
            Ok(0.0) => exact += 1,
            Ok(d) if d <= analyses::AGREEMENT => {}
            Ok(d) => {
                differ += 1;
                println!("differs: {} at {} Hz by {d:.1e}", e.name, e.sample_rate);
            }
            Err(why) => {
                differ += 1;
                println!("differs: {} at {} Hz: {why}", e.name, e.sample_rate);
            }
        }
    }
    println!(
        "{differ} of {} entries differ from models/analyses.txt ({exact} bit for bit, the rest \
         within {:.0e}, the last bits another processor's SIMD width moves)",
        table.entries.len(),
        analyses::AGREEMENT
    );
}
