//! The presets of `models/`, as the tests read them.

/// Every preset script of `models/`: (id, text), sorted by id.
pub fn presets() -> Vec<(String, String)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let mut presets: Vec<(String, String)> = std::fs::read_dir(&dir)
        .expect("models/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "mdl"))
        .map(|p| {
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&p).expect("preset text"))
        })
        .collect();
    presets.sort();
    presets
}
