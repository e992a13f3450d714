//! Where a state load's time goes, phase by phase, for every preset at 48 kHz (best of
//! five, release build): the script parsed (`parse`, also inside `prepare`), compiled with
//! its kept analyses and a motion channel (`prepare`), the editor's summary and modal copy;
//! `load` is what the host's thread waits for. The stability lines the editor shows are
//! worked out on its first look, not in the load.
//!
//! `cargo run --release -p ressort-plugin --example load_phases`.
use ressort_engine::instrument::{self, ModalModel};
use ressort_plugin::model::{prepare, stability_lines, summary, Playing};
use ressort_plugin::presets::PRESETS;
use std::time::Instant;

fn main() {
    println!(
        "| preset | parse (ms) | prepare (ms) | summary (ms) | modal copy (ms) | load (ms) | stability lines (ms) |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    let mut presets: Vec<_> = PRESETS.iter().collect();
    presets.sort_by_key(|p| p.id);
    for preset in presets {
        let (name, text) = (preset.id, preset.text);
        let mut best = [f64::MAX; 6];
        for _ in 0..5 {
            let t = Instant::now();
            let _ = instrument::parse_script(text).expect("it parses");
            let parse = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let (p, _reader) = prepare(name, text, 48000.0, 0, Playing::Musical).expect("it loads");
            let prep = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let _s = summary(&p);
            let sum = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let m = ModalModel::of(&p);
            let modal = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let _lines = stability_lines(&m);
            let lines = t.elapsed().as_secs_f64();
            let all = [parse, prep, sum, modal, prep + sum + modal, lines];
            for (b, v) in best.iter_mut().zip(all) {
                *b = b.min(v);
            }
        }
        println!(
            "| {name} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
            best[0] * 1e3,
            best[1] * 1e3,
            best[2] * 1e3,
            best[3] * 1e3,
            best[4] * 1e3,
            best[5] * 1e3
        );
    }
}
