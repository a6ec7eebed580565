//! Amplitude spectra of sampled signals (paper Fig. 7, MODELS.md §7).
//!
//! Two estimators, because they answer different questions: the *plain* spectrum (rectangular
//! window, no padding) is what an FFT of the record shows, bins 2π/T apart; the paper's
//! 20.11 rad/s is bin 16 of a 5 s record. The *refined* spectrum (Hann window, zero padding to 16n,
//! parabolic fit on ln|X|) recovers the frequency of a lightly damped mode to ~0.005 rad/s on a 4 s
//! record; a rectangular window would bias it low through leakage from the low-frequency content.
//!
//! The refined spectrum is never formed whole: a 16×-padded transform of a 400 000-sample window
//! costs 30× the unpadded one and 100 MB. Its values are samples of the windowed signal's DTFT,
//! so [`RefinedSpectrum`] evaluates them only where a peak can be, by Gaussian gridding
//! (Greengard & Lee 2004, SIAM Rev. 46: the signal pre-scaled by the inverse of a Gaussian's
//! transform, one 2×-oversampled FFT, then a 25-term Gaussian sum per value): to ~1e-11 of the
//! spectrum's largest value at any frequency, for 2.2× the cost of the unpadded transform.
//! [`DenseSpectrum`] is the whole padded transform, for figures and as the reference the local
//! evaluation is tested against.

mod refined;

pub use refined::RefinedSpectrum;
use refined::gridding_tau;

use realfft::num_complex::Complex;
use realfft::{RealFftPlanner, RealToComplex};
use std::cell::RefCell;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::Arc;

/// A spectral peak: frequency [rad/s] and one-sided amplitude (signal units).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Peak {
    pub omega: f64,
    pub amplitude: f64,
    /// Bin index of the peak before refinement (on the padded grid for a refined peak).
    pub bin: usize,
}

/// Why a signal has no spectral peak in a band.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NoPeak {
    /// Fewer than two samples, or no bin in the band.
    Empty,
    /// The spectrum only falls from the band's lowest bin (a drift or a step leaks there).
    AtEdge,
    /// Its largest peak stands only this many dB above the band's median amplitude (less than
    /// [`PEAK_PROMINENCE`]).
    BelowFloor { db: f64 },
    /// The signal varies by `p2p` over the window, less than the run resolves (`resolution`):
    /// its spectrum is the integrator's error (e.g. at its step rate), not the signal's.
    Unresolved { p2p: f64, resolution: f64 },
}

impl std::fmt::Display for NoPeak {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NoPeak::Empty => write!(f, "the band has no bin"),
            NoPeak::AtEdge => write!(
                f,
                "its spectrum only falls from the band's lowest bin (a drift or a step leaks there)"
            ),
            NoPeak::Unresolved { p2p, resolution } => write!(
                f,
                "it varies by {p2p:e} over the window, less than the {resolution:e} the run resolves \
                 (simulation.atol): its spectrum is the integrator's error"
            ),
            NoPeak::BelowFloor { db } => write!(
                f,
                "its largest peak stands {db:.1} dB above the band's median amplitude, less than the {:.0} dB a peak needs",
                20.0 * PEAK_PROMINENCE.log10()
            ),
        }
    }
}

/// A peak of `amplitude` over a band of median `floor`, or why it is none.
fn prominent(peak: Peak, floor: f64) -> Result<Peak, NoPeak> {
    if peak.amplitude >= PEAK_PROMINENCE * floor {
        Ok(peak)
    } else {
        Err(NoPeak::BelowFloor {
            db: 20.0 * (peak.amplitude / floor).log10(),
        })
    }
}

/// Window applied before the transform.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Window {
    Rectangular,
    /// The symmetric Hann window sin²(πk/(n − 1)).
    Hann,
}

/// A signal has a spectral peak only where a local maximum stands this many times above the
/// median amplitude of the band searched (20 dB): white noise's largest bin of a 400 000-sample
/// record stands ~4.3× (12.7 dB) above its median, a lightly damped mode 10³–10⁵×.
pub const PEAK_PROMINENCE: f64 = 10.0;

/// Most lengths whose plans a thread keeps (a sweep repeats a few lengths).
const CACHED_LENGTHS: usize = 8;

thread_local! {
    /// Plans and window weights per length, each plan made by a fresh planner. A planner that
    /// has planned other lengths reuses their sub-transforms (rustfft's AVX planner picks a
    /// cached FFT as the base of a new mixed-radix plan), so a shared planner made a length's
    /// plan, and the last bits of its spectrum, depend on what the thread had transformed
    /// before: a sweep point's record changed with the points run before it on its thread.
    static CACHE: RefCell<Cache> = RefCell::new(Cache::default());
}

#[derive(Default)]
struct Cache {
    plans: HashMap<usize, Arc<dyn RealToComplex<f64>>>,
    windows: HashMap<(usize, Window), Arc<Vec<f64>>>,
    /// The gridding's pre-scale e^{τs²}/√(4πτ) per length ([`RefinedSpectrum`]).
    prescales: HashMap<usize, Arc<Vec<f64>>>,
    buffers: Buffers,
}

/// A transform's input, output and scratch, kept between transforms.
#[derive(Default)]
struct Buffers {
    input: Vec<f64>,
    output: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
}

impl Cache {
    fn plan(&mut self, len: usize) -> Arc<dyn RealToComplex<f64>> {
        if !self.plans.contains_key(&len) && self.plans.len() >= CACHED_LENGTHS {
            self.plans.clear();
        }
        self.plans
            .entry(len)
            .or_insert_with(|| RealFftPlanner::new().plan_fft_forward(len))
            .clone()
    }

    fn prescale(&mut self, n: usize) -> Arc<Vec<f64>> {
        if !self.prescales.contains_key(&n) && self.prescales.len() >= CACHED_LENGTHS {
            self.prescales.clear();
        }
        self.prescales
            .entry(n)
            .or_insert_with(|| {
                let tau = gridding_tau(n);
                let centre = 0.5 * (n - 1) as f64;
                let norm = 1.0 / (4.0 * PI * tau).sqrt();
                let weights = (0..n).map(|t| {
                    let s = t as f64 - centre;
                    (tau * s * s).exp() * norm
                });
                Arc::new(weights.collect())
            })
            .clone()
    }

    fn window(&mut self, n: usize, window: Window) -> Arc<Vec<f64>> {
        if !self.windows.contains_key(&(n, window)) && self.windows.len() >= CACHED_LENGTHS {
            self.windows.clear();
        }
        self.windows
            .entry((n, window))
            .or_insert_with(|| Arc::new(weights(n, window)))
            .clone()
    }
}

/// The window's weights for `n` samples.
fn weights(n: usize, window: Window) -> Vec<f64> {
    (0..n)
        .map(|k| match window {
            Window::Rectangular => 1.0,
            Window::Hann => {
                let s = (PI * k as f64 / (n - 1) as f64).sin();
                s * s
            }
        })
        .collect()
}

/// `signal` with its mean removed and windowed, and the window's sum.
fn windowed(signal: &[f64], window: Window) -> (Vec<f64>, f64) {
    let n = signal.len();
    let mean = signal.iter().sum::<f64>() / n as f64;
    let weights = CACHE.with(|c| c.borrow_mut().window(n, window));
    let mut weight_sum = 0.0;
    let y = signal
        .iter()
        .zip(weights.iter())
        .map(|(&v, &w)| {
            weight_sum += w;
            (v - mean) * w
        })
        .collect();
    (y, weight_sum)
}

/// The real FFT of `y` zero-padded to `len` points, its one-sided coefficients handed to `read`,
/// in the thread's buffers (a sweep's points transform the same lengths over and over: fresh
/// buffers of 10–100 MB per point cost more in page faults than the transforms).
fn fft<R>(y: &[f64], len: usize, read: impl FnOnce(&[Complex<f64>]) -> R) -> R {
    let (fft, mut buffers) = CACHE.with(|c| {
        let mut c = c.borrow_mut();
        (c.plan(len), std::mem::take(&mut c.buffers))
    });
    let Buffers {
        input,
        output,
        scratch,
    } = &mut buffers;
    input.clear();
    input.extend_from_slice(y);
    input.resize(len, 0.0);
    output.resize(len / 2 + 1, Complex::new(0.0, 0.0));
    scratch.resize(fft.get_scratch_len(), Complex::new(0.0, 0.0));
    fft.process_with_scratch(input, output, scratch)
        .expect("buffer lengths come from the plan");
    let result = read(output);
    CACHE.with(|c| c.borrow_mut().buffers = buffers);
    result
}

/// |z| as √(re² + im²): a fifth of `hypot`'s cost on a spectrum's 200 000 bins, and as exact
/// for the amplitudes of a spectrum (no overflow or underflow near them).
fn magnitude(z: Complex<f64>) -> f64 {
    z.norm_sqr().sqrt()
}

/// One-sided amplitude spectrum on the grid ω_k = k·Δω (no padding).
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrum {
    /// Bin spacing Δω [rad/s].
    pub omega_step: f64,
    /// |X_k|·2/Σw, k = 0 … n/2: the amplitude of a sinusoid at a bin centre.
    amplitudes: Vec<f64>,
}

impl Spectrum {
    /// Spectrum of `signal` sampled every `dt` [s], mean removed and windowed.
    pub fn new(signal: &[f64], dt: f64, window: Window) -> Self {
        if signal.len() < 2 {
            return Self {
                omega_step: 0.0,
                amplitudes: Vec::new(),
            };
        }
        let (y, weight_sum) = windowed(signal, window);
        Self::of_windowed(&y, weight_sum, dt)
    }

    /// The spectrum of the windowed signal `y` whose window sums to `weight_sum`.
    fn of_windowed(y: &[f64], weight_sum: f64, dt: f64) -> Self {
        let scale = 2.0 / weight_sum;
        Self {
            omega_step: 2.0 * PI / (y.len() as f64 * dt),
            amplitudes: fft(y, y.len(), |x| {
                x.iter().map(|c| magnitude(*c) * scale).collect()
            }),
        }
    }

    /// Number of one-sided bins (0 for a signal of fewer than 2 samples).
    pub fn len(&self) -> usize {
        self.amplitudes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.amplitudes.is_empty()
    }

    /// Amplitude of bin k.
    pub fn amplitude(&self, k: usize) -> f64 {
        self.amplitudes[k]
    }

    /// Frequency of bin k [rad/s].
    pub fn omega(&self, k: usize) -> f64 {
        k as f64 * self.omega_step
    }

    /// First bin with ω ≥ `min_omega` (and k ≥ 1).
    fn first_bin(&self, min_omega: f64) -> usize {
        ((min_omega / self.omega_step).ceil() as usize).max(1)
    }

    /// Largest bin with ω ≥ `min_omega` (and k ≥ 1), no refinement; the first of equals.
    pub fn max_bin(&self, min_omega: f64) -> Option<Peak> {
        let mut best: Option<Peak> = None;
        for k in self.first_bin(min_omega)..self.len() {
            let amplitude = self.amplitudes[k];
            if best.is_none_or(|b| amplitude > b.amplitude) {
                best = Some(Peak {
                    omega: self.omega(k),
                    amplitude,
                    bin: k,
                });
            }
        }
        best
    }

    /// The median amplitude of the bins with ω ≥ `min_omega` (every fourth bin: the floor a
    /// peak must stand above, [`PEAK_PROMINENCE`]); NaN where there is no bin.
    pub fn median_amplitude(&self, min_omega: f64) -> f64 {
        let mut sample: Vec<f64> = (self.first_bin(min_omega)..self.len())
            .step_by(4)
            .map(|k| self.amplitudes[k])
            .collect();
        if sample.is_empty() {
            return f64::NAN;
        }
        let mid = sample.len() / 2;
        *sample.select_nth_unstable_by(mid, f64::total_cmp).1
    }

    /// The largest bin with ω ≥ `min_omega` where it is a peak: above the band's lowest bin
    /// (a maximum there is a drift's leakage) and [`PEAK_PROMINENCE`] times the band's median
    /// amplitude or more (else why it is none).
    pub fn max_bin_peak(&self, min_omega: f64) -> Result<Peak, NoPeak> {
        let peak = self.max_bin(min_omega).ok_or(NoPeak::Empty)?;
        if peak.bin == self.first_bin(min_omega) {
            return Err(NoPeak::AtEdge);
        }
        prominent(peak, self.median_amplitude(min_omega))
    }

    /// Coarse bins that are local maxima at or above bin `from`, the `count` largest, in bin
    /// order.
    fn largest_local_maxima(&self, from: usize, count: usize) -> Vec<usize> {
        let a = &self.amplitudes;
        let mut maxima: Vec<usize> = (from.max(1)..a.len())
            .filter(|&k| a[k] > a[k - 1] && a.get(k + 1).is_none_or(|&next| a[k] >= next))
            .collect();
        if maxima.len() > count {
            maxima.select_nth_unstable_by(count, |&x, &y| a[y].total_cmp(&a[x]).then(x.cmp(&y)));
            maxima.truncate(count);
        }
        maxima.sort_unstable();
        maxima
    }
}

/// The whole zero-padded spectrum, every bin: what a figure draws, and the reference
/// [`RefinedSpectrum`] is tested against.
#[derive(Debug, Clone, PartialEq)]
pub struct DenseSpectrum {
    /// Bin spacing Δω [rad/s].
    pub omega_step: f64,
    /// |X_k|·2/Σw: the amplitude of a sinusoid at a bin centre.
    pub amplitude: Vec<f64>,
}

impl DenseSpectrum {
    /// Spectrum of `signal` sampled every `dt` [s], mean removed, windowed and zero-padded to
    /// `pad`·n points.
    pub fn new(signal: &[f64], dt: f64, window: Window, pad: usize) -> Self {
        let n = signal.len();
        if n < 2 {
            return Self {
                omega_step: 0.0,
                amplitude: Vec::new(),
            };
        }
        let len = n * pad.max(1);
        let (y, weight_sum) = windowed(signal, window);
        let scale = 2.0 / weight_sum;
        Self {
            omega_step: 2.0 * PI / (len as f64 * dt),
            amplitude: fft(&y, len, |x| x.iter().map(|c| c.norm() * scale).collect()),
        }
    }

    /// Frequency of bin k [rad/s].
    pub fn omega(&self, k: usize) -> f64 {
        k as f64 * self.omega_step
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refined_peak_finds_an_off_bin_sinusoid() {
        // 4 s at 1 kHz: bins 1.571 rad/s apart; 20.3738 rad/s lies between bins.
        let dt = 1e-3;
        let omega = 20.3738;
        let signal: Vec<f64> = (0..4000)
            .map(|k| 1e-3 * (omega * k as f64 * dt).sin() + 0.5)
            .collect();
        let plain = Spectrum::new(&signal, dt, Window::Rectangular)
            .max_bin(0.0)
            .unwrap();
        assert_eq!(
            plain.bin, 13,
            "nearest bin of 20.37 rad/s at 1.571 rad/s spacing"
        );
        let refined = RefinedSpectrum::new(&signal, dt, 16)
            .refined_peak(2.0)
            .unwrap();
        // The Hann main lobe sampled 16× finer is fit by the parabola to ~1e-4 of a bin.
        assert!((refined.omega - omega).abs() < 2e-3, "{refined:?}");
        assert!((refined.amplitude - 1e-3).abs() < 1e-5, "{refined:?}");
    }
}
