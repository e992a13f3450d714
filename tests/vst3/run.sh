#!/usr/bin/env bash
# Runs the VST3 end-to-end tests (tests/vst3/test_*.py) in pedalboard and DawDreamer, two
# JUCE-based VST3 hosts from PyPI, on target/bundled/Ressort.vst3. The hosts and pytest are
# installed into a virtual environment, target/vst3-venv, made again when
# tests/vst3/requirements.txt changes. Extra arguments go to pytest.
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/vst3-venv
requirements=tests/vst3/requirements.txt
if [ ! -x "$venv/bin/python" ] || ! cmp -s "$requirements" "$venv/requirements.txt"; then
  rm -rf "$venv"
  python3 -m venv "$venv"
  "$venv/bin/python" -m pip install -q --disable-pip-version-check -r "$requirements"
  cp "$requirements" "$venv/requirements.txt"
fi
cd tests/vst3
exec "../../$venv/bin/python" -m pytest -q "$@"
