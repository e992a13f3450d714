//! `ressort-standalone`: Ressort without a host, on JACK, ALSA or the dummy backend.
//!
//! Besides nice-plug's options (`ressort-standalone --help`), two of its own come first:
//! `--model NAME|FILE.mdl` starts with a built-in model or a script file instead of the
//! default, and `--audition` strikes the model every second (the editor's Audition switch),
//! which makes a model sound and move without a MIDI device.

use ressort_plugin::model::ModelState;
use ressort_plugin::presets::{Preset, PRESETS};
use ressort_plugin::StandaloneStart;

fn main() {
    let mut start = StandaloneStart::default();
    let mut rest = Vec::new();
    let mut args = std::env::args();
    rest.extend(args.next());
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--model" => {
                let Some(what) = args.next() else {
                    fail("--model needs a built-in model name or a .mdl file");
                };
                start.model = Some(load(&what));
            }
            "--audition" => start.audition = true,
            "--help" | "-h" => {
                println!(
                    "Ressort options (before the others):\n  --model NAME|FILE.mdl  start with a \
                     built-in model or a script file\n  --audition             strike the model \
                     every second\nBuilt-in models: {}\n",
                    PRESETS.iter().map(|p| p.id).collect::<Vec<_>>().join(", ")
                );
                rest.push(arg);
            }
            _ => rest.push(arg),
        }
    }
    ressort_plugin::set_standalone_start(start);
    nice_plug::prelude::nice_export_standalone_with_args::<ressort_plugin::Ressort, _>(rest);
}

fn load(what: &str) -> ModelState {
    if let Some(p) = Preset::find(what) {
        return ModelState::new(p.id, p.text);
    }
    match std::fs::read_to_string(what) {
        Ok(script) => ModelState::new(
            std::path::Path::new(what)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "script".into()),
            script,
        ),
        Err(e) => fail(&format!(
            "--model {what}: not a built-in model, and the file cannot be read: {e}"
        )),
    }
}

fn fail(message: &str) -> ! {
    eprintln!("ressort-standalone: {message}");
    std::process::exit(2)
}
