//! Measurements of rendered signals: spectral peaks, band energy, cents, the oscillator's
//! exact frequency.

/// The frequency of the strongest spectral peak of `signal` between `lo_hz` and `hi_hz`:
/// mean removed, Hann window, FFT (realfft), parabolic interpolation of the log magnitude
/// around the peak bin. For a steady sinusoid over N samples the error is a small fraction
/// of a bin (SR/N).
pub fn peak_frequency(signal: &[f32], sample_rate: f64, lo_hz: f64, hi_hz: f64) -> f64 {
    let n = signal.len();
    let spectrum = hann_spectrum(signal);
    let bin_hz = sample_rate / n as f64;
    let lo = ((lo_hz / bin_hz).floor() as usize).max(1);
    let hi = ((hi_hz / bin_hz).ceil() as usize).min(spectrum.len() - 2);
    assert!(lo < hi, "empty search band {lo_hz}..{hi_hz} Hz");
    let mag: Vec<f64> = spectrum.iter().map(|c| c.norm().max(1e-300)).collect();
    let k = (lo..=hi)
        .max_by(|&a, &b| mag[a].total_cmp(&mag[b]))
        .expect("band");
    let (a, b, c) = (mag[k - 1].ln(), mag[k].ln(), mag[k + 1].ln());
    let denominator = a - 2.0 * b + c;
    let delta = if denominator.abs() > 0.0 {
        (0.5 * (a - c) / denominator).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    (k as f64 + delta) * bin_hz
}

/// The spectrum of a signal with its mean removed, under a Hann window (realfft).
pub(crate) fn hann_spectrum(signal: &[f32]) -> Vec<realfft::num_complex::Complex<f64>> {
    use realfft::RealFftPlanner;
    let n = signal.len();
    assert!(n >= 16, "too short for a spectrum: {n} samples");
    let mean = signal.iter().map(|&v| v as f64).sum::<f64>() / n as f64;
    let mut buf: Vec<f64> = signal
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
            (v as f64 - mean) * w
        })
        .collect();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut spectrum = fft.make_output_vec();
    fft.process(&mut buf, &mut spectrum).expect("FFT");
    spectrum
}

/// The share of a signal's energy between `lo_hz` and `hi_hz` (mean removed, Hann window):
/// 1 when all of it lies in the band.
pub fn band_energy_share(signal: &[f32], sample_rate: f64, lo_hz: f64, hi_hz: f64) -> f64 {
    let n = signal.len();
    let spectrum = hann_spectrum(signal);
    let bin_hz = sample_rate / n as f64;
    let power: Vec<f64> = spectrum.iter().map(|c| c.norm_sqr()).collect();
    let total: f64 = power.iter().sum();
    let band: f64 = power
        .iter()
        .enumerate()
        .filter(|(k, _)| (lo_hz..=hi_hz).contains(&(*k as f64 * bin_hz)))
        .map(|(_, p)| p)
        .sum();
    if total > 0.0 {
        band / total
    } else {
        0.0
    }
}

/// The interval from `b` to `a` in cents.
pub fn cents(a: f64, b: f64) -> f64 {
    1200.0 * (a / b).log2()
}

/// The undamped frequency of a mass-spring oscillator (script values M, K tuned at
/// 44.1 kHz) at `sample_rate`, by the exact discrete law sin²(πf/SR) = K·(44100/SR)²/(4M),
/// with the Stiffness gain `k_gain` applied to K.
pub fn oscillator_frequency(m: f64, k: f64, k_gain: f64, sample_rate: f64) -> f64 {
    let r = 44_100.0 / sample_rate;
    let s2 = k_gain * k * r * r / (4.0 * m);
    assert!(s2 < 1.0, "unstable oscillator: sin² = {s2}");
    sample_rate / std::f64::consts::PI * s2.sqrt().asin()
}
