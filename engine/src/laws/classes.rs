//! The scaling class of each argument: what its script value is multiplied by at a sample
//! rate (spec §1.7) and which host gain moves it. A law's row gives one per column; the
//! compiler gives one to every other argument (masses, gravity).

/// The classes an argument's value is multiplied by: spec §1.7 plus two internal ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ArgClass {
    None = 0,
    Stiffness = 1,
    Damping = 2,
    Gravity = 3,
    /// `massG` gravity: ×(44100/SR)², not divided by 44100 (spec §2.1.4).
    LegacyGravity = 4,
    /// The bow's Vscale: a per-step velocity, SR-scaled like Z but not a damping, so the host's
    /// damping gain leaves it alone.
    VelocityScale = 5,
}

pub(crate) const NUM_ARG_CLASSES: usize = 6;
