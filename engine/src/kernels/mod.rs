//! Kernels of the sample loop that live in their own files, each with its equation.

pub(crate) mod mesh;

#[cfg(test)]
mod tests {
    use crate::{compile, parse, CompileOptions};

    /// The sample loop gives the same bits whichever instruction set runs it (the baseline or
    /// AVX2 through pulp): every preset, 4096 samples after a strike on every input.
    #[test]
    fn every_instruction_set_gives_the_same_samples() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
        let mut names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "mdl"))
            .collect();
        names.sort();
        assert!(names.len() > 10);
        for path in names {
            let text = std::fs::read_to_string(&path).unwrap();
            let spec = parse(&text).spec.expect("a preset parses");
            let mut fast = compile(&spec, &CompileOptions::at(48_000.0)).expect("compiles");
            let mut plain = fast.clone();
            plain.arch = pulp::Arch::Scalar;
            let (n_in, n_out) = (fast.info().num_inputs(), fast.info().num_outputs());
            let frames = if fast.info().num_points > 5000 {
                256
            } else {
                4096
            };
            let mut inputs = vec![0.0; n_in * frames];
            for c in 0..n_in {
                inputs[c * frames] = -0.01;
            }
            let mut a = vec![0.0; n_out * frames];
            let mut b = vec![0.0; n_out * frames];
            fast.process(frames, &inputs, &mut a);
            plain.process(frames, &inputs, &mut b);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&a), bits(&b), "{}", path.display());
            assert_eq!(
                bits(fast.positions()),
                bits(plain.positions()),
                "{}",
                path.display()
            );
        }
    }
}
