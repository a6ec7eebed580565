//! Every mode of a robot at rest with its reels as the model holds them — locked, for the printer
//! whose firmware drives its reels by length and holds them between moves (MODELS.md §11) —
//! each one named ([`crate::modes::classify`]: in space the effector's x, y and vertical
//! motions, each cable's string in and across its vertical plane, and its axial modes).
//!
//! No controller and no finite differences: the undamped problem K φ = ω² M φ of the model's
//! second-order form (R = M q'' − F(q, q')), with M = ∂R/∂q'' and K = −∂F/∂q read from its
//! analytic iteration matrix S(c_q) = M − c_q ∂F/∂q at q' = 0, q'' = 0 (S(1) − S(0) = K), over
//! the coordinates the model's layout leaves free. K is symmetric for conservative forces; its
//! asymmetry is reported, the symmetric part solved, and the frequencies come out in ascending
//! order. A lumped (diagonal) M scales K by M^(−1/2); a consistent one (the FE cables') by its
//! Cholesky factor, L⁻¹ K L⁻ᵀ. The dense self-adjoint eigen-solve costs O(n³): it is bounded by
//! [`crate::linearise::DENSE_MAX_STATES`]. At any size, [`rest_modes_near`] finds the modes
//! nearest a chosen frequency by shift-invert Lanczos ([`cdpr_numerics::lanczos`]) on the
//! sparse K − ω_s² M, factorised once by the implicit path's sparse LU, in the M inner product.

use crate::AnalysisError;
use crate::linearise::DENSE_MAX_STATES;
use crate::modes::{ClassifiedMode, classify};
use cdpr_core::modal_layout::{Dof, ModalLayout};
use cdpr_core::model::CableModel;
use cdpr_core::second_order::SecondOrderForm;
use cdpr_numerics::eigen::Mode;
use cdpr_numerics::sparse::IterationMatrix;
use faer::{Mat, Side};

/// The named modes of a robot at rest.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RestModes {
    /// Every mode, by ascending frequency, numbered within its kind.
    pub modes: Vec<ClassifiedMode>,
    /// Per mode, the effector's displacement in its shape (mass-normalised, one component per
    /// axis; empty without an effector in the layout).
    pub effector_motion: Vec<Vec<f64>>,
    /// max |K − Kᵀ| / max |K| of the mass-scaled stiffness (round-off for conservative forces;
    /// None from the sparse solve, which does not form K).
    pub asymmetry: Option<f64>,
}

/// The dense stiffness K = −∂F/∂q [N/m] and the diagonal of the mass M [kg] of a second-order
/// form at rest in `state` under `tensions` [N]: S(c_q = 1) − S(0) and the diagonal of S(0) of
/// its iteration matrix (q' = 0, q'' = 0, damping off).
pub fn stiffness_and_mass(
    form: &mut dyn SecondOrderForm,
    state: &[f64],
    tensions: &[f64],
) -> (Mat<f64>, Vec<f64>) {
    let (k, m) = stiffness_and_mass_matrix(form, state, tensions);
    let diagonal = (0..m.nrows()).map(|i| m[(i, i)]).collect();
    (k, diagonal)
}

/// The dense stiffness K = −∂F/∂q [N/m] and mass M = ∂R/∂q'' [kg] of a second-order form at
/// rest in `state` under `tensions` [N]: S(c_q = 1) − S(0) and S(0) of its iteration matrix
/// (q' = 0, q'' = 0, damping off). M is diagonal for lumped masses, full for consistent ones.
pub fn stiffness_and_mass_matrix(
    form: &mut dyn SecondOrderForm,
    state: &[f64],
    tensions: &[f64],
) -> (Mat<f64>, Mat<f64>) {
    let n = form.dofs();
    let pattern = form.iteration_pattern();
    let qdd = vec![0.0; n];
    let (mut stiff, mut mass) = (vec![0.0; pattern.len()], vec![0.0; pattern.len()]);
    form.iteration_matrix(state, &qdd, tensions, 0.0, 1.0, &mut stiff);
    form.iteration_matrix(state, &qdd, tensions, 0.0, 0.0, &mut mass);
    let (mut k, mut m) = (Mat::<f64>::zeros(n, n), Mat::<f64>::zeros(n, n));
    for (e, &(row, col)) in pattern.iter().enumerate() {
        k[(row, col)] += stiff[e] - mass[e];
        m[(row, col)] += mass[e];
    }
    (k, m)
}

/// How an eigenvector v of the mass-scaled stiffness becomes the physical shape u (K u = ω² M u,
/// uᵀ M u = 1): u = M^(−1/2) v for lumped masses, u = L⁻ᵀ v for consistent ones (M = L Lᵀ).
enum Shapes {
    Lumped(Vec<f64>),
    Consistent(Mat<f64>),
}

impl Shapes {
    /// The shape u over all `n` coordinates (zero on the frozen ones) of `v` over `keep`.
    fn physical(&self, n: usize, keep: &[usize], v: Vec<f64>) -> Vec<f64> {
        let mut u = vec![0.0; n];
        match self {
            Shapes::Lumped(m) => {
                for (row, &i) in keep.iter().enumerate() {
                    u[i] = v[row] / m[i].sqrt();
                }
            }
            Shapes::Consistent(l) => {
                let mut x = Mat::from_fn(keep.len(), 1, |r, _| v[r]);
                faer::linalg::triangular_solve::solve_upper_triangular_in_place(
                    l.transpose(),
                    x.as_mut(),
                    faer::Par::Seq,
                );
                for (row, &i) in keep.iter().enumerate() {
                    u[i] = x[(row, 0)];
                }
            }
        }
        u
    }
}

/// L⁻¹ K L⁻ᵀ over `keep` with M = L Lᵀ (Cholesky: M is positive definite, the kinetic energy of
/// the free coordinates), and L for the shapes.
fn consistent(
    k: &Mat<f64>,
    mass: &Mat<f64>,
    keep: &[usize],
) -> Result<(Mat<f64>, Shapes), AnalysisError> {
    let restrict =
        |a: &Mat<f64>| Mat::from_fn(keep.len(), keep.len(), |r, c| a[(keep[r], keep[c])]);
    let llt = restrict(mass)
        .llt(Side::Lower)
        .map_err(|_| AnalysisError::MassNotPositive)?;
    let l = llt.L().to_owned();
    let solve = |mut x: Mat<f64>| {
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(
            l.as_ref(),
            x.as_mut(),
            faer::Par::Seq,
        );
        x
    };
    // L⁻¹ (L⁻¹ Kᵀ)ᵀ = L⁻¹ K L⁻ᵀ.
    let half = solve(restrict(k).transpose().to_owned());
    let scaled = solve(half.transpose().to_owned());
    Ok((scaled, Shapes::Consistent(l)))
}

/// The modes of `model` at rest in `state` (its velocities zero), the commanded `tensions` [N]
/// as they act in its forces (none on a locked reel).
pub fn rest_modes<M: CableModel<D>, const D: usize>(
    model: &mut M,
    state: &[f64],
    tensions: &[f64],
) -> Result<RestModes, AnalysisError> {
    let layout = model.modal_layout(state);
    let form = model
        .second_order_mut()
        .ok_or(AnalysisError::NoSecondOrder)?;
    let n = form.dofs();
    if n > DENSE_MAX_STATES {
        return Err(AnalysisError::TooLarge {
            states: n,
            limit: DENSE_MAX_STATES,
        });
    }
    let (k, mass) = stiffness_and_mass_matrix(form, state, tensions);
    let keep: Vec<usize> = (0..n).filter(|i| !layout.frozen.contains(i)).collect();
    let lumped = keep
        .iter()
        .all(|&i| keep.iter().all(|&j| i == j || mass[(i, j)] == 0.0));
    let (scaled, shapes) = if lumped {
        let m: Vec<f64> = (0..n).map(|i| mass[(i, i)]).collect();
        let scaled = Mat::from_fn(keep.len(), keep.len(), |r, c| {
            let (i, j) = (keep[r], keep[c]);
            k[(i, j)] / (m[i] * m[j]).sqrt()
        });
        (scaled, Shapes::Lumped(m))
    } else {
        consistent(&k, &mass, &keep)?
    };
    let mut largest = 0.0f64;
    let mut asymmetry = 0.0f64;
    for r in 0..keep.len() {
        for c in 0..keep.len() {
            largest = largest.max(scaled[(r, c)].abs());
            asymmetry = asymmetry.max((scaled[(r, c)] - scaled[(c, r)]).abs());
        }
    }
    let symmetric = Mat::from_fn(keep.len(), keep.len(), |r, c| {
        0.5 * (scaled[(r, c)] + scaled[(c, r)])
    });
    let evd = symmetric
        .self_adjoint_eigen(Side::Lower)
        .map_err(AnalysisError::Eigen)?;
    let (values, vectors) = (evd.S().column_vector(), evd.U());
    let pairs = (0..keep.len()).map(|e| {
        let shape: Vec<f64> = (0..keep.len()).map(|row| vectors[(row, e)]).collect();
        (values[e], shapes.physical(n, &keep, shape))
    });
    let (modes, effector_motion) = named(&layout, pairs);
    Ok(RestModes {
        modes,
        effector_motion,
        asymmetry: Some(if largest > 0.0 {
            asymmetry / largest
        } else {
            0.0
        }),
    })
}

/// The modes of `pairs` (eigenvalue ω², mass-normalised shape over all coordinates), in the
/// given order, each classified on `layout` and numbered within its kind, and each one's effector
/// motion.
fn named(
    layout: &ModalLayout,
    pairs: impl Iterator<Item = (f64, Vec<f64>)>,
) -> (Vec<ClassifiedMode>, Vec<Vec<f64>>) {
    let effector: Vec<usize> = layout
        .dofs
        .iter()
        .find_map(|dof| match dof {
            Dof::Effector { coordinates, .. } => Some(coordinates.clone()),
            _ => None,
        })
        .unwrap_or_default();
    let mut modes = Vec::new();
    let mut effector_motion = Vec::new();
    let mut counts = std::collections::HashMap::new();
    for (value, shape) in pairs {
        let u: Vec<(f64, f64)> = shape.iter().map(|&x| (x, 0.0)).collect();
        let (kind, purity) = classify(layout, &u);
        effector_motion.push(effector.iter().map(|&k| u[k].0).collect());
        let order = counts.entry(kind).or_insert(0);
        *order += 1;
        modes.push(ClassifiedMode {
            mode: Mode {
                growth: 0.0,
                omega: value.max(0.0).sqrt(),
            },
            kind,
            order: *order,
            purity,
        });
    }
    (modes, effector_motion)
}

/// The `count` modes of `model` at rest in `state` nearest `omega` [rad/s] (numbered within
/// their kinds among those found), at any size: K − ω²M assembled from the model's sparse
/// iteration matrix S(c_q) = M + c_q K at c_q = −1/ω² (S = −(K − ω² M)/ω²), factorised once,
/// and shift-invert Lanczos on B = (K − ω² M)⁻¹ M in the M inner product over the free
/// coordinates, lumped or consistent masses alike (a frozen coordinate's row of S is its mass
/// alone, so a solve leaves it at zero). `steps` Lanczos
/// steps bound the work (each one solve); the pairs' residuals are in `residuals`.
pub fn rest_modes_near<M: CableModel<D>, const D: usize>(
    model: &mut M,
    state: &[f64],
    tensions: &[f64],
    (omega, count, steps): (f64, usize, usize),
) -> Result<(RestModes, Vec<f64>), AnalysisError> {
    let layout = model.modal_layout(state);
    let form = model
        .second_order_mut()
        .ok_or(AnalysisError::NoSecondOrder)?;
    let n = form.dofs();
    let pattern = form.iteration_pattern();
    let qdd = vec![0.0; n];
    let shift = omega * omega;
    let (mut shifted, mut mass) = (vec![0.0; pattern.len()], vec![0.0; pattern.len()]);
    form.iteration_matrix(state, &qdd, tensions, 0.0, -1.0 / shift, &mut shifted);
    form.iteration_matrix(state, &qdd, tensions, 0.0, 0.0, &mut mass);
    let keep: Vec<usize> = (0..n).filter(|i| !layout.frozen.contains(i)).collect();
    let sparse = |e: cdpr_numerics::sparse::SparseError| AnalysisError::Sparse(e.to_string());
    let mut lu = IterationMatrix::new(n, &pattern).map_err(sparse)?;
    lu.factorise(&shifted).map_err(sparse)?;
    // M over the free coordinates, entry by entry (local row, local col, value).
    let local: Vec<Option<usize>> = (0..n).map(|i| keep.binary_search(&i).ok()).collect();
    let free_mass: Vec<(usize, usize, f64)> = pattern
        .iter()
        .zip(&mass)
        .filter_map(|(&(row, col), &v)| Some((local[row]?, local[col]?, v)))
        .collect();
    let product = |v: &[f64], out: &mut [f64]| {
        out.fill(0.0);
        for &(r, c, value) in &free_mass {
            out[r] += value * v[c];
        }
    };
    // B y = (K − ω² M)⁻¹ M y, and (K − ω² M)⁻¹ = −S⁻¹/ω².
    let (mut rhs, mut my) = (vec![0.0; n], vec![0.0; keep.len()]);
    let solve = |y: &[f64], out: &mut [f64]| {
        product(y, &mut my);
        rhs.fill(0.0);
        for (row, &i) in keep.iter().enumerate() {
            rhs[i] = my[row];
        }
        lu.solve_in_place(&mut rhs);
        for (row, &i) in keep.iter().enumerate() {
            out[row] = -rhs[i] / shift;
        }
    };
    let pairs =
        cdpr_numerics::lanczos::nearest_with_mass(keep.len(), shift, count, steps, solve, product)
            .map_err(|e| AnalysisError::Sparse(e.to_string()))?;
    let residuals = pairs.iter().map(|p| p.residual).collect();
    let shapes = pairs.into_iter().map(|p| {
        let mut u = vec![0.0; n];
        for (row, &i) in keep.iter().enumerate() {
            u[i] = p.vector[row];
        }
        (p.value, u)
    });
    let (modes, effector_motion) = named(&layout, shapes);
    Ok((
        RestModes {
            modes,
            effector_motion,
            asymmetry: None,
        },
        residuals,
    ))
}
