"""Helpers for the VST3 end-to-end tests: where the bundle is, plugin states as .vstpreset
files, and the measures the tests apply to rendered audio."""

import json
import os
import struct
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]

#: The plugin's VST3 class ID (`Vst3Plugin::VST3_CLASS_ID`), as 16 bytes.
CLASS_ID = b"RessortMassInter"


def bundle() -> Path:
    """The VST3 bundle under test: $RESSORT_VST3, or the one `cargo xtask bundle` made."""
    path = Path(os.environ.get("RESSORT_VST3", REPO / "target" / "bundled" / "Ressort.vst3"))
    if not path.exists():
        raise FileNotFoundError(
            f"{path} does not exist: run `cargo xtask bundle ressort-plugin` first"
        )
    return path


def shared_script(name: str) -> str:
    """A script of tests/models/, shared with the CLAP end-to-end tests."""
    return (REPO / "tests" / "models" / name).read_text()


def model_state(name: str, script: str, params: dict | None = None) -> bytes:
    """A plugin state (nice-plug's JSON) that loads `script` as the running model and sets
    the given parameters (plain values by id: an int for an integer parameter such as
    `voices`, a float otherwise); the others keep their defaults."""
    def value(v):
        return {"i32": v} if isinstance(v, int) else {"f32": float(v)}

    state = {
        "version": "0.1.0",
        "params": {id: value(v) for id, v in (params or {}).items()},
        "fields": {"model": json.dumps({"name": name, "script": script})},
    }
    return json.dumps(state).encode()


def write_vstpreset(path: Path, component_state: bytes) -> Path:
    """Writes a VST3 preset file (the SDK's PresetFile layout: header, one 'Comp' chunk, the
    chunk list) holding `component_state`."""
    header_size = 4 + 4 + 32 + 8
    class_id = CLASS_ID.hex().upper().encode()
    list_offset = header_size + len(component_state)
    data = bytearray()
    data += b"VST3" + struct.pack("<i", 1) + class_id + struct.pack("<q", list_offset)
    data += component_state
    data += b"List" + struct.pack("<i", 1)
    data += b"Comp" + struct.pack("<qq", header_size, len(component_state))
    path.write_bytes(bytes(data))
    return path


def peak_frequency(signal: np.ndarray, sample_rate: float) -> float:
    """The strongest spectral peak of `signal` (Hann window, parabolic interpolation on the
    log magnitude), in Hz."""
    x = np.asarray(signal, dtype=np.float64)
    x = x - x.mean()
    n = len(x)
    spectrum = np.abs(np.fft.rfft(x * np.hanning(n)))
    k = int(np.argmax(spectrum[1:-1])) + 1
    a, b, c = np.log(spectrum[k - 1 : k + 2] + 1e-300)
    delta = 0.5 * (a - c) / (a - 2 * b + c) if (a - 2 * b + c) != 0 else 0.0
    return (k + delta) * sample_rate / n


def cents(f: float, reference: float) -> float:
    return 1200.0 * np.log2(f / reference)


def oscillator_frequency(m: float, k: float, sample_rate: float) -> float:
    """The exact discrete law of a mass-spring oscillator (spec §5.3) for a script tuned at
    44.1 kHz: K is scaled by (44100/SR)², and sin²(πf/SR) = K/4M."""
    k_step = k * (44100.0 / sample_rate) ** 2
    return sample_rate / np.pi * np.arcsin(np.sqrt(k_step / (4.0 * m)))


def kicks(channels: int, frames: int, every: int, sample_rate: float, peak_db: float = -6.0) -> np.ndarray:
    """A kick drum every `every` samples on every channel, from sample 0: a sine gliding 120 →
    50 Hz under a 60 ms decay, each hit peaking at `peak_db` dBFS (the drum of issue 36)."""
    t = np.arange(int(0.4 * sample_rate)) / sample_rate
    phase = np.cumsum(2 * np.pi * (50 + 70 * np.exp(-t / 0.03)) / sample_rate)
    hit = np.exp(-t / 0.06) * np.sin(phase)
    hit *= 10 ** (peak_db / 20) / np.abs(hit).max()
    audio = np.zeros((channels, frames), dtype=np.float32)
    for start in range(0, frames, every):
        n = min(len(hit), frames - start)
        audio[:, start : start + n] += hit[:n].astype(np.float32)
    return audio


def clicks(channels: int, frames: int, every: int, value: float) -> np.ndarray:
    """A click train: `value` every `every` samples on every channel, from sample 0."""
    audio = np.zeros((channels, frames), dtype=np.float32)
    audio[:, ::every] = value
    return audio


def read_float_wav(path: Path) -> tuple[int, np.ndarray]:
    """The sample rate and samples (frames × channels) of a 32-bit float WAV file. Reads the
    `data` chunk only: libsndfile's PEAK chunk holds a time stamp, so two exports of the same
    audio differ as files."""
    data = Path(path).read_bytes()
    if data[:4] != b"RIFF" or data[8:12] != b"WAVE":
        raise ValueError(f"{path}: not a WAV file")
    pos, fmt, samples = 12, None, None
    while pos + 8 <= len(data):
        chunk, size = data[pos:pos + 4], struct.unpack_from("<I", data, pos + 4)[0]
        body = data[pos + 8:pos + 8 + size]
        if chunk == b"fmt ":
            tag, channels, rate, _, _, bits = struct.unpack_from("<HHIIHH", body)
            if tag == 0xFFFE:  # WAVE_FORMAT_EXTENSIBLE: the format is the subformat's
                tag = struct.unpack_from("<H", body, 24)[0]
            fmt = (tag, channels, rate, bits)
        elif chunk == b"data":
            samples = body
        pos += 8 + size + (size & 1)
    if fmt is None or samples is None:
        raise ValueError(f"{path}: no fmt or data chunk")
    tag, channels, rate, bits = fmt
    if (tag, bits) != (3, 32):
        raise ValueError(f"{path}: format {tag} with {bits} bits, not 32-bit float")
    return rate, np.frombuffer(samples, dtype="<f4").reshape(-1, channels)
