//! The audio busses a VST3 host sees (Ressort patch).
//!
//! VST3 fixes the number of busses when the host first asks, and lets the host change only their
//! channel counts and whether each is active. The published wrapper showed the busses of the
//! plugin's first audio IO layout, so a layout with more busses (an effect with a main input as
//! well as a sidechain, next to an instrument with the sidechain alone) could never be chosen.
//!
//! Here the host sees the union of all layouts: a main input if any layout has one, then as many
//! auxiliary inputs as the layout with the most, and likewise for outputs. A bus is active by
//! default when the first layout has it. The layout in use is the first one whose busses are
//! exactly the ones the host made present (active, with a non-empty arrangement) with the
//! channel counts it asked for.

use nice_plug_core::audio_setup::AudioIOLayout;

/// One audio bus as the host sees it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BusDesc {
    pub main: bool,
    pub channels: u32,
    pub name: String,
    pub default_active: bool,
}

/// Whether `layouts` have a main bus in direction `input`, and how many auxiliary busses the
/// largest one has.
fn shape(layouts: &[AudioIOLayout], input: bool) -> (bool, usize) {
    let main = layouts.iter().any(|l| main_channels(l, input) > 0);
    let aux = layouts
        .iter()
        .map(|l| aux_ports(l, input).len())
        .max()
        .unwrap_or(0);
    (main, aux)
}

fn main_channels(layout: &AudioIOLayout, input: bool) -> u32 {
    let c = if input {
        layout.main_input_channels
    } else {
        layout.main_output_channels
    };
    c.map(|c| c.get()).unwrap_or(0)
}

fn aux_ports(layout: &AudioIOLayout, input: bool) -> &[std::num::NonZeroU32] {
    if input {
        layout.aux_input_ports
    } else {
        layout.aux_output_ports
    }
}

/// The number of busses in direction `input`.
pub fn count(layouts: &[AudioIOLayout], input: bool) -> usize {
    let (main, aux) = shape(layouts, input);
    main as usize + aux
}

/// The index of the first auxiliary bus in direction `input` (1 after a main bus).
pub fn aux_start(layouts: &[AudioIOLayout], input: bool) -> usize {
    shape(layouts, input).0 as usize
}

/// The channel count `layout` gives the host's bus `index` in direction `input`; 0 when the
/// layout does not have that bus.
pub fn channels_in(
    layouts: &[AudioIOLayout],
    layout: &AudioIOLayout,
    input: bool,
    index: usize,
) -> u32 {
    let (main, _) = shape(layouts, input);
    if main && index == 0 {
        return main_channels(layout, input);
    }
    let aux_index = index - main as usize;
    aux_ports(layout, input)
        .get(aux_index)
        .map(|c| c.get())
        .unwrap_or(0)
}

/// The host's bus `index` in direction `input`: the first layout that has it gives its
/// channel count and name.
pub fn describe(layouts: &[AudioIOLayout], input: bool, index: usize) -> Option<BusDesc> {
    if index >= count(layouts, input) {
        return None;
    }
    let (main, _) = shape(layouts, input);
    let is_main = main && index == 0;
    let owner = layouts
        .iter()
        .find(|l| channels_in(layouts, l, input, index) > 0)?;
    let name = if is_main {
        let names = &owner.names;
        let name = if input {
            names.main_input
        } else {
            names.main_output
        };
        name.unwrap_or(if input { "Input" } else { "Output" })
            .to_owned()
    } else {
        let aux_index = index - main as usize;
        let name = if input {
            owner.aux_input_name(aux_index)
        } else {
            owner.aux_output_name(aux_index)
        };
        name.unwrap_or_default()
    };
    let default_active = layouts
        .first()
        .is_some_and(|first| channels_in(layouts, first, input, index) > 0);
    Some(BusDesc {
        main: is_main,
        channels: channels_in(layouts, owner, input, index),
        name,
        default_active,
    })
}

/// The first layout whose busses are exactly the present ones with these channel counts:
/// `inputs[i]` and `outputs[i]` are the counts of the host's busses, 0 for an absent one.
pub fn matching(
    layouts: &[AudioIOLayout],
    inputs: &[u32],
    outputs: &[u32],
) -> Option<AudioIOLayout> {
    layouts
        .iter()
        .find(|layout| {
            let fits = |input: bool, counts: &[u32]| {
                counts.len() == count(layouts, input)
                    && counts
                        .iter()
                        .enumerate()
                        .all(|(i, &c)| channels_in(layouts, layout, input, i) == c)
            };
            fits(true, inputs) && fits(false, outputs)
        })
        .copied()
}

/// What the host said about the busses: the channel counts of its last accepted arrangement and
/// which busses it activated.
/// Whether the host may arrange the busses with these channel counts: some layout has every
/// one of its busses at the count given. Busses that layout lacks may carry any arrangement,
/// since they stay inactive while it is in use (JUCE arranges every bus, active or not).
pub fn arrangeable(layouts: &[AudioIOLayout], inputs: &[u32], outputs: &[u32]) -> bool {
    layouts.iter().any(|layout| {
        let fits = |input: bool, counts: &[u32]| {
            counts.len() == count(layouts, input)
                && counts.iter().enumerate().all(|(i, &c)| {
                    let own = channels_in(layouts, layout, input, i);
                    own == 0 || own == c
                })
        };
        fits(true, inputs) && fits(false, outputs)
    })
}

#[derive(Debug, Clone, Default)]
pub struct HostBusses {
    pub input_channels: Vec<u32>,
    pub output_channels: Vec<u32>,
    pub input_active: Vec<bool>,
    pub output_active: Vec<bool>,
}

impl HostBusses {
    /// The defaults: every bus with its described channel count, active as described.
    pub fn new(layouts: &[AudioIOLayout]) -> HostBusses {
        let side = |input: bool| -> (Vec<u32>, Vec<bool>) {
            (0..count(layouts, input))
                .map(|i| {
                    let d = describe(layouts, input, i);
                    (
                        d.as_ref().map(|d| d.channels).unwrap_or(0),
                        d.is_some_and(|d| d.default_active),
                    )
                })
                .unzip()
        };
        let (input_channels, input_active) = side(true);
        let (output_channels, output_active) = side(false);
        HostBusses {
            input_channels,
            output_channels,
            input_active,
            output_active,
        }
    }

    /// The layout for the present busses: active ones with their channel counts.
    pub fn layout(&self, layouts: &[AudioIOLayout]) -> Option<AudioIOLayout> {
        let present = |channels: &[u32], active: &[bool]| -> Vec<u32> {
            channels
                .iter()
                .zip(active)
                .map(|(&c, &a)| if a { c } else { 0 })
                .collect()
        };
        matching(
            layouts,
            &present(&self.input_channels, &self.input_active),
            &present(&self.output_channels, &self.output_active),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nice_plug_core::audio_setup::{PortNames, new_nonzero_u32};

    const LAYOUTS: &[AudioIOLayout] = &[
        AudioIOLayout {
            main_input_channels: None,
            main_output_channels: Some(new_nonzero_u32(2)),
            aux_input_ports: &[new_nonzero_u32(2)],
            aux_output_ports: &[],
            names: PortNames {
                layout: Some("Instrument with sidechain"),
                main_input: None,
                main_output: Some("Output"),
                aux_inputs: &["Sidechain"],
                aux_outputs: &[],
            },
        },
        AudioIOLayout {
            main_input_channels: Some(new_nonzero_u32(2)),
            main_output_channels: Some(new_nonzero_u32(2)),
            aux_input_ports: &[new_nonzero_u32(2)],
            aux_output_ports: &[],
            names: PortNames {
                layout: Some("Effect with sidechain"),
                main_input: Some("Input"),
                main_output: Some("Output"),
                aux_inputs: &["Sidechain"],
                aux_outputs: &[],
            },
        },
        AudioIOLayout {
            main_input_channels: Some(new_nonzero_u32(2)),
            main_output_channels: Some(new_nonzero_u32(2)),
            aux_input_ports: &[],
            aux_output_ports: &[],
            names: PortNames {
                layout: Some("Effect"),
                main_input: Some("Input"),
                main_output: Some("Output"),
                aux_inputs: &[],
                aux_outputs: &[],
            },
        },
    ];

    #[test]
    fn the_host_sees_the_union_of_the_layouts() {
        assert_eq!(count(LAYOUTS, true), 2);
        assert_eq!(count(LAYOUTS, false), 1);
        assert_eq!(aux_start(LAYOUTS, true), 1);
        let main = describe(LAYOUTS, true, 0).unwrap();
        assert_eq!(
            (
                main.main,
                main.channels,
                main.name.as_str(),
                main.default_active
            ),
            (true, 2, "Input", false)
        );
        let sidechain = describe(LAYOUTS, true, 1).unwrap();
        assert_eq!(
            (
                sidechain.main,
                sidechain.channels,
                sidechain.name.as_str(),
                sidechain.default_active
            ),
            (false, 2, "Sidechain", true)
        );
        let out = describe(LAYOUTS, false, 0).unwrap();
        assert_eq!((out.name.as_str(), out.default_active), ("Output", true));
        assert_eq!(describe(LAYOUTS, true, 2), None);
    }

    #[test]
    fn present_busses_choose_the_layout() {
        let name = |l: Option<AudioIOLayout>| l.and_then(|l| l.names.layout);
        assert_eq!(
            name(matching(LAYOUTS, &[0, 2], &[2])),
            Some("Instrument with sidechain")
        );
        assert_eq!(
            name(matching(LAYOUTS, &[2, 2], &[2])),
            Some("Effect with sidechain")
        );
        assert_eq!(name(matching(LAYOUTS, &[2, 0], &[2])), Some("Effect"));
        assert_eq!(name(matching(LAYOUTS, &[1, 2], &[2])), None);
        assert_eq!(name(matching(LAYOUTS, &[2], &[2])), None);

        let mut host = HostBusses::new(LAYOUTS);
        assert_eq!(
            name(host.layout(LAYOUTS)),
            Some("Instrument with sidechain")
        );
        host.input_active[0] = true;
        assert_eq!(name(host.layout(LAYOUTS)), Some("Effect with sidechain"));
        host.input_active[1] = false;
        assert_eq!(name(host.layout(LAYOUTS)), Some("Effect"));
    }

    #[test]
    fn busses_a_layout_lacks_may_carry_any_arrangement() {
        // A host that arranges the main input in stereo while it stays inactive: the
        // instrument layout still fits.
        assert!(arrangeable(LAYOUTS, &[2, 2], &[2]));
        assert!(arrangeable(LAYOUTS, &[0, 2], &[2]));
        assert!(arrangeable(LAYOUTS, &[2, 0], &[2]));
        // No layout has a mono output or a mono sidechain.
        assert!(!arrangeable(LAYOUTS, &[0, 2], &[1]));
        assert!(!arrangeable(LAYOUTS, &[0, 1], &[2]));
        assert!(!arrangeable(LAYOUTS, &[2], &[2]));
    }
}
