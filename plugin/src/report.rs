//! Telling the host about guard trips: the `guard` parameter.
//!
//! nice-plug 0.4.2 lets a plugin send parameter values to the host only through the editor's
//! `GuiContext` on the main thread (`ProcessContext::set_parameter` is a TODO there). The
//! editor hands its context to a [`HostLink`] when it is built; the link keeps it after the
//! window closes. The audio thread, on a trip, asks for a main-thread task (CLAP only: its
//! tasks run in the host's main-thread callback; other formats route them through nice-plug's
//! shared background thread, which aborts hosts when an instance is gone), and the task turns
//! the parameter on.

use crate::params::RessortParams;
use nice_plug::context::gui::GuiContext;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// A task the audio thread queues for the main thread.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MainThreadTask {
    /// The guard reset an exploding model: raise the `guard` parameter.
    ReportGuardTrip,
    /// The Voices setting changed: re-prepare the running model with it.
    ApplyVoices,
    /// A new model started playing. Nothing to do for the plugin; the CLAP wrapper asks for
    /// the remote-control pages again after every main-thread task, and they follow the
    /// model's macros.
    ModelChanged,
}

/// The editor's `GuiContext`, kept for main-thread parameter changes.
#[derive(Default)]
pub struct HostLink {
    /// Locked on the main thread only.
    context: Mutex<Option<GuiContext>>,
    /// Whether `context` is set; the audio thread reads it.
    attached: AtomicBool,
}

impl HostLink {
    /// Keeps the context of a newly built editor.
    pub fn attach(&self, context: GuiContext) {
        *self.context.lock().unwrap_or_else(|e| e.into_inner()) = Some(context);
        self.attached.store(true, Ordering::Release);
    }

    /// Whether an editor has been built: only then can the host be told anything.
    /// Realtime-safe.
    pub fn is_attached(&self) -> bool {
        self.attached.load(Ordering::Acquire)
    }

    /// Sets the `guard` parameter as the host sees it; nothing when no editor has been built
    /// yet (no context to send it through).
    pub fn set_guard(&self, params: &RessortParams, tripped: bool) {
        let context = self.context.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(context) = context.as_ref() {
            set_guard_with(context, params, tripped);
        }
    }
}

/// Sets the `guard` parameter through `context` as one gesture, when it differs.
pub fn set_guard_with(context: &GuiContext, params: &RessortParams, tripped: bool) {
    if params.guard.value() == tripped {
        return;
    }
    let setter = context.param_setter();
    setter.begin_set_parameter(&params.guard);
    setter.set_parameter(&params.guard, tripped);
    setter.end_set_parameter(&params.guard);
}
