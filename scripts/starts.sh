#!/usr/bin/env bash
# Starts the optimised `ressort-standalone` many times, each under a fresh private Xvfb with
# Mesa's software OpenGL, while busy loops load every core, and counts the starts whose editor
# window does not appear (crashes, hangs). Prints the backtrace of every crash that left a
# core dump. Takes about a second per start on an idle machine, several under load.
#
# Usage: bash scripts/starts.sh [STARTS (default 200)] [BUSY LOOPS (default: one per core)]
#        [-- standalone options, default -b dummy]
# The failed starts' logs and cores stay in target/starts/.
set -euo pipefail
cd "$(dirname "$0")/.."
starts="${1:-200}"
busy="${2:-$(nproc)}"
shift $(( $# < 2 ? $# : 2 ))
[ "${1:-}" = "--" ] && shift
extra=("$@")
[ ${#extra[@]} -eq 0 ] && extra=(-b dummy)
target="${CARGO_TARGET_DIR:-target}"
# The `profiling` profile is the release build with symbols and line tables, for backtraces.
cargo build --profile profiling --locked -p ressort-plugin --bin ressort-standalone
cargo build --release --locked -p ressort-tests --bin ressort-starts
standalone="$target/profiling/ressort-standalone"

loads=()
stop_load() {
  for p in "${loads[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${loads[@]}"; do wait "$p" 2>/dev/null || true; done
  loads=()
}
trap stop_load EXIT
trap 'exit 130' INT TERM HUP
for _ in $(seq 1 "$busy"); do
  ( while :; do :; done ) &
  loads+=($!)
done

ulimit -c unlimited 2>/dev/null || echo "starts: core dumps are limited, crashes will have no backtrace" >&2
rm -rf target/starts
status=0
"$target/release/ressort-starts" --standalone "$standalone" \
  --starts "$starts" --keep target/starts -- "${extra[@]}" || status=$?
stop_load

for core in $(find target/starts -name 'core*' -type f 2>/dev/null); do
  echo "=== $core"
  if command -v gdb >/dev/null; then
    gdb -batch -q -ex 'thread apply all bt 30' \
      "$standalone" "$core" 2>/dev/null | grep -v '^\[New LWP' || true
  else
    echo "(gdb is not installed)"
  fi
done
exit "$status"
