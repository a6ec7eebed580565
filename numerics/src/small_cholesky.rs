//! Cholesky factorisation of a small symmetric positive-definite matrix held in fixed arrays
//! (the FE model's border of at most four unknowns, a robot's D × D Gram matrix): at these
//! sizes a general factorisation's views and allocations cost more than the arithmetic.

/// Overwrites the leading `n` × `n` lower triangle of `a` with L of A = L Lᵀ (the upper
/// triangle is left as it was). False, with `a` partly overwritten, when a pivot l_jj² is NaN or
/// at most `floor` (0 for a plain positive-definiteness test; a rank test passes a small share
/// of the trace).
///
/// # Examples
///
/// ```
/// use cdpr_numerics::small_cholesky::factor;
///
/// let mut a = [[4.0, 2.0], [2.0, 5.0]];
/// assert!(factor(&mut a, 2, 0.0));
/// assert_eq!([a[0][0], a[1][0], a[1][1]], [2.0, 1.0, 2.0]);
/// assert!(!factor(&mut [[1.0, 1.0], [1.0, 1.0]], 2, 1e-12));
/// ```
pub fn factor<const N: usize>(a: &mut [[f64; N]; N], n: usize, floor: f64) -> bool {
    for j in 0..n {
        let mut pivot = a[j][j];
        for v in &a[j][..j] {
            pivot -= v * v;
        }
        if pivot.is_nan() || pivot <= floor {
            return false;
        }
        let root = pivot.sqrt();
        a[j][j] = root;
        let l_j = a[j];
        for row_i in &mut a[j + 1..n] {
            let mut v = row_i[j];
            for (a_ik, l_jk) in row_i[..j].iter().zip(&l_j[..j]) {
                v -= a_ik * l_jk;
            }
            row_i[j] = v / root;
        }
    }
    true
}
