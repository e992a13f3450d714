//! What a voice of a preset costs in heap memory, at 48 kHz: the bytes a prepared model holds
//! with one voice, what each further voice of its bank adds (the difference between 9 voices
//! and 1, over 8: a bank keeps a quarter more copies than voices, for the voices it steals),
//! and what one more copy of the compiled engine costs (its state: the compiled model is
//! shared), counted by a global allocator that tracks live bytes:
//! `cargo run --release -p ressort-engine --example voice_memory -- string-1000 chladni-150x150`
//! (names of scripts in `models/`, run from the workspace root).
use ressort_engine::instrument::prepare;
#[path = "common/counting.rs"]
mod counting;
use counting::{Counting, LIVE};
use std::sync::atomic::Ordering;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn mib(bytes: usize) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

fn main() {
    for name in std::env::args().skip(1) {
        let text =
            std::fs::read_to_string(format!("models/{name}.mdl")).expect("a preset in models/");
        let before = LIVE.load(Ordering::Relaxed);
        let mut model = prepare(&name, &text, 48_000.0).expect("the preset prepares");
        model.set_voices(1);
        let one = LIVE.load(Ordering::Relaxed) - before;
        model.set_voices(9);
        let nine = LIVE.load(Ordering::Relaxed) - before;
        let per_voice = nine.saturating_sub(one) / 8;
        let before_copy = LIVE.load(Ordering::Relaxed);
        let copy = model.engine.clone();
        let engine_copy = LIVE.load(Ordering::Relaxed) - before_copy;
        drop(copy);
        println!(
            "{name:<24} prepared, 1 voice {:8.2} MiB   each further voice {:8.3} MiB ({per_voice} bytes)   one engine copy {:8.3} MiB",
            mib(one),
            mib(per_voice),
            mib(engine_copy)
        );
        drop(model);
    }
}
