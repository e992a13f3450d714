//! Bounces in the CLAP test host: the same project rendered twice gives the same bits, whatever
//! the host's activation time and block sizes, because the control grid follows the song
//! position while the transport plays (`Instrument::set_song_position`).

use ressort_tests::{plugin_with_musical_model, Score, Stereo, TestPlugin};

const SR: f64 = 48_000.0;

/// The song position where the bounce starts: not on the 16-sample control grid, so an
/// instance whose grid counted from activation would step its controls elsewhere.
const SONG_START: u64 = 96_011;

/// The bounce: 0.6 s of a struck string, a chord, and Stiffness and Damping ramps written as
/// automation points every 37 samples (a DAW's automation lane), then a note-off.
fn project(plugin: &mut TestPlugin) -> Score {
    let stiffness = plugin.param("Stiffness").id;
    let damping = plugin.param("Damping").id;
    let mut score = Score::new()
        .note_on(100, 60, 0.8)
        .note_on(4_801, 64, 0.6)
        .note_on(9_602, 67, 0.7);
    // Normalized values: Stiffness 0.5 is ×1, Damping 0.5 is ×1 (±4 octaves).
    for (i, t) in (2_000u32..24_000).step_by(37).enumerate() {
        let x = i as f64 / 594.0;
        score = score
            .param(t, stiffness, 0.5 + 0.06 * x)
            .param(t, damping, 0.5 - 0.1 * x);
    }
    score.note_off(20_000, 60)
}

/// One bounce: the project loaded, activated with blocks up to 4096, `idle` samples run with
/// the transport stopped (the time the host took before the export), then the project played
/// from the song position (or, with `song` false, from a host that gives none).
fn bounce(idle: usize, blocks: &[usize], song: bool) -> Stereo {
    let script = include_str!("../../models/struck-string.mdl");
    let mut plugin = plugin_with_musical_model("struck-string", script, &[]);
    plugin.activate(SR, 1, 4096);
    if idle > 0 {
        plugin.render_song(idle, &[333], None, &Score::new());
    }
    let score = project(&mut plugin);
    let start = song.then_some(SONG_START);
    let out = plugin.render_song(28_800, blocks, start, &score);
    plugin.deactivate();
    out.audio
}

/// Block-size patterns a DAW might use: fixed, and irregular (the splits of automation,
/// loops and a host's own scheduling).
const STEADY: &[usize] = &[512];
const IRREGULAR: &[usize] = &[1, 7, 300, 4096, 33, 64, 129, 5, 1000, 16, 2];

#[test]
fn a_bounce_from_the_same_song_position_is_bit_identical() {
    let reference = bounce(0, STEADY, true);
    assert!(reference.is_finite() && reference.peak() > 1e-3);
    for (idle, blocks) in [(1_237, STEADY), (0, IRREGULAR), (5_003, IRREGULAR)] {
        let other = bounce(idle, blocks, true);
        let diff = reference.first_difference(&other);
        println!(
            "activated {idle} samples before the bounce, blocks {blocks:?}: \
             first difference {diff:?} (of {} samples)",
            reference.len()
        );
        assert_eq!(
            diff, None,
            "the bounce after {idle} idle samples in blocks {blocks:?} differs"
        );
    }
}

/// What a render depends on without a song position: the grid counts from activation, so
/// automation steps at other samples when the host activated the plugin at another time.
#[test]
fn without_a_song_position_the_grid_counts_from_activation() {
    let a = bounce(0, STEADY, false);
    let same_phase = bounce(1_600, IRREGULAR, false);
    let other_phase = bounce(1_237, STEADY, false);
    assert_eq!(a.first_difference(&same_phase), None);
    let diff = a.first_difference(&other_phase);
    println!("activation 1,237 samples earlier, no song position: first difference {diff:?}");
    assert!(
        diff.is_some_and(|d| d >= 2_000),
        "expected the automation to step elsewhere, from frame 2,000 on: {diff:?}"
    );
}
