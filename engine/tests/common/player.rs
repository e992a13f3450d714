//! A preset played through the instrument the plugin runs, from rest, as often as a test
//! asks: what `playing.rs` and `sidechain.rs` hear.

use super::presets;
use ressort_engine::instrument::{
    self, Controls, Event, Gains, Instrument, Prepared, Timed, MAX_HOST_INPUTS, MAX_HOST_OUTPUTS,
};

/// The script of `models/NAME.mdl`.
pub fn preset(name: &str) -> String {
    presets()
        .into_iter()
        .find(|p| p.0 == name)
        .unwrap_or_else(|| panic!("models/{name}.mdl"))
        .1
}

/// A preset prepared once at one rate, played from rest as often as a test asks.
pub struct Player {
    pub model: Option<Box<Prepared>>,
    pub sample_rate: f64,
    /// The model's engine as prepared: at rest, every parameter as declared (a played copy
    /// holds the values its exciters last pressed).
    pub template: ressort_engine::Engine,
}

/// What one performance gave: every host output channel, and the strikes the sidechain
/// trigger played.
pub struct Take {
    pub channels: Vec<Vec<f32>>,
    pub triggered: u32,
    /// Guard trips: the model exploded and was reset.
    pub trips: u32,
    /// The Stiffness and Damping gains the instrument played the last note with.
    pub gains: Gains,
}

impl Take {
    pub fn peak(&self) -> f64 {
        self.channels
            .iter()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs() as f64))
    }

    pub fn peak_db(&self) -> f64 {
        db(self.peak())
    }

    /// The peak of the main channels between `from` and `to` seconds.
    pub fn peak_between(&self, sr: f64, from: f64, to: f64) -> f64 {
        let (a, b) = ((from * sr) as usize, (to * sr) as usize);
        self.channels[..2]
            .iter()
            .flat_map(|c| &c[a.min(c.len())..b.min(c.len())])
            .fold(0.0f64, |m, v| m.max(v.abs() as f64))
    }

    pub fn left(&self) -> Vec<f64> {
        self.channels[0].iter().map(|&v| v as f64).collect()
    }
}

/// x in dB (−240 for silence).
pub fn db(x: f64) -> f64 {
    if x > 0.0 {
        20.0 * x.log10()
    } else {
        -240.0
    }
}

impl Player {
    pub fn new(script: &str, sample_rate: f64) -> Player {
        let mut model = instrument::prepare("test", script, sample_rate).expect("it prepares");
        if let Some(v) = model.facts().settings.voices {
            model.set_voices(v as usize);
        }
        Player {
            template: model.engine.clone(),
            model: Some(Box::new(model)),
            sample_rate,
        }
    }

    pub fn model(&self) -> &Prepared {
        self.model.as_deref().unwrap()
    }

    /// Plays `events` (sample, event) and `sidechain` (both channels) for `seconds` with
    /// `controls`, from rest.
    pub fn play(
        &mut self,
        controls: Controls,
        events: &[(usize, Event)],
        sidechain: Option<&[f32]>,
        seconds: f64,
    ) -> Take {
        let sr = self.sample_rate;
        let mut model = self.model.take().expect("a model");
        model.engine.reset();
        model.rest_gestures();
        if let Some(b) = model.bank.as_mut() {
            b.clear();
        }
        let channels = match model.facts().num_outputs {
            0..=2 => 2,
            n => n.min(MAX_HOST_OUTPUTS).div_ceil(2) * 2,
        };
        let mut inst = Instrument::new(sr, controls);
        inst.set_model(model);
        let frames = (seconds * sr) as usize;
        let mut out = vec![vec![0.0f32; frames]; channels];
        let block = 480;
        let mut done = 0;
        let mut triggered = 0;
        let mut trips = 0;
        while done < frames {
            let len = block.min(frames - done);
            let mut evs = events
                .iter()
                .filter(|(t, _)| *t >= done && *t < done + len)
                .map(|&(t, e)| Timed::new((t - done) as u32, e));
            let mut host: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
            if let Some(s) = sidechain {
                host[2] = s.get(done..);
                host[3] = s.get(done..);
            }
            let mut slices: Vec<&mut [f32]> =
                out.iter_mut().map(|c| &mut c[done..done + len]).collect();
            let report = inst.process(len, &host, false, &mut evs, &controls, &mut slices);
            triggered += report.triggered;
            trips += report.trips;
            done += len;
        }
        let gains = inst.gains();
        let [model, _, _] = inst.take_models();
        self.model = model;
        Take {
            channels: out,
            triggered,
            trips,
            gains,
        }
    }

    /// One note held for `seconds`.
    pub fn note(&mut self, key: u8, velocity: f32, seconds: f64) -> Take {
        self.play(
            Controls::DEFAULT,
            &[(0, Event::note_on(key, velocity))],
            None,
            seconds,
        )
    }
}
