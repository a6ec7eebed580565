//! # cdpr-numerics
//!
//! The numerical methods of cdpr-bench, knowing nothing of robots: the ODE interfaces
//! ([`ode`]), Dormand–Prince 5(4) ([`dopri5`]), generalised-α ([`generalized_alpha`]), the
//! refactorising sparse LU of its iteration matrix ([`sparse`]), Newton's method for square
//! nonlinear systems ([`newton`]), finite differences ([`differences`]), eigen-analysis
//! ([`eigen`]), the Riccati equation of LQR design ([`riccati`]) and lane norms ([`norms`]).
//! faer lives here and nowhere else in the library.
//!
//! # Examples
//!
//! The harmonic oscillator y'' = −y over one period with DOPRI5:
//!
//! ```
//! use cdpr_numerics::{Dopri5, Dopri5Options, OdeSystem};
//!
//! struct Oscillator;
//! impl OdeSystem for Oscillator {
//!     fn dimension(&self) -> usize { 2 }
//!     fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
//!         dy[0] = y[1];
//!         dy[1] = -y[0];
//!     }
//! }
//!
//! let period = 2.0 * std::f64::consts::PI;
//! let opts = Dopri5Options { rtol: 1e-10, atol: 1e-12, ..Default::default() };
//! let mut solver = Dopri5::new(2, opts);
//! solver.start(&mut Oscillator, 0.0, &[1.0, 0.0], period).unwrap();
//! while solver.time() < period {
//!     solver.step(&mut Oscillator, period).unwrap();
//! }
//! assert!((solver.state()[0] - 1.0).abs() < 1e-8);
//! ```

pub mod alpha_coefficients;
pub mod alpha_error;
pub mod differences;
pub mod dopri5;
pub mod eigen;
pub mod generalized_alpha;
pub mod lanczos;
pub mod matrix_parts;
pub mod newton;
pub mod norms;
pub mod ode;
pub mod riccati;
pub mod small_cholesky;
pub mod sparse;

pub use alpha_error::{ErrorControl, ErrorPositions};
pub use dopri5::{Dopri5, Dopri5Options};
pub use generalized_alpha::{AlphaCoefficients, GeneralizedAlpha, GeneralizedAlphaOptions};
pub use matrix_parts::MatrixParts;
pub use ode::{IntegratorError, MatrixCost, OdeSystem, SecondOrderSystem, SolverStats, Stepper};
