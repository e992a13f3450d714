//! The sound library in a CLAP host's own browser: preset discovery (the bundle's
//! `clap.preset-discovery-factory/2`, indexed as a DAW does, without an instance) lists every
//! factory preset with its category and tags, and the user's presets beside them with the
//! favourites; preset load (`clap.preset-load/2`) plays what choosing the preset in the editor
//! plays, sample for sample, and a preset the plugin cannot load is reported to the host while
//! the running model plays on.
//!
//! The user preset folder is the test's own (`RESSORT_PRESET_DIR`), the same for every test of
//! this binary.

use ressort_tests::discovery::{self, Place};
use ressort_tests::presets::presets;
use ressort_tests::screen::{capture, click, in_private_display, type_text, HostWindow};
use ressort_tests::{Score, TestPlugin};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// CLAP's preset flags.
const FACTORY: u32 = 1 << 0;
const USER: u32 = 1 << 1;
const FAVORITE: u32 = 1 << 3;

const USER_PRESET: &str = "\
# My Bell
#
# Category: Bells and Plates
# Tags: mine, struck
# What: a test's own bell: one damped oscillator.
# How to play: a key strikes it.
# Source: the host-presets test.
@b osc 1. 0.01 0.0001 0. 0.
@in1 frcInput @b
@out1 posOutput @b
";

/// A user preset with an error on line 2, column 12.
const BROKEN_PRESET: &str = "@b osc 1. 0.01 0.0001 0. 0.\n@s spring @b @nowhere 0.1\n";

/// The test's user preset folder: one preset, one broken script, and favourites (Marimba and
/// the user's bell). Set before the bundle is asked anything.
fn user_folder() -> PathBuf {
    static DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("host-presets-user");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("user preset folder");
        std::fs::write(dir.join("My Bell.mdl"), USER_PRESET).unwrap();
        std::fs::write(dir.join("Broken.mdl"), BROKEN_PRESET).unwrap();
        std::fs::write(dir.join("notes.txt"), "not a preset").unwrap();
        std::fs::write(
            dir.join("favourites.txt"),
            "factory:marimba\nuser:My Bell\n",
        )
        .unwrap();
        // SAFETY: set once, before any test of this binary loads the bundle or reads the
        // environment on another thread (every test goes through here first).
        unsafe { std::env::set_var("RESSORT_PRESET_DIR", &dir) };
        dir
    })
    .clone()
}

/// A header field of a script (`# Category: …`).
fn field(text: &str, key: &str) -> String {
    text.lines()
        .find_map(|l| l.strip_prefix("# ")?.strip_prefix(key))
        .map(|v| v.trim().to_string())
        .unwrap_or_default()
}

#[test]
fn the_host_indexes_every_preset_with_its_category() {
    let dir = user_folder();
    let index = discovery::index();
    println!("providers: {:?}", index.providers);
    assert_eq!(
        index.providers,
        vec![(
            "audio.ressort.ressort.presets".to_string(),
            "Ressort presets".to_string(),
            "Ressort".to_string()
        )]
    );
    assert_eq!(
        index.filetypes,
        vec![("Ressort script".to_string(), "mdl".to_string())]
    );
    println!("locations: {:?}", index.locations);
    assert_eq!(index.locations.len(), 2, "{:?}", index.locations);
    assert_eq!(index.locations[0].place, Place::Plugin);
    assert_eq!(index.locations[0].flags, FACTORY);
    assert_eq!(index.locations[1].place, Place::File(dir.clone()));
    assert_eq!(index.locations[1].flags, USER);

    // The broken script is listed too: its header is read, its errors show when it loads.
    let shipped = presets();
    assert_eq!(
        index.presets.len(),
        shipped.len() + 2,
        "{:#?}",
        index.presets
    );
    assert!(index.errors.is_empty(), "{:?}", index.errors);
    let mut listing: Vec<(String, String, String)> = Vec::new();
    for (id, text) in &shipped {
        let found = index
            .presets
            .iter()
            .find(|p| p.file.is_none() && p.load_key.as_deref() == Some(id))
            .unwrap_or_else(|| panic!("{id} is not listed"));
        let category = field(text, "Category:");
        assert!(!category.is_empty(), "{id} has no category");
        assert_eq!(found.extra("category"), Some(category.as_str()), "{id}");
        let title = text
            .lines()
            .next()
            .unwrap_or("")
            .trim_start_matches('#')
            .trim();
        assert_eq!(found.name, title, "{id}");
        assert_eq!(
            found.plugin_ids,
            vec![("clap".to_string(), "audio.ressort.ressort".to_string())],
            "{id}"
        );
        let favourite = if id == "marimba" { FAVORITE } else { 0 };
        assert_eq!(found.flags, FACTORY | favourite, "{id}");
        assert!(found.features.contains(&category), "{id}");
        for tag in field(text, "Tags:").split(',') {
            let tag = tag.trim().to_lowercase();
            assert!(found.features.contains(&tag), "{id}: tag {tag}");
        }
        assert!(!found.description.is_empty(), "{id}: no description");
        listing.push((category, found.name.clone(), id.clone()));
    }
    let mine = index
        .presets
        .iter()
        .find(|p| p.file.as_deref() == Some(&dir.join("My Bell.mdl")))
        .expect("the user preset is listed");
    assert_eq!(mine.name, "My Bell");
    assert_eq!(mine.load_key, None);
    assert_eq!(mine.flags, USER | FAVORITE);
    assert_eq!(mine.extra("category"), Some("Bells and Plates"));
    assert_eq!(mine.extra("tags"), Some("mine, struck"));

    listing.sort();
    println!(
        "the host's browser: {} factory presets and 2 user files",
        listing.len()
    );
    let mut current = String::new();
    for (category, name, id) in &listing {
        if *category != current {
            println!("  {category}");
            current = category.clone();
        }
        println!("    {name} (load key {id})");
    }
}

/// Renders until the running model is `id` (the first remote-control page is named after it
/// and its macros),
/// at most 30 s of wall time.
fn wait_for_model(plugin: &mut TestPlugin, id: &str) {
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        plugin.render(0.05, 480, &Score::new());
        plugin.idle();
        let page = plugin.remote_control_pages().into_iter().next();
        if page.is_some_and(|p| p.name == id || p.name.starts_with(&format!("{id}:"))) {
            return;
        }
        assert!(Instant::now() < deadline, "{id} never started playing");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// What a test plays once the preset runs: half a second of quiet (the switch's crossfade is
/// long over), then C4 for a second.
fn phrase(plugin: &mut TestPlugin) -> ressort_tests::Stereo {
    plugin.render(0.5, 480, &Score::new());
    let out = plugin
        .render(1.0, 480, &Score::new().note_on(0, 60, 0.8))
        .audio;
    assert!(out.is_finite());
    out
}

#[test]
fn a_preset_the_plugin_cannot_load_is_reported_and_the_model_plays_on() {
    let dir = user_folder();
    let mut plugin = TestPlugin::new();
    plugin.activate(48_000.0, 1, 512);
    plugin.render(0.05, 480, &Score::new());
    plugin.idle();
    let before = plugin.remote_control_pages()[0].name.clone();
    let unknown = plugin.load_preset(None, Some("no-such-preset"));
    println!("unknown load key: {unknown:?}");
    assert!(unknown.is_err_and(|e| e.contains("no factory preset `no-such-preset`")));
    let broken = plugin.load_preset(Some(&dir.join("Broken.mdl")), None);
    println!("broken user preset: {broken:?}");
    let broken = broken.expect_err("a script with an error is refused");
    assert!(
        broken.contains("Broken.mdl") && broken.contains("2:"),
        "{broken}"
    );
    let missing = plugin.load_preset(Some(&dir.join("Gone.mdl")), None);
    assert!(missing.is_err(), "{missing:?}");
    plugin.render(0.2, 480, &Score::new());
    plugin.idle();
    assert_eq!(
        plugin.remote_control_pages()[0].name,
        before,
        "the model changed"
    );

    // The user's own preset loads from its file.
    let mine = plugin.load_preset(Some(&dir.join("My Bell.mdl")), None);
    assert_eq!(mine, Ok(dir.join("My Bell.mdl").display().to_string()));
    wait_for_model(&mut plugin, "My Bell");
    assert!(phrase(&mut plugin).peak() > 1e-3, "the user preset sounds");
}

/// What clap-validator's preset-discovery-load does (scripts/clap-validator.sh says why it is
/// left out there): every preset the index lists, loaded in turn into one instance through
/// preset load, processed after each; each one becomes the running model and a note on it
/// stays finite.
#[test]
fn every_listed_preset_loads_through_preset_load() {
    user_folder();
    let index = discovery::index();
    let mut plugin = TestPlugin::new();
    plugin.activate(48_000.0, 1, 512);
    let mut loaded = 0;
    for preset in &index.presets {
        let file = preset.file.as_deref();
        let result = plugin.load_preset(file, preset.load_key.as_deref());
        if file.is_some_and(|f| f.ends_with("Broken.mdl")) {
            assert!(result.is_err(), "the broken script is refused");
            continue;
        }
        result.unwrap_or_else(|e| panic!("{}: {e}", preset.name));
        let id = match (file, &preset.load_key) {
            (Some(f), _) => f.file_stem().unwrap().to_string_lossy().into_owned(),
            (None, Some(key)) => key.clone(),
            (None, None) => panic!("{}: a factory preset without a load key", preset.name),
        };
        wait_for_model(&mut plugin, &id);
        let out = plugin
            .render(0.1, 480, &Score::new().note_on(0, 60, 0.8))
            .audio;
        assert!(out.is_finite(), "{id}");
        loaded += 1;
    }
    println!("{loaded} presets loaded through preset load, one instance, processed after each");
    assert_eq!(loaded, index.presets.len() - 1);
}

/// Where the editor's browser is in a 1100 × 700 editor (window pixels): the search field and
/// the `>` button of the Presets tab's filter row.
const SEARCH: (i16, i16) = (145, 98);
const NEXT: (i16, i16) = (49, 98);

#[test]
fn a_preset_loaded_by_the_host_plays_as_chosen_in_the_editor() {
    let name = "a_preset_loaded_by_the_host_plays_as_chosen_in_the_editor";
    let Some(display) = in_private_display(name, 1280, 800) else {
        return;
    };
    user_folder();
    let preset = "glockenspiel";

    // The host's browser: preset load with the factory location and the load key.
    let mut by_host = TestPlugin::new();
    by_host.activate(48_000.0, 1, 512);
    by_host.render(0.05, 480, &Score::new());
    assert_eq!(
        by_host.load_preset(None, Some(preset)),
        Ok(format!("plugin:{preset}"))
    );
    wait_for_model(&mut by_host, preset);
    let hosted = phrase(&mut by_host);

    // The editor's browser: search for the preset and load the first match with `>`.
    let host = HostWindow::open(&display, "Test DAW", 1100, 700).expect("host window");
    let mut by_editor = TestPlugin::new();
    by_editor
        .open_editor(host.window)
        .expect("the editor opens");
    by_editor.activate(48_000.0, 1, 512);
    let editor = host
        .embedded(Duration::from_secs(20))
        .expect("the editor embeds its window within 20 s");
    for _ in 0..20 {
        by_editor.render(0.05, 480, &Score::new());
        by_editor.idle();
        std::thread::sleep(Duration::from_millis(50));
    }
    let shots = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/screenshots");
    let before = capture(&display, editor).expect("capture");
    before
        .save_png(&shots.join("test-host-presets-browser.png"))
        .unwrap();
    click(&display, editor, SEARCH.0, SEARCH.1).expect("click the search field");
    std::thread::sleep(Duration::from_millis(200));
    type_text(&display, preset).expect("type the search");
    for _ in 0..10 {
        by_editor.render(0.05, 480, &Score::new());
        by_editor.idle();
        std::thread::sleep(Duration::from_millis(50));
    }
    capture(&display, editor)
        .expect("capture")
        .save_png(&shots.join("test-host-presets-search.png"))
        .unwrap();
    click(&display, editor, NEXT.0, NEXT.1).expect("click >");
    wait_for_model(&mut by_editor, preset);
    let chosen = phrase(&mut by_editor);
    by_editor.close_editor();

    println!(
        "{preset}: preset load and the editor's choice, C4 for 1 s: peaks {:.4} and {:.4}",
        hosted.peak(),
        chosen.peak()
    );
    assert!(hosted.peak() > 0.05, "the preset sounds");
    assert_eq!(
        hosted.first_difference(&chosen),
        None,
        "preset load and the editor's choice play other samples"
    );
    println!("bit-identical over {} frames", hosted.len());
}
