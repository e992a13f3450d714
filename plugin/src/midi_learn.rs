//! MIDI controllers on macro slots: which CC moves which slot (saved with the project), and
//! MIDI learn (the editor arms a slot; the next controller the audio thread sees is bound to
//! it). Atomics only, so the audio thread reads and learns without locks.

use nice_plug::params::persist::PersistentField;
use ressort_engine::instrument::NUM_MACROS;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicI8, AtomicU8, Ordering};
use std::sync::Arc;

/// No slot is armed.
const NOT_LEARNING: i8 = -1;

/// The controller of each macro slot (0: none) and the slot armed for learning.
#[derive(Debug)]
pub struct CcMap {
    slots: [AtomicU8; NUM_MACROS],
    learning: AtomicI8,
}

impl Default for CcMap {
    fn default() -> Self {
        CcMap {
            slots: std::array::from_fn(|_| AtomicU8::new(0)),
            learning: AtomicI8::new(NOT_LEARNING),
        }
    }
}

/// The saved form: `[slot, cc]` pairs of the mapped slots (1-based slot numbers, as the
/// editor shows them).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CcMapState(pub Vec<(u8, u8)>);

impl CcMap {
    /// The controller mapped to `slot`.
    pub fn cc_of(&self, slot: usize) -> Option<u8> {
        let cc = self.slots.get(slot)?.load(Ordering::Relaxed);
        (cc != 0).then_some(cc)
    }

    /// Every slot's controller. Realtime-safe.
    pub fn mapping(&self) -> [Option<u8>; NUM_MACROS] {
        std::array::from_fn(|slot| self.cc_of(slot))
    }

    /// Maps `cc` (1 … 127; 0 clears) to `slot`.
    pub fn assign(&self, slot: usize, cc: u8) {
        if let Some(s) = self.slots.get(slot) {
            s.store(if cc <= 127 { cc } else { 0 }, Ordering::Relaxed);
        }
    }

    pub fn clear(&self, slot: usize) {
        self.assign(slot, 0);
    }

    /// Arms `slot` for learning (None disarms).
    pub fn learn(&self, slot: Option<usize>) {
        let v = slot
            .filter(|s| *s < NUM_MACROS)
            .map_or(NOT_LEARNING, |s| s as i8);
        self.learning.store(v, Ordering::Release);
    }

    /// The slot armed for learning.
    pub fn learning(&self) -> Option<usize> {
        let v = self.learning.load(Ordering::Acquire);
        (v >= 0).then_some(v as usize)
    }

    /// Audio thread: a controller arrived. When a slot is armed, `cc` becomes its controller
    /// and learning ends. CC 0 (bank select) is never learned. Realtime-safe.
    pub fn heard(&self, cc: u8) {
        if cc == 0 || cc > 127 {
            return;
        }
        let armed = self.learning.load(Ordering::Acquire);
        if armed >= 0
            && self
                .learning
                .compare_exchange(armed, NOT_LEARNING, Ordering::AcqRel, Ordering::Acquire)
                .is_ok()
        {
            self.assign(armed as usize, cc);
        }
    }

    fn state(&self) -> CcMapState {
        CcMapState(
            (0..NUM_MACROS)
                .filter_map(|s| self.cc_of(s).map(|cc| (s as u8 + 1, cc)))
                .collect(),
        )
    }

    fn set_state(&self, state: &CcMapState) {
        for s in &self.slots {
            s.store(0, Ordering::Relaxed);
        }
        for &(slot, cc) in &state.0 {
            if (1..=NUM_MACROS as u8).contains(&slot) && (1..=127).contains(&cc) {
                self.assign(slot as usize - 1, cc);
            }
        }
    }
}

impl<'a> PersistentField<'a, CcMapState> for Arc<CcMap> {
    fn set(&self, new_value: CcMapState) {
        self.set_state(&new_value);
    }

    fn map<F, R>(&self, f: F) -> R
    where
        F: Fn(&CcMapState) -> R,
    {
        f(&self.state())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn learning_binds_the_next_controller_once() {
        let m = CcMap::default();
        m.heard(74);
        assert_eq!(
            m.mapping(),
            [None; NUM_MACROS],
            "nothing armed, nothing learned"
        );
        m.learn(Some(2));
        assert_eq!(m.learning(), Some(2));
        m.heard(0);
        assert_eq!(m.cc_of(2), None, "bank select is not learned");
        m.heard(74);
        assert_eq!(m.cc_of(2), Some(74));
        assert_eq!(m.learning(), None);
        m.heard(1);
        assert_eq!(
            m.cc_of(2),
            Some(74),
            "learning ended with the first controller"
        );
        m.clear(2);
        assert_eq!(m.cc_of(2), None);
    }

    #[test]
    fn the_map_survives_its_saved_form_and_ignores_bad_entries() {
        let m = Arc::new(CcMap::default());
        m.assign(0, 1);
        m.assign(15, 127);
        let saved = m.map(|s: &CcMapState| s.clone());
        assert_eq!(saved, CcMapState(vec![(1, 1), (16, 127)]));
        let json = serde_json::to_string(&saved).unwrap();
        let other = Arc::new(CcMap::default());
        other.set(serde_json::from_str(&json).unwrap());
        assert_eq!(other.mapping(), m.mapping());
        other.set(CcMapState(vec![(0, 5), (17, 5), (3, 0), (3, 200), (2, 11)]));
        let mut expected = [None; NUM_MACROS];
        expected[1] = Some(11);
        assert_eq!(other.mapping(), expected);
    }
}
