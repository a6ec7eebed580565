//! Stability margins from the modal analysis: the linearisation's resolution in growth rate and
//! the smallest axial damping that makes every closed-loop mode decay. Both take the analysis as
//! a function of the scenario, so they work for any model the caller can build.

use crate::AnalysisError;
use crate::modes::{Analysis, ClassifiedMode, Loop, RELEVANT_BAND};
use cdpr_core::scenario::Scenario;

/// The linearisation's resolution in growth rate [1/s]: the largest |σ| of an oscillatory mode
/// below [`RELEVANT_BAND`] of the undamped open loop, which is conservative (MODELS.md §4 energy,
/// FE.7), so every such σ is exactly 0 and what the analysis shows is finite-difference and
/// eigen-solver error. Real (ω = 0) modes are excluded: a conservative system may have real pairs
/// ±σ (a divergence). Above the band the lumped model's nearly degenerate axial modes of the two
/// stored chains split into ±σ pairs of up to ~0.4 1/s at 2e5 rad/s (|σ|/ω ~ 2e-6, the FD error
/// acting on a near-double eigenvalue); they are not physical and any damping removes them.
///
/// `analyse` is the modal analysis of a scenario's model at x under a feedback (the registry's
/// `cdpr_bench::analyse`).
pub fn growth_resolution<E>(
    scenario: &Scenario,
    x: f64,
    analyse: &mut impl FnMut(&Scenario, f64, Loop) -> Result<Analysis, E>,
) -> Result<f64, E> {
    Ok(resolution_of(&open_undamped(scenario, x, analyse)?))
}

fn open_undamped<E>(
    scenario: &Scenario,
    x: f64,
    analyse: &mut impl FnMut(&Scenario, f64, Loop) -> Result<Analysis, E>,
) -> Result<Analysis, E> {
    let mut undamped = scenario.clone();
    undamped.cable.axial_damping = 0.0;
    analyse(&undamped, x, Loop::Open)
}

fn resolution_of(open: &Analysis) -> f64 {
    open.modes
        .iter()
        .filter(|m| m.mode.omega > 0.0 && m.mode.omega < RELEVANT_BAND)
        .fold(0.0, |a, m| a.max(m.mode.growth.abs()))
}

/// One point of the damping sweep.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SweepPoint {
    /// Axial damping C [N s] (MODELS.md §4, FE.5.7).
    pub damping: f64,
    /// The least stable closed-loop mode at that damping.
    pub least_stable: ClassifiedMode,
}

/// Result of [`damping_sweep`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Sweep {
    pub model: &'static str,
    pub x: f64,
    /// Growth rates at or below this count as decaying [1/s] (the caller's choice, see
    /// [`damping_sweep`]).
    pub threshold: f64,
    /// The linearisation's resolution at x ([`growth_resolution`]) [1/s].
    pub resolution: f64,
    /// Every point evaluated, in damping order.
    pub points: Vec<SweepPoint>,
    /// The smallest damping [N s] found (to the bisection's relative width) for which every
    /// closed-loop mode has growth ≤ threshold; None if even the largest tried does not.
    pub smallest: Option<f64>,
}

/// Smallest Kelvin–Voigt coefficient C in [`low`, `high`] N s for which every closed-loop mode at
/// x has growth ≤ `threshold` [1/s]: a log-spaced scan (`scan` points, to see the curve) then
/// bisection on log C to a relative width of 1e-3 from the last unstable scan point.
///
/// Why a threshold and not σ < 0: axial (Kelvin–Voigt) damping barely touches the transverse
/// string modes (they hardly stretch), so they stay neutral to within the linearisation's error
/// (above the answer at x = 0.6: |σ| ≤ 1.8e-6 1/s, lumped and FE), and "< 0" would be decided by
/// that error. The caller's threshold should sit well above it and below the undamped axial
/// growth (0.16–0.57 1/s, MODELS.md §4, FE.9.1): the xtask uses 1e-2 1/s (≤ 5 % growth over the
/// 5 s run). The growing axial mode's σ falls about linearly in C (slope ≈ −97 (1/s)/(N s) for
/// FE, −90 lumped), so the threshold moves the answer by ≈ 1e-4 N s from the σ = 0 crossing.
/// (Before the velocity columns were differentiated with a step of their own scale, see
/// `modal::jacobian_within`, the string modes' σ scattered non-monotonically up to 2e-3 1/s and
/// the FE answer moved by 0.1 % with the last bits of the equilibrium.)
pub fn damping_sweep<E: From<AnalysisError>>(
    scenario: &Scenario,
    x: f64,
    (low, high): (f64, f64),
    scan: usize,
    threshold: f64,
    analyse: &mut impl FnMut(&Scenario, f64, Loop) -> Result<Analysis, E>,
) -> Result<Sweep, E> {
    let open = open_undamped(scenario, x, analyse)?;
    let (model, resolution) = (open.model, resolution_of(&open));
    let mut points = Vec::new();
    let mut eval = |c: f64, points: &mut Vec<SweepPoint>| -> Result<bool, E> {
        let mut s = scenario.clone();
        s.cable.axial_damping = c;
        let a = analyse(&s, x, Loop::Closed)?;
        let worst = a.least_stable().cloned().ok_or(AnalysisError::NoMode)?;
        let stable = worst.mode.growth <= threshold;
        points.push(SweepPoint {
            damping: c,
            least_stable: worst,
        });
        Ok(stable)
    };
    let scan = scan.max(2);
    let ratio = (high / low).ln() / (scan - 1) as f64;
    let mut last_unstable = None;
    let mut first_stable = None;
    for k in 0..scan {
        let c = low * (ratio * k as f64).exp();
        if eval(c, &mut points)? {
            first_stable.get_or_insert(c);
        } else {
            last_unstable = Some(c);
            first_stable = None;
        }
    }
    let smallest = match (last_unstable, first_stable) {
        (_, None) => None,
        (None, Some(c)) => Some(c),
        (Some(mut lo), Some(mut hi)) => {
            while hi / lo > 1.0 + 1e-3 {
                let mid = (lo * hi).sqrt();
                if eval(mid, &mut points)? {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            Some(hi)
        }
    };
    points.sort_by(|a, b| a.damping.total_cmp(&b.damping));
    Ok(Sweep {
        model,
        x,
        threshold,
        resolution,
        points,
        smallest,
    })
}
