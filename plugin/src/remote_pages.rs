//! The CLAP remote-control pages: the eight knobs a hardware controller or a host's device
//! panel shows, for the running model.

use crate::model::{self, ModelStore};
use crate::params::RessortParams;
use nice_plug::prelude::*;
use std::sync::Arc;

/// The pages a hardware controller or a host's device panel shows (CLAP remote controls),
/// for the running model: first a page named after it with its bound macro slots (whose
/// value text names their `param`s) and, where fewer than eight are bound, the physics
/// (Stiffness, Damping, Release, Output Gain, Tune, Force Gain, Position Gain, Velocity
/// Curve); then the physics that did not fit, the bound slots beyond the eighth, and how it
/// is played. Unbound slots do nothing and are on no page. The vendored CLAP wrapper asks
/// again after a state load and after each main-thread task (the audio thread posts one
/// when a new model starts) and tells the host when the pages changed (vendor/README.md).
///
/// Made from the parameters and the model store alone, so the vendored wrapper can ask again
/// on the main thread while the audio thread holds the plugin (patch 10, vendor/README.md).
pub struct RemotePages {
    pub params: Arc<RessortParams>,
    pub store: Arc<ModelStore>,
}

impl RemotePages {
    pub fn define(&self, context: &mut impl RemoteControlsContext) {
        let p = &self.params;
        let (model, names) = self.store.macro_names();
        let bound: Vec<usize> = (0..model::NUM_MACROS)
            .filter(|&i| names.get(i).is_some_and(|n| n.is_some()))
            .collect();
        let physics: [&FloatParam; 8] = [
            &p.stiffness,
            &p.damping,
            &p.release,
            &p.output_gain,
            &p.tune,
            &p.force_gain,
            &p.position_gain,
            &p.velocity_curve,
        ];
        let first = bound.len().min(8);
        let fill = 8 - first;
        let title: String = if bound.is_empty() {
            model.clone()
        } else {
            let list: Vec<&str> = bound[..first]
                .iter()
                .filter_map(|&i| names[i].as_deref())
                .collect();
            format!("{model}: {}", list.join(", "))
        };
        context.add_section("Model", |section| {
            section.add_page(title.as_str(), |page| {
                for &i in &bound[..first] {
                    page.add_param(&p.macros[i].value);
                }
                for param in &physics[..fill] {
                    page.add_param(*param);
                }
            });
        });
        if fill < physics.len() {
            context.add_section("Instrument", |section| {
                section.add_page("Physics", |page| {
                    for param in &physics[fill..] {
                        page.add_param(*param);
                    }
                });
            });
        }
        if bound.len() > 8 {
            context.add_section("Model", |section| {
                section.add_page("More macros", |page| {
                    for &i in &bound[8..] {
                        page.add_param(&p.macros[i].value);
                    }
                });
            });
        }
        context.add_section("Playing", |section| {
            section.add_page("Playing", |page| {
                page.add_param(&p.a4);
                page.add_param(&p.bend_range);
                page.add_param(&p.mpe);
                page.add_param(&p.voices);
                page.add_param(&p.trigger);
                page.add_param(&p.trigger_sensitivity);
                page.add_param(&p.dc_filter);
            });
        });
    }
}

impl ClapRemoteControls for RemotePages {
    fn pages(&self, context: &mut RemoteControlPages<'_>) {
        self.define(context);
    }
}
