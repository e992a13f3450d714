//! `ressort-standalone`: Ressort without a host, on JACK, ALSA or the dummy backend
//! (`ressort-standalone --help` lists the options).

fn main() {
    nice_plug::prelude::nice_export_standalone::<ressort_plugin::Ressort>();
}
