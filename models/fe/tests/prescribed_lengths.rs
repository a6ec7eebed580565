//! FE.11.10, the Du-type form (MODELS.md FE.5.6, FE.7, FE.10.3): the free lengths are prescribed,
//! l_1 = l_10 + d, l_2 = l_20 − d with d = 0.015 (1 − cos 4πt), and only the span's equations
//! remain. With the rigid stored variant the span's rows are exactly those equations: the stored
//! cable's kinetic energy ½ μ (L0 − l) l'² depends on l and l' alone, so it and the reel
//! tensions enter only the l-rows. The span's own energy then obeys
//! d/dt (E_span + E_P) = Σ Q_l,i l_i', Q_l = (M q'' − F)_l minus the stored cable's
//! Lagrange term μ (L0 − l) l'' − ½ μ l'², a balance the model's assembly does not contain.

use crate::common;

use cdpr_core::model::{CableModel, SplitRule};
use cdpr_fe::{Fe, FeMass, FeStored};
use cdpr_numerics::{Dopri5, Dopri5Options, OdeSystem};
use common::model;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

/// The prescribed offset d(t) = 0.015 (1 − cos 4πt) [m] and its two derivatives.
fn offset(t: f64) -> [f64; 3] {
    let w = 4.0 * PI;
    [
        0.015 * (1.0 - (w * t).cos()),
        0.015 * w * (w * t).sin(),
        0.015 * w * w * (w * t).cos(),
    ]
}

/// The span-only system: state [u, u', W_1, W_2] with u every position coordinate but l_1, l_2,
/// and W_i = ∫ Q_l,i l_i' dt the work done to impose each length (outside the error norm).
struct PrescribedLengths {
    model: Fe,
    /// l_10, l_20 [m].
    start: [f64; 2],
    /// Indices of l_1, l_2 among the positions, and of the other coordinates.
    l: [usize; 2],
    free: Vec<usize>,
    /// The model's state [q, q'] (positions_len each), filled from u and l(t).
    full: Vec<f64>,
}

impl PrescribedLengths {
    /// Fills the model's state at time t from u, u'; returns (l'', M, F) there.
    fn at(&mut self, t: f64, y: &[f64]) -> ([f64; 2], DMatrix<f64>, DVector<f64>) {
        let (np, nu) = (self.model.positions_len(), self.free.len());
        for (k, &i) in self.free.iter().enumerate() {
            self.full[i] = y[k];
            self.full[np + i] = y[nu + k];
        }
        let [d, dd, ddd] = offset(t);
        for (c, sign) in [1.0, -1.0].into_iter().enumerate() {
            self.full[self.l[c]] = self.start[c] + sign * d;
            self.full[np + self.l[c]] = sign * dd;
        }
        let mass = self.model.mass_matrix(&self.full);
        let force = self.model.force_vector(&self.full, [0.0, 0.0]);
        ([ddd, -ddd], mass, force)
    }

    /// The span's energy E_span + E_P [J]: the model's energy less the rigid stored cable's
    /// kinetic energy.
    fn span_energy(&self) -> f64 {
        let np = self.model.positions_len();
        let mu = self.model.material.mu;
        let stored: f64 = (0..2)
            .map(|c| {
                let (l, ld) = (self.full[self.l[c]], self.full[np + self.l[c]]);
                0.5 * mu * (self.model.modelled_length - l) * ld * ld
            })
            .sum();
        self.model.energy(&self.full).total() - stored
    }
}

impl PrescribedLengths {
    /// u'' from the span's rows and Q_l,i l_i' of each cable [W] at time t.
    fn solve(&mut self, t: f64, y: &[f64]) -> (DVector<f64>, [f64; 2], [f64; 2]) {
        let nu = self.free.len();
        let (ldd, mass, force) = self.at(t, y);
        // M_uu u'' = F_u − M_ul l''.
        let m_uu = mass.select_rows(&self.free).select_columns(&self.free);
        let mut rhs = DVector::from_iterator(nu, self.free.iter().map(|&i| force[i]));
        for c in 0..2 {
            for (k, &i) in self.free.iter().enumerate() {
                rhs[k] -= mass[(i, self.l[c])] * ldd[c];
            }
        }
        let udd = m_uu
            .cholesky()
            .expect("M_uu is positive definite")
            .solve(&rhs);
        // Q_l = (M q'' − F)_l less the stored cable's μ (L0 − l) l'' − ½ μ l'².
        let np = self.model.positions_len();
        let mu = self.model.material.mu;
        let (mut q, mut power) = ([0.0; 2], [0.0; 2]);
        for c in 0..2 {
            let li = self.l[c];
            q[c] = -force[li] + mass[(li, self.l[0])] * ldd[0] + mass[(li, self.l[1])] * ldd[1];
            for (k, &i) in self.free.iter().enumerate() {
                q[c] += mass[(li, i)] * udd[k];
            }
            let (l, ld) = (self.full[li], self.full[np + li]);
            q[c] -= mu * (self.model.modelled_length - l) * ldd[c] - 0.5 * mu * ld * ld;
            power[c] = q[c] * ld;
        }
        (udd, q, power)
    }
}

impl OdeSystem for PrescribedLengths {
    fn dimension(&self) -> usize {
        2 * self.free.len() + 2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        let nu = self.free.len();
        let (udd, _, power) = self.solve(t, y);
        dy[..nu].copy_from_slice(&y[nu..2 * nu]);
        dy[nu..2 * nu].copy_from_slice(udd.as_slice());
        dy[2 * nu..].copy_from_slice(&power);
    }
}

/// FE.11.10 (Du-type): 0.5 s from the x = 0.5 equilibrium, max |E_span+P − E0 − W| below 1e-7 J
/// at rtol 1e-5 (atol 1e-8) and below 1e-8 J at rtol 1e-8 (atol 1e-11), the required bounds
/// (MODELS.md FE.10.3 measured 7.1e-10 and 4.4e-14 J). Each imposed length does work of order
/// T · 0.03 m (the two nearly cancel in W = W_1 + W_2), so |W_1| > 1 J shows the balance is not
/// trivially small; Q_l stays in MODELS.md's [−102.4, −97.4] N (≈ −T, FE.7), to its printed digit.
#[test]
fn energy_identity_with_prescribed_lengths() {
    for (rtol, atol, bound) in [(1e-5, 1e-8, 1e-7), (1e-8, 1e-11, 1e-8)] {
        let mut m: Fe = model(10, FeMass::Consistent, FeStored::Rigid);
        let eq = m.equilibrium(&SplitRule::new(0.5, 200.0)).unwrap();
        let np = m.positions_len();
        let l = [m.l_index(0), m.l_index(1)];
        let free: Vec<usize> = (0..np).filter(|i| !l.contains(i)).collect();
        let nu = free.len();
        let mut sys = PrescribedLengths {
            start: [eq.state[l[0]], eq.state[l[1]]],
            model: m,
            l,
            free: free.clone(),
            full: eq.state.clone(),
        };
        let mut y0: Vec<f64> = free.iter().map(|&i| eq.state[i]).collect();
        y0.extend(free.iter().map(|&i| eq.state[np + i]));
        y0.extend([0.0, 0.0]);
        sys.at(0.0, &y0);
        let e0 = sys.span_energy();
        let opts = Dopri5Options {
            rtol,
            atol,
            norm_components: Some(2 * nu),
            ..Dopri5Options::default()
        };
        let mut d = Dopri5::new(y0.len(), opts);
        d.start(&mut sys, 0.0, &y0, 0.5).unwrap();
        let (mut worst, mut work) = (0.0f64, 0.0f64);
        let (mut q_min, mut q_max) = (f64::INFINITY, f64::NEG_INFINITY);
        while d.time() < 0.5 {
            d.step(&mut sys, 0.5).unwrap();
            let y = d.state().to_vec();
            let (_, q, _) = sys.solve(d.time(), &y);
            let w = y[2 * nu] + y[2 * nu + 1];
            worst = worst.max((sys.span_energy() - e0 - w).abs());
            work = work.max(y[2 * nu].abs());
            for q in q {
                q_min = q_min.min(q);
                q_max = q_max.max(q);
            }
        }
        eprintln!(
            "rtol {rtol:e}: max |E − E0 − W| = {worst:e} J, max |W_1| = {work:.4} J, Q_l in [{q_min:.2}, {q_max:.2}] N"
        );
        assert!(worst < bound, "rtol {rtol:e}: {worst:e} J");
        assert!(work > 1.0, "the imposed length did work: {work} J");
        assert!(
            (q_min + 102.4).abs() < 0.05 && (q_max + 97.4).abs() < 0.05,
            "Q_l in [{q_min}, {q_max}] N"
        );
    }
}
