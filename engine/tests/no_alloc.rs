//! Proves that nothing allocates after compile: a counting global allocator wraps the system
//! one, and every reference model runs through process, parameter and gain changes, reset and
//! motion writes while counting. Runs without the test harness so no other thread allocates.

use ressort_engine::{compile, reference, CompileOptions, MotionStore, ScaleClass};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn counted<R>(f: impl FnOnce() -> R) -> (R, usize) {
    ALLOCATIONS.store(0, Ordering::SeqCst);
    COUNTING.store(true, Ordering::SeqCst);
    let r = f();
    COUNTING.store(false, Ordering::SeqCst);
    (r, ALLOCATIONS.load(Ordering::SeqCst))
}

fn main() {
    // The counter itself must see allocations, or the test proves nothing.
    let (_, n) = counted(|| std::hint::black_box(vec![1u8; 64]));
    assert!(n >= 1, "the counting allocator does not count");

    let mut passed = 0;
    let mut failed = 0;
    let mut audio_params_set = 0;
    let mut natives = 0;
    for (name, spec) in reference::all() {
        // A clone, as voices and the plugin run: `clone` keeps lengths, not capacities.
        let mut e = compile(&spec, &CompileOptions::at(48_000.0))
            .unwrap()
            .clone();
        let frames = 256;
        let in_ch = e.info().num_inputs();
        let out_ch = e.info().num_outputs();
        let mut input = vec![0.0; in_ch * frames];
        if in_ch > 0 {
            input[0] = -0.01;
        }
        for (c, chunk) in input.chunks_mut(frames).enumerate().skip(1) {
            chunk.iter_mut().for_each(|v| *v = 0.3 + 0.01 * c as f64);
        }
        let mut output = vec![0.0; out_ch * frames];
        let store = Arc::new(MotionStore::new(e.info().num_points));
        let store_for_engine = Arc::clone(&store);
        let param = (0..e.info().params.len())
            .map(|i| ressort_engine::ParamId(i as u32))
            .find(|&id| e.info().params[id.0 as usize].audio_input.is_none());
        // Setting an audio-rate parameter moves its default.
        let audio_param = (0..e.info().params.len())
            .map(|i| ressort_engine::ParamId(i as u32))
            .find(|&id| e.info().params[id.0 as usize].audio_input.is_some());
        audio_params_set += audio_param.is_some() as usize;
        let blocks = if name == "chladni_150" { 2 } else { 20 };
        let (_, allocations) = counted(|| {
            e.set_motion_store(Some(store_for_engine));
            for b in 0..blocks {
                e.process(frames, &input, &mut output);
                if let Some(id) = param {
                    let v = e.param(id).unwrap_or(0.0);
                    let _ = e.set_param(id, v * (1.0 + 1e-3 * b as f64));
                }
                if let Some(id) = audio_param {
                    let d = e.info().params[id.0 as usize].default;
                    e.set_param(id, d + 1e-3 * b as f64).unwrap();
                }
                e.set_class_gain(ScaleClass::Stiffness, 1.0 + 0.01 * b as f64);
                e.set_class_gain(ScaleClass::Damping, 1.0 - 0.01 * b as f64);
                // Odd block sizes.
                e.process(1, &input[..in_ch], &mut output[..out_ch]);
            }
            e.reset();
            e.process(frames, &input, &mut output);
        });
        let frames_written = store.frames_written();
        if allocations == 0 && frames_written > 0 {
            passed += 1;
            println!("test no_alloc::{name} ... ok");
        } else {
            failed += 1;
            println!(
                "test no_alloc::{name} ... FAILED ({allocations} allocations, {frames_written} \
                 motion frames)"
            );
        }
        // Without a motion store a small model runs on its native code (engine/src/sim/jit.rs):
        // the same life again, on that path.
        drop(e.set_motion_store(None));
        e.apply_pending_changes();
        if e.native_code_bytes().is_some() {
            natives += 1;
            let (native_blocks, allocations) = counted(|| {
                let mut native_blocks = 0;
                for b in 0..blocks {
                    native_blocks += e.native_code_bytes().is_some() as usize;
                    e.process(frames, &input, &mut output);
                    if let Some(id) = param {
                        let v = e.param(id).unwrap_or(0.0);
                        let _ = e.set_param(id, v * (1.0 + 1e-3 * b as f64));
                    }
                    e.set_class_gain(ScaleClass::Stiffness, 1.0 + 0.01 * b as f64);
                    e.process(1, &input[..in_ch], &mut output[..out_ch]);
                }
                e.reset();
                e.process(frames, &input, &mut output);
                native_blocks
            });
            if allocations == 0 && native_blocks > 0 {
                passed += 1;
                println!("test no_alloc::{name}_native ... ok");
            } else {
                failed += 1;
                println!(
                    "test no_alloc::{name}_native ... FAILED ({allocations} allocations, \
                     {native_blocks} native blocks)"
                );
            }
        }
    }
    // At least one reference model runs native code, or that path went unchecked.
    if natives == 0 {
        println!("test no_alloc::native_code ... FAILED (no model runs native code)");
        failed += 1;
    }
    // The instrument with a voice bank through a storm of 10,000 notes (stealing, releasing,
    // the sustain pedal, controllers, pitch bend), host input, and a reset: a small model of
    // single masses, and macros with connection points (both in voice lanes).
    let storms = [
        (
            "instrument_note_storm",
            "@K param 0.05\n@o osc 1. K 0.0005 0. 0.\n@g ground 0.1\n@h mass 1. 0.1 0.\n\
             @hs springDamper @g @h 0.0001 0.01\n@hit contact @o @h 0.1 0.001\n\
             @in1 frcInput @h\n@out1 posOutput @o\n",
            false,
        ),
        (
            "instrument_note_storm_macros",
            "@s string 24 1. 0.1 0.0005 0. 0.\n@m cornerMesh 5 4 1. 0.1 0.001 0. 0.\n\
             @j springDamper [@s 0.5] [@m 0.5 0.5] 0.02 0.001\n@in1 frcInput [@s 0.3]\n\
             @out1 posOutput [@m 0.7 0.6]\n",
            false,
        ),
        // Exciters on every voice: a bow whose friction a key presses, a plectrum, and a
        // strike; the sidechain in trigger mode (onsets become voices).
        (
            "instrument_note_storm_exciters_trigger",
            "@nlZ audioParam @in3\n@s string 24 1. 0.1 0.0005 0. 0.\n@in1 posInput 0.\n\
             @in2 posInput 0.\n@b nlBow @in1 [@s 0.2] nlZ 0.00005\n\
             @p nlPluck @in2 [@s 0.6] 0.1 0.005\n@in4 frcInput [@s 0.4]\n\
             @out1 posOutput [@s 0.7]\n~exciter in1 bow\n~exciter in2 pluck\n\
             ~exciter in3 press 0.1\n~exciter in4 strike\n~route in4 sidechain_1\n",
            true,
        ),
    ];
    for (name, script, trigger) in storms {
        use ressort_engine::instrument::{self, Controls, Event, Instrument, Timed};
        let mut model = instrument::prepare("storm", script, 48_000.0).unwrap();
        model.set_voices(16);
        let controls = Controls {
            release: 0.5,
            trigger,
            ..Controls::DEFAULT
        };
        let mut inst = Instrument::new(48_000.0, controls);
        inst.set_model(Box::new(model));
        inst.set_cc_map(&std::array::from_fn(|i| (i == 0).then_some(74)));
        let frames = 512;
        // A click train on the sidechain: a hit every 128 samples for the trigger.
        let side: Vec<f32> = (0..frames)
            .map(|n| if n % 128 < 4 { 0.5 } else { 0.01 })
            .collect();
        let (mut l, mut r) = (vec![0.0f32; frames], vec![0.0f32; frames]);
        let mut ended = 0usize;
        let (notes, allocations) = counted(|| {
            let mut notes = 0usize;
            let mut block = 0u32;
            while notes < 10_000 {
                let base = notes;
                let events = (0..64u32).map(move |k| {
                    let n = base + k as usize;
                    let event = match k % 8 {
                        0..=4 => Event::note_on((24 + n % 80) as u8, 0.5),
                        5 => Event::note_off((24 + (n - 3) % 80) as u8),
                        6 => Event::Controller {
                            cc: if block.is_multiple_of(2) { 64 } else { 74 },
                            value: 0.9,
                        },
                        _ => Event::PitchBend {
                            value: 0.7,
                            channel: 0,
                        },
                    };
                    Timed::new(k * 8, event)
                });
                let mut events = events;
                let host_in: [Option<&[f32]>; 4] = [None, None, Some(&side), None];
                let mut out: [&mut [f32]; 2] = [&mut l, &mut r];
                inst.process(frames, &host_in, false, &mut events, &controls, &mut out);
                inst.drain_ended(|_| ended += 1);
                notes += 40;
                block += 1;
            }
            inst.reset(controls);
            notes
        });
        if allocations == 0 && notes >= 10_000 && ended > 0 {
            passed += 1;
            println!("test no_alloc::{name} ... ok ({notes} notes, {ended} voices ended)");
        } else {
            failed += 1;
            println!(
                "test no_alloc::{name} ... FAILED ({allocations} allocations, {ended} voices \
                 ended)"
            );
        }
    }
    // At least one reference model has an audio-rate parameter, or its path went unchecked.
    if audio_params_set == 0 {
        println!("test no_alloc::audio_rate_parameters ... FAILED (no model has one)");
        failed += 1;
    }
    println!();
    println!("{passed} passed, {failed} failed");
    if failed > 0 {
        std::process::exit(1);
    }
}
