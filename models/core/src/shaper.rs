//! Input shapers: a few impulses (amplitudes summing to 1) timed so that a move convolved with
//! them puts no energy into one lightly damped mode, and the residual-vibration function that
//! says how much is left when the mode is not where the shaper was designed.
//!
//! For a mode of natural frequency ω and damping ratio ζ, with ω_d = ω√(1 − ζ²), the damped
//! period T_d = 2π/ω_d and K = exp(−ζπ/√(1 − ζ²)):
//!
//! - ZV, ZVD, ZVDD (Singer & Seering 1990, "Preshaping command inputs to reduce system
//!   vibration"): amplitudes ∝ binomial(n, i) Kⁱ at t = i T_d/2, exact for any ζ;
//! - MZV (three impulses over 3/4 of T_d, as Klipper's firmware defines its default `mzv`):
//!   amplitudes ∝ (1 − 1/√2, (√2 − 1) K′, (1 − 1/√2) K′²) at t = (0, 3/8, 3/4) T_d,
//!   K′ = exp(−3ζπ/(4√(1 − ζ²)));
//! - EI (Singhose, Seering & Singer 1994, "Residual vibration reduction using vector diagrams
//!   to generate shaping inputs"): ((1 + V)/4, (1 − V)/2, (1 + V)/4) at (0, T_d/2, T_d), whose
//!   residual is V_tol at the design frequency and 0 at two frequencies around it;
//! - two- and three-hump EI (Singhose, Porter, Tuttle & Singhose 1997, "Vibration reduction
//!   using multi-hump input shapers"): four and five impulses at multiples of T_d/2, with the
//!   undamped closed forms in V_tol.
//!
//! The EI family is exact for ζ = 0; for ζ > 0 each amplitude is weighted by Kⁱ (the weighting
//! that makes ZV/ZVD exact), which keeps V ≤ V_tol over the band to O(ζ²) (tested to ζ = 0.02;
//! the modes shaped here have ζ ≤ 1e-3). The published damped curve fits for EI (used by
//! firmware) were tried first: at ζ = 0 they put V(ω₀) 4 % above V_tol = 0.02.
//!
//! Residual vibration (Singer & Seering 1990, eq. 4): for impulses (A_i, t_i),
//! V(ω, ζ) = e^{−ζω t_N} √[(Σ A_i e^{ζω t_i} cos ω_d t_i)² + (Σ A_i e^{ζω t_i} sin ω_d t_i)²],
//! the ringing after the last impulse relative to a single unit impulse's.

use crate::scenario::ScenarioError;

/// The shaper family.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Deserialize, serde::Serialize, Default,
)]
#[serde(rename_all = "kebab-case")]
pub enum ShaperKind {
    #[default]
    None,
    Zv,
    Zvd,
    Zvdd,
    Mzv,
    Ei,
    #[serde(rename = "2hump-ei")]
    TwoHumpEi,
    #[serde(rename = "3hump-ei")]
    ThreeHumpEi,
}

impl ShaperKind {
    /// Every shaper, unshaped first.
    pub const ALL: [ShaperKind; 8] = [
        ShaperKind::None,
        ShaperKind::Zv,
        ShaperKind::Zvd,
        ShaperKind::Zvdd,
        ShaperKind::Mzv,
        ShaperKind::Ei,
        ShaperKind::TwoHumpEi,
        ShaperKind::ThreeHumpEi,
    ];

    /// The scenario file's spelling.
    pub fn name(self) -> &'static str {
        match self {
            ShaperKind::None => "none",
            ShaperKind::Zv => "zv",
            ShaperKind::Zvd => "zvd",
            ShaperKind::Zvdd => "zvdd",
            ShaperKind::Mzv => "mzv",
            ShaperKind::Ei => "ei",
            ShaperKind::TwoHumpEi => "2hump-ei",
            ShaperKind::ThreeHumpEi => "3hump-ei",
        }
    }
}

/// Impulses (A_i, t_i) [-, s], amplitudes summing to 1, times from 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Impulses {
    pub amplitudes: Vec<f64>,
    pub times: Vec<f64>,
}

impl Impulses {
    /// One unit impulse at 0: the unshaped move.
    pub fn none() -> Self {
        Self {
            amplitudes: vec![1.0],
            times: vec![0.0],
        }
    }

    /// Whether this is the unshaped move (one unit impulse at 0).
    pub fn is_none(&self) -> bool {
        self.amplitudes == [1.0] && self.times == [0.0]
    }

    /// A signal convolved with the impulses: Σ A_i f(t − t_i) (the shaped reference from
    /// `step5`'s position, velocity or acceleration).
    #[inline]
    pub fn convolve(&self, t: f64, f: impl Fn(f64) -> f64) -> f64 {
        self.amplitudes
            .iter()
            .zip(&self.times)
            .map(|(&a, &ti)| a * f(t - ti))
            .sum()
    }

    /// The shaper's duration t_N [s]: the move-time penalty.
    pub fn duration(&self) -> f64 {
        self.times.last().copied().unwrap_or(0.0)
    }

    /// The shaper `kind` designed for a mode of natural frequency `omega` [rad/s] and damping
    /// ratio `zeta`, with the EI family's tolerated vibration `v_tol`.
    ///
    /// # Examples
    ///
    /// The zero-vibration shaper for an undamped 20 rad/s mode: two halves, half a period apart,
    /// and no residual vibration there.
    ///
    /// ```
    /// use cdpr_core::shaper::{Impulses, ShaperKind};
    ///
    /// let zv = Impulses::design(ShaperKind::Zv, 20.0, 0.0, 0.05).unwrap();
    /// assert_eq!(zv.amplitudes, vec![0.5, 0.5]);
    /// assert!((zv.times[1] - std::f64::consts::PI / 20.0).abs() < 1e-15);
    /// assert!(zv.residual(20.0, 0.0) < 1e-15);
    /// ```
    pub fn design(
        kind: ShaperKind,
        omega: f64,
        zeta: f64,
        v_tol: f64,
    ) -> Result<Self, ScenarioError> {
        check(omega, zeta, v_tol)?;
        let df = (1.0 - zeta * zeta).sqrt();
        let period = 2.0 * std::f64::consts::PI / (omega * df);
        let k = (-zeta * std::f64::consts::PI / df).exp();
        let half = 0.5 * period;
        let (amplitudes, times): (Vec<f64>, Vec<f64>) = match kind {
            ShaperKind::None => return Ok(Self::none()),
            ShaperKind::Zv => binomial(1, k, half),
            ShaperKind::Zvd => binomial(2, k, half),
            ShaperKind::Zvdd => binomial(3, k, half),
            ShaperKind::Mzv => {
                let kp = (-0.75 * zeta * std::f64::consts::PI / df).exp();
                let a1 = 1.0 - std::f64::consts::FRAC_1_SQRT_2;
                (
                    vec![a1, (std::f64::consts::SQRT_2 - 1.0) * kp, a1 * kp * kp],
                    vec![0.0, 0.375 * period, 0.75 * period],
                )
            }
            ShaperKind::Ei => {
                let a1 = 0.25 * (1.0 + v_tol);
                weighted(&[a1, 0.5 * (1.0 - v_tol), a1], k, half)
            }
            ShaperKind::TwoHumpEi => {
                let v2 = v_tol * v_tol;
                let x = (v2 * ((1.0 - v2).sqrt() + 1.0)).cbrt();
                let a1 = (3.0 * x * x + 2.0 * x + 3.0 * v2) / (16.0 * x);
                weighted(&[a1, 0.5 - a1, 0.5 - a1, a1], k, half)
            }
            ShaperKind::ThreeHumpEi => {
                let a1 = (1.0 + 3.0 * v_tol + 2.0 * (2.0 * (v_tol + 1.0) * v_tol).sqrt()) / 16.0;
                let a2 = 0.25 * (1.0 - v_tol);
                weighted(&[a1, a2, 1.0 - 2.0 * (a1 + a2), a2, a1], k, half)
            }
        };
        let sum: f64 = amplitudes.iter().sum();
        Ok(Self {
            amplitudes: amplitudes.iter().map(|a| a / sum).collect(),
            times,
        })
    }

    /// The residual vibration V(ω, ζ) of a mode of natural frequency `omega` [rad/s] and
    /// damping ratio `zeta` after the last impulse, relative to one unit impulse's (Singer &
    /// Seering 1990).
    pub fn residual(&self, omega: f64, zeta: f64) -> f64 {
        let wd = omega * (1.0 - zeta * zeta).sqrt();
        let (mut c, mut s) = (0.0, 0.0);
        let tn = self.duration();
        for (&a, &t) in self.amplitudes.iter().zip(&self.times) {
            // e^{ζω t_i} e^{−ζω t_N}, combined so no factor overflows.
            let weight = a * (zeta * omega * (t - tn)).exp();
            c += weight * (wd * t).cos();
            s += weight * (wd * t).sin();
        }
        c.hypot(s)
    }
}

/// The ZV family: amplitudes ∝ C(n, i) Kⁱ at i·half.
fn binomial(n: usize, k: f64, half: f64) -> (Vec<f64>, Vec<f64>) {
    let coefficients: &[f64] = match n {
        1 => &[1.0, 1.0],
        2 => &[1.0, 2.0, 1.0],
        _ => &[1.0, 3.0, 3.0, 1.0],
    };
    weighted(coefficients, k, half)
}

/// Amplitudes a_i Kⁱ at i·half.
fn weighted(a: &[f64], k: f64, half: f64) -> (Vec<f64>, Vec<f64>) {
    let mut kp = 1.0;
    let mut amplitudes = Vec::with_capacity(a.len());
    for &ai in a {
        amplitudes.push(ai * kp);
        kp *= k;
    }
    let times = (0..a.len()).map(|i| i as f64 * half).collect();
    (amplitudes, times)
}

/// The shaper's inputs: ω > 0 finite, ζ in [0, 1), V_tol in (0, 1).
fn check(omega: f64, zeta: f64, v_tol: f64) -> Result<(), ScenarioError> {
    use crate::scenario::out_of_range;
    if !(omega.is_finite() && omega > 0.0) {
        return Err(out_of_range(
            "trajectory.shaper_frequency",
            omega,
            "finite and > 0 rad/s",
        ));
    }
    if !(0.0..1.0).contains(&zeta) {
        return Err(out_of_range("trajectory.shaper_damping", zeta, "[0, 1)"));
    }
    if !(v_tol > 0.0 && v_tol < 1.0) {
        return Err(out_of_range("trajectory.shaper_vtol", v_tol, "(0, 1)"));
    }
    Ok(())
}
