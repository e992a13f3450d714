//! `ressort modes` and `ressort tune`: the modal analysis of the engine (spec §5.5) as a table,
//! and tuning one mode "by maths" (spec §5.3) through a parameter or the K-class gain.

use crate::{build, load, usage, Failure};
use clap::Args;
use ressort_engine::modes::{note_frequency, note_name, ModalAnalysis, Solver, StiffnessLimit};
use ressort_engine::{Engine, ScaleClass};
use std::path::PathBuf;

/// The residual (relative to the typical force) below which a static equilibrium Newton did
/// not converge on is still reported as found.
const NEAR_EQUILIBRIUM: f64 = 1e-6;

#[derive(Args, Debug)]
pub(crate) struct ModesArgs {
    /// The model script.
    model: PathBuf,
    /// Show the lowest N modes (default: all for models up to 1500 moving masses, the
    /// lowest 50 beyond).
    #[arg(long)]
    count: Option<usize>,
    /// Sample rate in Hz.
    #[arg(long, default_value_t = 44_100.0)]
    sample_rate: f64,
    /// Write comma-separated values (for plotting) instead of the table.
    #[arg(long)]
    csv: bool,
}

#[derive(Args, Debug)]
pub(crate) struct TuneArgs {
    /// The model script.
    model: PathBuf,
    /// The mode to tune, numbered as `ressort modes` prints them (1 is the lowest).
    #[arg(long)]
    mode: usize,
    /// The target: a frequency in Hz (`440`, `440Hz`) or a note (`A4`, `C#3`, `Eb2`).
    #[arg(long)]
    to: String,
    /// The parameter to change; without it, the K-class gain (with the Z class by its square
    /// root, which keeps the decay per cycle).
    #[arg(long)]
    param: Option<String>,
    /// Sample rate in Hz.
    #[arg(long, default_value_t = 44_100.0)]
    sample_rate: f64,
}

/// A number with 9 significant digits, without trailing zeros.
fn sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (8 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// (channel, channel) pairs of the gain columns: every input to every output that some
/// listed mode links (a position input on a contact open at rest links nothing).
fn gain_columns(a: &ModalAnalysis) -> Vec<(usize, usize)> {
    let mut cols = Vec::new();
    for i in 1..=a.num_inputs {
        for o in 1..=a.num_outputs {
            if (0..a.modes.len()).any(|k| a.gain(k, i, o) != 0.0) {
                cols.push((i, o));
            }
        }
    }
    cols
}

/// The inputs that reach no output through the listed modes, as `in2, in3`.
fn silent_inputs(a: &ModalAnalysis, cols: &[(usize, usize)]) -> String {
    (1..=a.num_inputs)
        .filter(|i| !cols.iter().any(|c| c.0 == *i))
        .map(|i| format!("in{i}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The modes table (or CSV) of an analysis.
pub(crate) fn format_modes(a: &ModalAnalysis, csv: bool) -> String {
    let cols = gain_columns(a);
    let mut out = String::new();
    if csv {
        out.push_str("mode,frequency_hz,note,cents,t60_s");
        for (i, o) in &cols {
            out.push_str(&format!(",gain_in{i}_out{o}"));
        }
        out.push('\n');
    } else {
        out.push_str(&format!(
            "{:>4}  {:>12}  {:<5} {:>6}  {:>10}",
            "mode", "Hz", "note", "cents", "T60 s"
        ));
        for (i, o) in &cols {
            out.push_str(&format!("  {:>10}", format!("in{i}→out{o}")));
        }
        out.push('\n');
    }
    for (k, m) in a.modes.iter().enumerate() {
        let (note, cents) = note_name(m.frequency_hz).unwrap_or(("-".into(), 0.0));
        let t60 = if m.t60_s.is_finite() {
            format!("{:.4}", m.t60_s)
        } else {
            "inf".into()
        };
        if csv {
            out.push_str(&format!(
                "{},{},{note},{cents:.2},{}",
                k + 1,
                sig(m.frequency_hz),
                if m.t60_s.is_finite() {
                    sig(m.t60_s)
                } else {
                    "inf".into()
                }
            ));
            for (i, o) in &cols {
                out.push_str(&format!(",{:e}", a.gain(k, *i, *o)));
            }
        } else {
            out.push_str(&format!(
                "{:>4}  {:>12.4}  {note:<5} {cents:>+6.1}  {t60:>10}",
                k + 1,
                m.frequency_hz
            ));
            for (i, o) in &cols {
                out.push_str(&format!("  {:>10.3e}", a.gain(k, *i, *o)));
            }
        }
        out.push('\n');
    }
    out
}

pub(crate) fn modes(a: &ModesArgs) -> Result<(), Failure> {
    let spec = load(&a.model)?;
    let mut engine = build(&a.model, &spec, a.sample_rate)?;
    let analysis = engine.modes(a.count);
    if a.csv {
        print!("{}", format_modes(&analysis, true));
        return Ok(());
    }
    let solver = match analysis.solver {
        Solver::Dense => "dense",
        Solver::Companion => "companion matrix",
        Solver::Sparse => "sparse shift-invert",
    };
    let damping = if analysis.proportional {
        "exact decays"
    } else {
        "decays from the projected damping"
    };
    let what = if engine.is_3d() {
        "degrees of freedom (3-D: one per moving point and free axis)"
    } else {
        "moving masses"
    };
    println!(
        "{}: {} {what} at {} Hz; {} modes ({solver}, {damping})",
        a.model.display(),
        analysis.degrees_of_freedom,
        a.sample_rate,
        analysis.modes.len()
    );
    if let Some(eq) = engine.static_equilibrium() {
        // Newton stalls a little above its tolerance where a law has a kink at the rest it
        // seeks (a rope stretched by exactly its load, engaged only when ℓ > L): a residual
        // of a millionth of the typical force still places every point far closer than the
        // modes can tell.
        let how = if eq.converged {
            "found"
        } else if eq.residual <= NEAR_EQUILIBRIUM {
            "found to within its residual (Newton stalled above its 1e-12 tolerance, as at a \
             rope's kink)"
        } else {
            "NOT found (linearised at the best point reached)"
        };
        println!(
            "static equilibrium {how}: {} Newton step(s), largest residual {:.1e} of the typical force",
            eq.iterations, eq.residual
        );
    }
    print!("{}", format_modes(&analysis, false));
    if let Some(why) = &analysis.skipped {
        println!("modal analysis skipped: {why}");
    }
    let silent = silent_inputs(&analysis, &gain_columns(&analysis));
    if !silent.is_empty() {
        println!("no gain at rest from {silent} (open contacts or parameter inputs)");
    }
    let gersh = engine.gershgorin_stiffness_limit(1.0);
    match engine.stiffness_limit(1.0) {
        StiffnessLimit::Exact(g) => println!(
            "stiffness gain limit: ×{} exact (Gershgorin bound ×{})",
            sig(g),
            sig(gersh)
        ),
        StiffnessLimit::Bound(g) => println!(
            "stiffness gain limit: ×{} (Gershgorin bound; the exact analysis does not apply)",
            sig(g)
        ),
    }
    Ok(())
}

/// Parses `440`, `440Hz` or a note name.
fn parse_target(text: &str) -> Option<f64> {
    let t = text.trim();
    let number = t
        .strip_suffix("Hz")
        .or_else(|| t.strip_suffix("hz"))
        .unwrap_or(t)
        .trim();
    number
        .parse::<f64>()
        .ok()
        .or_else(|| note_frequency(t))
        .filter(|f| *f > 0.0 && f.is_finite())
}

/// λ of the undamped law of spec §5.3: 4·sin²(πf/SR).
fn lambda_of(f: f64, sr: f64) -> f64 {
    4.0 * (std::f64::consts::PI * f / sr).sin().powi(2)
}

/// The frequency of mode `k` (1-based) of the engine as it stands.
fn mode_frequency(engine: &mut Engine, k: usize) -> Option<f64> {
    let a = engine.modes(Some(k.max(1)));
    a.modes.get(k - 1).map(|m| m.frequency_hz)
}

pub(crate) fn tune(a: &TuneArgs) -> Result<(), Failure> {
    let target = parse_target(&a.to)
        .ok_or_else(|| usage(format!("`--to {}`: not a frequency or a note name", a.to)))?;
    if a.mode == 0 {
        return Err(usage("`--mode`: modes are numbered from 1"));
    }
    if !(target < a.sample_rate / 2.0) {
        return Err(usage(format!("{target} Hz is above the Nyquist frequency")));
    }
    let spec = load(&a.model)?;
    let mut engine = build(&a.model, &spec, a.sample_rate)?;
    let sr = a.sample_rate;
    let start = mode_frequency(&mut engine, a.mode)
        .ok_or_else(|| usage(format!("the model has no mode {}", a.mode)))?;
    let lt = lambda_of(target, sr);
    let within = |f: f64| (f - target).abs() <= 1e-9 * target;
    match &a.param {
        None => {
            // λ is linear in the K-class gain c (spec §5.5): c ← c·λ_target/λ(c), with the Z
            // class at √c; exact in one step without damping, a few with it.
            let mut c = 1.0;
            let mut f = start;
            for _ in 0..50 {
                if within(f) {
                    break;
                }
                c *= lt / lambda_of(f, sr);
                engine.set_class_gain(ScaleClass::Stiffness, c);
                engine.set_class_gain(ScaleClass::Damping, c.sqrt());
                f = mode_frequency(&mut engine, a.mode).ok_or(Failure::Model)?;
            }
            if !within(f) {
                return Err(usage(format!(
                    "mode {} did not converge to {target} Hz (reached {f} Hz)",
                    a.mode
                )));
            }
            println!(
                "mode {} from {} Hz to {} Hz: K-class gain ×{}, Z-class gain ×{}",
                a.mode,
                sig(start),
                sig(f),
                sig(c),
                sig(c.sqrt())
            );
            println!(
                "multiply every stiffness (K, K2, Knl…) by {} and every damping (Z, Zo…) by {}, \
                 or render with --control stiffness={} --control damping={}",
                sig(c),
                sig(c.sqrt()),
                sig(c),
                sig(c.sqrt())
            );
        }
        Some(name) => {
            let id = engine
                .param_id(name)
                .ok_or_else(|| usage(format!("the model has no parameter `{name}`")))?;
            let v0 = engine.param(id).unwrap_or(0.0);
            // Secant steps on λ(v) − λ_target; the first step assumes λ ∝ v (a stiffness).
            let mut eval = |v: f64| -> Option<f64> {
                engine.set_param(id, v).ok()?;
                mode_frequency(&mut engine, a.mode)
            };
            let (mut x0, mut y0) = (v0, lambda_of(start, sr) - lt);
            let mut x1 = if v0 != 0.0 {
                v0 * lt / lambda_of(start, sr)
            } else {
                1e-3
            };
            let mut f1 = eval(x1).ok_or(Failure::Model)?;
            for _ in 0..60 {
                if within(f1) {
                    break;
                }
                let y1 = lambda_of(f1, sr) - lt;
                if y1 == y0 {
                    break;
                }
                let x2 = x1 - y1 * (x1 - x0) / (y1 - y0);
                (x0, y0) = (x1, y1);
                x1 = x2;
                f1 = eval(x1).ok_or(Failure::Model)?;
            }
            if !within(f1) {
                return Err(usage(format!(
                    "no value of `{name}` puts mode {} on {target} Hz (reached {f1} Hz at \
                     {name} = {x1})",
                    a.mode
                )));
            }
            println!(
                "mode {} from {} Hz to {} Hz: {name} = {} (was {})",
                a.mode,
                sig(start),
                sig(f1),
                sig(x1),
                sig(v0)
            );
            let text = std::fs::read_to_string(&a.model).unwrap_or_default();
            let declaration = text.lines().enumerate().find(|(_, l)| {
                let mut words = l.split_whitespace();
                words.next() == Some(&format!("@{name}")) && words.next() == Some("param")
            });
            match declaration {
                Some((line, old)) => {
                    println!("{}:{}: {}", a.model.display(), line + 1, old.trim());
                    println!("change to: @{name} param {}", sig(x1));
                }
                None => println!("@{name} param {}", sig(x1)),
            }
        }
    }
    Ok(())
}
