//! Irvine's elastic catenary (Irvine, *Cable Structures*, 1981, §1–2; MODELS.md FE.8.2): the exact
//! static shape of an extensible cable under its own weight, the reference the discrete cable
//! models must converge to.
//!
//! Lagrangian coordinate s ∈ [0, L0] (unstrained arc length) from end A at the origin, weight
//! w = μ g per unstrained length, tension vector T(s) = (H, V0 + w s):
//!   x(s) = H s/EA + (H/w) [asinh((V0 + w s)/H) − asinh(V0/H)]
//!   z(s) = (V0 s + w s²/2)/EA + (1/w) [√(H² + (V0 + w s)²) − √(H² + V0²)]

use cdpr_bench::numerics::newton::{self, NewtonError, NewtonOptions, StaticProblem};

/// An elastic catenary hanging from the origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Catenary {
    /// Horizontal tension component H [N] (> 0).
    pub horizontal: f64,
    /// Vertical tension component at A, V0 [N].
    pub vertical: f64,
    /// Weight per unstrained length w = μ g [N/m].
    pub weight: f64,
    /// Axial stiffness EA [N].
    pub axial_stiffness: f64,
}

impl Catenary {
    /// Position at unstrained arc length s [m] from A.
    pub fn position(&self, s: f64) -> [f64; 2] {
        let (h, v0, w, ea) = (
            self.horizontal,
            self.vertical,
            self.weight,
            self.axial_stiffness,
        );
        let v = v0 + w * s;
        [
            h * s / ea + h / w * ((v / h).asinh() - (v0 / h).asinh()),
            (v0 * s + 0.5 * w * s * s) / ea + (h.hypot(v) - h.hypot(v0)) / w,
        ]
    }

    /// The catenary of unstrained length `length` from the origin to `end` (Newton on (H, V0)
    /// from the taut chord stretch or the parabolic sag).
    pub fn through(
        end: [f64; 2],
        length: f64,
        weight: f64,
        axial_stiffness: f64,
    ) -> Result<Self, NewtonError> {
        let chord = end[0].hypot(end[1]);
        let (h0, v0) = if chord >= length {
            // Taut: tension from the stretch, directed along the chord, plus half the weight.
            let t = axial_stiffness * (chord / length - 1.0);
            (
                t * end[0] / chord,
                t * end[1] / chord - 0.5 * weight * length,
            )
        } else {
            // Slack: parabola with sag √(3c(L − c)/8) carries the weight with H = wL c/(8 sag).
            let sag = (3.0 * chord * (length - chord) / 8.0).sqrt();
            let h = weight * length * chord / (8.0 * sag);
            (h, -0.5 * weight * length + h * end[1] / end[0])
        };
        let mut problem = Fit {
            end,
            length,
            weight,
            axial_stiffness,
        };
        let mut u = [h0, v0];
        newton::solve(
            &mut problem,
            &mut u,
            NewtonOptions {
                residual_tol: 1e-13,
                update_tol: f64::INFINITY,
                max_iterations: 100,
            },
        )?;
        Ok(problem.catenary(u))
    }
}

struct Fit {
    end: [f64; 2],
    length: f64,
    weight: f64,
    axial_stiffness: f64,
}

impl Fit {
    fn catenary(&self, u: [f64; 2]) -> Catenary {
        Catenary {
            horizontal: u[0],
            vertical: u[1],
            weight: self.weight,
            axial_stiffness: self.axial_stiffness,
        }
    }
}

impl StaticProblem for Fit {
    fn dimension(&self) -> usize {
        2
    }
    fn length_unknowns(&self) -> usize {
        0
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        let p = self.catenary([u[0], u[1]]).position(self.length);
        r[0] = p[0] - self.end[0];
        r[1] = p[1] - self.end[1];
    }
    fn scale(&self, _i: usize) -> f64 {
        1e-2
    }
}
