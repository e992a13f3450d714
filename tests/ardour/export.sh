#!/usr/bin/env bash
# Exports an automated Ardour session with Ressort's VST3, headlessly (Debian's `ardour`
# 7.3, installed by scripts/setup.sh), into OUT-DIR:
#   build_1, build_2, build_3  the new session in the process that made it (build_3 after the
#                              plugin was deactivated and activated again);
#   noauto                     the same with the Stiffness automation off;
#   reload_1, reload_2         the saved session loaded in a new process;
#   tool                       the saved session through `ardour7-export`.
# All are 0 … 5 s, 48 kHz, 32-bit float (session.lua says what the session holds).
# tests/vst3/test_ardour.py runs it and compares the files.
#
#   tests/ardour/export.sh BUNDLE.vst3 OUT-DIR
#
# Ardour's configuration, cache and home are made under OUT-DIR, so that nothing of the
# user's Ardour takes part.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
bundle="$(cd "$1" && pwd)"
out="$(mkdir -p "$2" && cd "$2" && pwd)"
preset=5e0b1b8e-6a56-4f0c-9f53-7d2a1f3c0a02

for tool in ardour7-lua ardour7-export; do
  command -v "$tool" >/dev/null || { echo "$tool is missing: run scripts/setup.sh" >&2; exit 1; }
done

mkdir -p "$out"/{home,config/ardour7/export,cache,vst3,empty,logs}
export HOME="$out/home" XDG_CONFIG_HOME="$out/config" XDG_CACHE_HOME="$out/cache"
export VST3_PATH="$out/vst3"
export LV2_PATH="$out/empty" LADSPA_PATH="$out/empty" LXVST_PATH="$out/empty" VST_PATH="$out/empty"
export LC_ALL=C LANG=C
unset DISPLAY
ln -sfn "$bundle" "$out/vst3/Ressort.vst3"
# No port resampler: its latency joins the master's at a random moment (see session.lua).
cat > "$XDG_CONFIG_HOME/ardour7/config" <<'EOF'
<?xml version="1.0" encoding="UTF-8"?>
<Ardour>
  <Config>
    <Option name="port-resampler-quality" value="0"/>
  </Config>
</Ardour>
EOF
# A float WAV export without dither (Ardour's presets dither, with noise) or normalisation.
cp "$here"/export-presets/* "$XDG_CONFIG_HOME/ardour7/export/"

step() {
  local name="$1"
  shift
  local t0=$SECONDS
  local tries=0 status=0
  # Ardour 7.3's headless tools crash now and then, with or without Ressort: a segmentation
  # fault or glibc's "free(): invalid next size" abort in its own export code
  # (`ARDOUR::PortExportChannel`'s buffer is overrun). A session of one empty MIDI track and no
  # plugin, exported three times by `simple_export`, aborted in 8 of 20 runs on the Dec 3
  # machine (docs/NOTES.md). A crash (SIGSEGV or SIGABRT) is run again, five times at most; a
  # tool that ends with an error, or a render that differs, is never retried.
  while true; do
    status=0
    "$@" >"$out/logs/$name.out" 2>"$out/logs/$name.err" || status=$?
    if { [ "$status" -eq 139 ] || [ "$status" -eq 134 ]; } && [ "$tries" -lt 5 ]; then
      tries=$((tries + 1))
      echo "ardour: $name crashed (signal $((status - 128))), running it again ($tries)" >&2
      # The build starts its session afresh; the crashed run may have left half of one.
      if [ "$name" = build ]; then rm -rf "$out/session"; fi
      continue
    fi
    break
  done
  if [ "$status" -ne 0 ]; then
    echo "ardour: $name failed:" >&2
    tail -n 20 "$out/logs/$name.out" "$out/logs/$name.err" >&2
    exit 1
  fi
  grep -h '^\[ressort\]' "$out/logs/$name.out" | sed "s/^/ardour: $name: /" || true
  echo "ardour: $name took $((SECONDS - t0)) s"
}

# Lua cannot scan for plugins: Ardour's scanner writes the bundle into the cache it reads.
step scan env LD_LIBRARY_PATH=/usr/lib/ardour7 /usr/lib/ardour7/ardour-vst3-scanner \
  -f "$out/vst3/Ressort.vst3"
step build ardour7-lua "$here/session.lua" build "$out/session" ressort "$out" "$preset"
step reload ardour7-lua "$here/session.lua" export "$out/session" ressort "$out" "$preset" reload 2
step tool ardour7-export -b float -s 48000 -o "$out/tool.wav" "$out/session" ressort
