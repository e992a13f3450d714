//! Expression: what moves one voice after its note-on. MPE pitch bend and channel pressure,
//! CLAP note expressions (tuning, pressure), polyphonic modulation of Stiffness and Damping,
//! and MIDI controllers (the sustain pedal, macro slots). A voice whose pitch or gains moved
//! is re-tuned by the exact law and the stability clamp before its next sample.

use super::*;

/// Gains worked out for the voices tuned in one pass over the bank, by the bits of a voice's
/// own inputs (note, Release, modulation): voices on the same note share them. Every entry was
/// computed from the same smoothed controls, so a hit gives the gains the voice would have
/// computed, bit for bit ([`Smoothed::gains_offset`] is a function of its inputs). Cleared
/// before each pass; kept in the instrument so that a pass writes no table on the stack.
#[derive(Debug)]
pub(super) struct SharedGains {
    entries: [([u64; 4], Gains); SharedGains::SIZE],
    len: usize,
    next: usize,
}

impl SharedGains {
    const SIZE: usize = 32;

    pub(super) fn new() -> SharedGains {
        SharedGains {
            entries: [([0; 4], Gains::default()); SharedGains::SIZE],
            len: 0,
            next: 0,
        }
    }

    /// Empties the table for a pass with other smoothed controls.
    pub(super) fn clear(&mut self) {
        self.len = 0;
        self.next = 0;
    }

    fn get(&self, key: &[u64; 4]) -> Option<Gains> {
        self.entries[..self.len]
            .iter()
            .find(|(k, _)| k == key)
            .map(|&(_, g)| g)
    }

    fn insert(&mut self, key: [u64; 4], g: Gains) {
        self.entries[self.next] = (key, g);
        self.next = (self.next + 1) % SharedGains::SIZE;
        self.len = (self.len + 1).min(SharedGains::SIZE);
    }
}

/// Puts a voice's gains on its engine: its note, MPE bend and tuning, its polyphonic
/// modulation, and the Release damper (`release`, a Damping factor) once its key is up.
/// `shared` holds the gains of voices tuned before it with the same smoothed controls.
pub(super) fn tune_voice(
    smoothed: &Smoothed,
    controls: &ControlsKey,
    view: &ClampView<'_>,
    bank: &mut voices::VoiceBank,
    i: usize,
    release: f64,
    shared: &mut SharedGains,
) -> Gains {
    let v = &mut bank.voices[i];
    let z = if v.state == VoiceState::Released {
        release
    } else {
        1.0
    };
    let note_st = v.note_st + v.bend_st + v.tuning_st;
    // Every chunk re-tunes every voice; most of the time nothing moved (the exact law and
    // the clamp cost more than a small voice's 16 samples).
    let key = TuneKey::new(controls, note_st, z, v.mod_k, v.mod_z);
    if let Some((k, g)) = v.tuned {
        if k == key {
            return g;
        }
    }
    let own = [note_st, z, v.mod_k, v.mod_z].map(f64::to_bits);
    let g = match shared.get(&own) {
        Some(g) => g,
        None => {
            let g = smoothed.gains_offset(view, note_st, z, v.mod_k, v.mod_z, &mut v.tuning);
            shared.insert(own, g);
            g
        }
    };
    v.tuned = Some((key, g));
    smoothed.set(&mut bank.copy(i), view.macros, &g);
    g
}

/// A value in 0 … 1 (NaN reads 0).
fn unit(v: f32) -> f64 {
    if v.is_finite() {
        (v as f64).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

fn push(list: &mut [usize; 64], n: &mut usize, i: usize) {
    if *n < list.len() {
        list[*n] = i;
        *n += 1;
    }
}

impl Instrument {
    /// Tunes and sets up voice `i` of the bank for its note, before its first sample.
    pub(super) fn apply_voice(&mut self, i: usize) {
        let Some(m) = self.current.as_deref_mut() else {
            return;
        };
        let Some(bank) = m.bank.as_mut() else {
            return;
        };
        let view = clamp_view!(m);
        let release = 16f64.powf(self.controls.release);
        self.shared_gains.clear();
        self.gains = tune_voice(
            &self.smoothed,
            &self.smoothed.controls_key(),
            &view,
            bank,
            i,
            release,
            &mut self.shared_gains,
        );
    }

    /// An expression event: MPE bend, pressure, note tuning, polyphonic modulation. Returns
    /// whether the monophonic model's pitch changed (a chunk starts at its sample).
    pub(super) fn expression(&mut self, event: Event) -> bool {
        let mpe = self.controls.mpe;
        let Some(m) = self.current.as_deref_mut() else {
            return false;
        };
        let Some(bank) = m.bank.as_mut() else {
            // One model: pressure and tuning are the model's own.
            return match event {
                Event::Pressure { value, .. } => {
                    self.pressure = unit(value);
                    false
                }
                Event::Tuning { semitones, .. } if semitones.is_finite() => {
                    self.tuning_st = semitones as f64;
                    true
                }
                _ => false,
            };
        };
        let mut retune = [0usize; 64];
        let mut n = 0;
        match event {
            Event::PitchBend { value, channel } => {
                let st = events::bend_semitones(value, events::MPE_MEMBER_BEND_ST);
                self.channel_bend[channel as usize % 16] = st;
                for i in 0..bank.voices.len() {
                    if !bank.addresses(i, None, None, channel) {
                        continue;
                    }
                    bank.voices[i].bend_st = st;
                    push(&mut retune, &mut n, i);
                }
            }
            Event::Pressure {
                value,
                channel,
                note,
                voice_id,
            } => {
                let v = unit(value);
                if note.is_none() && voice_id.is_none() && !(mpe && channel != 0) {
                    // Channel pressure without MPE: every voice, and the model itself.
                    self.pressure = v;
                    for voice in bank.voices.iter_mut() {
                        voice.pressure = v;
                    }
                } else {
                    if note.is_none() && voice_id.is_none() {
                        self.channel_pressure[channel as usize % 16] = v;
                    }
                    for i in 0..bank.voices.len() {
                        if !bank.addresses(i, voice_id, note, channel) {
                            continue;
                        }
                        bank.voices[i].pressure = v;
                    }
                }
            }
            Event::Tuning {
                semitones,
                channel,
                note,
                voice_id,
            } if semitones.is_finite() => {
                for i in 0..bank.voices.len() {
                    if !bank.addresses(i, voice_id, note, channel) {
                        continue;
                    }
                    bank.voices[i].tuning_st = semitones as f64;
                    push(&mut retune, &mut n, i);
                }
            }
            Event::Modulation {
                target,
                octaves,
                voice_id,
            } if octaves.is_finite() => {
                for i in 0..bank.voices.len() {
                    if !bank.addresses(i, Some(voice_id), None, 0) {
                        continue;
                    }
                    match target {
                        Modulated::Stiffness => bank.voices[i].mod_k = octaves as f64,
                        Modulated::Damping => bank.voices[i].mod_z = octaves as f64,
                    }
                    push(&mut retune, &mut n, i);
                }
            }
            _ => {}
        }
        for &i in &retune[..n] {
            self.apply_voice(i);
        }
        false
    }

    /// A control change: moves the slots mapped to `cc`. Returns whether one moved.
    pub(super) fn controller(&mut self, cc: u8, value: f32) -> bool {
        let v = if value.is_finite() {
            value.clamp(0.0, 1.0) as f64
        } else {
            return false;
        };
        if cc == SUSTAIN_CC {
            if let Some(bank) = self.current.as_deref_mut().and_then(|m| m.bank.as_mut()) {
                bank.set_sustain(v >= 0.5);
            }
        }
        let mut moved = false;
        for slot in 0..NUM_MACROS {
            if self.cc_map[slot] == Some(cc) {
                self.cc_macros[slot] = Some(v);
                moved |= self.controls.macros[slot] != v;
                self.controls.macros[slot] = v;
            }
        }
        moved
    }
}
