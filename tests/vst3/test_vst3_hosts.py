"""End-to-end tests of Ressort.vst3 in two JUCE-based VST3 hosts, pedalboard and DawDreamer:
loading, parameters by value, MIDI notes at their pitch, state restored into a fresh instance,
and audio into the plugin striking the model.

The bundle is the one the test command builds (`assert_process_allocs`: an allocation in
process() aborts the host process, so these tests also check that in JUCE hosts).
"""

import time
from pathlib import Path

import dawdreamer as daw
import mido
import numpy as np
import pedalboard
import pytest

from ressort_vst3 import (
    bundle,
    cents,
    clicks,
    kicks,
    model_state,
    oscillator_frequency,
    peak_frequency,
    shared_script,
    write_vstpreset,
)

SR = 48_000

#: One oscillator (M = 1, K = 0.001, about 222 Hz) that MIDI notes strike directly, and a
#: small membrane with two bound macros (a model other than the default, for the state test).
#: The CLAP end-to-end tests play the same scripts.
OSCILLATOR = shared_script("low-oscillator.mdl")
OSC_M, OSC_K = 1.0, 0.001
SMALL_MESH = shared_script("small-mesh.mdl")


def routed_oscillator(source: str) -> str:
    """The oscillator, with its in1 fed by one host channel (`~route`)."""
    return OSCILLATOR + f"~route in1 {source}\n"



#: The MIDI controllers the VST3 plugin lists as proxies (`VST3_CONTROLLERS` in the plugin).
VST3_CONTROLLERS = [1, 2, 4, 7, 11, 16, 17, 18, 19, 64, 71, 72, 73, 74, "channel_pressure", "bend"]

#: The plugin's own parameters (before the MIDI controller proxies).
PARAMETERS = [
    "stiffness",
    "damping",
    "tune_st",
    "output_gain_db",
    "force_gain_db",
    "position_gain_db",
    "dc_filter",
    "guard_tripped",
    "model_edits",
    "voices",
    "release",
    "mpe",
    "bend_range_st",
    "velocity_curve",
    "a4_hz",
    "sidechain_trigger",
    "trigger_sensitivity_db",
] + [f"macro_{i}" for i in range(1, 17)]


@pytest.fixture
def preset_dir(tmp_path: Path) -> Path:
    return tmp_path


def preset(directory: Path, name: str, script: str, **params) -> str:
    state = model_state(name, script, params)
    return str(write_vstpreset(directory / f"{name}.vstpreset", state))


def note(key: int, velocity: int = 100) -> list:
    return [mido.Message("note_on", note=key, velocity=velocity, time=0.0)]


# ------------------------------------------------------------------------------------------
# pedalboard
# ------------------------------------------------------------------------------------------


def test_pedalboard_loads_the_plugin_with_its_parameters():
    plugin = pedalboard.load_plugin(str(bundle()))
    names = list(plugin.parameters.keys())
    assert names[: len(PARAMETERS)] == PARAMETERS
    # VST3 delivers MIDI controllers through hidden proxy parameters, one per controller and
    # channel: the plugin lists the ones MIDI learn offers and pitch bend, nothing else.
    proxies = names[len(PARAMETERS) :]
    def proxy(c, cc):
        if cc == "bend":
            return f"midi_ch_{c}_pitch_bend"
        if cc == "channel_pressure":
            return f"midi_ch_{c}_channel_pressure"
        return f"midi_ch_{c}_cc_{cc}"

    expected = [proxy(c, cc) for c in range(1, 17) for cc in VST3_CONTROLLERS]
    assert proxies == expected, proxies
    assert plugin.is_instrument


def test_pedalboard_reads_and_sets_parameters_by_value():
    plugin = pedalboard.load_plugin(str(bundle()))
    assert plugin.stiffness == 1.0
    # A new model's level is set by its automatic trim; Output Gain adds to it.
    assert plugin.output_gain_db == 0.0
    assert plugin.a4_hz == 440.0
    plugin.stiffness = 4
    assert plugin.stiffness == 4.0
    assert plugin.parameters["stiffness"].raw_value == pytest.approx(0.75, abs=1e-6)
    plugin.damping = 0.25
    assert plugin.damping == 0.25
    plugin.output_gain_db = -6
    assert plugin.output_gain_db == -6.0
    plugin.tune_st = 3
    assert plugin.tune_st == 3.0
    plugin.force_gain_db = -12.5
    assert plugin.force_gain_db == -12.5


def test_pedalboard_plays_midi_notes_at_their_pitch(preset_dir):
    plugin = pedalboard.load_plugin(str(bundle()))
    plugin.load_preset(preset(preset_dir, "oscillator", OSCILLATOR, output_gain=-20.0))
    f0 = oscillator_frequency(OSC_M, OSC_K, SR)
    # Note 60 is the model's key: it plays as written. Other notes follow the exact law.
    for key, semitones in [(60, 0), (72, 12), (67, 7), (55, -5)]:
        plugin.reset()
        out = plugin(note(key), duration=1.0, sample_rate=SR)
        assert np.isfinite(out).all()
        assert np.abs(out).max() > 0.01, f"note {key} is silent"
        f = peak_frequency(out[0], SR)
        expected = f0 * 2 ** (semitones / 12)
        print(f"note {key}: {f:.3f} Hz, expected {expected:.3f} Hz")
        assert abs(cents(f, expected)) < 3.0, f"note {key}: {f:.3f} Hz, not {expected:.3f} Hz"


#: A hammer on an oscillator: each voice is nonlinear on its own.
STRUCK = shared_script("struck-oscillator.mdl")


def test_pedalboard_plays_a_chord_as_the_sum_of_its_notes(preset_dir):
    # Notes 60, 64 and 67 started 0.25 s apart and held: with 8 voices the chord is the three
    # notes played alone, summed (with one voice it was 157 % off).
    plugin = pedalboard.load_plugin(str(bundle()))
    plugin.load_preset(preset(preset_dir, "struck", STRUCK, voices=8, output_gain=-20.0))

    def notes(keys):
        return [
            mido.Message("note_on", note=k, velocity=100, time=0.25 * i)
            for i, k in enumerate([60, 64, 67])
            if k in keys
        ]

    plugin.reset()
    chord = plugin(notes([60, 64, 67]), duration=1.5, sample_rate=SR)
    total = np.zeros_like(chord, dtype=np.float64)
    for k in [60, 64, 67]:
        plugin.reset()
        total += plugin(notes([k]), duration=1.5, sample_rate=SR)
    level = np.abs(chord).max()
    error = np.abs(chord - total).max()
    print(f"chord peak {level:.4f}, largest difference from the sum {error:.2e}")
    assert 1e-3 < level < 0.5
    # The README's bar for a chord (10⁻⁶ of its peak, as in the CLAP test host).
    assert error <= 1e-6 * level


def test_pedalboard_hears_a_voices_change_without_reactivating(preset_dir):
    # A DAW does not re-activate a plugin when a parameter moves. Voices set from 1 to 8 while
    # the plugin runs (no reset in between) must play the chord as 8 voices do from the start:
    # the VST3 wrapper runs no main-thread task for it, so the plugin's own thread applies it.
    chord = [
        mido.Message("note_on", note=k, velocity=100, time=0.25 * i)
        for i, k in enumerate([60, 64, 67])
    ]
    silence = []

    def play(plugin, change_voices):
        plugin.reset()
        plugin(silence, duration=0.2, sample_rate=SR)
        if change_voices:
            plugin.parameters["voices"].raw_value = 8 / 128
            plugin(silence, duration=0.05, sample_rate=SR, reset=False)
            time.sleep(0.5)
        plugin(silence, duration=0.1, sample_rate=SR, reset=False)
        return plugin(chord, duration=1.5, sample_rate=SR, reset=False)

    changed = pedalboard.load_plugin(str(bundle()))
    changed.load_preset(preset(preset_dir, "mono", STRUCK, voices=1, output_gain=-20.0))
    played = play(changed, True)
    assert changed.voices == "8"
    fresh = pedalboard.load_plugin(str(bundle()))
    fresh.load_preset(preset(preset_dir, "poly", STRUCK, voices=8, output_gain=-20.0))
    expected = play(fresh, False)
    level = np.abs(expected).max()
    error = np.abs(played - expected).max()
    print(f"chord peak {level:.4f}, largest difference from 8 voices from the start {error:.2e}")
    assert 1e-3 < level < 0.5
    assert error <= 1e-6 * level


def test_pedalboard_restores_state_bit_identically_into_a_fresh_instance(preset_dir):
    first = pedalboard.load_plugin(str(bundle()))
    first.load_preset(preset(preset_dir, "small-mesh", SMALL_MESH))
    first.stiffness = 2
    first.parameters["macro_1"].raw_value = 0.7
    first.output_gain_db = 6
    # JUCE hosts hand parameter changes to the plugin with the next audio block.
    first(note(60), duration=0.1, sample_rate=SR)
    state = first.raw_state

    second = pedalboard.load_plugin(str(bundle()))
    second.raw_state = state
    assert second.raw_state == state
    assert second.stiffness == 2.0
    assert second.output_gain_db == 6.0

    renders = []
    for plugin in (first, second):
        plugin.reset()
        renders.append(plugin(note(64), duration=1.0, sample_rate=SR))
    assert np.abs(renders[0]).max() > 1e-3
    assert np.array_equal(renders[0], renders[1])
    # The restored instance plays the small mesh, not the default model.
    default = pedalboard.load_plugin(str(bundle()))
    default.stiffness = 2
    default.output_gain_db = 6
    other = default(note(64), duration=1.0, sample_rate=SR)
    assert not np.array_equal(renders[0], other)


def test_pedalboard_audio_input_strikes_the_model():
    # pedalboard enables the main input and switches the sidechain off where it can: the
    # plugin runs in its "Effect" layout, and the main input's left channel is @in1. A kick at
    # -6 dBFS strikes the default model (Mesh 15x15) like a medium note, four times a second.
    plugin = pedalboard.load_plugin(str(bundle()))
    struck = plugin(kicks(2, SR, SR // 4, SR), SR)
    assert struck.shape == (2, SR)
    assert np.isfinite(struck).all()
    plugin.reset()
    silent = plugin(np.zeros((2, SR), dtype=np.float32), SR)
    print(f"peak struck {np.abs(struck).max():.4f}, silent input {np.abs(silent).max():.2e}")
    assert np.abs(silent).max() == 0.0
    # Like a note (-12 dBFS at velocity 0.8) within 6 dB, below the soft ceiling's knee.
    assert 0.125 < np.abs(struck).max() < 0.5
    # Every kick strikes: the output rises within 25 ms after each one.
    for n in range(4):
        start = n * SR // 4
        window = struck[0, start : start + SR // 40]
        assert np.abs(window).max() > 0.01, f"kick {n} did not strike"


# ------------------------------------------------------------------------------------------
# DawDreamer
# ------------------------------------------------------------------------------------------


def render_dawdreamer(setup, seconds: float = 1.0) -> np.ndarray:
    engine = daw.RenderEngine(SR, 512)
    graph = setup(engine)
    engine.load_graph(graph)
    engine.render(seconds)
    return engine.get_audio()


def test_dawdreamer_loads_the_plugin_with_stereo_input_and_output():
    engine = daw.RenderEngine(SR, 512)
    plugin = engine.make_plugin_processor("ressort", str(bundle()))
    assert plugin.get_num_input_channels() == 2
    assert plugin.get_num_output_channels() == 2
    names = [plugin.get_parameter_name(i) for i in range(plugin.get_plugin_parameter_size())]
    assert names[:3] == ["Stiffness", "Damping", "Tune"]
    assert len(names) == len(PARAMETERS) + 16 * len(VST3_CONTROLLERS)


def test_dawdreamer_sidechain_kicks_strike_the_model():
    def with_drum(audio):
        def setup(engine):
            plugin = engine.make_plugin_processor("ressort", str(bundle()))
            source = engine.make_playback_processor("drum", audio)
            return [(source, []), (plugin, ["drum"])]

        return setup

    struck = render_dawdreamer(with_drum(kicks(2, SR, SR // 4, SR)))
    silent = render_dawdreamer(with_drum(np.zeros((2, SR), dtype=np.float32)))
    print(f"peak struck {np.abs(struck).max():.4f}, silent input {np.abs(silent).max():.2e}")
    assert np.isfinite(struck).all()
    assert np.abs(silent).max() == 0.0
    assert 0.125 < np.abs(struck).max() < 0.5


def test_dawdreamer_plays_a_preset_and_a_midi_note_at_its_pitch(preset_dir):
    path = preset(preset_dir, "oscillator", OSCILLATOR, output_gain=-20.0)

    def setup(engine):
        plugin = engine.make_plugin_processor("ressort", str(bundle()))
        assert plugin.load_vst3_preset(path)
        plugin.add_midi_note(72, 100, 0.0, 0.5)
        return [(plugin, [])]

    out = render_dawdreamer(setup)
    f = peak_frequency(out[0], SR)
    expected = 2 * oscillator_frequency(OSC_M, OSC_K, SR)
    print(f"note 72: {f:.3f} Hz, expected {expected:.3f} Hz")
    assert abs(cents(f, expected)) < 3.0


def test_dawdreamer_parameters_by_value():
    def setup(engine):
        plugin = engine.make_plugin_processor("ressort", str(bundle()))
        # DawDreamer sets normalized values; the plugin's text says what they mean.
        plugin.set_parameter(0, 0.75)
        assert plugin.get_parameter_text(0) == "4.00"
        plugin.set_parameter(3, (-6.0 + 40.0) / 100.0)
        assert plugin.get_parameter_text(3) == "-6.0"
        return [(plugin, [])]

    render_dawdreamer(setup, seconds=0.1)


def test_pedalboard_feeds_the_main_input_of_the_effect_layout(preset_dir):
    peaks = {}
    for source in ("main_left", "sidechain_left"):
        plugin = pedalboard.load_plugin(str(bundle()))
        plugin.load_preset(preset(preset_dir, source, routed_oscillator(source), output_gain=-20.0))
        out = plugin(clicks(2, SR, SR // 10, 0.05), SR)
        peaks[source] = float(np.abs(out).max())
    print(f"peaks by the channel feeding in1: {peaks}")
    assert peaks["main_left"] > 0.01
    assert peaks["sidechain_left"] == 0.0


def test_dawdreamer_negotiates_the_instrument_and_the_effect_layout(preset_dir):
    # DawDreamer's plugin input takes its channels from the first active input busses. As
    # loaded, the main input is off (the VST3's default is the instrument layout), so they go
    # to the sidechain; with every bus enabled the plugin runs "Effect with sidechain" and
    # they go to the main input. A model whose in1 listens to one channel tells which.
    peaks = {}
    for enable_all in (False, True):
        for source in ("main_left", "sidechain_left"):
            path = preset(preset_dir, source, routed_oscillator(source), output_gain=-20.0)

            def setup(engine):
                plugin = engine.make_plugin_processor("ressort", str(bundle()))
                assert plugin.load_vst3_preset(path)
                if enable_all:
                    plugin.enable_all_buses()
                source_clicks = engine.make_playback_processor(
                    "clicks", clicks(2, SR, SR // 10, 0.05)
                )
                return [(source_clicks, []), (plugin, ["clicks"])]

            out = render_dawdreamer(setup)
            assert np.isfinite(out).all()
            peaks[(enable_all, source)] = float(np.abs(out).max())
    print(f"peaks by (every bus enabled, channel feeding in1): {peaks}")
    assert peaks[(False, "sidechain_left")] > 0.01
    assert peaks[(False, "main_left")] == 0.0
    assert peaks[(True, "main_left")] > 0.01
    assert peaks[(True, "sidechain_left")] == 0.0
