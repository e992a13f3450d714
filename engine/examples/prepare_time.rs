//! How long preparing a preset takes, under the legacy conventions and the musical ones (whose
//! difference is the pitch probe and the level renders), best of three, at 48 kHz:
//! `cargo run --release -p ressort-engine --example prepare_time -- string-1000 mesh-15x15`
//! (names of scripts in `models/`, run from the workspace root).
use ressort_engine::instrument::{prepare_with, Conventions};
use std::time::Instant;
fn main() {
    // The preset names on the command line.
    for name in std::env::args().skip(1) {
        let text =
            std::fs::read_to_string(format!("models/{name}.mdl")).expect("a preset in models/");
        let mut best = [f64::MAX; 2];
        for _ in 0..3 {
            for (i, c) in [Conventions::Legacy, Conventions::Musical]
                .into_iter()
                .enumerate()
            {
                let t = Instant::now();
                let p = prepare_with(&name, &text, 48000.0, c);
                let s = t.elapsed().as_secs_f64();
                assert!(p.is_ok(), "{name} prepares");
                best[i] = best[i].min(s);
            }
        }
        println!(
            "{name:<24} legacy {:.3} s  musical {:.3} s  renders +{:.3} s",
            best[0],
            best[1],
            best[1] - best[0]
        );
    }
}
