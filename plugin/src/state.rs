//! The saved state's format: its version number, what an older state means today, the refusal
//! of a newer one, and the A/B slots saved with the project.
//!
//! A state is nice-plug's JSON object: `params` (plain values by parameter id, see
//! `params.rs`: ids never change) and `fields`, the persisted fields, each a JSON text:
//!
//! | field     | holds                                                          | since    |
//! |-----------|----------------------------------------------------------------|----------|
//! | `model`   | the running model: `name`, `script`, `playing`                 | format 0 |
//! |           | … and `analyses`, what its analyses found (a script not shipped) | format 1 |
//! | `cc_map`  | MIDI learn: the controller of each macro slot                  | format 0 |
//! | `compare` | the A/B slots (each as `model`) and which one runs             | format 1 |
//! | `format`  | [`STATE_FORMAT`]                                               | format 1 |
//!
//! `analyses` came after format 1 without a new number: an older Ressort ignores it and
//! analyses the script, as it always did (`ressort_engine::instrument::saved_analyses`).
//!
//! **Formats.** 0: projects saved before the state said its format (`model` without `playing`
//! plays by the conventions of its time, [`crate::model::Playing::Legacy`]; with it, as
//! saved). 1: the format field and the A/B slots. The number goes up only when a state could
//! no longer be read right by an older Ressort (a field renamed or its meaning changed); a
//! field an older version can ignore does not bump it. Every older format is read as it
//! sounded when it was saved: `tests/tests/state_fixtures.rs` loads committed states of every
//! format and renders them against committed references.
//!
//! **A newer format is refused**: [`filter`] removes every parameter and field but the format
//! before nice-plug applies the state, so nothing of it is loaded, and the format field tells
//! the model store, whose diagnostics say why (the editor shows them). The running model, its
//! parameters and the rest of the project keep playing.

use crate::model::{Compare, ModelStore, SavedModel};
use nice_plug::params::persist::PersistentField;
use nice_plug::prelude::PluginState;
use nice_plug::REFUSED_STATE_FIELD;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::sync::Arc;

/// The format this version writes and the newest it reads.
pub const STATE_FORMAT: u64 = 1;

/// The persisted field's key of the format.
const FORMAT_FIELD: &str = "format";
/// The persisted field's key of the A/B slots.
const COMPARE_FIELD: &str = "compare";

/// The format a state says it has: 0 without the field (saved before it existed).
/// `Err` holds the field's text when it is not a format number.
fn format_of(state: &PluginState) -> Result<u64, String> {
    match state.fields.get(FORMAT_FIELD) {
        None => Ok(0),
        Some(text) => serde_json::from_str::<Value>(text)
            .ok()
            .and_then(|v| v.as_u64())
            .ok_or_else(|| text.clone()),
    }
}

/// Runs before nice-plug applies a state (`Plugin::filter_state`): a newer or unreadable
/// format keeps only its format field, so that nothing else is loaded and the format field
/// reports the refusal to the editor, and is marked refused ([`REFUSED_STATE_FIELD`]), so that
/// the host's state load fails (vendor/README.md, patch 11). Older formats get the one field
/// whose absence would keep something of the instance's past: empty A/B slots; their other
/// fields default as the table above says.
pub fn filter(state: &mut PluginState) {
    match format_of(state) {
        Ok(format) if format <= STATE_FORMAT => {
            // A project without A/B slots (format 0, saved before them) has empty ones: the
            // slots of whatever the instance ran before are not the project's.
            if !state.fields.contains_key(COMPARE_FIELD) {
                let empty = serde_json::to_string(&SavedCompare::default()).unwrap_or_default();
                state.fields.insert(COMPARE_FIELD.to_string(), empty);
            }
        }
        newer => {
            state.params.clear();
            state.fields.retain(|key, _| key == FORMAT_FIELD);
            // Text that is no JSON reaches the format field as a JSON string.
            if let Err(text) = newer {
                if serde_json::from_str::<Value>(&text).is_err() {
                    let quoted = Value::String(text).to_string();
                    state.fields.insert(FORMAT_FIELD.to_string(), quoted);
                }
            }
            let saved = state
                .fields
                .get(FORMAT_FIELD)
                .and_then(|text| serde_json::from_str::<Value>(text).ok())
                .unwrap_or(Value::Null);
            let reason = Value::String(refusal(&saved)).to_string();
            state.fields.insert(REFUSED_STATE_FIELD.to_string(), reason);
        }
    }
}

/// Why a state of `saved` format (the field's JSON) is refused, for the editor.
pub fn refusal(saved: &Value) -> String {
    match saved.as_u64() {
        Some(n) => format!(
            "state: refused: this project was saved by a newer Ressort (state format {n}); this \
             version reads formats up to {STATE_FORMAT}. Nothing of it was loaded and the \
             running model keeps playing: open the project with that Ressort or a newer one."
        ),
        None => format!(
            "state: refused: the state's format field is {saved}, not a format number. Nothing \
             of it was loaded and the running model keeps playing."
        ),
    }
}

/// The persisted `format` field: saves [`STATE_FORMAT`]; loading a newer one reports the
/// refusal ([`filter`] has removed the rest of that state).
pub struct FormatField(pub Arc<ModelStore>);

impl<'a> PersistentField<'a, Value> for FormatField {
    fn set(&self, saved: Value) {
        if saved.as_u64().is_none_or(|n| n > STATE_FORMAT) {
            self.0.refuse_state(refusal(&saved));
        }
    }

    fn map<F, R>(&self, f: F) -> R
    where
        F: Fn(&Value) -> R,
    {
        f(&Value::from(STATE_FORMAT))
    }
}

/// The persisted `compare` field: the A/B slots, saved with the project since format 1.
pub struct CompareField(pub Arc<ModelStore>);

/// The A/B slots as the state saves them: [`Compare`]'s JSON, each slot a [`SavedModel`] with
/// its analyses. A member missing from the JSON reads as empty.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SavedCompare {
    pub slots: [Option<SavedModel>; 2],
    pub active: usize,
}

impl<'a> PersistentField<'a, SavedCompare> for CompareField {
    fn set(&self, saved: SavedCompare) {
        let slots = saved.slots.map(|s| s.map(SavedModel::restore));
        self.0.restore_compare(Compare {
            slots,
            active: saved.active,
        });
    }

    fn map<F, R>(&self, f: F) -> R
    where
        F: Fn(&SavedCompare) -> R,
    {
        // The running slot's analyses are the `model` field's: only the other slot's are
        // saved here (a load takes the running slot from `model` too).
        let c = self.0.compare();
        let slots = [0, 1].map(|i| {
            let model = c.slots[i].clone()?;
            Some(if i == c.active {
                SavedModel {
                    model,
                    analyses: None,
                }
            } else {
                SavedModel::of(model)
            })
        });
        f(&SavedCompare {
            slots,
            active: c.active,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn state(fields: &[(&str, &str)]) -> PluginState {
        PluginState {
            version: String::from("0.1.0"),
            params: BTreeMap::from([(
                String::from("stiffness"),
                nice_plug::plugin::ParamValue::F32(1.0),
            )]),
            fields: fields
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
        }
    }

    #[test]
    fn older_and_current_formats_pass_with_empty_slots_where_they_had_none() {
        for fields in [
            vec![("model", "{}")],
            vec![("model", "{}"), ("format", "0")],
            vec![("model", "{}"), ("format", "1"), ("compare", "{}")],
        ] {
            let mut s = state(&fields);
            filter(&mut s);
            assert_eq!(s.params.len(), 1, "{fields:?}");
            for (k, v) in &fields {
                assert_eq!(s.fields.get(*k).map(String::as_str), Some(*v), "{fields:?}");
            }
            let slots: SavedCompare =
                serde_json::from_str(&s.fields["compare"]).expect("the slots read");
            if !fields.iter().any(|f| f.0 == "compare") {
                assert_eq!(slots, SavedCompare::default(), "{fields:?}");
            }
        }
    }

    #[test]
    fn a_newer_or_unreadable_format_keeps_only_its_format() {
        for format in ["2", "999", "\"two\"", "-1", "1.5", "not json"] {
            let mut s = state(&[("model", "{}"), ("cc_map", "{}"), ("format", format)]);
            filter(&mut s);
            assert!(s.params.is_empty(), "format {format}: parameters kept");
            assert_eq!(
                s.fields.keys().collect::<Vec<_>>(),
                vec!["format", REFUSED_STATE_FIELD],
                "format {format}"
            );
            let reason: String = serde_json::from_str(&s.fields[REFUSED_STATE_FIELD])
                .expect("the reason is a JSON string");
            assert!(reason.starts_with("state: refused:"), "{reason}");
        }
    }

    #[test]
    fn saved_slots_come_back_and_the_running_one_follows_the_model() {
        use crate::model::ModelState;
        use crate::presets::Preset;
        let store = Arc::new(ModelStore::default());
        assert!(store.activate(48_000.0, true).is_some());
        let running = store.running();
        let p = Preset::find("harmonic-oscillator").expect("a preset");
        let other = ModelState::new(p.id, p.text);
        let stale = ModelState::new("stale", "@m mass 1. 0. 0.\n");
        let field = CompareField(store.clone());
        field.set(SavedCompare {
            slots: [Some(other.clone()), Some(stale)].map(|s| s.map(SavedModel::of)),
            active: 1,
        });
        let saved = field.map(|c| c.clone());
        assert_eq!(saved.active, 1);
        let model = |slot: usize| saved.slots[slot].as_ref().map(|s| &s.model);
        assert_eq!(model(1), Some(&running), "B is the running model");
        assert_eq!(model(0), Some(&other));
        store.switch_compare().expect("A loads");
        assert_eq!(store.running(), other);
        // A slot number from nowhere reads as A.
        field.set(SavedCompare {
            slots: [None, None],
            active: 7,
        });
        assert_eq!(field.map(|c| c.active), 0);
        store.deactivate();
    }

    #[test]
    fn a_refused_format_leaves_the_model_and_says_why() {
        let store = Arc::new(ModelStore::default());
        let running = store.running();
        FormatField(store.clone()).set(Value::from(1));
        assert!(store.status().diagnostics.is_empty(), "format 1 is read");
        FormatField(store.clone()).set(Value::from(2));
        assert_eq!(store.running(), running);
        let why = store.status().diagnostics.join("\n");
        assert!(why.contains("state format 2"), "{why}");
    }

    #[test]
    fn the_refusal_says_which_formats_this_version_reads() {
        let m = refusal(&Value::from(2));
        assert!(m.contains("format 2") && m.contains("up to 1"), "{m}");
        assert!(m.contains("keeps playing"), "{m}");
        let m = refusal(&Value::from("two"));
        assert!(m.contains("\"two\""), "{m}");
    }
}
