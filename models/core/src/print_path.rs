//! A printed path as a robot's reference: the firmware's plan ([`cdpr_printing::planner`])
//! placed in the robot's frame (`[printer] origin` + the file's coordinates), each Cartesian
//! axis convolved with its own input shaper as the firmware's step generation does
//! (Σ A_i x(t − τ_i), the pulses' times τ_i taken from their centroid). A
//! planar robot prints the file's X and Z.
//!
//! The loop's clock starts `lead` before the plan's t = 0: [`PRE_ROLL`] plus the largest
//! centroid of the axes' shapers (the shaped reference starts moving that much early), so the
//! loop starts at rest under a reference at rest — a trapezoid's acceleration jumps at its
//! first instant.

use crate::robot::Vector;
use cdpr_printing::planner::{Plan, Reference};
use std::sync::Arc;

/// Rest before the plan's first move [s].
pub const PRE_ROLL: f64 = 0.02;

/// Pulses applied to one axis: amplitudes summing to 1 at times τ_i [s] about their centroid.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisShaper {
    pub amplitudes: Vec<f64>,
    pub offsets: Vec<f64>,
}

impl AxisShaper {
    /// From a firmware shaper's pulses (A_i, T_i): normalised and centred.
    pub fn from_pulses(amplitudes: &[f64], times: &[f64]) -> Self {
        let (amplitudes, offsets) = cdpr_printing::shaper::centred(amplitudes, times);
        AxisShaper {
            amplitudes,
            offsets,
        }
    }
}

/// The reference of a print.
#[derive(Debug, Clone)]
pub struct PrintPath<const D: usize> {
    plan: Arc<Plan>,
    origin: [f64; 3],
    /// Shapers of the file's X, Y, Z (None: unshaped).
    shapers: [Option<AxisShaper>; 3],
    lead: f64,
    duration: f64,
}

impl<const D: usize> PrintPath<D> {
    /// The file's axis behind each of the robot's coordinates: X, Y, Z in space, X and Z in the
    /// plane.
    const AXES: [usize; D] = {
        let mut axes = [0; D];
        let mut k = 0;
        while k < D {
            axes[k] = if D == 2 && k == 1 { 2 } else { k };
            k += 1;
        }
        axes
    };

    /// The plan (at least one moving segment) at `origin` [m], the file's axes shaped by
    /// `shapers`; None when the plan does not move.
    ///
    /// # Examples
    /// ```
    /// use cdpr_core::print_path::PrintPath;
    /// use cdpr_printing::{gcode, planner};
    /// let program = gcode::read("G1 X100 F6000", [0.0; 3]).unwrap();
    /// let plan = planner::plan(&program, &planner::Limits::new(0.1, 1.0)).unwrap();
    /// let path = PrintPath::<3>::new(plan.into(), [0.5, 0.0, -0.2], Default::default()).unwrap();
    /// assert_eq!(path.start().as_slice(), &[0.5, 0.0, -0.2]);
    /// assert!((path.end()[0] - 0.6).abs() < 1e-15);
    /// assert!((path.duration() - (1.1 + cdpr_core::print_path::PRE_ROLL)).abs() < 1e-12);
    /// ```
    pub fn new(
        plan: Arc<Plan>,
        origin: [f64; 3],
        shapers: [Option<AxisShaper>; 3],
    ) -> Option<Self> {
        plan.segments.first()?;
        let early = |s: &Option<AxisShaper>| {
            s.as_ref()
                .map_or(0.0, |s| s.offsets.iter().fold(0.0f64, |m, &o| m.max(-o)))
        };
        let late = |s: &Option<AxisShaper>| {
            s.as_ref()
                .map_or(0.0, |s| s.offsets.iter().fold(0.0f64, |m, &o| m.max(o)))
        };
        let lead = PRE_ROLL + shapers.iter().map(early).fold(0.0, f64::max);
        let tail = shapers.iter().map(late).fold(0.0, f64::max);
        let duration = lead + plan.print_time + tail;
        Some(PrintPath {
            plan,
            origin,
            shapers,
            lead,
            duration,
        })
    }

    /// The plan.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The loop's time at the plan's t = 0 [s].
    pub fn lead(&self) -> f64 {
        self.lead
    }

    /// When the shaped reference has come to rest after the plan's end [s].
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// The loop's times [s] where the reference may jump in velocity or acceleration, ascending:
    /// the plan's [`Plan::breakpoints`] delayed by each pulse of each axis's shaper (a shaped
    /// axis is a sum of delayed copies of the plan, each with the plan's jumps).
    pub fn breakpoints(&self) -> Vec<f64> {
        let plan = self.plan.breakpoints();
        let mut delays = Vec::new();
        for axis in Self::AXES {
            match &self.shapers[axis] {
                Some(shaper) => delays.extend(&shaper.offsets),
                None => delays.push(0.0),
            }
        }
        let mut times: Vec<f64> = delays
            .iter()
            .flat_map(|tau| plan.iter().map(move |b| self.lead + b + tau))
            .collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        times
    }

    /// Where the print starts [m].
    pub fn start(&self) -> Vector<D> {
        self.reference(0.0, false)[0]
    }

    /// Where it ends [m].
    pub fn end(&self) -> Vector<D> {
        self.reference(self.duration, false)[0]
    }

    /// Start and end of the plan's segment `i` in the robot's frame [m].
    pub fn segment_ends(&self, i: usize) -> (Vector<D>, Vector<D>) {
        let s = &self.plan.segments[i];
        let length = s.length();
        let at = |d: f64| {
            Vector::<D>::from_fn(|k, _| {
                let axis = Self::AXES[k];
                self.origin[axis] + s.start[axis] + s.dir[axis] * d
            })
        };
        (at(0.0), at(length))
    }

    /// The unshaped commanded position at the plan's time `t` [s] in the robot's frame: the
    /// path the nozzle should draw.
    pub fn commanded(&self, t: f64) -> Vector<D> {
        let (p, _, _) = self.plan.reference(t).expect("a plan with segments");
        Vector::<D>::from_fn(|k, _| self.origin[Self::AXES[k]] + p[Self::AXES[k]])
    }

    /// p_ref, ṗ_ref, p̈_ref at the loop's time `t` [s] (ṗ, p̈ zero unless `derivatives`).
    pub fn reference(&self, t: f64, derivatives: bool) -> [Vector<D>; 3] {
        let s = t - self.lead;
        // The plan convolved with each distinct shaper once: axes sharing a shaper (or none)
        // share the evaluation.
        let mut evaluated: [Option<Reference>; D] = [None; D];
        let mut out = [Vector::<D>::zeros(); 3];
        for (k, &axis) in Self::AXES.iter().enumerate() {
            let shaper = &self.shapers[axis];
            let twin = (0..k).find(|&j| self.shapers[Self::AXES[j]] == *shaper);
            let (p, v, a) = match twin.and_then(|j| evaluated[j]) {
                Some(done) => done,
                None => self.convolved(shaper.as_ref(), s),
            };
            evaluated[k] = Some((p, v, a));
            out[0][k] = self.origin[axis] + p[axis];
            if derivatives {
                out[1][k] = v[axis];
                out[2][k] = a[axis];
            }
        }
        out
    }

    /// Σ A_i (p, v, a)(s − τ_i) of the plan at its time `s` [s] (unshaped: the plan's own).
    fn convolved(&self, shaper: Option<&AxisShaper>, s: f64) -> Reference {
        let Some(shaper) = shaper else {
            return self.plan.reference(s).expect("a plan with segments");
        };
        let mut sum = ([0.0; 3], [0.0; 3], [0.0; 3]);
        for (a, tau) in shaper.amplitudes.iter().zip(&shaper.offsets) {
            let (p, v, acc) = self.plan.reference(s - tau).expect("a plan with segments");
            for k in 0..3 {
                sum.0[k] += a * p[k];
                sum.1[k] += a * v[k];
                sum.2[k] += a * acc[k];
            }
        }
        sum
    }
}
