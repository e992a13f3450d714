#!/usr/bin/env bash
# Sets up and runs the main job on a machine with no audio device: checks, renders and
# benchmarks reference models with the `ressort` command line, then measures every reference
# model of the specification (spec §7) on the engine and the load time (parse + compile) of
# every preset script in models/. Extra arguments go to both engine benchmarks (`--save` writes
# engine/benches/RESULTS.md and engine/benches/LOAD_TIME.md; a bare word keeps only the models
# whose name contains it). Finally it bundles the plugin (target/bundled/Ressort.clap and
# Ressort.vst3) and builds ressort-standalone, both release builds.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo build --release --locked -p ressort-cli
ressort=target/release/ressort
mkdir -p out
"$ressort" check models/mesh-25x20.mdl
"$ressort" render models/mesh-25x20.mdl -o out/mesh-25x20.wav --seconds 3 --impulse in1=-0.01
"$ressort" render models/string-1000.mdl -o out/string-1000.wav --seconds 3 --impulse in1=-0.01
"$ressort" bench models/string-1000.mdl
# Compiled Faust mi.lib on the same element-by-element models, where the shared benchmark is
# present: builds Faust's renderer into target/faust-mi (faust and g++ from Debian) and prints
# the comparison; the engine benchmark below then sets its twins against that renderer.
if [ -f ../shared/bench/faust-mi/compare.sh ]; then
  bash ../shared/bench/faust-mi/compare.sh "$ressort"
fi
cargo bench -p ressort-engine --bench reference_models --locked -- "$@"
cargo bench -p ressort-engine --bench load_time --locked -- "$@"
# The plugin: CLAP and VST3 bundles in target/bundled/, and the standalone application.
cargo xtask bundle ressort-plugin --release
cargo build --release --locked -p ressort-plugin --bin ressort-standalone
ls -l target/bundled/
