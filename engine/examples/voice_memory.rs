//! What a voice of a preset costs in heap memory, at 48 kHz: the bytes a prepared model holds
//! with one voice, what each further voice of its bank adds (the difference between 9 voices
//! and 1, over 8: a bank keeps a quarter more copies than voices, for the voices it steals),
//! and what one more copy of the compiled engine costs (its state: the compiled model is
//! shared), counted by a global allocator that tracks live bytes:
//! `cargo run --release -p ressort-engine --example voice_memory -- string-1000 chladni-150x150`
//! (names of scripts in `models/`, run from the workspace root).
use ressort_engine::instrument::prepare;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator, counting the bytes live at any moment.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded to the system allocator with its own arguments; the counter
// only observes the sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LIVE.fetch_add(layout.size(), Ordering::Relaxed);
        // SAFETY: the caller's layout, as `GlobalAlloc::alloc` requires.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: `ptr` was allocated by `alloc` above with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LIVE.fetch_add(new_size, Ordering::Relaxed);
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: as for `dealloc` and `alloc`.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

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
