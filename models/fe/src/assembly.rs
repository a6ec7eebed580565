//! The model's assembly (FE.5.3): M(q) and F(q, q', T) element by element into the block system
//! of FE.5.5 and its O(N) solve, the right-hand side's whole work; and the dense M and F of a
//! state for tests and analyses.

use crate::element::{self, Chord};
use crate::{Fe, TOWARD_REEL};
use nalgebra::Vector2;

impl Fe {
    /// Assembles M(q) and F(q, q', T) (FE.5.3) into the block system of FE.5.5.
    pub(crate) fn assemble(&mut self, y: &[f64], tensions: [f64; 2]) {
        let mut sys = std::mem::take(&mut self.system);
        sys.clear();
        let n = self.elements;
        let mat = self.material;
        let nn = self.chain_nodes();
        element::chords(
            &y[..nn],
            &y[nn..2 * nn],
            &mut self.chord_length,
            &mut self.chord_inv_length,
        );
        for cable in 0..2 {
            let lb = sys.l_index[cable];
            let col = 2 + 2 * cable;
            for (e, (s, k)) in (1..=n).zip(self.span(y, cable).zip(&self.coefficients)) {
                let ja = self.chain_index(cable, e - 1);
                let jb = self.chain_index(cable, e).expect("node e ≥ 1 is free");
                // An element between chain nodes j, j + 1 has chord j of the pass; element 1
                // starts at the pulley, which is not a chain node.
                let chord = match ja {
                    Some(ja) => self.chord_at(ja.min(jb)),
                    None => Chord::of(&s),
                };
                let t = element::terms_at_chord(&mat, k, &s, self.axial_damping, chord);
                if let Some(ja) = ja {
                    sys.diag[ja] += t.m_diag;
                    sys.off[ja.min(jb)] += t.m_off;
                    let r = &mut sys.rhs[ja];
                    r[0] += t.fa.x;
                    r[1] += t.fa.y;
                    r[col] += t.m_al.x;
                    r[col + 1] += t.m_al.y;
                }
                sys.diag[jb] += t.m_diag;
                let r = &mut sys.rhs[jb];
                r[0] += t.fb.x;
                r[1] += t.fb.y;
                r[col] += t.m_bl.x;
                r[col + 1] += t.m_bl.y;
                sys.d[lb][lb] += t.m_ll;
                sys.f_border[lb] += t.fl;
            }
            let li = self.l_index(cable);
            match self.stored_element(y, cable) {
                Some(s) => {
                    // Row ρ: the projection of the kernel's R-node terms on e_out (R = A + ρ e_out),
                    // plus the commanded tension pulling R away from the pulley (FE.5.3).
                    let t = element::terms_damped(
                        &mat,
                        &self.stored_coefficients,
                        &s,
                        self.axial_damping,
                    );
                    let e_out = Vector2::new(TOWARD_REEL[cable], 0.0);
                    let rb = lb + 1;
                    sys.d[rb][rb] += t.m_diag;
                    let m_rho_l = t.m_al.dot(&e_out);
                    sys.d[rb][lb] += m_rho_l;
                    sys.d[lb][rb] += m_rho_l;
                    sys.d[lb][lb] += t.m_ll;
                    sys.f_border[rb] += t.fa.dot(&e_out) + tensions[cable];
                    sys.f_border[lb] += t.fl;
                }
                None => {
                    // Rigid stored cable: T_s = ½ μ (L0 − l) l'², virtual work −T_i δl_i.
                    let np = self.positions_len();
                    let ld = y[np + li];
                    sys.d[lb][lb] += mat.mu * (self.modelled_length - y[li]);
                    sys.f_border[lb] += 0.5 * mat.mu * ld * ld - tensions[cable];
                }
            }
        }
        let p = self.effector_index();
        sys.diag[p] += self.effector_mass;
        sys.rhs[p][1] -= self.effector_mass * mat.gravity;
        self.system = sys;
    }

    /// Generalised accelerations q'' = M⁻¹F for state `y` and tensions [T1, T2] into `qdd`
    /// (length n) [m/s²]; false if M is not positive definite (the state left the model's
    /// domain, FE.9.4).
    pub fn accelerations(&mut self, y: &[f64], tensions: [f64; 2], qdd: &mut [f64]) -> bool {
        self.assemble(y, tensions);
        self.solve_assembled(qdd)
    }

    /// The solve of FE.5.5 on the system just assembled (it consumes the assembly).
    pub(crate) fn solve_assembled(&mut self, qdd: &mut [f64]) -> bool {
        let nn = self.chain_nodes();
        let (ax, rest) = qdd.split_at_mut(nn);
        let (az, border) = rest.split_at_mut(nn);
        self.system.solve(ax, az, border)
    }

    /// Assembles only (for benches): M and F of `y` into the internal system.
    pub fn assemble_only(&mut self, y: &[f64], tensions: [f64; 2]) {
        self.assemble(y, tensions);
    }

    /// The dense mass matrix M(q) (n × n, FE.5.3) of state `y` (allocates; tests and analysis).
    pub fn mass_matrix(&mut self, y: &[f64]) -> nalgebra::DMatrix<f64> {
        self.assemble(y, [0.0, 0.0]);
        let (nn, np) = (self.chain_nodes(), self.positions_len());
        let s = &self.system;
        let mut m = nalgebra::DMatrix::zeros(np, np);
        for axis in 0..2 {
            for j in 0..nn {
                let i = axis * nn + j;
                m[(i, i)] = s.diag[j];
                if j + 1 < nn {
                    m[(i, i + 1)] = s.off[j];
                    m[(i + 1, i)] = s.off[j];
                }
                for cable in 0..2 {
                    let c = s.rhs[j][2 + 2 * cable + axis];
                    let l = 2 * nn + s.l_index[cable];
                    m[(i, l)] = c;
                    m[(l, i)] = c;
                }
            }
        }
        for a in 0..s.border {
            for b in 0..s.border {
                m[(2 * nn + a, 2 * nn + b)] = s.d[a][b];
            }
        }
        m
    }

    /// The generalised forces F(q, q', T) (n, FE.5.2) of state `y` (allocates; tests).
    pub fn force_vector(&mut self, y: &[f64], tensions: [f64; 2]) -> nalgebra::DVector<f64> {
        self.assemble(y, tensions);
        let (nn, np) = (self.chain_nodes(), self.positions_len());
        let s = &self.system;
        let mut f = nalgebra::DVector::zeros(np);
        for j in 0..nn {
            f[j] = s.rhs[j][0];
            f[nn + j] = s.rhs[j][1];
        }
        for b in 0..s.border {
            f[2 * nn + b] = s.f_border[b];
        }
        f
    }
}
