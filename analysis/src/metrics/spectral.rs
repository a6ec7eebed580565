//! The spectral peaks of a run (MODELS.md §7): the settled window's plain and refined peaks of
//! z and of the error, the error's high-frequency maxima in dB below its main peak, and the
//! whole record's plain FFT peak of z.

use super::{HF_FROM, HF_PEAKS, MIN_SPECTRAL_WINDOW, PAD, REFINED_FROM, peak_to_peak};
use crate::spectrum::{NoPeak, Peak, RefinedSpectrum, Spectrum, Window};

/// The spectral peaks of a run (MODELS.md §7), keys of `metrics.json` as in [`Metrics`](super::Metrics).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SpectralPeaks {
    /// Refined spectral peaks (Hann, 16× padding, ω ≥ 2 rad/s) of z and of the error over the
    /// `settled` window, at least [`MIN_SPECTRAL_WINDOW`] long [rad/s].
    pub z_peak_rad_s: f64,
    pub err_peak_rad_s: f64,
    /// Plain FFT peaks (rectangular window, no padding) over the `settled` window [rad/s].
    pub z_plain_peak_rad_s: f64,
    pub err_plain_peak_rad_s: f64,
    /// Plain FFT peak of z over the whole `record`, at least [`MIN_SPECTRAL_WINDOW`] long
    /// [rad/s], and its bin index (the paper's 20.11 rad/s is bin 16 of its 5 s record).
    pub z_fft_record_rad_s: f64,
    pub z_fft_record_bin: usize,
    /// Largest local maximum of the refined error spectrum above 100 rad/s over the `settled`
    /// window [rad/s] and its level
    /// relative to the main error peak [dB].
    pub err_hf_peak_rad_s: f64,
    pub err_hf_peak_db: f64,
    /// The [`HF_PEAKS`] largest local maxima of the refined error spectrum above 100 rad/s,
    /// as [ω rad/s, dB relative to the main error peak], largest first.
    pub err_hf_peaks: Vec<[f64; 2]>,
    /// Why each null spectral peak is none (read into `unavailable`).
    #[serde(skip)]
    pub(super) no_peak: Vec<(&'static str, NoPeak)>,
}

fn peak_omega(p: Result<Peak, NoPeak>) -> f64 {
    p.map_or(f64::NAN, |p| p.omega)
}

/// The spectra of a run: the settled window's z and error (only where the window is long enough
/// to be read; none below) and the whole record's z.
pub(super) struct Spectra {
    z: SettledPeaks,
    err: SettledPeaks,
    whole: Result<Peak, NoPeak>,
}

impl Spectra {
    pub(super) fn of(
        z: &[f64],
        err: &[f64],
        spectral: std::ops::Range<usize>,
        long_enough: bool,
        t_end: f64,
        dt: f64,
        resolution: f64,
    ) -> Self {
        let (z_spec, err_spec) = if long_enough {
            (
                SettledPeaks::new(&z[spectral.clone()], dt, 0, resolution),
                SettledPeaks::new(&err[spectral], dt, HF_PEAKS, resolution),
            )
        } else {
            (SettledPeaks::none(), SettledPeaks::none())
        };
        let whole = if t_end >= MIN_SPECTRAL_WINDOW {
            let p2p = peak_to_peak(z);
            if p2p < resolution {
                Err(NoPeak::Unresolved { p2p, resolution })
            } else {
                Spectrum::new(z, dt, Window::Rectangular).max_bin_peak(0.0)
            }
        } else {
            Err(NoPeak::Empty)
        };
        Self {
            z: z_spec,
            err: err_spec,
            whole,
        }
    }
}

/// The level of peak `p` relative to the error's main peak [dB] (NaN without one).
fn db(p: &Peak, main: Result<Peak, NoPeak>) -> f64 {
    match main {
        Ok(main) => 20.0 * (p.amplitude / main.amplitude).log10(),
        Err(_) => f64::NAN,
    }
}

/// The spectral peaks of one signal over the settled window: the plain peak (rectangular
/// window, no padding), the refined peak (Hann, [`PAD`]× padding, ω ≥ [`REFINED_FROM`]) and,
/// for `hf` > 0, the largest local maxima of the refined spectrum above [`HF_FROM`].
pub struct SettledPeaks {
    pub plain: Result<Peak, NoPeak>,
    pub refined: Result<Peak, NoPeak>,
    pub high_frequency: Vec<Peak>,
}

impl SettledPeaks {
    /// The peaks of `signal` sampled every `dt` [s]; none where it varies by less than
    /// `resolution` (its spectrum is then the integrator's error).
    pub fn new(signal: &[f64], dt: f64, hf: usize, resolution: f64) -> Self {
        let p2p = peak_to_peak(signal);
        if p2p < resolution {
            let none = Err(NoPeak::Unresolved { p2p, resolution });
            return Self {
                plain: none,
                refined: none,
                high_frequency: Vec::new(),
            };
        }
        let plain = Spectrum::new(signal, dt, Window::Rectangular).max_bin_peak(0.0);
        let fine = RefinedSpectrum::new(signal, dt, PAD);
        Self {
            plain,
            refined: fine.refined_peak(REFINED_FROM),
            high_frequency: if hf > 0 {
                fine.local_maxima_above(HF_FROM, hf)
            } else {
                Vec::new()
            },
        }
    }

    fn none() -> Self {
        Self {
            plain: Err(NoPeak::Empty),
            refined: Err(NoPeak::Empty),
            high_frequency: Vec::new(),
        }
    }
}

impl SpectralPeaks {
    /// The peaks of `spectra`, the main error peak the reference of the high-frequency levels.
    pub(super) fn of(spectra: Spectra) -> Self {
        let Spectra {
            z: z_spec,
            err: err_spec,
            whole,
        } = spectra;
        let err_main = err_spec.refined;
        let err_hf = err_spec.high_frequency.first().copied();
        let err_hf_peak_db = err_hf.as_ref().map_or(f64::NAN, |p| db(p, err_main));
        let err_hf_peaks = err_spec
            .high_frequency
            .iter()
            .map(|p| [p.omega, db(p, err_main)])
            .collect();
        Self {
            z_peak_rad_s: peak_omega(z_spec.refined),
            err_peak_rad_s: peak_omega(err_main),
            z_plain_peak_rad_s: peak_omega(z_spec.plain),
            err_plain_peak_rad_s: peak_omega(err_spec.plain),
            z_fft_record_rad_s: peak_omega(whole),
            z_fft_record_bin: whole.map_or(0, |p| p.bin),
            no_peak: [
                ("z_peak_rad_s", z_spec.refined),
                ("err_peak_rad_s", err_spec.refined),
                ("z_plain_peak_rad_s", z_spec.plain),
                ("err_plain_peak_rad_s", err_spec.plain),
                ("z_fft_record_rad_s", whole),
            ]
            .into_iter()
            .filter_map(|(key, p)| p.err().map(|why| (key, why)))
            .collect(),
            err_hf_peak_rad_s: err_hf.map_or(f64::NAN, |p| p.omega),
            err_hf_peak_db,
            err_hf_peaks,
        }
    }
}
