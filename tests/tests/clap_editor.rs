//! The editor in a CLAP host: the bundled plugin (built with `assert_process_allocs`) embeds
//! its editor in a host window under a private Xvfb, through the CLAP gui extension as a DAW
//! on Linux does. Sidechain strikes rendered by the host show up in the motion view; the host
//! can resize the editor; after the editor has been open, the host sees guard trips as the
//! `Guard Tripped` parameter; closing it and destroying the instance is clean.
//!
//! The test runs in a child process that gets the Xvfb display in `DISPLAY`, so the X server
//! outlives every X11 connection the plugin opened (Xlib exits the process when its server
//! goes away).

use ressort_tests::screen::{capture, in_private_display, plot_stats, shows_motion, HostWindow};
use ressort_tests::{state, struck_default, thread_count, Score};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// An oscillator with a negative stiffness, displaced at rest: it runs away and its guard trips
/// at once (no clamp can hold a negative stiffness).
const EXPLODING: &str = "\
# An oscillator with a negative stiffness, displaced at rest (guard report test).
@o osc 1. -2. 0. 1. 0.
@out1 posOutput @o
";

#[test]
fn the_editor_opens_in_a_clap_host_and_shows_sidechain_strikes() {
    let name = "the_editor_opens_in_a_clap_host_and_shows_sidechain_strikes";
    let Some(display) = in_private_display(name, 1280, 800) else {
        return;
    };
    let host = HostWindow::open(&display, "Test DAW", 1100, 700).expect("host window");

    let mut plugin = struck_default();
    let threads_before = thread_count();
    let (w, h) = plugin.open_editor(host.window).expect("the editor opens");
    println!("editor size {w}×{h}");
    assert_eq!((w, h), (1100, 700), "the editor's default size");
    plugin.activate(48_000.0, 1, 512);

    // The editor's window is embedded in the host's.
    let editor = host
        .embedded(Duration::from_secs(20))
        .expect("the editor embeds its window within 20 s");

    // Strike the default preset (the 15 × 15 mesh, in1 = force on its hammer) through the
    // sidechain, in real time, until the motion view shows it.
    let mut shown = None;
    let mut blocks = 0;
    let deadline = Instant::now() + Duration::from_secs(30);
    while Instant::now() < deadline {
        let score = if blocks % 8 == 0 {
            Score::new().impulse(0, -0.05)
        } else {
            Score::new()
        };
        let out = plugin.render(0.1, 480, &score);
        assert!(out.audio.is_finite());
        plugin.idle();
        blocks += 1;
        std::thread::sleep(Duration::from_millis(100));
        let image = capture(&display, editor).expect("capture the editor");
        if let Some(stats) = plot_stats(&image) {
            if shows_motion(&stats) {
                shown = Some((image, stats));
                break;
            }
        }
    }
    let (image, stats) = shown.expect("the motion view shows the strikes within 30 s");
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../target/screenshots/test-clap-editor-mesh-15x15.png");
    image.save_png(&path).unwrap();
    println!("{} after {blocks} blocks of 0.1 s: {stats}", path.display());

    // The host resizes the editor.
    let (resizable, rw, rh) = plugin.resize_editor(900, 600).expect("resize");
    assert!(resizable, "the editor is resizable");
    assert_eq!((rw, rh), (900, 600));
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        let image = capture(&display, editor).expect("capture the editor");
        if (image.width, image.height) == (900, 600) && plot_stats(&image).is_some() {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "the editor window did not follow the resize: {}×{}",
            image.width,
            image.height
        );
        plugin.render(0.05, 480, &Score::new());
        std::thread::sleep(Duration::from_millis(100));
    }

    // The editor's window thread finishes before the process can exit.
    assert!(
        plugin.close_editor_and_wait(threads_before, Duration::from_secs(10)),
        "the editor's threads did not finish within 10 s of closing it ({} > {threads_before})",
        thread_count()
    );

    // The host sees a guard trip: the plugin raises `Guard Tripped` through the context the
    // editor left (from the host's main-thread callback; the editor is closed by now).
    let guard = plugin.param("Guard Tripped");
    assert_eq!(plugin.param_value(guard.id), Some(0.0), "no trip yet");
    plugin.deactivate();
    let blob = state::with_model(&plugin.save_state(), "exploding", EXPLODING);
    plugin.load_state(&blob).expect("load the exploding model");
    plugin.take_param_output();
    plugin.activate(48_000.0, 1, 512);
    let out = plugin.render(0.1, 480, &Score::new());
    assert!(out.audio.is_finite());
    // The report reaches the host with the next block's output events.
    plugin.render(0.01, 480, &Score::new());
    let sent: Vec<f64> = plugin
        .take_param_output()
        .into_iter()
        .filter(|(id, _)| *id == guard.id)
        .map(|(_, v)| v)
        .collect();
    let value = plugin.param_value(guard.id);
    println!(
        "after the guard tripped: the plugin sent Guard Tripped = {sent:?}; the host reads {value:?} ({})",
        plugin
            .param_text(guard.id, value.unwrap_or(0.0))
            .unwrap_or_default()
    );
    assert_eq!(sent, vec![1.0], "one parameter event reports the trip");
    assert_eq!(value, Some(1.0));
    plugin.deactivate();
    drop(plugin);
    drop(host);
    println!("editor closed and instance destroyed");
}
