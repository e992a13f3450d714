#!/usr/bin/env bash
# Validates the CLAP bundle with free-audio's clap-validator, built from its source in
# ../shared/tools/clap-validator into target/clap-validator (once per machine; about a
# minute on two cores). Fails when any of its tests fails. Extra arguments go to
# `clap-validator validate` (for example `--json` or `-t param-fuzz`).
# Usage: bash scripts/clap-validator.sh [BUNDLE] [validate options]
set -euo pipefail
cd "$(dirname "$0")/.."
source_dir=../shared/tools/clap-validator
bundle=target/bundled/Ressort.clap
if [ $# -gt 0 ] && [ "${1#-}" = "$1" ]; then
  bundle="$1"
  shift
fi
if [ ! -d "$source_dir" ]; then
  echo "clap-validator: $source_dir is missing (the shared tools sit beside this repository)" >&2
  exit 2
fi
[ -e "$bundle" ] || { echo "clap-validator: no bundle at $bundle (cargo xtask bundle ressort-plugin)" >&2; exit 2; }
cargo build --release --locked -q --manifest-path "$source_dir/Cargo.toml" \
  --target-dir target/clap-validator
# --only-failed keeps the log to the failures and the summary line.
#
# Two tests are left out: preset-discovery-crawl and preset-discovery-load hang in the validator
# itself on any plugin whose presets live inside it. Its metadata receiver's `begin_preset`
# holds the lock of its result while it calls `flush_preset`, which takes the same lock again
# when a second preset with a load key begins (src/plugin/preset_discovery/metadata_receiver.rs
# in this copy and upstream at b2f1d9b): a self-deadlock, then "Timed out after 45 seconds".
# Ressort's factory presets are such a container. tests/tests/host_presets.rs crawls every
# declared location and loads presets in the CLAP test host instead (docs/NOTES.md).
target/clap-validator/release/clap-validator validate "$bundle" --only-failed \
  -x '^preset-discovery-crawl$' -x '^preset-discovery-load$' "$@"
