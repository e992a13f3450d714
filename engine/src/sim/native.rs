//! Running a copy of a model on its native code ([`crate::sim::jit`]): the driver that calls
//! the generated function block by block and keeps what stays with the interpreter (the
//! guard's record, the periodic flush, a sample the code refuses).

use crate::sim::engine::{BlockIo, Engine};
use crate::sim::flush::FLUSH_INTERVAL;
use crate::sim::jit;

impl Engine {
    /// Compiles this engine's sample loop to machine code when the model is small enough
    /// ([`jit::NativeCode::build`]; 1-D and 3-D alike), and notes whether it fits the
    /// current state. Off the audio thread: called once when the model is compiled.
    pub(crate) fn attach_native_code(&mut self) {
        self.native = jit::NativeCode::build(&self.parts()).map(std::sync::Arc::new);
        self.native_fits = self
            .native
            .as_ref()
            .is_some_and(|code| code.fits(&self.parts()));
    }

    /// The size in bytes of the machine code this model's sample loop runs on, when it runs on
    /// code compiled for it ([`crate::CompileOptions::jit`]: small models; see
    /// [`crate::sim::jit`]) rather than on the interpreter. Parameter changes are counted from
    /// the next block (or [`Engine::apply_pending_changes`]).
    pub fn native_code_bytes(&self) -> Option<usize> {
        self.native
            .as_ref()
            .filter(|_| self.native_fits)
            .map(|code| code.size())
    }

    /// Whether this model is one the native code compiles (its kinds and size; see
    /// [`crate::sim::jit`]), whether or not it got the code. A model that fits and runs on
    /// the interpreter with [`crate::CompileOptions::jit`] set means Cranelift failed on it.
    pub fn fits_native_code(&self) -> bool {
        jit::fits(&self.parts())
    }

    /// The compiled model and the parts of this copy's state the native code is made from.
    pub(crate) fn parts(&self) -> jit::Parts<'_> {
        jit::Parts {
            model: &self.model,
            points: &self.points,
            args: &self.args,
            singles: &self.singles,
            macros: &self.macros,
            proxies: &self.proxies,
            interactions: &self.interactions,
            control_bindings: &self.control.bindings,
            space: self.space.as_deref(),
        }
    }

    /// Samples `start..end` of a block on the native code (`self.native`, which `fits`):
    /// what [`Engine::run`] does on the interpreter, with the same samples. Returns how many
    /// samples ran (fewer when the guard trips).
    pub(crate) fn run_native(
        &mut self,
        samples: std::ops::Range<usize>,
        io: BlockIo<'_>,
        outputs: &mut [f64],
    ) -> usize {
        let BlockIo {
            frames,
            inputs,
            in_channels,
            out_channels,
        } = io;
        let Some(entry) = self.native.as_ref().map(|code| code.entry()) else {
            return 0;
        };
        // The native code reads and writes these buffers by raw pointer: checked on every call
        // (two comparisons a block), in release builds too.
        assert!(
            inputs.len() >= in_channels.saturating_mul(frames)
                && outputs.len() >= out_channels.saturating_mul(frames)
                && samples.end <= frames,
            "native code: buffers smaller than the block"
        );
        let mut sink = [0.0f64; jit::SPARE];
        let mut n = samples.start;
        while n < samples.end {
            // Calls end where the periodic flush is due.
            let due = FLUSH_INTERVAL - self.samples_since_reset % FLUSH_INTERVAL;
            let stop = samples.end.min(n + due as usize);
            let (space_axes, [coef, units, perp, rest, mic_weights, mic_dirs]) = self.space_frame();
            let frame = jit::Frame {
                x: self.points.x.as_mut_ptr(),
                xp: self.points.xp.as_mut_ptr(),
                f: self.points.f.as_mut_ptr(),
                args: self.args.as_ptr(),
                a: self.singles.a.as_ptr(),
                b: self.singles.b.as_ptr(),
                inv_m: self.singles.inv_m.as_ptr(),
                gravity: self.singles.gravity.as_ptr(),
                inputs: inputs.as_ptr(),
                outputs: outputs.as_mut_ptr(),
                frames,
                in_channels,
                out_channels,
                limit: self.position_limit,
                sign: -0.0,
                zero: jit::ZEROS.as_ptr(),
                sink: sink.as_mut_ptr(),
                axes: space_axes,
                coef,
                units,
                perp,
                rest,
                mic_weights,
                mic_dirs,
            };
            debug_assert!(stop - n <= jit::SPARE);
            // SAFETY: the code was made for this engine's arrays, whose lengths `fits`
            // checked; it reads input channels below `in_channels` and writes output channels
            // below `out_channels`, at samples below `stop` ≤ `frames`, which the caller's
            // buffers hold.
            let result = unsafe { entry(&frame, n as i64, stop as i64) };
            if result & jit::BAIL != 0 {
                // Samples n … k − 1 ran; sample k runs on the interpreter, which also counts
                // it, flushes and guards.
                let k = (result & !jit::BAIL) as usize;
                self.samples_since_reset += (k - n) as u64;
                let ran = self.run_interpreted(k..k + 1, io, outputs);
                if self.guard.is_some() {
                    return ran;
                }
                n = k + 1;
                continue;
            }
            let done = result as usize;
            if done < stop {
                // A bad output at sample `done`: the state is as after it.
                self.samples_since_reset += (done - n) as u64;
                if self.outputs_or_trip(done, frames, out_channels, outputs) {
                    return done + 1;
                }
                debug_assert!(false, "the native code and the guard disagree");
                self.samples_since_reset += 1;
                if self.samples_since_reset.is_multiple_of(FLUSH_INTERVAL) {
                    self.flush_all();
                }
                n = done + 1;
                continue;
            }
            self.samples_since_reset += (stop - n) as u64;
            if self.samples_since_reset.is_multiple_of(FLUSH_INTERVAL) {
                self.flush_all();
            }
            n = stop;
        }
        samples.end
    }

    /// A 3-D model's parts of the [`jit::Frame`]: its x and y axes (x, x̃, F) and its coef,
    /// units, perp, rest, mic weights and mic directions; null for a 1-D model.
    fn space_frame(&mut self) -> ([[*mut f64; 3]; 2], [*const f64; 6]) {
        let null = std::ptr::null_mut::<f64>();
        let mut axes = [[null; 3]; 2];
        let Some(space) = self.space.as_deref_mut() else {
            return (axes, [std::ptr::null(); 6]);
        };
        for (to, axis) in axes.iter_mut().zip(space.planar_axes()) {
            *to = [
                axis.x.as_mut_ptr(),
                axis.xp.as_mut_ptr(),
                axis.f.as_mut_ptr(),
            ];
        }
        let data = [
            space.coef.as_ptr().cast::<f64>(),
            space.directions.units.as_ptr().cast::<f64>(),
            space.directions.perp.as_ptr().cast::<f64>(),
            space.rest.as_ptr().cast::<f64>(),
            space.mic_weights.as_ptr(),
            space.mic_dirs.as_ptr().cast::<f64>(),
        ];
        (axes, data)
    }
}
