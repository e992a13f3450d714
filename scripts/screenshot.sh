#!/usr/bin/env bash
# Looks at the editor: starts the release `ressort-standalone` with a model (default the
# 25 x 20 mesh) on the dummy audio backend under a private Xvfb with Mesa's software OpenGL,
# strikes it every second, captures the editor window as a PNG and says what the motion view
# shows. Usage: bash scripts/screenshot.sh [MODEL] [extra ressort-screenshot options]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
model="${1:-mesh-25x20}"
shift || true
cargo build --release --locked -p ressort-plugin --bin ressort-standalone
cargo build --release --locked -p ressort-tests --bin ressort-screenshot
target="${CARGO_TARGET_DIR:-target}"
# exec: a signal sent to this script reaches ressort-screenshot itself, which stops its Xvfb
# and the standalone on every path (its children die with it).
exec "$target/release/ressort-screenshot" --standalone "$target/release/ressort-standalone" \
  --model "$model" "$@"
