#!/usr/bin/env bash
# The test command (README; .ci/run runs it): sets up the machine, bundles the plugin in a debug
# build with nice-plug's assert_process_allocs (any allocation inside process() aborts the
# host), runs every Rust test (engine, command line, plugin, and the end-to-end tests in a CLAP
# host and under Xvfb), validates the CLAP bundle with clap-validator, and plays the VST3
# bundle in pedalboard and DawDreamer.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo xtask bundle ressort-plugin --features assert_process_allocs
cargo test --workspace --locked
bash scripts/clap-validator.sh
bash tests/vst3/run.sh
