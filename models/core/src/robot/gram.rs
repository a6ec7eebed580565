//! The Gram matrix W_F W_Fᵀ = Σ_{i free} u_i u_iᵀ of a set of cables and its inverse, which the
//! distributions solve with (one per call at D ≤ 3, so its cost is a share of a spatial RHS).

use super::{Matrix, StructureMatrix};
use cdpr_numerics::small_cholesky;

/// Σ_{i free} u_i u_iᵀ, inverted; None when the free cables span fewer than D directions.
pub(super) fn gram_inverse<const D: usize>(
    w: &StructureMatrix<D>,
    free: &[bool],
) -> Option<Matrix<D>> {
    let mut g = Matrix::<D>::zeros();
    for (u, _) in w.columns().iter().zip(free).filter(|(_, f)| **f) {
        g += u * u.transpose();
    }
    // Rank test: every Cholesky pivot above 1e-12 of the trace (unit columns: the free count).
    let floor = 1e-12 * g.trace().max(1.0);
    spd_inverse(&g, floor)
}

/// G⁻¹ = L⁻ᵀ L⁻¹ of a symmetric D × D matrix by its Cholesky factor G = L Lᵀ, on fixed arrays (a
/// general factorisation's column views cost more than the arithmetic at D ≤ 3, a quarter of a
/// spatial RHS). None when a pivot l_jj² is at most `floor`.
fn spd_inverse<const D: usize>(g: &Matrix<D>, floor: f64) -> Option<Matrix<D>> {
    let mut l: [[f64; D]; D] = std::array::from_fn(|i| std::array::from_fn(|j| g[(i, j)]));
    if !small_cholesky::factor(&mut l, D, floor) {
        return None;
    }
    // L⁻¹, lower triangular, column by column.
    let mut l_inv = [[0.0; D]; D];
    for j in 0..D {
        l_inv[j][j] = 1.0 / l[j][j];
        for i in j + 1..D {
            let mut v = 0.0;
            for k in j..i {
                v -= l[i][k] * l_inv[k][j];
            }
            l_inv[i][j] = v / l[i][i];
        }
    }
    // (L⁻ᵀ L⁻¹)_rc = Σ_{k ≥ max(r, c)} (L⁻¹)_kr (L⁻¹)_kc: symmetric by construction.
    Some(Matrix::<D>::from_fn(|r, c| {
        (r.max(c)..D).map(|k| l_inv[k][r] * l_inv[k][c]).sum()
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    use crate::robot::Vector;

    fn unit(v: [f64; 3]) -> Vector<3> {
        Vector::<3>::from(v).normalize()
    }

    proptest! {
        /// The written-out Cholesky inverse against nalgebra's factorisation of the same Gram
        /// matrix Σ u uᵀ of 3 to 8 cable directions: equal to 1e-12 of the inverse's largest
        /// entry (both are backward stable; the directions are kept ≥ 0.1 rad from coplanar so
        /// the condition number stays below ~1e3), and G G⁻¹ = I to the same.
        #[test]
        fn spd_inverse_matches_a_general_cholesky(
            directions in proptest::collection::vec(
                (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0), 3..=8),
        ) {
            let columns: Vec<Vector<3>> = directions
                .iter()
                .filter(|(x, y, z)| x * x + y * y + z * z > 0.01)
                .map(|&(x, y, z)| unit([x, y, z]))
                .collect();
            let mut g = Matrix::<3>::zeros();
            for u in &columns {
                g += u * u.transpose();
            }
            let Some(reference) = g.cholesky().map(|c| c.inverse()) else {
                return Ok(());
            };
            prop_assume!(reference.amax() < 1e3);
            let inverse = spd_inverse(&g, 1e-12 * g.trace().max(1.0)).unwrap();
            let scale = reference.amax();
            prop_assert!((inverse - reference).amax() <= 1e-12 * scale);
            prop_assert!((g * inverse - Matrix::<3>::identity()).amax() <= 1e-12 * scale);
        }
    }

    /// Cables in one plane cannot hold the third axis: the Gram matrix is singular and the rank
    /// test refuses it rather than returning a huge inverse.
    #[test]
    fn coplanar_cables_have_no_inverse() {
        let mut g = Matrix::<3>::zeros();
        for v in [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 2.0, 0.0],
        ] {
            let u = unit(v);
            g += u * u.transpose();
        }
        assert!(spd_inverse(&g, 1e-12 * g.trace()).is_none());
    }
}
