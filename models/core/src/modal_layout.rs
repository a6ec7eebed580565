//! What the modal analysis needs to know about a model's coordinates: which is the effector, which
//! a free cable node (and along which tangent its cable runs there), which moves material along
//! the cable (lumped stored nodes, FE lengths l_i and ρ_i), and which a constraint holds fixed
//! (lumped stored nodes' z, MODELS.md §4 eq. 6). Each model states it
//! ([`crate::model::CableModel::modal_layout`]); the analysis classifies modes from it without
//! knowing any model. Coordinates are listed per axis, x first and z last, in any dimension.

/// What a group of position coordinates is, for the classification (indices into the model's
/// position coordinates, i.e. the first half of its state).
#[derive(Debug, Clone, PartialEq)]
pub enum Dof {
    /// The effector's coordinates (one per axis, the vertical last), mass M [kg].
    Effector { coordinates: Vec<usize>, mass: f64 },
    /// A free cable node: its displacement along `tangent` (a unit vector, one component per
    /// axis) is axial, across it transverse.
    Node {
        cable: usize,
        coordinates: Vec<usize>,
        tangent: Vec<f64>,
        mass: f64,
    },
    /// A coordinate that moves material along the cable (lumped stored node's x, FE l_i and ρ_i),
    /// with the mass that moves with it [kg].
    Axial {
        cable: usize,
        index: usize,
        mass: f64,
    },
}

/// A model's coordinates at one state, as the modal classification needs them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ModalLayout {
    pub dofs: Vec<Dof>,
    /// Position coordinates held fixed by a constraint at this state (their velocities are
    /// frozen too).
    pub frozen: Vec<usize>,
}
