//! The input shapers of printer firmware: pulses (A_i, T_i) for a shaper frequency f [Hz] and
//! damping ratio ζ, with t_d = 1 / (f √(1 − ζ²)) the damped period. Klipper offers these six
//! (its documentation, "Resonance compensation"); the formulas and fitted numbers are the
//! published ones cited below.
//!
//! - ZV, ZVD (Singer & Seering 1990): (1, K) at (0, t_d/2); (1, 2K, K²) at (0, t_d/2, t_d),
//!   K = exp(−ζπ/√(1 − ζ²)).
//! - MZV: three pulses over 3/4 t_d with zero residual vibration at f and 5f/3, i.e.
//!   (1 − 1/√2, √2 − 1, 1 − 1/√2) weighted by K′ⁱ = exp(−3ζπ/(4√(1 − ζ²)))ⁱ at (0, 3/8, 3/4) t_d.
//! - EI, two- and three-hump EI (Singhose, Porter, Tuttle & Singhose 1997, "Vibration reduction
//!   using multi-hump input shapers", J. Dyn. Sys. Meas. Control 119): the damped designs as
//!   curve fits in ζ, EI's also in the tolerated vibration V (firmware uses V = 5 %), the
//!   multi-hump ones at V = 5 %.
//!
//! How firmware applies them per axis (Klipper's kinematic shaper): the position at t is
//! Σ A_i x(t − (T_i − T̄)) / Σ A, T̄ = Σ A_i T_i / Σ A — the convolution advanced by the
//! pulses' centroid, so shaping delays no axis on average ([`centred`]).

/// The firmware's shapers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Shaper {
    /// Zero vibration.
    Zv,
    /// Modified ZV (Klipper's default).
    Mzv,
    /// Zero vibration and derivative.
    Zvd,
    /// Extra-insensitive.
    Ei,
    /// Two-hump EI.
    TwoHumpEi,
    /// Three-hump EI.
    ThreeHumpEi,
}

/// The vibration the EI family tolerates at its design frequency (5 %).
const EI_VTOL: f64 = 0.05;

/// c₀ + c₁ ζ + c₂ ζ² + … by Horner's rule.
fn polynomial(coefficients: &[f64], zeta: f64) -> f64 {
    coefficients
        .iter()
        .rev()
        .fold(0.0, |acc, &c| acc * zeta + c)
}

/// Pulses (amplitudes as designed, not normalised; times [s] from 0) of `shaper` at `freq` [Hz]
/// and damping ratio `damping`.
///
/// # Examples
/// ```
/// use cdpr_printing::shaper::{pulses, Shaper};
/// // An undamped ZV at 20 Hz: two equal pulses 25 ms apart.
/// let (a, t) = pulses(Shaper::Zv, 20.0, 0.0);
/// assert_eq!((a, t), (vec![1.0, 1.0], vec![0.0, 0.025]));
/// ```
pub fn pulses(shaper: Shaper, freq: f64, damping: f64) -> (Vec<f64>, Vec<f64>) {
    let df = (1.0 - damping * damping).sqrt();
    let t_d = 1.0 / (freq * df);
    let k = (-damping * std::f64::consts::PI / df).exp();
    match shaper {
        Shaper::Zv => (vec![1.0, k], vec![0.0, 0.5 * t_d]),
        Shaper::Zvd => (vec![1.0, 2.0 * k, k * k], vec![0.0, 0.5 * t_d, t_d]),
        Shaper::Mzv => {
            let kp = (-0.75 * damping * std::f64::consts::PI / df).exp();
            let a1 = 1.0 - std::f64::consts::FRAC_1_SQRT_2;
            (
                vec![a1, (std::f64::consts::SQRT_2 - 1.0) * kp, a1 * kp * kp],
                vec![0.0, 0.375 * t_d, 0.75 * t_d],
            )
        }
        Shaper::Ei => ei(damping, t_d),
        Shaper::TwoHumpEi => fitted(&TWO_HUMP_EI, freq, damping),
        Shaper::ThreeHumpEi => fitted(&THREE_HUMP_EI, freq, damping),
    }
}

/// EI's three pulses: the outer amplitudes and the middle pulse's time as quadratics
/// (amplitudes) and a cubic (time, in units of t_d) in ζ, each coefficient linear in V.
fn ei(zeta: f64, t_d: f64) -> (Vec<f64>, Vec<f64>) {
    let v = EI_VTOL;
    let first = [
        0.24968 + 0.24961 * v,
        0.80008 + 1.23328 * v,
        0.49599 + 3.17316 * v,
    ];
    let last = [
        0.25149 + 0.21474 * v,
        -0.83249 + 1.41498 * v,
        0.85181 - 4.90094 * v,
    ];
    let middle_time = [
        0.4999,
        (0.46159 + 8.57843 * v) * v,
        (4.26169 - 108.644 * v) * v,
        (1.75601 + 336.989 * v) * v,
    ];
    let (a1, a3) = (polynomial(&first, zeta), polynomial(&last, zeta));
    (
        vec![a1, 1.0 - a1 - a3, a3],
        vec![0.0, polynomial(&middle_time, zeta) * t_d, t_d],
    )
}

/// One pulse of a fitted design: its time (in periods 1/f) and amplitude as cubics in ζ
/// (coefficients of 1, ζ, ζ², ζ³).
struct FittedPulse {
    periods: [f64; 4],
    amplitude: [f64; 4],
}

/// A fitted design's pulses at `freq` [Hz] and damping ratio `zeta`.
fn fitted(design: &[FittedPulse], freq: f64, zeta: f64) -> (Vec<f64>, Vec<f64>) {
    design
        .iter()
        .map(|p| {
            (
                polynomial(&p.amplitude, zeta),
                polynomial(&p.periods, zeta) / freq,
            )
        })
        .unzip()
}

/// Two-hump EI at V = 5 % (Singhose et al. 1997).
#[rustfmt::skip]
const TWO_HUMP_EI: [FittedPulse; 4] = [
    FittedPulse { periods: [0.0, 0.0, 0.0, 0.0], amplitude: [0.16054, 0.76699, 2.26560, -1.22750] },
    FittedPulse { periods: [0.49890, 0.16270, -0.54262, 6.16180], amplitude: [0.33911, 0.45081, -2.58080, 1.73650] },
    FittedPulse { periods: [0.99748, 0.18382, -1.58270, 8.17120], amplitude: [0.34089, -0.61533, -0.68765, 0.42261] },
    FittedPulse { periods: [1.49920, -0.09297, -0.28338, 1.85710], amplitude: [0.15997, -0.60246, 1.00280, -0.93145] },
];

/// Three-hump EI at V = 5 % (Singhose et al. 1997).
#[rustfmt::skip]
const THREE_HUMP_EI: [FittedPulse; 5] = [
    FittedPulse { periods: [0.0, 0.0, 0.0, 0.0], amplitude: [0.11275, 0.76632, 3.29160, -1.44380] },
    FittedPulse { periods: [0.49974, 0.23834, 0.44559, 12.4720], amplitude: [0.23698, 0.61164, -2.57850, 4.85220] },
    FittedPulse { periods: [0.99849, 0.29808, -2.36460, 23.3990], amplitude: [0.30008, -0.19062, -2.14560, 0.13744] },
    FittedPulse { periods: [1.49870, 0.10306, -2.01390, 17.0320], amplitude: [0.23775, -0.73297, 0.46885, -2.08650] },
    FittedPulse { periods: [1.99960, -0.28231, 0.61536, 5.40450], amplitude: [0.11244, -0.45439, 0.96382, -1.46000] },
];

/// The pulses as firmware applies them to an axis: amplitudes normalised to sum 1, times
/// relative to their centroid (x_shaped(t) = Σ A_i x(t − τ_i)).
pub fn centred(amplitudes: &[f64], times: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let sum: f64 = amplitudes.iter().sum();
    let a: Vec<f64> = amplitudes.iter().map(|a| a / sum).collect();
    let centroid: f64 = a.iter().zip(times).map(|(a, t)| a * t).sum();
    (a, times.iter().map(|t| t - centroid).collect())
}

/// Residual vibration of pulses for an undamped mode at `freq` [Hz] relative to one pulse's:
/// |Σ A_i e^{2πi f T_i}| / Σ A_i (what a shaper leaves of a mode it was or was not designed for).
pub fn residual(amplitudes: &[f64], times: &[f64], freq: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI * freq;
    let (c, s) = amplitudes
        .iter()
        .zip(times)
        .fold((0.0, 0.0), |(c, s), (a, t)| {
            (c + a * (w * t).cos(), s + a * (w * t).sin())
        });
    c.hypot(s) / amplitudes.iter().sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every shaper nearly cancels an undamped mode at its frequency: ZV, ZVD, MZV exactly;
    /// the EI family to its tolerance (Klipper's fits keep the residual at f within 5 %: 1/20).
    #[test]
    fn every_shaper_cancels_its_mode() {
        for (shaper, bound) in [
            (Shaper::Zv, 1e-15),
            (Shaper::Zvd, 1e-15),
            (Shaper::Mzv, 1e-15),
            (Shaper::Ei, 0.06),
            (Shaper::TwoHumpEi, 0.06),
            (Shaper::ThreeHumpEi, 0.06),
        ] {
            let (a, t) = pulses(shaper, 40.0, 0.0);
            let v = residual(&a, &t, 40.0);
            assert!(v <= bound, "{shaper:?}: residual {v}");
            assert!(
                t.windows(2).all(|w| w[0] < w[1]),
                "{shaper:?}: times increase"
            );
            assert!(a.iter().all(|&a| a > 0.0), "{shaper:?}: positive pulses");
        }
    }

    /// MZV's zeros sit at f and 5f/3 (Klipper's construction).
    #[test]
    fn mzv_vanishes_at_five_thirds() {
        let (a, t) = pulses(Shaper::Mzv, 30.0, 0.0);
        assert!(residual(&a, &t, 50.0) < 1e-15);
    }

    #[test]
    fn centred_pulses_have_zero_mean_time() {
        let (a, t) = pulses(Shaper::Ei, 25.0, 0.1);
        let (a, t) = centred(&a, &t);
        let mean: f64 = a.iter().zip(&t).map(|(a, t)| a * t).sum();
        assert!(mean.abs() < 1e-16 && (a.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }
}
