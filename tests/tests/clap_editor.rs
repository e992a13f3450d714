//! The editor in a CLAP host: the bundled plugin (built with `assert_process_allocs`) embeds
//! its editor in a host window under a private Xvfb, through the CLAP gui extension as a DAW
//! on Linux does. Sidechain strikes rendered by the host show up in the motion view; the host
//! can resize the editor; closing it and destroying the instance is clean.
//!
//! The test runs in a child process that gets the Xvfb display in `DISPLAY`, so the X server
//! outlives every X11 connection the plugin opened (Xlib exits the process when its server
//! goes away).

use ressort_tests::screen::{capture, plot_stats, shows_motion, HostWindow, Xvfb};
use ressort_tests::{Score, TestPlugin};
use std::path::PathBuf;
use std::time::{Duration, Instant};

const DISPLAY_ENV: &str = "RESSORT_TEST_DISPLAY";

#[test]
fn the_editor_opens_in_a_clap_host_and_shows_sidechain_strikes() {
    let name = "the_editor_opens_in_a_clap_host_and_shows_sidechain_strikes";
    let Ok(display) = std::env::var(DISPLAY_ENV) else {
        let x = Xvfb::start(1280, 800)
            .expect("Xvfb starts (scripts/setup.sh installs the xvfb package)");
        let status = std::process::Command::new(std::env::current_exe().unwrap())
            .args([name, "--exact", "--nocapture", "--test-threads=1"])
            .env(DISPLAY_ENV, x.display())
            .env("DISPLAY", x.display())
            .status()
            .expect("run the test in a child process");
        assert!(status.success(), "the editor test failed: {status}");
        return;
    };
    let host = HostWindow::open(&display, "Test DAW", 1100, 700).expect("host window");

    let mut plugin = TestPlugin::new();
    let (w, h) = plugin.open_editor(host.window).expect("the editor opens");
    println!("editor size {w}×{h}");
    assert_eq!((w, h), (1100, 700), "the editor's default size");
    plugin.activate(48_000.0, 1, 512);

    // The editor's window is embedded in the host's.
    let deadline = Instant::now() + Duration::from_secs(20);
    let editor = loop {
        if let Some(&child) = host.children().first() {
            break child;
        }
        assert!(
            Instant::now() < deadline,
            "the editor never embedded its window"
        );
        std::thread::sleep(Duration::from_millis(50));
    };

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

    plugin.close_editor();
    plugin.deactivate();
    drop(plugin);
    drop(host);
    println!("editor closed and instance destroyed");
}
