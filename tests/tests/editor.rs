//! The editor as a person would check it: `ressort-standalone` (the debug build that
//! `cargo test --workspace` makes, with `assert_process_allocs`) opens its editor under a private Xvfb with Mesa's software
//! OpenGL, plays a mesh preset, and the captured window shows the membrane moving. The same
//! capture of the model at rest shows no motion, so the check can fail.
//!
//! The PNGs are written to `target/screenshots/`. `scripts/screenshot.sh` does the same with
//! the release build.

use ressort_tests::screen::{capture_standalone, shows_motion, standalone_path, Xvfb};
use std::path::PathBuf;
use std::time::Duration;

fn screenshots() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/screenshots")
}

fn standalone() -> PathBuf {
    let path = standalone_path();
    assert!(
        path.exists(),
        "{} is missing: `cargo test --workspace` builds it (or set RESSORT_STANDALONE)",
        path.display()
    );
    path
}

fn xvfb() -> Xvfb {
    Xvfb::start(1280, 800).expect("Xvfb starts (scripts/setup.sh installs the xvfb package)")
}

#[test]
fn the_motion_view_shows_a_struck_mesh_moving() {
    let x = xvfb();
    let capture = capture_standalone(
        &standalone(),
        x.display(),
        "mesh-25x20",
        true,
        true,
        Duration::from_secs(30),
    )
    .expect("the standalone runs and opens its editor");
    let path = screenshots().join("test-editor-mesh-25x20.png");
    capture.image.save_png(&path).unwrap();
    let stats = capture.stats.expect("the capture shows the motion view");
    println!("{} after {:.1} s: {stats}", path.display(), capture.after_s);
    assert!(
        (1000, 600) <= (capture.image.width, capture.image.height),
        "the window opens at its default size"
    );
    assert!(
        stats.rect.2 > 200 && stats.rect.3 > 200,
        "the plot takes the centre of the window: {stats}"
    );
    assert!(shows_motion(&stats), "the struck mesh moves: {stats}");
}

#[test]
fn the_motion_view_of_a_model_at_rest_is_still() {
    let x = xvfb();
    let capture = capture_standalone(
        &standalone(),
        x.display(),
        "mesh-25x20",
        false,
        false,
        Duration::from_secs(30),
    )
    .expect("the standalone runs and opens its editor");
    let path = screenshots().join("test-editor-mesh-25x20-at-rest.png");
    capture.image.save_png(&path).unwrap();
    let stats = capture.stats.expect("the capture shows the motion view");
    println!("{}: {stats}", path.display());
    assert!(!shows_motion(&stats), "nothing strikes the mesh: {stats}");
}
