//! The robot's space: D = 2 (the paper's vertical plane, axes x and z) or D = 3 (x, y, z), the
//! last axis vertical, gravity along −z. A planar robot is not embedded in 3-D: its vectors have
//! two components, so its state (and DOPRI5's error norm over it) is the paper's.

/// A vector of the robot's space [m, m/s, N, …].
pub type Vector<const D: usize> = nalgebra::SVector<f64, D>;

/// A D × D matrix of the robot's space (stiffness, the square structure matrix).
pub type Matrix<const D: usize> = nalgebra::SMatrix<f64, D, D>;

/// The index of the vertical axis z (the last).
pub const fn vertical<const D: usize>() -> usize {
    D - 1
}

/// The name of axis `k` of a D-dimensional robot: "x", "z" in the plane; "x", "y", "z" in space.
pub fn axis_name<const D: usize>(k: usize) -> &'static str {
    match (D, k) {
        (_, 0) => "x",
        (3, 1) => "y",
        _ => "z",
    }
}

/// The vertical component of `v` (z).
#[inline]
pub fn height<const D: usize>(v: &Vector<D>) -> f64 {
    v[vertical::<D>()]
}

/// A vector with `value` along the vertical axis and zero elsewhere.
#[inline]
pub fn along_vertical<const D: usize>(value: f64) -> Vector<D> {
    let mut v = Vector::<D>::zeros();
    v[vertical::<D>()] = value;
    v
}
