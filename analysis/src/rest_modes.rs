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
//! order. The dense self-adjoint eigen-solve costs O(n³): it is bounded by
//! [`crate::linearise::DENSE_MAX_STATES`].

use crate::AnalysisError;
use crate::linearise::DENSE_MAX_STATES;
use crate::modes::{ClassifiedMode, classify};
use cdpr_core::modal_layout::Dof;
use cdpr_core::model::CableModel;
use cdpr_numerics::eigen::Mode;
use faer::{Mat, Side};

/// The named modes of a robot at rest.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RestModes {
    /// Every mode, by ascending frequency, numbered within its kind.
    pub modes: Vec<ClassifiedMode>,
    /// Per mode, the effector's displacement in its shape (mass-normalised, one component per
    /// axis; empty without an effector in the layout).
    pub effector_motion: Vec<Vec<f64>>,
    /// max |K − Kᵀ| / max |K| of the mass-scaled stiffness (round-off for conservative forces).
    pub asymmetry: f64,
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
    let pattern = form.iteration_pattern();
    let qdd = vec![0.0; n];
    let (mut stiff, mut mass) = (vec![0.0; pattern.len()], vec![0.0; pattern.len()]);
    form.iteration_matrix(state, &qdd, tensions, 0.0, 1.0, &mut stiff);
    form.iteration_matrix(state, &qdd, tensions, 0.0, 0.0, &mut mass);
    let mut k = Mat::<f64>::zeros(n, n);
    let mut m = vec![0.0; n];
    for (e, &(row, col)) in pattern.iter().enumerate() {
        k[(row, col)] += stiff[e] - mass[e];
        if row == col {
            m[row] += mass[e];
        }
    }
    let keep: Vec<usize> = (0..n).filter(|i| !layout.frozen.contains(i)).collect();
    let scaled = Mat::from_fn(keep.len(), keep.len(), |r, c| {
        let (i, j) = (keep[r], keep[c]);
        k[(i, j)] / (m[i] * m[j]).sqrt()
    });
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
    let effector: Vec<usize> = layout
        .dofs
        .iter()
        .find_map(|dof| match dof {
            Dof::Effector { coordinates, .. } => Some(coordinates.clone()),
            _ => None,
        })
        .unwrap_or_default();
    let mut effector_motion = Vec::with_capacity(keep.len());
    let mut modes = Vec::with_capacity(keep.len());
    let mut counts = std::collections::HashMap::new();
    let mut u = vec![(0.0, 0.0); n];
    for e in 0..keep.len() {
        for (row, &i) in keep.iter().enumerate() {
            u[i] = (vectors[(row, e)] / m[i].sqrt(), 0.0);
        }
        let (kind, purity) = classify(&layout, &u);
        effector_motion.push(effector.iter().map(|&k| u[k].0).collect());
        let order = counts.entry(kind).or_insert(0);
        *order += 1;
        modes.push(ClassifiedMode {
            mode: Mode {
                growth: 0.0,
                omega: values[e].max(0.0).sqrt(),
            },
            kind,
            order: *order,
            purity,
        });
    }
    Ok(RestModes {
        modes,
        effector_motion,
        asymmetry: if largest > 0.0 {
            asymmetry / largest
        } else {
            0.0
        },
    })
}
