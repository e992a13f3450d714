//! The event stage's vocabulary: notes, pitch bend and strikes at their sample, as a host (or
//! a MIDI file, or the editor) delivers them.

/// What happens at one sample of a block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// A MIDI note: retunes the model to `note` (relative to the script's `~key`) from this
    /// sample on and strikes its note input with `velocity` (0 … 1) through the velocity
    /// curve. With voices, it takes a voice of its own. `channel` (0 … 15) and the host's
    /// `voice_id` identify the voice when it ends.
    NoteOn {
        note: u8,
        velocity: f32,
        channel: u8,
        voice_id: Option<i32>,
    },
    /// The end of a note. A struck model rings on; with voices, its voice is released.
    NoteOff {
        note: u8,
        channel: u8,
        voice_id: Option<i32>,
    },
    /// Pitch bend, 0 … 1 with 0.5 at rest, on MIDI channel `channel` (0 … 15). Scaled by the
    /// Bend Range; with MPE on, a member channel's bend (channels 1 … 15) moves only the voices
    /// of that channel, by ±[`MPE_MEMBER_BEND_ST`].
    PitchBend { value: f32, channel: u8 },
    /// Pressure, 0 … 1: of one note (`note`/`voice_id` set: polyphonic aftertouch, the CLAP
    /// pressure expression) or of a channel (channel pressure; with MPE on, a member channel's
    /// voices). It drives the script's `~pressure` input.
    Pressure {
        value: f32,
        channel: u8,
        note: Option<u8>,
        voice_id: Option<i32>,
    },
    /// A note's own tuning in semitones (the CLAP tuning expression).
    Tuning {
        semitones: f32,
        channel: u8,
        note: Option<u8>,
        voice_id: Option<i32>,
    },
    /// Polyphonic modulation of one voice's Stiffness or Damping, in octaves of the gain.
    Modulation {
        target: Modulated,
        octaves: f32,
        voice_id: i32,
    },
    /// A strike without retuning (the editor's Strike and Audition), `velocity` 0 … 1,
    /// linear.
    Strike { velocity: f32 },
    /// A MIDI control change, `value` 0 … 1: it moves the macro slots mapped to `cc`
    /// ([`super::Instrument::set_cc_map`]) from this sample on, until the host moves them.
    Controller { cc: u8, value: f32 },
}

impl Event {
    /// A note-on on channel 0 without a host voice id.
    pub fn note_on(note: u8, velocity: f32) -> Event {
        Event::NoteOn {
            note,
            velocity,
            channel: 0,
            voice_id: None,
        }
    }

    /// A note-off on channel 0.
    pub fn note_off(note: u8) -> Event {
        Event::NoteOff {
            note,
            channel: 0,
            voice_id: None,
        }
    }
}

/// What a [`Event::Modulation`] moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Modulated {
    Stiffness,
    Damping,
}

/// The pitch-bend range of an MPE member channel (the MPE specification's default).
pub const MPE_MEMBER_BEND_ST: f64 = 48.0;

/// An event at sample `timing` of the block being processed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timed {
    pub timing: u32,
    pub event: Event,
}

impl Timed {
    pub fn new(timing: u32, event: Event) -> Timed {
        Timed { timing, event }
    }
}

/// A velocity through the curve: v^exponent, for v clamped to 0 … 1 (NaN reads 0).
#[inline]
pub fn velocity_response(velocity: f32, exponent: f64) -> f64 {
    let v = if velocity.is_finite() {
        (velocity as f64).clamp(0.0, 1.0)
    } else {
        0.0
    };
    if exponent == 1.0 || !exponent.is_finite() {
        v
    } else {
        v.powf(exponent)
    }
}

/// A pitch-bend value as semitones: (value − ½) × 2 × range; NaN reads as the centre.
#[inline]
pub fn bend_semitones(value: f32, range_st: f64) -> f64 {
    let v = if value.is_finite() {
        value.clamp(0.0, 1.0) as f64
    } else {
        0.5
    };
    (v - 0.5) * 2.0 * range_st
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bend_spans_the_range_both_ways() {
        assert_eq!(bend_semitones(0.5, 2.0), 0.0);
        assert_eq!(bend_semitones(1.0, 2.0), 2.0);
        assert_eq!(bend_semitones(0.0, 48.0), -48.0);
        assert_eq!(bend_semitones(f32::NAN, 12.0), 0.0);
        assert_eq!(bend_semitones(7.0, 12.0), 12.0);
    }

    #[test]
    fn velocity_curve_bends_the_middle_and_keeps_the_ends() {
        assert_eq!(velocity_response(0.5, 1.0), 0.5);
        assert!((velocity_response(0.5, 2.0) - 0.25).abs() < 1e-12);
        assert!((velocity_response(0.25, 0.5) - 0.5).abs() < 1e-12);
        for e in [0.25, 1.0, 4.0] {
            assert_eq!(velocity_response(1.0, e), 1.0);
            assert_eq!(velocity_response(0.0, e), 0.0);
        }
        assert_eq!(velocity_response(f32::NAN, 2.0), 0.0);
        assert_eq!(velocity_response(3.0, 2.0), 1.0);
    }
}
