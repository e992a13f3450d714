#!/usr/bin/env bash
# Sets up and runs the main job: measures the reference models of the specification (spec §7)
# on the engine and prints the table (ns per sample, % of one core at 48 kHz, compile time).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo bench -p ressort-engine --bench reference_models --locked -- "$@"
