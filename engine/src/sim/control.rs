//! Control-rate arguments: every argument that depends on no audio-rate parameter, kept equal
//! to `expression(parameters) × class factor` (spec §1.7: the sample-rate factor of its
//! scaling class times the host's gain of that class) without re-evaluating what did not move.
//!
//! A host that automates Stiffness, Damping or a macro changes a class gain or a parameter every
//! 16-sample chunk. Re-evaluating every argument then costs as much as the simulation on a model
//! written element by element (thousands of arguments, each its own expression). Here:
//! - each binding's expression value (`raw`, without its class factor) is cached, and a
//!   parameter change re-evaluates only the bindings that read that parameter;
//! - a class factor change rescales only the bindings of that class (a constant 0 never does);
//! - only the single masses and connection points whose arguments changed bit for bit are
//!   re-derived.
//!
//! Every argument is computed by the same operations as a full re-evaluation
//! (`eval(expr) × factor`), so the incremental and the full refresh give the same bits
//! (test `incremental_refresh_equals_a_full_one`).

use crate::laws::NUM_ARG_CLASSES;
use crate::sim::compiled::Binding;
use crate::spec::expr::Program;

/// `slot_dep` value of a slot nothing derives from.
const NO_DEP: u32 = u32::MAX;
/// `slot_dep` value of a connection-point coordinate.
const PROXY_DEP: u32 = u32::MAX - 1;

/// What a refresh changed, for the engine to re-derive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Changed {
    /// Everything was evaluated (the first refresh).
    All,
    /// Only the singles in [`ControlArgs::dirty_singles`], and the connection points if
    /// `proxies` is set. `values` tells whether a parameter moved an expression's value
    /// (not only a class factor, which scales equal arguments to equal arguments).
    Some { proxies: bool, values: bool },
}

/// The control bindings of a model and what their incremental refresh needs.
#[derive(Clone, Debug, Default)]
pub(crate) struct ControlArgs {
    pub bindings: Vec<Binding>,
    /// Each bound slot's expression value, without its class factor (by slot; a slot no
    /// binding writes holds its argument).
    raw: Vec<f64>,
    /// The bindings that read parameter p: `readers[reader_start[p]..reader_start[p + 1]]`.
    reader_start: Vec<u32>,
    readers: Vec<u32>,
    /// The slots of each class that a factor change rescales (a constant 0 never moves):
    /// those nothing derives from, then those a single or a connection point derives from.
    rescale: [Vec<u32>; NUM_ARG_CLASSES],
    rescale_derived: [Vec<u32>; NUM_ARG_CLASSES],
    /// Which single mass derives from each argument slot (or [`NO_DEP`], [`PROXY_DEP`]).
    slot_dep: Vec<u32>,
    /// The parameter values and class factors the arguments were computed from.
    seen_params: Vec<f64>,
    seen_factors: [f64; NUM_ARG_CLASSES],
    /// Singles whose arguments changed in the last refresh: `dirty[..num_dirty]` (sized for
    /// every single, as a length and not a capacity, which `clone` would not keep).
    dirty: Vec<u32>,
    num_dirty: usize,
    is_dirty: Vec<bool>,
    proxies_changed: bool,
    /// No refresh has run yet: `raw` holds the values at `seen_params`, `args` nothing yet.
    fresh: bool,
}

impl ControlArgs {
    /// Indexes `bindings` once, when the model is compiled: which parameters each reads, its
    /// class, and the single mass (`single_cols`: the four argument columns of `singles`
    /// masses) or connection point (`proxy_slots`) that derives from its slot. Each binding's
    /// value at the parameters' values `params` is evaluated here, once: the first refresh
    /// uses it when the parameters have not moved since.
    pub fn new(
        bindings: Vec<Binding>,
        program: &Program,
        params: &[f64],
        args: &[f64],
        single_cols: [usize; 4],
        singles: usize,
        proxy_slots: impl Iterator<Item = usize>,
    ) -> ControlArgs {
        let num_params = params.len();
        let mut count = vec![0u32; num_params + 1];
        let mut rescale: [Vec<u32>; NUM_ARG_CLASSES] = Default::default();
        let mut rescale_derived: [Vec<u32>; NUM_ARG_CLASSES] = Default::default();
        let num_slots = args.len();
        let mut slot_dep = vec![NO_DEP; num_slots];
        for col in single_cols {
            for i in 0..singles {
                if let Some(d) = slot_dep.get_mut(col + i) {
                    *d = i as u32;
                }
            }
        }
        for s in proxy_slots {
            if let Some(d) = slot_dep.get_mut(s) {
                *d = PROXY_DEP;
            }
        }
        // Two sweeps of the bindings: count each parameter's readers, then list them. A
        // binding that reads a parameter twice is listed once. (An expression reads a few
        // parameters at most, so finding its distinct ones needs no allocation.)
        let params_of = |e| {
            program
                .params_read(e)
                .enumerate()
                .filter(move |&(k, p)| !program.params_read(e).take(k).any(|q| q == p))
                .map(|(_, p)| p)
        };
        let mut stack = program.new_stack().0;
        // Slots no binding writes keep the compiler's value.
        let mut raw = args.to_vec();
        for (i, b) in bindings.iter().enumerate() {
            let mut reads_none = true;
            for p in params_of(b.expr) {
                count[p as usize + 1] += 1;
                reads_none = false;
            }
            let value = program.eval(b.expr, params, &mut stack);
            if let Some(r) = raw.get_mut(b.slot as usize) {
                *r = value;
            }
            let constant_zero = reads_none && value == 0.0;
            if !constant_zero {
                let c = b.class as usize;
                match slot_dep[b.slot as usize] {
                    NO_DEP => rescale[c].push(b.slot),
                    _ => rescale_derived[c].push(i as u32),
                }
            }
        }
        let mut reader_start = count;
        for p in 0..num_params {
            reader_start[p + 1] += reader_start[p];
        }
        let mut fill = reader_start.clone();
        let mut readers = vec![0; reader_start[num_params] as usize];
        if !readers.is_empty() {
            for (i, b) in bindings.iter().enumerate() {
                for p in params_of(b.expr) {
                    readers[fill[p as usize] as usize] = i as u32;
                    fill[p as usize] += 1;
                }
            }
        }
        debug_assert!(
            {
                let mut slots: Vec<u32> = bindings.iter().map(|b| b.slot).collect();
                slots.sort_unstable();
                slots.windows(2).all(|w| w[0] != w[1])
            },
            "one binding per slot"
        );
        ControlArgs {
            raw,
            bindings,
            reader_start,
            readers,
            rescale,
            rescale_derived,
            slot_dep,
            seen_params: params.to_vec(),
            seen_factors: [0.0; NUM_ARG_CLASSES],
            dirty: vec![0; singles],
            num_dirty: 0,
            is_dirty: vec![false; singles],
            proxies_changed: false,
            fresh: true,
        }
    }

    /// Every slot's value before its class factor. Arguments of one class that are equal
    /// here are equal whatever the factors.
    pub fn raw(&self) -> &[f64] {
        &self.raw
    }

    /// The slots a change of class `c`'s factor rescales: those nothing derives from, and
    /// those a single (its index) derives from. For the voice lanes, which keep one factor per
    /// lane.
    pub fn rescaled(
        &self,
        c: usize,
    ) -> (&[u32], impl Iterator<Item = (usize, Option<usize>)> + '_) {
        let derived = self.rescale_derived[c].iter().map(|&i| {
            let slot = self.bindings[i as usize].slot as usize;
            let single = match self.slot_dep[slot] {
                NO_DEP | PROXY_DEP => None,
                s => Some(s as usize),
            };
            (slot, single)
        });
        (&self.rescale[c], derived)
    }

    /// The singles whose arguments the last refresh changed.
    pub fn dirty_singles(&self) -> &[u32] {
        &self.dirty[..self.num_dirty]
    }

    /// Brings `args` up to date with `params` and `factors`. Never allocates.
    pub fn refresh(
        &mut self,
        program: &Program,
        params: &[f64],
        stack: &mut Vec<f64>,
        factors: &[f64; NUM_ARG_CLASSES],
        args: &mut [f64],
    ) -> Changed {
        for &i in &self.dirty[..self.num_dirty] {
            self.is_dirty[i as usize] = false;
        }
        self.num_dirty = 0;
        self.proxies_changed = false;
        if self.fresh {
            // `raw` holds every binding's value at `seen_params` (see `new`).
            let moved = params.len() != self.seen_params.len()
                || params
                    .iter()
                    .zip(&self.seen_params)
                    .any(|(p, q)| p.to_bits() != q.to_bits());
            for b in &self.bindings {
                let slot = b.slot as usize;
                if moved {
                    self.raw[slot] = program.eval(b.expr, params, stack);
                }
                args[slot] = self.raw[slot] * factors[b.class as usize];
            }
            self.seen_params.copy_from_slice(params);
            self.seen_factors = *factors;
            self.fresh = false;
            return Changed::All;
        }
        let mut values = false;
        for p in 0..self.seen_params.len() {
            if params[p].to_bits() == self.seen_params[p].to_bits() {
                continue;
            }
            self.seen_params[p] = params[p];
            let range = self.reader_start[p] as usize..self.reader_start[p + 1] as usize;
            values |= !range.is_empty();
            for k in range {
                let i = self.readers[k] as usize;
                let b = self.bindings[i];
                self.raw[b.slot as usize] = program.eval(b.expr, params, stack);
                self.write(i, factors, args);
            }
        }
        for c in 0..NUM_ARG_CLASSES {
            if factors[c].to_bits() == self.seen_factors[c].to_bits() {
                continue;
            }
            self.seen_factors[c] = factors[c];
            // Arguments only the kernels read: a plain loop.
            let f = factors[c];
            for &s in &self.rescale[c] {
                args[s as usize] = self.raw[s as usize] * f;
            }
            for k in 0..self.rescale_derived[c].len() {
                let i = self.rescale_derived[c][k] as usize;
                self.write(i, factors, args);
            }
        }
        Changed::Some {
            proxies: self.proxies_changed,
            values,
        }
    }

    /// Writes binding `i`'s argument and notes what derives from it, if it changed.
    #[inline]
    fn write(&mut self, i: usize, factors: &[f64; NUM_ARG_CLASSES], args: &mut [f64]) {
        let b = self.bindings[i];
        let slot = b.slot as usize;
        let v = self.raw[slot] * factors[b.class as usize];
        if v.to_bits() == args[slot].to_bits() {
            return;
        }
        args[slot] = v;
        match self.slot_dep[slot] {
            NO_DEP => {}
            PROXY_DEP => self.proxies_changed = true,
            s => {
                if !self.is_dirty[s as usize] {
                    self.is_dirty[s as usize] = true;
                    self.dirty[self.num_dirty] = s;
                    self.num_dirty += 1;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::spec::ScaleClass;
    use crate::{compile, parse, CompileOptions, Engine, ParamId};

    /// The next value of a small deterministic generator in [0, 1).
    fn next(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// Runs `engine` through blocks of parameter and gain changes (some blocks change
    /// nothing), beside a copy that re-evaluates every argument before each block; both must
    /// give the same arguments, coefficients and samples, bit for bit.
    fn incremental_equals_full(name: &str, mut engine: Engine, seed: &mut u64) {
        let mut full = engine.clone();
        let n_in = engine.info().num_inputs();
        let n_out = engine.info().num_outputs();
        let params: Vec<(ParamId, f64)> = engine
            .info()
            .params
            .iter()
            .filter(|p| p.audio_input.is_none())
            .map(|p| (engine.param_id(&p.name).unwrap(), p.default))
            .collect();
        let frames = 16;
        let mut input = vec![0.0; n_in * frames];
        let (mut a, mut b) = (vec![0.0; n_out * frames], vec![0.0; n_out * frames]);
        for block in 0..120 {
            input.fill(0.0);
            if block % 40 == 0 {
                for c in 0..n_in {
                    input[c * frames] = -0.01;
                }
            }
            match block % 4 {
                0 => {}
                1 => {
                    let g = 0.5 + next(seed);
                    engine.set_class_gain(ScaleClass::Stiffness, g);
                    full.set_class_gain(ScaleClass::Stiffness, g);
                }
                2 => {
                    let g = 0.5 + next(seed);
                    engine.set_class_gain(ScaleClass::Damping, g);
                    full.set_class_gain(ScaleClass::Damping, g);
                }
                _ => {
                    for &(id, default) in &params {
                        if next(seed) < 0.5 {
                            let v = default * (0.8 + 0.4 * next(seed));
                            engine.set_param(id, v).unwrap();
                            full.set_param(id, v).unwrap();
                        }
                    }
                }
            }
            full.control.fresh = true;
            full.params_dirty = true;
            engine.process(frames, &input, &mut a);
            full.process(frames, &input, &mut b);
            assert_eq!(
                bits(&engine.args),
                bits(&full.args),
                "{name}, block {block}"
            );
            let (s, t) = (&engine.singles, &full.singles);
            for (x, y) in [(&s.a, &t.a), (&s.b, &t.b), (&s.inv_m, &t.inv_m)] {
                assert_eq!(bits(x), bits(y), "{name}, block {block}");
            }
            assert_eq!(engine.proxies.nodes, full.proxies.nodes, "{name}");
            assert_eq!(bits(&a), bits(&b), "{name}, block {block}");
        }
        assert_eq!(bits(engine.positions()), bits(full.positions()), "{name}");
    }

    /// Every preset, and an element-by-element model whose masses, oscillators and links read
    /// parameters: the incremental refresh gives what a full re-evaluation gives.
    #[test]
    fn incremental_refresh_equals_a_full_one() {
        let mut seed = 7;
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
        let mut names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "mdl"))
            .collect();
        names.sort();
        assert!(names.len() > 10, "{}", dir.display());
        for path in names {
            let spec = crate::lang::parse_with_files(
                &std::fs::read_to_string(&path).unwrap(),
                &crate::lang::folder_files(&dir),
            )
            .spec
            .expect("a preset parses");
            let engine = compile(&spec, &CompileOptions::at(48_000.0)).expect("compiles");
            if engine.info().num_points > 5000 {
                continue;
            }
            incremental_equals_full(&path.display().to_string(), engine, &mut seed);
        }
        let text = "@M param 1.\n@K param 0.1\n@Z param 0.001\n@c param 0.5\n\
            @g ground 0.\n@o osc M K Z 0. 0.\n@m1 mass M*2 0. 0.\n@m2 mass 1.5 0. 0.\n\
            @l1 springDamper @g @o K Z\n@l2 springDamper @o @m1 K*c Z/c\n\
            @l3 springDamper @m1 @m2 0.2 Z\n@l4 contact @m2 @g K 0.01 0.\n\
            @in1 frcInput @o\n@out1 posOutput @m2\n";
        let spec = parse(text).spec.expect("parses");
        let engine = compile(&spec, &CompileOptions::at(44_100.0)).expect("compiles");
        incremental_equals_full("params", engine, &mut seed);
    }
}
