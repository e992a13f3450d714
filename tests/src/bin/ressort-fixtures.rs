//! `ressort-fixtures`: writes the state fixtures of the plugin as built now
//! (`target/bundled/Ressort.clap`) into `tests/fixtures/states/`, with their reference
//! renders, and the list of parameter ids into `tests/fixtures/parameter-ids.txt`.
//!
//! ```text
//! cargo xtask bundle ressort-plugin --features assert_process_allocs
//! cargo run -p ressort-tests --bin ressort-fixtures
//! ```
//!
//! Run it when the state format changes (a new `f<format>-` set appears beside the old ones,
//! which stay) and commit what it writes. It never overwrites a fixture that exists: the
//! committed ones are what earlier builds saved.

use ressort_tests::fixtures::{self, RECIPES};
use ressort_tests::{state, TestPlugin};
use std::fmt::Write as _;

/// nice-plug's CLAP and VST3 id of a parameter's string id (`wrapper::util::hash_param_id`).
fn host_id(id: &str) -> u32 {
    let hash = id
        .bytes()
        .fold(0u32, |h, c| h.wrapping_mul(31).wrapping_add(c as u32));
    hash & !(1 << 31)
}

fn main() {
    let dir = fixtures::dir();
    std::fs::create_dir_all(&dir).expect("the fixtures folder");
    for recipe in RECIPES {
        let Some(blob) = fixtures::make(recipe) else {
            println!("{}: not in this build's state format", recipe.name);
            continue;
        };
        let stem = format!("f{}-{}", fixtures::format_of(&blob), recipe.name);
        let json_path = dir.join(format!("{stem}.json"));
        if json_path.exists() {
            println!("{stem}: exists, kept");
            continue;
        }
        std::fs::write(&json_path, fixtures::json_text(&blob)).expect("write the state");
        let audio = fixtures::render(&blob);
        fixtures::write_wav(&json_path.with_extension("wav"), &audio);
        println!(
            "{stem}: written (peak {:.3}, finite {})",
            audio.peak(),
            audio.is_finite()
        );
    }

    // The parameter ids, as the state and the hosts know them.
    let mut plugin = TestPlugin::new();
    let saved = plugin.save_state();
    let params = plugin.params();
    let json = state::json(&saved).expect("a state");
    let mut list = String::from(
        "# Ressort's parameter ids: never change one (saved projects and automation use them).\n\
         # string id<TAB>CLAP/VST3 id<TAB>name; checked by tests/state_fixtures.rs.\n",
    );
    let ids = json["params"].as_object().expect("parameters");
    for id in ids.keys() {
        let hashed = host_id(id);
        let name = params
            .iter()
            .find(|p| p.id.get() == hashed)
            .map(|p| p.name.clone())
            .unwrap_or_else(|| panic!("no host parameter for {id}"));
        writeln!(list, "{id}\t{hashed}\t{name}").expect("write");
    }
    std::fs::write(fixtures::parameter_ids_path(), list).expect("write the ids");
    println!("{} parameter ids written", ids.len());
}
