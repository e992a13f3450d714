//! Voice upkeep between spans: the rest check that frees silent voices, and the packing of
//! sounding voices into as few lane groups as hold them.

use super::{group, Copies, Voice, VoiceBank, VoiceState, FREE_LEVEL, MOTION_CHECK};
use crate::sim::lanes::LANES;

impl VoiceBank {
    /// Counts a span of `len` samples; every [`MOTION_CHECK`] samples, measures every
    /// sounding voice's motion and frees the ones that have stayed silent long enough.
    /// Realtime-safe.
    pub fn free_silent(&mut self, len: usize) {
        self.unchecked += len as u64;
        if self.unchecked < MOTION_CHECK {
            return;
        }
        let len = std::mem::take(&mut self.unchecked);
        let mut levels = [0.0; LANES];
        for i in 0..self.voices.len() {
            // With lanes, a group's four levels at once, when its first voice comes up (the
            // positions the group last saw are its own, not the voices' `last`).
            if let Copies::Lanes(groups) = &mut self.copies {
                if i % LANES == 0
                    && self.voices[group(i / LANES, self.voices.len())]
                        .iter()
                        .any(|v| matches!(v.state, VoiceState::Held | VoiceState::Released))
                {
                    levels = groups[i / LANES].motion();
                }
            }
            let v = &mut self.voices[i];
            if !matches!(v.state, VoiceState::Held | VoiceState::Released) {
                continue;
            }
            if v.pressure > 0.0 || v.sustaining {
                // A key that still presses drives its voice, a bow still bows: it stays.
                v.quiet = 0;
                continue;
            }
            let level = match &self.copies {
                Copies::Engines(e) => e[i].motion_level(&mut v.last),
                Copies::Lanes(_) => levels[i % LANES],
            };
            v.level = level;
            if level < FREE_LEVEL {
                v.quiet += len as u64;
                if v.quiet >= self.free_after {
                    self.end(i);
                }
            } else {
                v.quiet = 0;
            }
        }
        self.pack();
    }

    /// Packs the voices into as few lane groups as hold them: while more groups run than
    /// their voices need, the voices of the emptiest running group move to free lanes of the
    /// fullest ones that have room. A group steps all its lanes while one voice sounds, so
    /// five voices spread over four groups cost sixteen lanes, packed eight. A moved voice
    /// goes on exactly as it would have (`LaneEngine::take_lane`); only the order in which
    /// the voices are summed changes. Realtime-safe.
    pub(super) fn pack(&mut self) {
        let Copies::Lanes(groups) = &mut self.copies else {
            return;
        };
        let voices = &mut self.voices;
        let busy = |voices: &[Voice], g: usize| {
            voices[group(g, voices.len())]
                .iter()
                .filter(|v| v.state != VoiceState::Free)
                .count()
        };
        loop {
            // The emptiest running group.
            let (mut running, mut total) = (0, 0);
            let mut from: Option<(usize, usize)> = None;
            for g in 0..groups.len() {
                let n = busy(voices, g);
                if n > 0 {
                    running += 1;
                    total += n;
                    if from.is_none_or(|(_, m)| n < m) {
                        from = Some((g, n));
                    }
                }
            }
            let Some((src, _)) = from else {
                return;
            };
            if running <= total.div_ceil(LANES) {
                return;
            }
            // The fullest other running group with a free lane (one exists: the others hold
            // all but the emptiest group's voices in fewer lanes than they have).
            let into = (0..groups.len())
                .filter(|&g| g != src)
                .map(|g| (g, busy(voices, g)))
                .filter(|&(g, n)| n > 0 && n < group(g, voices.len()).len())
                .max_by_key(|&(_, n)| n);
            let Some((dst, _)) = into else {
                return;
            };
            // One voice of `src` into the first free lane of `dst`.
            let Some(i) = group(src, voices.len()).find(|&i| voices[i].state != VoiceState::Free)
            else {
                return;
            };
            let Some(j) = group(dst, voices.len()).find(|&j| voices[j].state == VoiceState::Free)
            else {
                return;
            };
            let (a, b) = groups.split_at_mut(src.max(dst));
            let (to, from_group) = if dst < src {
                (&mut a[dst], &b[0])
            } else {
                (&mut b[0], &a[src])
            };
            to.take_lane(j % LANES, from_group, i % LANES);
            voices.swap(i, j);
        }
    }
}
