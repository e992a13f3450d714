//! The native code against the interpreter, bit for bit, through a scripted life (used by
//! the `jit` and `random_models` tests).

use ressort_engine::{compile, parse, CompileOptions, Engine, ParamId, ScaleClass};

pub fn build(text: &str, sr: f64, jit: bool) -> Engine {
    let spec = parse(text).spec.expect("parses");
    let options = CompileOptions {
        jit,
        ..CompileOptions::at(sr)
    };
    compile(&spec, &options).expect("compiles")
}

pub fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// A deterministic stream of numbers.
pub struct Lcg(pub u64);

impl Lcg {
    pub fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }

    pub fn below(&mut self, n: usize) -> usize {
        self.next() as usize % n
    }

    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    pub fn unit(&mut self) -> f64 {
        self.next() as f64 / (1u64 << 31) as f64
    }
}

/// Plays `text` natively and on the interpreter through `blocks` blocks of a scripted life and
/// compares everything after every block. Returns how many blocks ran native code.
pub fn native_equals_interpreter(text: &str, sr: f64, blocks: usize, seed: u64) -> usize {
    let mut native = build(text, sr, true);
    let mut interpreted = build(text, sr, false);
    assert!(interpreted.native_code_bytes().is_none());
    assert_eq!(
        native.native_code_bytes().is_some(),
        native.fits_native_code(),
        "a model that fits compiles:\n{text}"
    );
    let ins = native.info().num_inputs();
    let outs = native.info().num_outputs();
    let params: Vec<ParamId> = (0..native.info().params.len())
        .map(|i| ParamId(i as u32))
        .collect();
    let mut rng = Lcg(seed);
    let mut native_blocks = 0;
    for block in 0..blocks {
        let frames = match rng.next() % 4 {
            0 => 1,
            1 => 1 + rng.next() as usize % 17,
            _ => 1 + rng.next() as usize % 300,
        };
        // One channel fewer or more than the model has, now and then.
        let in_channels = match rng.next() % 8 {
            0 => ins.saturating_sub(1),
            1 => ins + 1,
            _ => ins,
        };
        let mut input = vec![0.0; in_channels * frames];
        match rng.next() % 8 {
            0 => {
                for v in input.iter_mut() {
                    *v = (rng.unit() - 0.5) * 0.01;
                }
            }
            1 | 2 => {
                for c in 0..in_channels {
                    input[c * frames + rng.next() as usize % frames] = -0.02 * rng.unit();
                }
            }
            3 if block % 5 == 0 => {
                let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -0.0, 1e300];
                for v in input.iter_mut().step_by(3) {
                    *v = bad[rng.next() as usize % bad.len()];
                }
            }
            _ => {}
        }
        for e in [&mut native, &mut interpreted] {
            match block % 97 {
                13 => e.set_class_gain(ScaleClass::Stiffness, 0.5 + block as f64 / blocks as f64),
                29 => e.set_class_gain(ScaleClass::Damping, 2.0),
                41 => e.set_position_limit(0.001),
                42 => e.set_position_limit(1e4),
                43 | 70 => e.reset(),
                _ => {}
            }
        }
        if block % 31 == 7 && !params.is_empty() {
            let id = params[rng.next() as usize % params.len()];
            let v = native.param(id).unwrap() * (0.5 + rng.unit());
            native.set_param(id, v).unwrap();
            interpreted.set_param(id, v).unwrap();
        }
        // One output channel fewer or more than the model has, now and then.
        let out_channels = match rng.next() % 8 {
            0 => outs.saturating_sub(1),
            1 => outs + 1,
            _ => outs,
        };
        let (mut a, mut b) = (
            vec![0.0; out_channels * frames],
            vec![0.0; out_channels * frames],
        );
        native.apply_pending_changes();
        native_blocks += native.native_code_bytes().is_some() as usize;
        let ra = native.process(frames, &input, &mut a);
        let rb = interpreted.process(frames, &input, &mut b);
        let at = format!("{text}\nblock {block} ({frames} frames)");
        assert_eq!(bits(&a), bits(&b), "outputs, {at}");
        assert_eq!(ra, rb, "report, {at}");
        assert_eq!(
            bits(native.positions()),
            bits(interpreted.positions()),
            "x, {at}"
        );
        assert_eq!(
            bits(native.delayed_positions()),
            bits(interpreted.delayed_positions()),
            "x̃, {at}"
        );
        assert_eq!(bits(native.forces()), bits(interpreted.forces()), "F, {at}");
        // A 3-D model's x and y axes (empty for a 1-D model).
        for c in 0..2 {
            let (a, b) = (native.axis_state(c), interpreted.axis_state(c));
            for (k, name) in ["x", "x̃", "F"].iter().enumerate() {
                assert_eq!(bits(a[k]), bits(b[k]), "{name} on axis {c}, {at}");
            }
        }
        assert_eq!(native.guard_event(), interpreted.guard_event(), "{at}");
    }
    native_blocks
}
