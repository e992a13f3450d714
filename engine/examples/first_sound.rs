//! Time to first sound for every preset: from the request (a script to load) to the first
//! sample of the new model, through the instrument the plugin runs, at 48 kHz, best of three:
//!
//! - **analysed**: every analysis run for the load (what every load did before the analyses
//!   were kept, and what a script never seen before still takes);
//! - **kept**: the analyses from the shipped table (a preset) or the process's memory (a
//!   script loaded before: an A/B switch, a Voices change);
//! - **provisional**: the quick stand-ins a script whose analyses are not kept plays on at
//!   once (`prepare_provisional`: the Gershgorin envelope, an impulse pitch, short level
//!   renders), while the exact analyses (the analysed column's work) run on another thread.
//!
//! `cargo run --release -p ressort-engine --example first_sound` from the workspace root
//! (names of scripts in `models/` on the command line to measure only those).
use ressort_engine::instrument::prepare::UNITS_BUDGET_S;
use ressort_engine::instrument::{
    prepare_analysed, prepare_provisional, prepare_with, Controls, Conventions, Event, Instrument,
    Prepared, Timed, MAX_HOST_INPUTS,
};
use std::time::Instant;

const SR: f64 = 48000.0;
/// The host's block: 10 ms, a note at its start, as a DAW opening a project plays on.
const BLOCK: usize = 480;

/// Seconds from `t0` to the end of the block holding the model's first sounding sample.
fn first_sound(t0: Instant, model: Prepared) -> f64 {
    let mut inst = Instrument::new(SR, Controls::DEFAULT);
    inst.set_model(Box::new(model));
    let mut out = [[0.0f32; BLOCK]; 2];
    // One note, in the first block: a key that throws a ball throws it again at each note, and
    // the Bouncing Ball, tossed up every block, would never land.
    for block in 0..200 {
        let mut evs = (block == 0)
            .then(|| Timed::new(0, Event::note_on(60, 0.8)))
            .into_iter();
        let host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
        let [l, r] = &mut out;
        let mut slices: [&mut [f32]; 2] = [l, r];
        inst.process(
            BLOCK,
            &host,
            false,
            &mut evs,
            &Controls::DEFAULT,
            &mut slices,
        );
        if out.iter().flatten().any(|s| *s != 0.0) {
            return t0.elapsed().as_secs_f64();
        }
    }
    f64::NAN
}

fn main() {
    let chosen: Vec<String> = std::env::args().skip(1).collect();
    let mut names: Vec<String> = std::fs::read_dir("models")
        .expect("run from the workspace root")
        .filter_map(|e| {
            let p = e.ok()?.path();
            (p.extension()? == "mdl").then(|| p.file_stem()?.to_str().map(String::from))?
        })
        .filter(|n| chosen.is_empty() || chosen.contains(n))
        .collect();
    names.sort();
    println!("| preset | analysed (ms) | kept (ms) | provisional (ms) |");
    println!("|---|---:|---:|---:|");
    let (mut worst_before, mut worst_after, mut worst_quick) = (0.0f64, 0.0f64, 0.0f64);
    for name in names {
        let text = std::fs::read_to_string(format!("models/{name}.mdl")).expect("a script");
        let mut best = [f64::MAX; 3];
        for _ in 0..3 {
            let t = Instant::now();
            let p = prepare_analysed(&name, &text, SR, Conventions::Musical, UNITS_BUDGET_S)
                .expect("a preset prepares");
            best[0] = best[0].min(first_sound(t, p));
            let t = Instant::now();
            let p = prepare_with(&name, &text, SR, Conventions::Musical).expect("it loads");
            best[1] = best[1].min(first_sound(t, p));
            let t = Instant::now();
            let p = prepare_provisional(&name, &text, SR, Conventions::Musical).expect("it plays");
            best[2] = best[2].min(first_sound(t, p));
        }
        worst_before = worst_before.max(best[0]);
        worst_after = worst_after.max(best[1]);
        worst_quick = worst_quick.max(best[2]);
        println!(
            "| {name} | {:.1} | {:.1} | {:.1} |",
            best[0] * 1e3,
            best[1] * 1e3,
            best[2] * 1e3
        );
    }
    println!(
        "| **slowest** | **{:.1}** | **{:.1}** | **{:.1}** |",
        worst_before * 1e3,
        worst_after * 1e3,
        worst_quick * 1e3
    );
}
