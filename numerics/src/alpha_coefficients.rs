//! The coefficients of generalised-α for a spectral radius ρ∞ (Chung & Hulbert's optimal set,
//! J. Appl. Mech. 60 (1993)), what they make of an undamped mode, and the constant of the
//! positions' local error that the error control estimates.

/// The method's coefficients for ρ∞.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlphaCoefficients {
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub gamma: f64,
    pub beta: f64,
}

impl AlphaCoefficients {
    /// Chung–Hulbert's optimal set for spectral radius ρ∞.
    pub fn new(rho_inf: f64) -> Self {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        Self {
            alpha_m,
            alpha_f,
            gamma,
            beta,
        }
    }

    /// How the method renders an undamped mode ω [rad/s] at step h [s]: the principal root λ of
    /// its one-step amplification matrix for q'' = −ω² q gives the discrete frequency arg(λ)/h
    /// [rad/s] and growth ln|λ|/h [1/s] (< 0: numerical damping). E.g. ρ∞ = 0.9, h = 1e-4 s maps
    /// the lumped model's 5649 rad/s axial mode to 5503.9 rad/s (MODELS.md FE.9.3: "period-
    /// elongated"), while the 20.37 rad/s vertical mode keeps its frequency to 1e-5 rad/s.
    pub fn discrete_mode(&self, omega: f64, h: f64) -> (f64, f64) {
        // State (q, h q', h² q'', h² a) of one step for unit mass and stiffness ω², by columns.
        let w2 = (omega * h).powi(2);
        let (am, af, g, b) = (self.alpha_m, self.alpha_f, self.gamma, self.beta);
        let k = (1.0 - af) / (1.0 - am);
        let mut amplification = nalgebra::Matrix4::<f64>::zeros();
        for j in 0..4 {
            let mut x = [0.0; 4];
            x[j] = 1.0;
            let [q, v, d, a] = x;
            let history = (af * d - am * a) / (1.0 - am);
            let predicted = q + v + (0.5 - b) * a + b * history;
            // Solve q''_{n+1} + ω² q_{n+1} = 0 with q_{n+1} = predicted + β k q''_{n+1}.
            let d1 = -w2 * predicted / (1.0 + w2 * b * k);
            let a1 = k * d1 + history;
            let column = [predicted + b * k * d1, v + (1.0 - g) * a + g * a1, d1, a1];
            for (i, c) in column.into_iter().enumerate() {
                amplification[(i, j)] = c;
            }
        }
        let principal = amplification
            .complex_eigenvalues()
            .iter()
            .copied()
            .max_by(|x, y| x.im.total_cmp(&y.im))
            .unwrap_or_default();
        (
            principal.im.atan2(principal.re) / h,
            principal.norm().ln() / h,
        )
    }

    /// C of the positions' local error C h³ q''' + O(h⁴) (see [`crate::alpha_error`]).
    pub fn error_constant(&self) -> f64 {
        0.5 * self.gamma - self.beta - 1.0 / 12.0
    }

    /// (γ', β') = ∂(q', q)_{n+1}/∂q''_{n+1} for step h.
    pub fn derivatives(&self, h: f64) -> (f64, f64) {
        let k = (1.0 - self.alpha_f) / (1.0 - self.alpha_m);
        (self.gamma * h * k, self.beta * h * h * k)
    }
}
