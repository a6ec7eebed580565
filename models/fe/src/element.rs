//! The one variable-length element of MODELS.md FE.3–FE.5.3: two nodes a, b with convective
//! weights w_a, w_b and unstrained length h(l), h' = dh/dl. A free element of the span has
//! h = l/N, h' = 1/N, w_k = 1 − k/N; the stored element (reel end R → pulley A) has h = L0 − l,
//! h' = −1, w_R = 0, w_A = 1. Both kinds are this same kernel, so the stored element cannot drift
//! from the span's physics.
//!
//! Kinematics (FE.3): v(η) = (1 − η) a + η b + l' w(η) Δ/h, Δ = r_b − r_a, w linear in η. The
//! kinetic energy is the paper's eq. 8 integrated exactly over the element, T_e = ½ μ h (c1|a|² +
//! 2c2 a·b + c1|b|²) + μ l'(α a + β b)·Δ + ½ μ γ l'²|Δ|²/h (FE.4), with the coefficients of
//! [`MassCoefficients`]; the potential is eq. 9's (strain energy and weight). Lagrange's equations
//! of the two (eq. 11, with the mass-flux work of eq. 10 contained in the ansatz, FE.5.2) give the
//! element's rows of eq. 12, m q'' + c q' + k q = f + f_g, as M_e and F_e (FE.5.3).

use crate::params::FeMass;
use nalgebra::SVector;

/// The vertical vector (0, …, 0, v): gravity acts along the last axis (z in the plane and in
/// space).
#[inline(always)]
fn vertical<const D: usize>(v: f64) -> SVector<f64, D> {
    SVector::<f64, D>::from_fn(|k, _| if k == D - 1 { v } else { 0.0 })
}

/// Element mass coefficients c1, c2, α, β, γ of MODELS.md FE.4 for weights (w_a, w_b).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassCoefficients {
    pub c1: f64,
    pub c2: f64,
    pub alpha: f64,
    pub beta: f64,
    pub gamma: f64,
}

impl MassCoefficients {
    /// Consistent mass (the exact integral of the linear ansatz) or lumped mass (nodal,
    /// trapezoidal quadrature of the kinetic energy), FE.4's table.
    pub fn new(mass: FeMass, wa: f64, wb: f64) -> Self {
        match mass {
            FeMass::Consistent => Self {
                c1: 1.0 / 3.0,
                c2: 1.0 / 6.0,
                alpha: wa / 3.0 + wb / 6.0,
                beta: wa / 6.0 + wb / 3.0,
                gamma: (wa * wa + wa * wb + wb * wb) / 3.0,
            },
            FeMass::Lumped => Self {
                c1: 0.5,
                c2: 0.0,
                alpha: 0.5 * wa,
                beta: 0.5 * wb,
                gamma: 0.5 * (wa * wa + wb * wb),
            },
        }
    }
}

/// Cable material per unit unstrained length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Axial stiffness EA [N].
    pub ea: f64,
    /// Mass per unstrained length μ [kg/m].
    pub mu: f64,
    /// Gravity g [m/s²] along −z.
    pub gravity: f64,
}

/// One element's configuration: node positions [m] and velocities [m/s], the span's l' [m/s],
/// the element's unstrained length h [m], its inverse 1/h [1/m] and h' = dh/dl.
///
/// 1/h is carried rather than recomputed because the N elements of a span share h: the span
/// divides once and every element multiplies (divisions and square roots share one slow unit, and
/// they were most of an element's cost). Build it with [`ElementState::new`] unless 1/h is at hand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementState<const D: usize = 2> {
    pub ra: SVector<f64, D>,
    pub rb: SVector<f64, D>,
    pub va: SVector<f64, D>,
    pub vb: SVector<f64, D>,
    pub l_rate: f64,
    pub h: f64,
    pub inv_h: f64,
    pub h_prime: f64,
}

impl<const D: usize> ElementState<D> {
    /// Nodes (r_a, v_a), (r_b, v_b), the span's l', unstrained length h and h'.
    #[inline]
    pub fn new(
        (ra, va): (SVector<f64, D>, SVector<f64, D>),
        (rb, vb): (SVector<f64, D>, SVector<f64, D>),
        l_rate: f64,
        h: f64,
        h_prime: f64,
    ) -> Self {
        Self {
            ra,
            rb,
            va,
            vb,
            l_rate,
            h,
            inv_h: 1.0 / h,
            h_prime,
        }
    }

    /// Strain ε = |Δ|/h − 1 and tension N = EA max(ε, 0) (FE.2, FE.1.4: tension only) for the
    /// chord length |Δ| = `length` [m].
    #[inline]
    pub fn tension(&self, ea: f64, length: f64) -> (f64, f64) {
        let strain = length * self.inv_h - 1.0;
        (strain, ea * strain.max(0.0))
    }

    /// [`Self::tension`] at the element's chord length |r_b − r_a|.
    #[inline]
    pub fn chord_tension(&self, ea: f64) -> (f64, f64) {
        self.tension(ea, (self.rb - self.ra).norm())
    }
}

/// What an element adds to M and F (FE.5.3), in its local unknowns (r_a, r_b, l).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementTerms<const D: usize = 2> {
    /// μ h c1: the r_a r_a and r_b r_b blocks (times I2) [kg].
    pub m_diag: f64,
    /// μ h c2: the r_a r_b block (times I2) [kg].
    pub m_off: f64,
    /// μ α Δ, μ β Δ: the r_a l and r_b l columns [kg].
    pub m_al: SVector<f64, D>,
    pub m_bl: SVector<f64, D>,
    /// μ γ |Δ|²/h: the l l entry [kg].
    pub m_ll: f64,
    /// Generalised forces F_a, F_b [N] and F_l [N] (FE.5.3), gravity included.
    pub fa: SVector<f64, D>,
    pub fb: SVector<f64, D>,
    pub fl: f64,
}

/// M_e and F_e of MODELS.md FE.5.3 for one element (no axial damping).
#[inline]
pub fn terms<const D: usize>(
    mat: &Material,
    k: &MassCoefficients,
    s: &ElementState<D>,
) -> ElementTerms<D> {
    terms_damped(mat, k, s, 0.0)
}

/// Strain rate ε' = (t·Δ')/h − (1 + ε) h' l'/h of MODELS.md FE.5.7 [1/s]: the chord's stretching
/// rate minus the relaxation by unstrained length flowing in.
#[inline]
pub fn strain_rate<const D: usize>(s: &ElementState<D>) -> f64 {
    strain_rate_at(s, (s.rb - s.ra).norm())
}

/// [`strain_rate`] given the chord length |Δ| = `len` (the same value, one square root fewer).
#[inline]
fn strain_rate_at<const D: usize>(s: &ElementState<D>, len: f64) -> f64 {
    let delta = s.rb - s.ra;
    let strain = len * s.inv_h - 1.0;
    (delta.dot(&(s.vb - s.va)) / len - (1.0 + strain) * s.h_prime * s.l_rate) * s.inv_h
}

/// The Kelvin–Voigt part of the element tension (MODELS.md FE.5.7) for damping C [N s]:
/// N_d = max(EA ε + C ε', 0) − EA ε while taut, else 0. As in the lumped model (MODELS.md §4) the
/// total tension is clipped at 0, so a fast-shortening taut element cannot push. Returns (N_d, ε').
#[inline]
pub fn damping_tension<const D: usize>(
    mat: &Material,
    s: &ElementState<D>,
    damping: f64,
) -> (f64, f64) {
    if damping == 0.0 {
        return (0.0, 0.0);
    }
    damping_tension_at(mat, s, damping, (s.rb - s.ra).norm())
}

/// [`damping_tension`] given the chord length |Δ| = `len`, as the kernels have it (the same
/// numbers, two square roots fewer per element).
#[inline]
fn damping_tension_at<const D: usize>(
    mat: &Material,
    s: &ElementState<D>,
    damping: f64,
    len: f64,
) -> (f64, f64) {
    if damping == 0.0 {
        return (0.0, 0.0);
    }
    let strain = len * s.inv_h - 1.0;
    if strain <= 0.0 {
        return (0.0, 0.0);
    }
    let rate = strain_rate_at(s, len);
    let elastic = mat.ea * strain;
    ((elastic + damping * rate).max(0.0) - elastic, rate)
}

/// Power dissipated by the element's axial damping, D_e = h N_d ε' ≥ 0 [W] (FE.5.7: C h ε'² when
/// not clipped; with clipping N_d = −EA ε < 0 only while ε' < 0, so still ≥ 0).
#[inline]
pub fn dissipation<const D: usize>(mat: &Material, s: &ElementState<D>, damping: f64) -> f64 {
    let (nd, rate) = damping_tension(mat, s, damping);
    s.h * nd * rate
}

/// An element's chord length |Δ| = |r_b − r_a| [m] and its inverse [1/m]. Computed apart when a
/// whole chain of elements is at hand ([`chords`]): their square roots and divisions then run two
/// at a time, where one element after another waits on each (they were a quarter of the FE
/// assembly).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chord {
    pub length: f64,
    pub inv_length: f64,
}

impl Chord {
    /// The chord of element `s`.
    #[inline]
    pub fn of<const D: usize>(s: &ElementState<D>) -> Self {
        let length = (s.rb - s.ra).norm();
        Self {
            length,
            inv_length: 1.0 / length,
        }
    }
}

/// The chords between consecutive points (x_j, z_j), (x_j+1, z_j+1) into `length` and
/// `inv_length` (as long as each other; `x` and `z` at least one longer: panics otherwise, a
/// caller's sizing error), bit for bit [`Chord::of`] of those elements.
pub fn chords(x: &[f64], z: &[f64], length: &mut [f64], inv_length: &mut [f64]) {
    let m = length.len();
    let (x, z, inv_length) = (&x[..m + 1], &z[..m + 1], &mut inv_length[..m]);
    for j in 0..m {
        let (dx, dz) = (x[j + 1] - x[j], z[j + 1] - z[j]);
        let l = (dx * dx + dz * dz).sqrt();
        length[j] = l;
        inv_length[j] = 1.0 / l;
    }
}

/// M_e and F_e of MODELS.md FE.5.3 plus the axial damping of FE.5.7 with coefficient C =
/// `damping` [N s]: the damping tension N_d acts along t like N_e on F_a, F_b, and adds
/// h' N_d (1 + ε) to F_l (the virtual work −h N_d δε with δε = t·δΔ/h − (1 + ε) h' δl/h; note
/// (1 + ε), not the (1 + ε/2) of the elastic term, which comes from the strain energy's h).
#[inline(always)]
pub fn terms_damped<const D: usize>(
    mat: &Material,
    k: &MassCoefficients,
    s: &ElementState<D>,
    damping: f64,
) -> ElementTerms<D> {
    terms_at_chord(mat, k, s, damping, Chord::of(s))
}

/// [`terms_damped`] with the element's chord given.
#[inline(always)]
pub fn terms_at_chord<const D: usize>(
    mat: &Material,
    k: &MassCoefficients,
    s: &ElementState<D>,
    damping: f64,
    chord: Chord,
) -> ElementTerms<D> {
    debug_assert!(
        (s.h * s.inv_h - 1.0).abs() < 1e-12,
        "inv_h out of step with h"
    );
    let mu = mat.mu;
    let (h, ld) = (s.h, s.l_rate);
    let (a, b) = (s.va, s.vb);
    let delta = s.rb - s.ra;
    let len2 = delta.norm_squared();
    let len = chord.length;
    let (strain, n) = s.tension(mat.ea, len);
    let (n_damp, _) = damping_tension_at(mat, s, damping, chord.length);
    // (N + N_d) t with t = Δ/|Δ|: the pull on node a towards b.
    let pull = delta * ((n + n_damp) * chord.inv_length);
    let h_rate = s.h_prime * ld;
    let delta_rate = b - a;
    let inv_h = s.inv_h;
    let flux = a * k.alpha + b * k.beta;
    // G = μ l'(α a + β b) + μ γ l'² Δ/h.
    let g = (flux * ld + delta * (k.gamma * ld * ld * inv_h)) * mu;
    let half_weight = 0.5 * mu * mat.gravity * h;
    let fa = pull
        - (a * k.c1 + b * k.c2) * (mu * h_rate)
        - delta_rate * (mu * k.alpha * ld)
        - g
        - vertical::<D>(half_weight);
    let fb = -pull - (a * k.c2 + b * k.c1) * (mu * h_rate) - delta_rate * (mu * k.beta * ld) + g
        - vertical::<D>(half_weight);
    let kinetic_density =
        0.5 * mu * (k.c1 * (a.norm_squared() + b.norm_squared()) + 2.0 * k.c2 * a.dot(&b));
    let ld2_len2_h2 = ld * ld * len2 * inv_h * inv_h;
    let fl = -mu * flux.dot(&delta_rate)
        - mu * k.gamma
            * (2.0 * ld * delta.dot(&delta_rate) * inv_h - ld * h_rate * len2 * inv_h * inv_h)
        + s.h_prime
            * (kinetic_density - 0.5 * mu * k.gamma * ld2_len2_h2
                + n * (1.0 + 0.5 * strain.max(0.0))
                + n_damp * (1.0 + strain)
                - mu * mat.gravity * 0.5 * (s.ra[D - 1] + s.rb[D - 1]));
    ElementTerms {
        m_diag: mu * h * k.c1,
        m_off: mu * h * k.c2,
        m_al: delta * (mu * k.alpha),
        m_bl: delta * (mu * k.beta),
        m_ll: mu * k.gamma * len2 * inv_h,
        fa,
        fb,
        fl,
    }
}

/// The element's rows of R = M q'' − F (FE.9.3) at node accelerations a_a = `aa`, a_b = `ab` and
/// l'' = `al` [m/s²], given its chord: (rows r_a, rows r_b, row l) [N]. The same function as
/// M_e q''_e − F_e from [`terms_at_chord`], with FE.5.3's terms collected before they are summed
/// (what the implicit residual evaluates twice per step):
///
/// ```text
/// R_a = μ c1 (h a_a + h' l' a) + μ c2 (h a_b + h' l' b) + μ l'(α + β) b + (μ(α l'' + γ l'²/h) − N_t/|Δ|) Δ + ½ μ g h e_z
/// R_b = μ c2 (h a_a + h' l' a) + μ c1 (h a_b + h' l' b) − μ l'(α + β) a + (μ(β l'' − γ l'²/h) + N_t/|Δ|) Δ + ½ μ g h e_z
/// R_l = μ [Δ·(α a_a + β a_b) + (α a + β b)·Δ' + γ (|Δ|²/h (l'' − ½ h' l'²/h) + 2 l' Δ·Δ'/h)]
///       − h' [½ μ (c1 (|a|² + |b|²) + 2 c2 a·b) + N (1 + ε⁺/2) + N_d (1 + ε) − ½ μ g (z_a + z_b)]
/// ```
///
/// with N_t = N + N_d and Δ' = b − a: F_a's
/// −μ α l' Δ' and −G share μ l' α a, which cancels, leaving μ l'(α + β) b (likewise for F_b),
/// and the l-row's l'²|Δ|²/h² terms of M_ll's convective part and of ∂T/∂l combine into one.
/// Fewer operations than forming M_e and F_e first; `implicit_residual_is_m_qdd_minus_f`
/// checks the two agree to round-off.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn residual_at_chord<const D: usize>(
    mat: &Material,
    k: &MassCoefficients,
    s: &ElementState<D>,
    damping: f64,
    chord: Chord,
    aa: SVector<f64, D>,
    ab: SVector<f64, D>,
    al: f64,
) -> (SVector<f64, D>, SVector<f64, D>, f64) {
    let mu = mat.mu;
    let (h, ld, inv_h) = (s.h, s.l_rate, s.inv_h);
    let (a, b) = (s.va, s.vb);
    let delta = s.rb - s.ra;
    let len2 = delta.norm_squared();
    let (strain, n) = s.tension(mat.ea, chord.length);
    let (n_damp, _) = damping_tension_at(mat, s, damping, chord.length);
    let h_rate = s.h_prime * ld;
    // (h a + h' l' a) and (h a_b + h' l' b): d(h r')/dt at each node.
    let da = aa * h + a * h_rate;
    let db = ab * h + b * h_rate;
    let drift = mu * ld * (k.alpha + k.beta);
    let pull = (n + n_damp) * chord.inv_length;
    let centripetal = mu * k.gamma * ld * ld * inv_h;
    let weight = vertical::<D>(0.5 * mu * mat.gravity * h);
    let ra = (da * k.c1 + db * k.c2) * mu
        + b * drift
        + delta * (mu * k.alpha * al + centripetal - pull)
        + weight;
    let rb = (da * k.c2 + db * k.c1) * mu - a * drift
        + delta * (mu * k.beta * al - centripetal + pull)
        + weight;
    let delta_rate = b - a;
    let kinetic_density =
        0.5 * mu * (k.c1 * (a.norm_squared() + b.norm_squared()) + 2.0 * k.c2 * a.dot(&b));
    let rl = mu
        * (delta.dot(&(aa * k.alpha + ab * k.beta))
            + (a * k.alpha + b * k.beta).dot(&delta_rate)
            + k.gamma
                * (len2 * inv_h * (al - 0.5 * h_rate * ld * inv_h)
                    + 2.0 * ld * inv_h * delta.dot(&delta_rate)))
        - s.h_prime
            * (kinetic_density + n * (1.0 + 0.5 * strain.max(0.0)) + n_damp * (1.0 + strain)
                - mu * mat.gravity * 0.5 * (s.ra[D - 1] + s.rb[D - 1]));
    (ra, rb, rl)
}

/// Element energies of MODELS.md FE.4: (kinetic T_e, strain ½ EA h max(ε,0)², gravity
/// μ g h (z_a + z_b)/2) [J].
pub fn energies<const D: usize>(
    mat: &Material,
    k: &MassCoefficients,
    s: &ElementState<D>,
) -> (f64, f64, f64) {
    let mu = mat.mu;
    let (h, ld) = (s.h, s.l_rate);
    let (a, b) = (s.va, s.vb);
    let delta = s.rb - s.ra;
    let len2 = delta.norm_squared();
    let kinetic =
        0.5 * mu * h * (k.c1 * (a.norm_squared() + b.norm_squared()) + 2.0 * k.c2 * a.dot(&b))
            + mu * ld * (a * k.alpha + b * k.beta).dot(&delta)
            + 0.5 * mu * k.gamma * ld * ld * len2 * s.inv_h;
    let strain = (len2.sqrt() * s.inv_h - 1.0).max(0.0);
    let elastic = 0.5 * mat.ea * h * strain * strain;
    let gravity = mu * mat.gravity * h * 0.5 * (s.ra[D - 1] + s.rb[D - 1]);
    (kinetic, elastic, gravity)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;
    use proptest::prelude::*;

    proptest! {
        /// The chain's pass gives every element's chord bit for bit, in either direction along
        /// the chain (the second cable's elements run against the chain's numbering).
        #[test]
        fn chain_chords_are_the_elements_chords(
            points in prop::collection::vec((-1.0f64..1.0, -1.0f64..0.0), 2..24),
        ) {
            let (x, z): (Vec<f64>, Vec<f64>) = points.iter().copied().unzip();
            let m = x.len() - 1;
            let (mut length, mut inv_length) = (vec![0.0; m], vec![0.0; m]);
            chords(&x, &z, &mut length, &mut inv_length);
            for j in 0..m {
                let (a, b) = (Vector2::new(x[j], z[j]), Vector2::new(x[j + 1], z[j + 1]));
                let still = Vector2::zeros();
                for (ra, rb) in [(a, b), (b, a)] {
                    let s = ElementState::new((ra, still), (rb, still), 0.0, 0.1, 0.1);
                    let chord = Chord::of(&s);
                    prop_assert_eq!(chord.length.to_bits(), length[j].to_bits());
                    prop_assert_eq!(chord.inv_length.to_bits(), inv_length[j].to_bits());
                }
            }
        }
    }
}
