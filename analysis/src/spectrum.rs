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

/// Oversampling of the gridded transform (its FFT has 2n points).
const OVERSAMPLING: usize = 2;
/// Terms on each side of a value in the Gaussian sum.
const SPREAD: i64 = 12;
/// τn², from balancing the sum's truncation e^{−π²W²/(4a)} against the aliasing e^{−2a} of the
/// 2×-oversampled grid: a = πW/(2√2); both ~3e-12 at W = 12.
const GRID_WIDTH: f64 = PI * SPREAD as f64 / (2.0 * std::f64::consts::SQRT_2);

/// The Gaussian's τ for `n` samples.
fn gridding_tau(n: usize) -> f64 {
    GRID_WIDTH / (n as f64 * n as f64)
}

/// The Hann-windowed spectrum of a signal zero-padded to `pad`·n points (MODELS.md §7's refined
/// spectrum), each value computed when asked, to ~1e-11 of the spectrum's largest, with the
/// unpadded spectrum to say where its peaks can be.
///
/// A value at p coarse bins is the DTFT Y(p) = Σ_s y_s e^{−iθs}, θ = 2πp/n, s = t − (n − 1)/2.
/// With u_s = y_s e^{τs²}/√(4πτ) and its 2n-point transform U, Y(p) = ∫ g(θ − φ) U(φ) dφ for the
/// Gaussian g(φ) = e^{−φ²/(4τ)}, summed on U's grid over the 2W + 1 points nearest θ.
pub struct RefinedSpectrum {
    /// The unpadded Hann spectrum.
    coarse: Spectrum,
    pad: usize,
    /// Samples n.
    n: usize,
    /// The one-sided 2n-point transform of u (before its centring phase).
    gridded: Vec<Complex<f64>>,
    tau: f64,
    /// e^{−h²k²/(4τ)}, k = 0 … 2W: the factor of the fast Gaussian gridding (Greengard & Lee)
    /// that does not depend on the value's frequency.
    tail: [f64; 2 * SPREAD as usize + 1],
    /// 2/Σw.
    scale: f64,
}

impl RefinedSpectrum {
    /// The refined spectrum of `signal` sampled every `dt` [s] (mean removed, Hann window),
    /// zero-padded to `pad`·n points.
    pub fn new(signal: &[f64], dt: f64, pad: usize) -> Self {
        let n = signal.len();
        let pad = pad.max(1);
        if n < 2 {
            return Self {
                coarse: Spectrum::new(signal, dt, Window::Hann),
                pad,
                n,
                gridded: Vec::new(),
                tau: 0.0,
                tail: [0.0; 2 * SPREAD as usize + 1],
                scale: 0.0,
            };
        }
        let (mut y, weight_sum) = windowed(signal, Window::Hann);
        let coarse = Spectrum::of_windowed(&y, weight_sum, dt);
        let prescale = CACHE.with(|c| c.borrow_mut().prescale(n));
        for (v, w) in y.iter_mut().zip(prescale.iter()) {
            *v *= w;
        }
        let tau = gridding_tau(n);
        let h = 2.0 * PI / (OVERSAMPLING * n) as f64;
        let tail = std::array::from_fn(|k| {
            let d = h * k as f64;
            (-d * d / (4.0 * tau)).exp()
        });
        Self {
            coarse,
            pad,
            n,
            gridded: fft(&y, OVERSAMPLING * n, <[_]>::to_vec),
            tau,
            tail,
            scale: 2.0 / weight_sum,
        }
    }

    /// The unpadded Hann spectrum.
    pub fn coarse(&self) -> &Spectrum {
        &self.coarse
    }

    /// Bin spacing of the padded grid [rad/s].
    pub fn omega_step(&self) -> f64 {
        self.coarse.omega_step / self.pad as f64
    }

    /// Bins on the one-sided padded grid.
    pub fn len(&self) -> usize {
        if self.gridded.is_empty() {
            0
        } else {
            self.pad * self.n / 2 + 1
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// V_k, the transform of u, for any integer k (periodic, conjugate-symmetric).
    fn gridded(&self, k: i64) -> Complex<f64> {
        let l = (OVERSAMPLING * self.n) as i64;
        let r = k.rem_euclid(l);
        if r as usize >= self.gridded.len() {
            self.gridded[(l - r) as usize].conj()
        } else {
            self.gridded[r as usize]
        }
    }

    /// Amplitude at padded bin j (frequency j·Δω/pad): |Σ_k g(θ − hk) e^{ikhc} V_k| h, summed
    /// over the 2W + 1 grid points from k₀ = round(θ/h) − W. The Gaussian factors as
    /// e^{−d₀²/4τ} (e^{d₀h/2τ})^m e^{−h²m²/4τ}, d₀ = θ − hk₀, m = k − k₀ (Greengard & Lee's fast
    /// gridding: two exponentials a value), and the centring phase e^{ikhc} (c = (n − 1)/2, of
    /// the unwrapped k: it is not periodic in k when c is a half) advances by one rotation.
    pub fn amplitude(&self, j: usize) -> f64 {
        let l = (OVERSAMPLING * self.n) as f64;
        let h = 2.0 * PI / l;
        let theta = 2.0 * PI * j as f64 / (self.pad * self.n) as f64;
        let k0 = (theta / h).round() as i64 - SPREAD;
        let d0 = theta - h * k0 as f64;
        let four_tau = 4.0 * self.tau;
        let mut weight = (-d0 * d0 / four_tau).exp();
        let growth = (2.0 * d0 * h / four_tau).exp();
        let centre = 0.5 * (self.n - 1) as f64;
        let mut phase = Complex::from_polar(1.0, h * centre * k0 as f64);
        let rotation = Complex::from_polar(1.0, h * centre);
        let mut sum = Complex::new(0.0, 0.0);
        for (m, tail) in self.tail.iter().enumerate() {
            sum += self.gridded(k0 + m as i64) * phase * (weight * tail);
            weight *= growth;
            phase *= rotation;
        }
        magnitude(sum) * h * self.scale
    }

    /// First padded bin with ω ≥ `min_omega` (and j ≥ 1).
    fn first_bin(&self, min_omega: f64) -> usize {
        ((min_omega / self.omega_step()).ceil() as usize).max(1)
    }

    /// The padded local maxima (F_j > F_{j−1}, F_j ≥ F_{j+1}) with j > `first`, within a
    /// coarse bin of each of the `candidates` largest coarse local maxima at or above coarse bin
    /// `from`: the largest `count`, largest first (equals by frequency).
    fn local_maxima(
        &self,
        from: usize,
        first: usize,
        candidates: usize,
        count: usize,
    ) -> Vec<Peak> {
        let pad = self.pad;
        let last = self.len() - 1;
        let mut found: Vec<Peak> = Vec::new();
        let mut scanned_to = 0;
        for k in self.coarse.largest_local_maxima(from, candidates) {
            let lo = (pad * k.saturating_sub(1)).max(first + 1).max(scanned_to);
            let hi = (pad * (k + 1)).min(last - 1);
            if lo > hi {
                continue;
            }
            let mut previous = self.amplitude(lo - 1);
            let mut here = self.amplitude(lo);
            for j in lo..=hi {
                let next = self.amplitude(j + 1);
                if here > previous && here >= next {
                    found.push(Peak {
                        omega: j as f64 * self.omega_step(),
                        amplitude: here,
                        bin: j,
                    });
                }
                (previous, here) = (here, next);
            }
            scanned_to = hi + 1;
        }
        found.sort_by(|p, q| q.amplitude.total_cmp(&p.amplitude).then(p.bin.cmp(&q.bin)));
        found.truncate(count);
        found
    }

    /// The largest padded local maximum with ω > `min_omega`, refined
    /// ([`RefinedSpectrum::refine`]), where it is a peak: [`PEAK_PROMINENCE`] times the band's
    /// median amplitude or more (else why it is none).
    pub fn refined_peak(&self, min_omega: f64) -> Result<Peak, NoPeak> {
        if self.is_empty() {
            return Err(NoPeak::Empty);
        }
        let first = self.first_bin(min_omega);
        let peak = self
            .local_maxima(first / self.pad, first, 16, 1)
            .into_iter()
            .next()
            .ok_or(NoPeak::AtEdge)?;
        let floor = self.coarse.median_amplitude(min_omega);
        prominent(peak, floor).map(|p| self.refine(p))
    }

    /// The `count` largest padded local maxima with ω > `min_omega` (refined), largest first,
    /// whatever their level: the discretisation modes above the physics of interest.
    pub fn local_maxima_above(&self, min_omega: f64, count: usize) -> Vec<Peak> {
        if self.is_empty() {
            return Vec::new();
        }
        // The padded grid's first bin strictly above min_omega.
        let first = ((min_omega / self.omega_step()).floor() as usize).saturating_add(1);
        self.local_maxima(
            first / self.pad,
            first.saturating_sub(1),
            4 * count.max(8),
            count,
        )
        .into_iter()
        .map(|p| self.refine(p))
        .collect()
    }

    /// A peak refined by a parabola through ln|X| at its padded bin and the two beside it (exact
    /// for a Gaussian-shaped peak, ≈ for the Hann main lobe).
    pub fn refine(&self, peak: Peak) -> Peak {
        let j = peak.bin;
        if j == 0 || j + 1 >= self.len() {
            return peak;
        }
        let (a, b, c) = (
            self.amplitude(j - 1).ln(),
            self.amplitude(j).ln(),
            self.amplitude(j + 1).ln(),
        );
        let denom = a - 2.0 * b + c;
        // A maximum has negative curvature; anything else (flat, NaN) is left unrefined.
        if denom.is_nan() || denom >= 0.0 {
            return peak;
        }
        let delta = 0.5 * (a - c) / denom;
        Peak {
            omega: (j as f64 + delta) * self.omega_step(),
            amplitude: (b - 0.25 * (a - c) * delta).exp(),
            bin: j,
        }
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
