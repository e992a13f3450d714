//! The multichannel layout in a CLAP host: an 8-channel sidechain feeds `@in1` … `@in8`, and
//! `@out3` … `@out8` leave on three stereo auxiliary outputs; `~route` reaches every channel.

use ressort_tests::{plugin_with_model, Block, TestPlugin};

const SR: f64 = 48_000.0;
const FRAMES: usize = 2_048;

/// Eight independent oscillators, each with its own force input and position output.
fn eight_oscillators(extra: &str) -> String {
    let mut s = String::from("# Eight oscillators, one per channel (multichannel tests).\n");
    for k in 1..=8 {
        s += &format!("@o{k} osc 1. {} 0.0001 0. 0.\n", 0.002 * k as f64);
    }
    for k in 1..=8 {
        s += &format!("@in{k} frcInput @o{k}\n@out{k} posOutput @o{k}\n");
    }
    s + extra
}

/// One block with an impulse on sidechain channel `channel` (0-based); every output channel.
fn strike_channel(plugin: &mut TestPlugin, channel: usize) -> Vec<Vec<f32>> {
    plugin.activate(SR, 1, FRAMES as u32);
    let mut impulse = vec![0.0f32; FRAMES];
    impulse[0] = -0.05;
    let silent = vec![0.0f32; FRAMES];
    let sidechain: Vec<&[f32]> = (0..8)
        .map(|c| {
            if c == channel {
                &impulse[..]
            } else {
                &silent[..]
            }
        })
        .collect();
    plugin.process(&Block {
        frames: FRAMES,
        sidechain: &sidechain,
        ..Block::default()
    });
    plugin.all_outputs(FRAMES)
}

fn peak(c: &[f32]) -> f32 {
    c.iter().fold(0.0f32, |m, x| m.max(x.abs()))
}

fn multichannel(script: &str) -> TestPlugin {
    let mut plugin = plugin_with_model("eight", script, &[]);
    plugin
        .select_audio_config("Multichannel instrument")
        .expect("select the multichannel layout");
    let inputs = plugin.audio_ports(true);
    let outputs = plugin.audio_ports(false);
    println!("inputs {inputs:?}\noutputs {outputs:?}");
    assert_eq!(inputs.len(), 1);
    assert_eq!(inputs[0].channels, 8);
    assert_eq!(outputs.len(), 4, "main plus three stereo auxiliary outputs");
    assert!(outputs.iter().all(|p| p.channels == 2));
    plugin
}

#[test]
fn each_sidechain_channel_reaches_its_input_and_each_output_its_channel() {
    let mut plugin = multichannel(&eight_oscillators(""));
    for k in 0..8 {
        let out = strike_channel(&mut plugin, k);
        assert_eq!(out.len(), 8);
        let peaks: Vec<f32> = out.iter().map(|c| peak(c)).collect();
        println!("sidechain channel {}: output peaks {peaks:?}", k + 1);
        for (c, p) in peaks.iter().enumerate() {
            if c == k {
                assert!(*p > 1e-4, "@in{} did not reach @out{}", k + 1, k + 1);
            } else {
                assert_eq!(*p, 0.0, "channel {} leaked into output {}", k + 1, c + 1);
            }
        }
    }
}

#[test]
fn routes_reach_every_sidechain_channel() {
    let mut plugin = multichannel(&eight_oscillators(
        "~route in1 sidechain_8\n~route in8 sidechain_left\n~route in2 none\n",
    ));
    let out = strike_channel(&mut plugin, 7);
    assert!(peak(&out[0]) > 1e-4, "sidechain_8 must feed @in1");
    assert_eq!(peak(&out[7]), 0.0, "@in8 listens to sidechain_left now");
    let out = strike_channel(&mut plugin, 0);
    assert!(peak(&out[7]) > 1e-4, "sidechain_left must feed @in8");
    assert_eq!(peak(&out[0]), 0.0);
    let out = strike_channel(&mut plugin, 1);
    assert!(
        out.iter().all(|c| peak(c) == 0.0),
        "`none` leaves @in2 unfed, and nothing else takes channel 2"
    );
}
