//! The analyses of a compiled model: its linearisation at rest (`network`), the stability
//! limit of spec §1.6 ([`stability`]), the envelope of stable host gains ([`envelope`]), and
//! the modes, exact limits and gains ([`modes`]).
//! They read a running model ([`crate::sim`]) and the laws' slopes ([`crate::laws`]); the
//! [`crate::instrument`] uses them to clamp, tune and trim what it plays.

pub(crate) mod concurrent;
pub mod envelope;
pub mod modes;
pub(crate) mod network;
pub mod space;
pub mod stability;
