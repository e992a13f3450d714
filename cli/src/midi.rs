//! Standard MIDI files (types 0 and 1, read with `midly`) as the instrument's events at
//! absolute sample times: notes, pitch bend and control changes of every track and channel, with
//! the file's tempo map (metrical time) or its SMPTE rate (timecode).

use midly::{MetaMessage, MidiMessage, Smf, Timing, TrackEventKind};
use ressort_engine::instrument::Event;

/// The default tempo of a MIDI file without a tempo event: 120 beats per minute.
const DEFAULT_MICROS_PER_BEAT: f64 = 500_000.0;

/// Every note and bend of `bytes` at its sample (at `sample_rate`), in time order (events of
/// one instant keep their file order).
pub fn read_events(bytes: &[u8], sample_rate: f64) -> Result<Vec<(u64, Event)>, String> {
    let smf = Smf::parse(bytes).map_err(|e| format!("not a readable MIDI file: {e}"))?;
    // (tick, track, index) keeps simultaneous events in file order across tracks.
    let mut timed: Vec<(u64, usize, usize, TrackEventKind)> = Vec::new();
    for (t, track) in smf.tracks.iter().enumerate() {
        let mut tick: u64 = 0;
        for (i, e) in track.iter().enumerate() {
            tick += u64::from(e.delta.as_int());
            timed.push((tick, t, i, e.kind));
        }
    }
    timed.sort_by_key(|&(tick, t, i, _)| (tick, t, i));

    let seconds_per_tick_fixed = match smf.header.timing {
        Timing::Metrical(_) => None,
        Timing::Timecode(fps, sub) => Some(1.0 / (fps.as_f32() as f64 * sub.max(1) as f64)),
    };
    let ticks_per_beat = match smf.header.timing {
        Timing::Metrical(t) => t.as_int().max(1) as f64,
        Timing::Timecode(..) => 1.0,
    };
    let mut micros_per_beat = DEFAULT_MICROS_PER_BEAT;
    let (mut last_tick, mut seconds) = (0u64, 0.0f64);
    let mut out = Vec::new();
    for (tick, _, _, kind) in timed {
        let per_tick = seconds_per_tick_fixed.unwrap_or(micros_per_beat * 1e-6 / ticks_per_beat);
        seconds += (tick - last_tick) as f64 * per_tick;
        last_tick = tick;
        let sample = (seconds * sample_rate).round() as u64;
        match kind {
            TrackEventKind::Meta(MetaMessage::Tempo(t)) => {
                micros_per_beat = f64::from(t.as_int()).max(1.0);
            }
            TrackEventKind::Midi { message, channel } => {
                let channel = channel.as_int();
                let event = match message {
                    MidiMessage::NoteOn { key, vel } if vel.as_int() > 0 => Event::NoteOn {
                        channel,
                        voice_id: None,
                        note: key.as_int(),
                        velocity: vel.as_int() as f32 / 127.0,
                    },
                    MidiMessage::NoteOn { key, .. } | MidiMessage::NoteOff { key, .. } => {
                        Event::NoteOff {
                            channel,
                            voice_id: None,
                            note: key.as_int(),
                        }
                    }
                    MidiMessage::PitchBend { bend } => Event::PitchBend {
                        value: (bend.as_int() as f32 + 8192.0) / 16383.0,
                        channel,
                    },
                    MidiMessage::ChannelAftertouch { vel } => Event::Pressure {
                        value: vel.as_int() as f32 / 127.0,
                        channel,
                        note: None,
                        voice_id: None,
                    },
                    MidiMessage::Aftertouch { key, vel } => Event::Pressure {
                        value: vel.as_int() as f32 / 127.0,
                        channel,
                        note: Some(key.as_int()),
                        voice_id: None,
                    },
                    MidiMessage::Controller { controller, value } => Event::Controller {
                        cc: controller.as_int(),
                        value: value.as_int() as f32 / 127.0,
                    },
                    _ => continue,
                };
                out.push((sample, event));
            }
            _ => {}
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use midly::num::{u15, u24, u28, u4, u7};
    use midly::{Format, Header, TrackEvent};

    fn file(timing: Timing, events: Vec<(u32, TrackEventKind<'static>)>) -> Vec<u8> {
        let track: Vec<TrackEvent> = events
            .into_iter()
            .map(|(delta, kind)| TrackEvent {
                delta: u28::new(delta),
                kind,
            })
            .collect();
        let smf = Smf {
            header: Header::new(Format::SingleTrack, timing),
            tracks: vec![track],
        };
        let mut bytes = Vec::new();
        smf.write_std(&mut bytes).unwrap();
        bytes
    }

    fn note_on(key: u8, vel: u8) -> TrackEventKind<'static> {
        TrackEventKind::Midi {
            channel: u4::new(0),
            message: MidiMessage::NoteOn {
                key: u7::new(key),
                vel: u7::new(vel),
            },
        }
    }

    #[test]
    fn ticks_follow_the_tempo_map() {
        // 480 ticks per beat; 120 bpm, then 60 bpm from beat 1.
        let bytes = file(
            Timing::Metrical(u15::new(480)),
            vec![
                (0, note_on(60, 127)),
                (480, note_on(64, 64)),
                (
                    0,
                    TrackEventKind::Meta(MetaMessage::Tempo(u24::new(1_000_000))),
                ),
                (480, note_on(67, 0)),
            ],
        );
        let events = read_events(&bytes, 48_000.0).unwrap();
        assert_eq!(events.len(), 3);
        assert_eq!(
            events[0],
            (
                0,
                Event::NoteOn {
                    channel: 0,
                    voice_id: None,
                    note: 60,
                    velocity: 1.0
                }
            )
        );
        assert_eq!(events[1].0, 24_000, "half a second at 120 bpm");
        assert_eq!(
            events[2],
            (
                72_000,
                Event::NoteOff {
                    channel: 0,
                    voice_id: None,
                    note: 67
                }
            ),
            "then 1 s"
        );
    }

    #[test]
    fn garbage_is_an_error() {
        assert!(read_events(b"RIFF....", 48_000.0).is_err());
        assert!(read_events(b"", 48_000.0).is_err());
    }
}
