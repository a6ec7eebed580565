//! The refined spectrum (MODELS.md §7) evaluated only where a peak can be, by Gaussian gridding
//! (Greengard & Lee 2004, SIAM Rev. 46); see the parent module for why it is never formed whole.

use super::{CACHE, NoPeak, Peak, Spectrum, Window, fft, magnitude, prominent, windowed};
use realfft::num_complex::Complex;
use std::f64::consts::PI;

/// Oversampling of the gridded transform (its FFT has 2n points).
const OVERSAMPLING: usize = 2;
/// Terms on each side of a value in the Gaussian sum.
const SPREAD: i64 = 12;
/// τn², from balancing the sum's truncation e^{−π²W²/(4a)} against the aliasing e^{−2a} of the
/// 2×-oversampled grid: a = πW/(2√2); both ~3e-12 at W = 12.
const GRID_WIDTH: f64 = PI * SPREAD as f64 / (2.0 * std::f64::consts::SQRT_2);

/// The Gaussian's τ for `n` samples.
pub(super) fn gridding_tau(n: usize) -> f64 {
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
    /// ([`RefinedSpectrum::refine`]), where it is a peak: [`PEAK_PROMINENCE`](super::PEAK_PROMINENCE) times the band's
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
