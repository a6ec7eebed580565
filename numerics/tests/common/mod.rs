//! Test systems shared by the integrator tests.

use cdpr_numerics::{MatrixCost, OdeSystem, SecondOrderSystem};

/// Kepler's problem q'' = −q/|q|³ written as R = q'' + q/|q|³, circular orbit q = (cos t, sin t).
pub struct Kepler;

impl OdeSystem for Kepler {
    fn dimension(&self) -> usize {
        4
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        let r3 = y[0].hypot(y[1]).powi(3);
        dy[0] = y[2];
        dy[1] = y[3];
        dy[2] = -y[0] / r3;
        dy[3] = -y[1] / r3;
    }
}

impl SecondOrderSystem for Kepler {
    fn dofs(&self) -> usize {
        2
    }
    fn iteration_pattern(&self) -> Vec<(usize, usize)> {
        vec![(0, 0), (0, 1), (1, 0), (1, 1)]
    }
    fn begin_step(&mut self, _t: f64, _y: &[f64], _h: f64) {}
    fn residual(&mut self, _t: f64, y: &[f64], qdd: &[f64], r: &mut [f64]) {
        let r3 = y[0].hypot(y[1]).powi(3);
        r[0] = qdd[0] + y[0] / r3;
        r[1] = qdd[1] + y[1] / r3;
    }
    fn iteration_matrix(
        &mut self,
        _t: f64,
        y: &[f64],
        _qdd: &[f64],
        _c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost {
        // ∂(q/|q|³)/∂q = I/|q|³ − 3 q qᵀ/|q|⁵.
        let r2 = y[0] * y[0] + y[1] * y[1];
        let r3 = r2 * r2.sqrt();
        let r5 = r3 * r2;
        values[0] = 1.0 + c_q * (1.0 / r3 - 3.0 * y[0] * y[0] / r5);
        values[1] = c_q * (-3.0 * y[0] * y[1] / r5);
        values[2] = values[1];
        values[3] = 1.0 + c_q * (1.0 / r3 - 3.0 * y[1] * y[1] / r5);
        MatrixCost::default()
    }
    fn end_step(&mut self, _t: f64, _y: &mut [f64]) {}
    fn tail_rate(&mut self, _t: f64, _y: &[f64], _out: &mut [f64]) {}
}
