"""Ardour 7.3, a real DAW, exports an automated session with Ressort's VST3 (issue 40: a
bounce with automation must not depend on when the host activated the plugin, nor on the
process that renders it). tests/ardour/export.sh makes the session and the exports."""

import subprocess

import numpy as np

from ressort_vst3 import REPO, bundle, read_float_wav

RATE = 48000


def test_ardour_exports_an_automated_session_bit_identically(tmp_path):
    run = subprocess.run(
        ["bash", str(REPO / "tests" / "ardour" / "export.sh"), str(bundle()), str(tmp_path)],
        capture_output=True, text=True, timeout=600,
    )
    print(run.stdout)
    assert run.returncode == 0, run.stdout + run.stderr

    def load(name):
        rate, audio = read_float_wav(tmp_path / f"{name}.wav")
        assert rate == RATE and audio.shape == (5 * RATE, 2), (name, rate, audio.shape)
        return audio

    reference = load("build_1")
    assert np.isfinite(reference).all()
    peak = float(np.abs(reference).max())
    print(f"build_1: peak {20 * np.log10(peak):.1f} dBFS")
    assert 0.01 < peak < 1.0, peak
    # The notes sound from 0.25 s; the automation moves Stiffness from 1 s.
    assert np.abs(reference[int(0.3 * RATE):int(0.5 * RATE)]).max() > 1e-3

    for name in ["build_2", "build_3", "reload_1", "reload_2", "tool"]:
        other = load(name)
        diff = float(np.abs(other - reference).max())
        print(f"{name}: max difference from build_1 {diff:.3g}")
        assert np.array_equal(other, reference), f"{name} differs from build_1 by {diff}"

    # The automation is heard: without it, the same before 1 s and different after.
    plain = load("noauto")
    assert np.array_equal(plain[:RATE], reference[:RATE])
    moved = np.abs(plain[RATE:] - reference[RATE:]).max()
    print(f"noauto: max difference from build_1 after 1 s {moved:.3g}")
    assert moved > 1e-2, moved
