//! The refined spectrum evaluated locally ([`FineSpectrum`]) against the whole zero-padded
//! transform ([`DenseSpectrum`]) it stands for, over signals of damped modes, drift and noise;
//! spectra independent of what the thread transformed before; no peak on a signal without one.

use cdpr_analysis::spectrum::{DenseSpectrum, RefinedSpectrum, Spectrum, Window};
use proptest::prelude::*;

const PAD: usize = 16;

/// MODELS.md §7's refined peak read off the whole padded spectrum: the argmax over ω ≥
/// `min_omega`, then the parabola through ln|X| at it and its neighbours.
fn dense_refined(dense: &DenseSpectrum, min_omega: f64) -> (usize, f64, f64) {
    let a = &dense.amplitude;
    let k0 = ((min_omega / dense.omega_step).ceil() as usize).max(1);
    let mut k = k0;
    for j in k0..a.len() {
        if a[j] > a[k] {
            k = j;
        }
    }
    let (l, m, r) = (a[k - 1].ln(), a[k].ln(), a[k + 1].ln());
    let delta = 0.5 * (l - r) / (l - 2.0 * m + r);
    (
        k,
        (k as f64 + delta) * dense.omega_step,
        (m - 0.25 * (l - r) * delta).exp(),
    )
}

/// A deterministic pseudo-random sequence in [−1, 1] (no dependency on a generator's stream).
fn noise(k: usize, seed: u64) -> f64 {
    let mut h = (k as u64 ^ seed).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    h ^= h >> 31;
    h = h.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h ^= h >> 27;
    (h >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

#[derive(Debug, Clone)]
struct Mode {
    omega: f64,
    amplitude: f64,
    zeta: f64,
    phase: f64,
}

fn signal(n: usize, dt: f64, modes: &[Mode], drift: f64, noise_level: f64, seed: u64) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            let modal: f64 = modes
                .iter()
                .map(|m| {
                    m.amplitude * (-m.zeta * m.omega * t).exp() * (m.omega * t + m.phase).sin()
                })
                .sum();
            -0.5 + drift * t + modal + noise_level * noise(k, seed)
        })
        .collect()
}

fn modes() -> impl Strategy<Value = Vec<Mode>> {
    prop::collection::vec(
        (
            5.0..3000.0f64,
            1e-6..1e-3f64,
            0.0..0.02f64,
            0.0..std::f64::consts::TAU,
        )
            .prop_map(|(omega, amplitude, zeta, phase)| Mode {
                omega,
                amplitude,
                zeta,
                phase,
            }),
        1..4,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// The refined peak and the high-frequency local maxima evaluated from the unpadded
    /// coefficients equal those read off the whole 16×-padded transform: the same padded bin, the
    /// frequency to 1e-9 relative and the amplitude to 1e-7 (the Dirichlet kernel's tail beyond
    /// 256 bins, rounding of a 16n-point FFT), the levels of every local maximum to 0.1 dB.
    #[test]
    fn local_evaluation_equals_the_padded_transform(
        seconds in 1.0..3.0f64,
        dt in prop::sample::select(vec![1e-4, 2.5e-4, 1e-3]),
        modes in modes(),
        drift in -1e-4..1e-4f64,
        noise_level in prop::sample::select(vec![0.0, 1e-12, 1e-9]),
        seed in any::<u64>(),
    ) {
        let n = (seconds / dt) as usize;
        let x = signal(n, dt, &modes, drift, noise_level, seed);
        let dense = DenseSpectrum::new(&x, dt, Window::Hann, PAD);
        let fine = RefinedSpectrum::new(&x, dt, PAD);
        prop_assert_eq!(fine.len(), dense.amplitude.len());
        // Every value the local search may read, sampled across the band.
        let peak_level = dense.amplitude.iter().cloned().fold(0.0, f64::max);
        for j in (1..dense.amplitude.len()).step_by(37) {
            let (a, b) = (fine.amplitude(j), dense.amplitude[j]);
            prop_assert!((a - b).abs() <= 1e-10 * peak_level, "bin {}: {} vs {} (peak {})", j, a, b, peak_level);
        }
        let (bin, omega, amplitude) = dense_refined(&dense, 2.0);
        let is_local_max = dense.amplitude[bin] > dense.amplitude[bin - 1]
            && bin > ((2.0 / dense.omega_step).ceil() as usize).max(1);
        if is_local_max {
            let peak = fine.refined_peak(2.0).expect("a mode stands above the noise");
            prop_assert_eq!(peak.bin, bin);
            prop_assert!((peak.omega - omega).abs() <= 1e-9 * omega, "{} vs {}", peak.omega, omega);
            prop_assert!((peak.amplitude - amplitude).abs() <= 1e-7 * amplitude);
        }
        // Every high-frequency peak found is a local maximum of the padded spectrum at its level,
        // largest first. (The padded grid also resolves the side lobes of every main lobe as
        // local maxima between the unpadded bins; they are leakage, not content, and the search
        // starts from the unpadded spectrum's local maxima.)
        let found = fine.local_maxima_above(100.0, 8);
        let a = &dense.amplitude;
        for p in &found {
            prop_assert!(a[p.bin] > a[p.bin - 1] && a[p.bin] >= a[p.bin + 1], "{:?}", p);
            prop_assert!((fine.amplitude(p.bin) - a[p.bin]).abs() <= 1e-10 * peak_level);
        }
        for w in found.windows(2) {
            prop_assert!(a[w[0].bin] >= a[w[1].bin]);
        }
        // Every mode above 100 rad/s standing clear of the others is among them, refined to the
        // Hann lobe's accuracy.
        for m in modes.iter().filter(|m| m.omega > 110.0 && m.zeta == 0.0) {
            let level = m.amplitude;
            let clear = modes.iter().all(|o| {
                std::ptr::eq(o, m) || (o.omega - m.omega).abs() > 40.0 * dense.omega_step * 16.0
                    || o.amplitude < 1e-2 * level
            });
            if clear && level > 1e-3 * peak_level {
                prop_assert!(
                    found.iter().any(|p| (p.omega - m.omega).abs() < dense.omega_step * 16.0),
                    "mode {:?} not among {:?}", m, found
                );
            }
        }
    }
}

/// A length's spectrum is the same bits whatever the thread transformed before: a planner
/// shared across lengths built a length's plan on the sub-transforms it had cached, so the
/// spectrum of a sweep point depended on the points its thread had run.
#[test]
fn spectra_do_not_depend_on_what_the_thread_transformed_before() {
    // Two lengths of a sweep over t_final at 0.1 ms (docs/sweeps.md): a record of 11 577
    // samples, then a settled window of 16 154 whose padded transform rustfft's shared planner
    // built on the 11 577-point plan's cached parts: 129 199 of its 129 233 bins moved.
    let dt = 1e-4;
    let x = signal(
        16_154,
        dt,
        &[Mode {
            omega: 20.37,
            amplitude: 5e-4,
            zeta: 1e-5,
            phase: 0.3,
        }],
        1e-5,
        1e-9,
        7,
    );
    let spectra = move |x: &[f64]| {
        (
            DenseSpectrum::new(x, dt, Window::Hann, PAD).amplitude,
            RefinedSpectrum::new(x, dt, PAD).refined_peak(2.0).unwrap(),
        )
    };
    let alone = std::thread::spawn({
        let x = x.clone();
        move || spectra(&x)
    })
    .join()
    .unwrap();
    let after_another = std::thread::spawn(move || {
        let record = signal(11_577, dt, &[], 1e-5, 1e-9, 1);
        let _ = Spectrum::new(&record, dt, Window::Rectangular);
        spectra(&x)
    })
    .join()
    .unwrap();
    assert_eq!(alone.1, after_another.1);
    let differ = (alone.0.iter().zip(&after_another.0))
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(differ, 0, "of {} bins", alone.0.len());
}

/// A signal at the rounding level of its value (z held flat at −0.5 m) and one that only drifts
/// have no spectral peak; a mode 1e-3 of the signal's size has one.
#[test]
fn no_peak_is_reported_on_a_signal_without_one() {
    let dt = 1e-3;
    let flat = signal(4000, dt, &[], 0.0, 1e-16, 3);
    let drift = signal(4000, dt, &[], 1e-6, 0.0, 3);
    for x in [&flat, &drift] {
        assert!(RefinedSpectrum::new(x, dt, PAD).refined_peak(2.0).is_err());
        // A drift's largest plain bin is its lowest: leakage, not a peak.
        let plain = Spectrum::new(x, dt, Window::Rectangular);
        assert!(plain.max_bin_peak(0.0).is_err());
    }
    let mode = Mode {
        omega: 20.0,
        amplitude: 1e-3,
        zeta: 1e-3,
        phase: 0.0,
    };
    let ringing = signal(4000, dt, &[mode], 0.0, 1e-16, 3);
    let peak = RefinedSpectrum::new(&ringing, dt, PAD)
        .refined_peak(2.0)
        .unwrap();
    assert!((peak.omega - 20.0).abs() < 0.01, "{peak:?}");
    let plain = Spectrum::new(&ringing, dt, Window::Rectangular);
    assert_eq!(
        plain.max_bin_peak(0.0).unwrap().bin,
        13,
        "20 rad/s in bins of 1.571 rad/s"
    );
}
