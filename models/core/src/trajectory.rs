//! The `step5` reference trajectory of the paper (eq. 13): a quintic that goes from x1 to x2 between
//! t1 and t2 with zero velocity and acceleration at both ends, so the controller sees no shock.

use crate::robot::Vector;
use crate::scenario;
use crate::shaper::Impulses;

/// Quintic `step5` (paper eq. 13), with its first two derivatives for analysis and plots.
///
/// # Examples
///
/// ```
/// use cdpr_core::trajectory::Step5;
///
/// let step = Step5 { x1: 0.5, x2: 0.6, t1: 0.0, t2: 0.2 };
/// assert_eq!(step.position(0.0), 0.5);
/// assert_eq!(step.position(0.2), 0.6);
/// // Paper §3.1: v_max = 15 Δx / (8 T) = 0.9375 m/s at the middle of the move.
/// assert!((step.velocity(0.1) - 0.9375).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step5 {
    /// Start position x1 [m].
    pub x1: f64,
    /// End position x2 [m].
    pub x2: f64,
    /// Start time t1 [s].
    pub t1: f64,
    /// End time t2 [s] (> t1).
    pub t2: f64,
}

impl From<&scenario::Trajectory> for Step5 {
    fn from(t: &scenario::Trajectory) -> Self {
        match t.kind {
            scenario::TrajectoryKind::Step5 => Self {
                x1: t.x1,
                x2: t.x2,
                t1: t.t1,
                t2: t.t2,
            },
        }
    }
}

impl Step5 {
    /// Δ(t) = (t − t1)/(t2 − t1) clamped to [0, 1] (eq. 13 is constant outside [t1, t2)).
    fn progress(&self, t: f64) -> f64 {
        ((t - self.t1) / (self.t2 - self.t1)).clamp(0.0, 1.0)
    }

    /// Reference position x_ref(t) [m], eq. 13: x1 + a Δ³ (10 − 15Δ + 6Δ²), a = x2 − x1.
    #[inline]
    pub fn position(&self, t: f64) -> f64 {
        if t >= self.t2 {
            return self.x2;
        }
        let s = self.progress(t);
        self.x1 + (self.x2 - self.x1) * s * s * s * (10.0 + s * (-15.0 + 6.0 * s))
    }

    /// Reference velocity [m/s]: a 30 Δ² (1 − Δ)² / (t2 − t1).
    pub fn velocity(&self, t: f64) -> f64 {
        let s = self.progress(t);
        let span = self.t2 - self.t1;
        (self.x2 - self.x1) * 30.0 * s * s * (1.0 - s) * (1.0 - s) / span
    }

    /// Reference acceleration [m/s²]: a 60 Δ (1 − Δ)(1 − 2Δ) / (t2 − t1)².
    pub fn acceleration(&self, t: f64) -> f64 {
        let s = self.progress(t);
        let span = self.t2 - self.t1;
        (self.x2 - self.x1) * 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s) / (span * span)
    }

    /// Largest speed, 15 Δx / (8 (t2 − t1)), reached at the midpoint (paper: 0.9375 m/s).
    pub fn max_speed(&self) -> f64 {
        15.0 * (self.x2 - self.x1).abs() / (8.0 * (self.t2 - self.t1))
    }

    /// Largest |acceleration|, 10 Δx / (√3 (t2 − t1)²) (paper: 14.434 m/s²).
    pub fn max_acceleration(&self) -> f64 {
        let span = self.t2 - self.t1;
        10.0 * (self.x2 - self.x1).abs() / (3f64.sqrt() * span * span)
    }

    /// Times of the acceleration extremes, Δ = 1/2 ∓ √3/6 (paper: 0.0423 s and 0.1577 s).
    pub fn max_acceleration_times(&self) -> [f64; 2] {
        let span = self.t2 - self.t1;
        let h = 3f64.sqrt() / 6.0;
        [self.t1 + (0.5 - h) * span, self.t1 + (0.5 + h) * span]
    }
}

/// `step5` along a straight segment of a spatial robot: eq. 13 applied to the arc length, so
/// p(t) = start + (end − start) σ(t), σ the quintic from 0 to 1 between t1 and t2. Velocity and
/// acceleration are the segment's direction times σ̇, σ̈ (the feedforward of the controllers).
///
/// # Examples
///
/// ```
/// use cdpr_core::robot::Vector;
/// use cdpr_core::trajectory::Segment;
///
/// let move_ = Segment::<3> {
///     start: Vector::<3>::zeros(),
///     end: Vector::<3>::new(0.1, 0.05, 0.02),
///     t1: 0.0,
///     t2: 0.2,
/// };
/// assert_eq!(move_.position(0.2), move_.end);
/// // The arc length's largest speed, 15 L / (8 T), at the middle of the move.
/// let length = (move_.end - move_.start).norm();
/// assert!((move_.velocity(0.1).norm() - 15.0 * length / (8.0 * 0.2)).abs() < 1e-12);
/// assert!((move_.max_speed() - move_.velocity(0.1).norm()).abs() < 1e-12);
/// // The issue's Hangprinter move: 10 L/(√3 T²) = 16.39 m/s² at Δ = 1/2 − √3/6.
/// let t_peak = (0.5 - 3f64.sqrt() / 6.0) * 0.2;
/// assert!((move_.acceleration(t_peak).norm() - move_.max_acceleration()).abs() < 1e-9);
/// assert!((move_.max_acceleration() - 16.394).abs() < 1e-3);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment<const D: usize> {
    /// Start pose [m].
    pub start: Vector<D>,
    /// End pose [m].
    pub end: Vector<D>,
    /// Start time t1 [s].
    pub t1: f64,
    /// End time t2 [s] (> t1).
    pub t2: f64,
}

impl<const D: usize> Segment<D> {
    /// The quintic σ from 0 to 1 (eq. 13 with x1 = 0, x2 = 1).
    fn unit(&self) -> Step5 {
        Step5 {
            x1: 0.0,
            x2: 1.0,
            t1: self.t1,
            t2: self.t2,
        }
    }

    /// p(t) [m].
    pub fn position(&self, t: f64) -> Vector<D> {
        self.at(self.unit().position(t))
    }

    /// The pose a fraction `sigma` of the way along the segment [m] (the start for 0, the end
    /// for 1; a shaped reference convolves σ).
    pub fn at(&self, sigma: f64) -> Vector<D> {
        if sigma >= 1.0 {
            return self.end;
        }
        self.start + (self.end - self.start) * sigma
    }

    /// ṗ(t) [m/s].
    pub fn velocity(&self, t: f64) -> Vector<D> {
        (self.end - self.start) * self.unit().velocity(t)
    }

    /// p̈(t) [m/s²].
    pub fn acceleration(&self, t: f64) -> Vector<D> {
        (self.end - self.start) * self.unit().acceleration(t)
    }

    /// p_ref, ṗ_ref, p̈_ref at t [s]: σ convolved with `shaper`'s impulses (None or one unit
    /// impulse: unshaped); ṗ and p̈ zero unless `derivatives`.
    #[inline]
    pub fn shaped(&self, shaper: Option<&Impulses>, t: f64, derivatives: bool) -> [Vector<D>; 3] {
        let sigma = self.unit();
        let convolve = |f: &dyn Fn(f64) -> f64| match shaper {
            Some(shaper) if !shaper.is_none() => shaper.convolve(t, f),
            _ => f(t),
        };
        let position = self.at(convolve(&|t| sigma.position(t)));
        if !derivatives {
            return [position, Vector::zeros(), Vector::zeros()];
        }
        let direction = self.end - self.start;
        [
            position,
            direction * convolve(&|t| sigma.velocity(t)),
            direction * convolve(&|t| sigma.acceleration(t)),
        ]
    }

    /// Largest speed along the segment, 15 L / (8 (t2 − t1)) [m/s].
    pub fn max_speed(&self) -> f64 {
        15.0 * (self.end - self.start).norm() / (8.0 * (self.t2 - self.t1))
    }

    /// Largest |acceleration|, 10 L / (√3 (t2 − t1)²) [m/s²].
    pub fn max_acceleration(&self) -> f64 {
        let span = self.t2 - self.t1;
        10.0 * (self.end - self.start).norm() / (3f64.sqrt() * span * span)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_values() {
        let s = Step5::from(&scenario::Trajectory::default());
        // The paper quotes 0.9375 m/s and 14.434 m/s² at t = 0.0423 s and 0.1577 s.
        assert!((s.max_speed() - 0.9375).abs() < 1e-12);
        assert!((s.velocity(0.1) - 0.9375).abs() < 1e-12);
        assert!((s.max_acceleration() - 14.434).abs() < 5e-4);
        let [ta, tb] = s.max_acceleration_times();
        assert!((ta - 0.0423).abs() < 5e-5 && (tb - 0.1577).abs() < 5e-5);
        assert!((s.acceleration(ta) - s.max_acceleration()).abs() < 1e-9);
    }
}
