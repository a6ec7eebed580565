//! # cdpr-lumped: lumped mass-spring cables over point pulleys (paper §2.2, MODELS.md §4)
//!
//! Each cable is N point masses P_0 … P_{N−1} (each m = μ l0, l0 = L0/N) joined by N tension-only
//! springs of stiffness k0 = EA/l0; spring j joins P_j and P_{j+1}, and P_N is the effector, shared
//! by both cables. P_0 is the reel end, pulled by the commanded tension along e_out. Nodes beyond
//! the pulley are *stored* (rolled on the reel): they slide on z = 0. The spring that straddles the
//! pulley measures its length along the cable path over the pulley (eq. 4). Nodes pass the pulley
//! as located events ([`pulley`]); no node ever changes mass, so the cable mass is conserved exactly.
//!
//! State: positions then velocities, each ordered cable 1 nodes 0…N−1, cable 2 nodes 0…N−1,
//! effector; every node has (x, z), so the state has 4(2N + 1) components (stored nodes keep
//! z = ż = 0). The number of stored nodes r_i per cable is the model's discrete mode.

mod pulley;
mod statics;

use cdpr_core::model::{CableModel, Effector, Energy, Equilibrium, ModelError, ModelEvent};
use cdpr_core::scenario::Scenario;
use nalgebra::Vector2;

pub use pulley::PULLEY_OFFSET;

/// The two-cable robot with lumped mass-spring cables.
#[derive(Debug, Clone, PartialEq)]
pub struct Lumped {
    /// Pulley distance d [m]: A1 = (0, 0), A2 = (d, 0).
    pub anchor_distance: f64,
    /// Effector mass M [kg].
    pub effector_mass: f64,
    /// Gravity g [m/s²] along −z.
    pub gravity: f64,
    /// Elements (springs, and masses) per cable N.
    pub elements: usize,
    /// Unstrained spring length l0 = L0/N [m].
    pub segment: f64,
    /// Node mass m = μ l0 [kg].
    pub node_mass: f64,
    /// Spring stiffness k0 = EA/l0 [N/m].
    pub stiffness: f64,
    /// Kelvin–Voigt coefficient per unit length rate, C/l0 [N s/m] (0: undamped, the paper's run).
    pub damping: f64,
    /// Number of stored nodes r_i of each cable (nodes 0 … r_i − 1 lie beyond the pulley).
    stored: [usize; 2],
}

/// Direction from each pulley towards its reel, e_out,i (MODELS.md §4).
pub const E_OUT: [f64; 2] = [-1.0, 1.0];

impl Lumped {
    /// The model with the scenario's robot, cable and element count; r_i are set by
    /// [`CableModel::equilibrium`].
    pub fn new(scenario: &Scenario) -> Result<Self, ModelError> {
        let n = scenario.model.elements();
        if n < 3 {
            return Err(ModelError::Parameter {
                name: "model.elements",
                value: n as f64,
                allowed: "≥ 3 for the lumped model (a reel end, a straddling spring, a free node)"
                    .into(),
            });
        }
        let cable = &scenario.cable;
        let segment = cable.modelled_length / n as f64;
        Ok(Self {
            anchor_distance: scenario.robot.anchor_distance,
            effector_mass: scenario.robot.effector_mass,
            gravity: scenario.robot.gravity,
            elements: n,
            segment,
            node_mass: cable.mass_per_length() * segment,
            stiffness: cable.axial_stiffness() / segment,
            damping: cable.axial_damping / segment,
            stored: [n / 2, n / 2],
        })
    }

    /// Stored nodes per cable, r_i.
    pub fn stored(&self) -> [usize; 2] {
        self.stored
    }

    /// Sets the stored-node counts (the discrete mode), e.g. for a hand-made state.
    pub fn set_stored(&mut self, stored: [usize; 2]) {
        self.stored = stored;
    }

    /// Pulley point A_i [m].
    pub fn pulley(&self, cable: usize) -> Vector2<f64> {
        Vector2::new(
            if cable == 0 {
                0.0
            } else {
                self.anchor_distance
            },
            0.0,
        )
    }

    /// Number of position coordinates, 2(2N + 1).
    pub fn positions_len(&self) -> usize {
        2 * (2 * self.elements + 1)
    }

    /// Index of the x coordinate of node `j` of `cable` (j = N is the effector).
    pub fn index(&self, cable: usize, j: usize) -> usize {
        if j == self.elements {
            4 * self.elements
        } else {
            2 * (cable * self.elements + j)
        }
    }

    /// Mass of node `j` (the effector at j = N) [kg].
    fn mass(&self, j: usize) -> f64 {
        if j == self.elements {
            self.effector_mass
        } else {
            self.node_mass
        }
    }

    fn point(&self, y: &[f64], i: usize) -> Vector2<f64> {
        Vector2::new(y[i], y[i + 1])
    }

    /// Spring law: T = k0 (λ − l0) + (C/l0) λ̇ while taut, else 0; a damping part that would push
    /// is clipped so the spring never pushes (MODELS.md §4).
    #[inline]
    fn spring_tension(&self, length: f64, rate: f64) -> f64 {
        let stretch = length - self.segment;
        if stretch <= 0.0 {
            return 0.0;
        }
        (self.stiffness * stretch + self.damping * rate).max(0.0)
    }

    /// Length λ_j of spring j of `cable` along the cable path, its rate λ̇_j, and the unit vectors
    /// along which it pulls its two end nodes. The straddling spring j = r − 1 runs over the pulley
    /// (eq. 4): λ = |P_{r−1} A| + |A P_r|, pulling both ends towards A.
    #[inline]
    fn spring(&self, y: &[f64], cable: usize, j: usize) -> (f64, f64, Vector2<f64>, Vector2<f64>) {
        let np = self.positions_len();
        let (ia, ib) = (self.index(cable, j), self.index(cable, j + 1));
        let (a, b) = (self.point(y, ia), self.point(y, ib));
        let (va, vb) = (self.point(y, np + ia), self.point(y, np + ib));
        if j + 1 == self.stored[cable] {
            let pulley = self.pulley(cable);
            let (da, db) = (pulley - a, pulley - b);
            let (la, lb) = (da.norm(), db.norm());
            let (ua, ub) = (da / la, db / lb);
            (la + lb, -ua.dot(&va) - ub.dot(&vb), ua, ub)
        } else {
            let d = b - a;
            let l = d.norm();
            let u = d / l;
            (l, u.dot(&(vb - va)), u, -u)
        }
    }

    /// Net forces on every position coordinate [N] (gravity included; stored nodes' vertical
    /// forces are constraint-reacted and zeroed), for the commanded tensions.
    fn accumulate_forces(&self, y: &[f64], tensions: [f64; 2], forces: &mut [f64]) {
        let n = self.elements;
        forces.fill(0.0);
        for cable in 0..2 {
            let i0 = self.index(cable, 0);
            forces[i0] += tensions[cable] * E_OUT[cable];
            for j in 0..n {
                let (length, rate, ua, ub) = self.spring(y, cable, j);
                let t = self.spring_tension(length, rate);
                let (ia, ib) = (self.index(cable, j), self.index(cable, j + 1));
                forces[ia] += t * ua.x;
                forces[ia + 1] += t * ua.y;
                forces[ib] += t * ub.x;
                forces[ib + 1] += t * ub.y;
            }
        }
        for cable in 0..2 {
            for j in 0..n {
                let i = self.index(cable, j);
                if j < self.stored[cable] {
                    forces[i + 1] = 0.0;
                } else {
                    forces[i + 1] -= self.node_mass * self.gravity;
                }
            }
        }
        forces[4 * n + 1] -= self.effector_mass * self.gravity;
    }

    /// Tension of spring j of `cable` [N].
    pub fn spring_force(&self, y: &[f64], cable: usize, j: usize) -> f64 {
        let (length, rate, _, _) = self.spring(y, cable, j);
        self.spring_tension(length, rate)
    }

    /// Unstrained length of cable between the pulley and the effector [m]: the free springs plus
    /// the free-side share of the straddling spring (uniform strain along it).
    pub fn free_length(&self, y: &[f64], cable: usize) -> f64 {
        let r = self.stored[cable];
        let free_springs = (self.elements - r) as f64 * self.segment;
        if r == 0 {
            return free_springs;
        }
        let (length, _, _, _) = self.spring(y, cable, r - 1);
        let ib = self.index(cable, r);
        let free_part = (self.pulley(cable) - self.point(y, ib)).norm();
        free_springs + self.segment * free_part / length
    }

    /// Total mass of the cables [kg] (constant: every node keeps its mass).
    pub fn cable_mass(&self) -> f64 {
        2.0 * self.elements as f64 * self.node_mass
    }
}

impl CableModel for Lumped {
    fn name(&self) -> &'static str {
        "lumped"
    }

    fn state_len(&self) -> usize {
        2 * self.positions_len()
    }

    fn equilibrium(
        &mut self,
        effector_x: f64,
        tension_sum: f64,
    ) -> Result<Equilibrium, ModelError> {
        statics::equilibrium(self, effector_x, tension_sum)
    }

    fn rhs(&mut self, _t: f64, y: &[f64], tensions: [f64; 2], rate: &mut [f64]) {
        let np = self.positions_len();
        let (dq, dv) = rate.split_at_mut(np);
        dq.copy_from_slice(&y[np..]);
        self.accumulate_forces(y, tensions, dv);
        for cable in 0..2 {
            for j in 0..self.elements {
                let i = self.index(cable, j);
                dv[i] /= self.node_mass;
                dv[i + 1] /= self.node_mass;
                if j < self.stored[cable] {
                    dq[i + 1] = 0.0;
                }
            }
        }
        let ip = 4 * self.elements;
        dv[ip] /= self.effector_mass;
        dv[ip + 1] /= self.effector_mass;
    }

    fn effector(&self, y: &[f64]) -> Effector {
        let (ip, np) = (4 * self.elements, self.positions_len());
        Effector {
            position: self.point(y, ip),
            velocity: self.point(y, np + ip),
        }
    }

    /// The reel end P_0 moving along e_out takes cable in.
    fn reel_speeds(&self, y: &[f64]) -> [f64; 2] {
        let np = self.positions_len();
        [0, 1].map(|c| y[np + self.index(c, 0)] * E_OUT[c])
    }

    fn energy(&self, y: &[f64]) -> Energy {
        let np = self.positions_len();
        let mut e = Energy::default();
        for j in 0..=self.elements {
            for cable in 0..2 {
                if j == self.elements && cable == 1 {
                    break; // the effector is shared
                }
                let i = self.index(cable, j);
                let m = self.mass(j);
                e.kinetic += 0.5 * m * (y[np + i] * y[np + i] + y[np + i + 1] * y[np + i + 1]);
                e.gravity += m * self.gravity * y[i + 1];
            }
        }
        for cable in 0..2 {
            for j in 0..self.elements {
                let (length, _, _, _) = self.spring(y, cable, j);
                let stretch = (length - self.segment).max(0.0);
                e.elastic += 0.5 * self.stiffness * stretch * stretch;
            }
        }
        e
    }

    /// Power of the damping forces: Σ (T − k0 (λ − l0)⁺) λ̇ ≥ 0 (clipping included).
    fn dissipation(&self, y: &[f64]) -> f64 {
        if self.damping == 0.0 {
            return 0.0;
        }
        let mut d = 0.0;
        for cable in 0..2 {
            for j in 0..self.elements {
                let (length, rate, _, _) = self.spring(y, cable, j);
                let elastic = self.stiffness * (length - self.segment).max(0.0);
                d += (self.spring_tension(length, rate) - elastic) * rate;
            }
        }
        d
    }

    fn event_count(&self) -> usize {
        pulley::EVENT_COUNT
    }

    fn event_functions(&self, y: &[f64], out: &mut [f64]) {
        pulley::event_functions(self, y, out);
    }

    fn apply_event(
        &mut self,
        index: usize,
        t: f64,
        y: &mut [f64],
    ) -> Result<ModelEvent, ModelError> {
        pulley::apply_event(self, index, t, y)
    }

    fn channel_names(&self) -> Vec<String> {
        [
            "T_effector_1",
            "T_effector_2",
            "T_pulley_1",
            "T_pulley_2",
            "l_free_1",
            "l_free_2",
            "stored_1",
            "stored_2",
        ]
        .map(String::from)
        .to_vec()
    }

    /// Spring tensions at the effector and over the pulley [N], free unstrained lengths [m] and
    /// stored-node counts.
    fn channels(&self, y: &[f64], _tensions: [f64; 2], out: &mut [f64]) {
        let n = self.elements;
        let straddle = |c: usize| {
            let r = self.stored[c];
            if r == 0 {
                f64::NAN
            } else {
                self.spring_force(y, c, r - 1)
            }
        };
        out.copy_from_slice(&[
            self.spring_force(y, 0, n - 1),
            self.spring_force(y, 1, n - 1),
            straddle(0),
            straddle(1),
            self.free_length(y, 0),
            self.free_length(y, 1),
            self.stored[0] as f64,
            self.stored[1] as f64,
        ]);
    }
}
