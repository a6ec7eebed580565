//! The named channels of a run's time series (MODELS.md §7): those every run has, in this order
//! before the model's own, the energy terms after them, and the cable channels every
//! massive-cable model provides. Naming a channel by this enum, not by its string, makes a
//! misspelt channel a compile error instead of an empty column.

/// A channel of the time series.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    /// Time t [s].
    Time,
    /// Reference x_ref [m].
    XRef,
    /// Effector x [m].
    X,
    /// Effector z [m].
    Z,
    /// Error e = x_ref − x [m].
    Error,
    /// Controller force F [N].
    Force,
    /// Commanded tension T1 [N].
    T1,
    /// Commanded tension T2 [N].
    T2,
    /// Kinetic energy [J].
    EKinetic,
    /// Elastic energy [J].
    EElastic,
    /// Gravitational energy [J].
    EGravity,
    /// Work W done by the reels [J].
    WReel,
    /// Energy D dissipated inside the model [J].
    EDissipated,
    /// Energy balance E(t) − E(0) − W(t) + D(t) − ΣΔE [J].
    EResidual,
    /// Tension at the effector end of cable 1 or 2 [N] (massive-cable models).
    TEffector(Cable),
    /// Tension next to the pulley of cable 1 or 2 [N] (massive-cable models).
    TPulley(Cable),
    /// Free unstrained length of cable 1 or 2 [m] (massive-cable models).
    LFree(Cable),
    /// Stored amount of cable 1 or 2 (lumped: nodes; FE: length ρ_i [m]).
    Stored(Cable),
}

/// Cable 1 (over pulley A1) or cable 2 (over A2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cable {
    One,
    Two,
}

impl Cable {
    /// Both cables, in order.
    pub const BOTH: [Cable; 2] = [Cable::One, Cable::Two];

    /// The cable's index in per-cable arrays (0 or 1).
    pub fn index(self) -> usize {
        match self {
            Cable::One => 0,
            Cable::Two => 1,
        }
    }
}

impl Channel {
    /// The channels every run has, in order, before the model's own.
    pub const COMMON: [Channel; 8] = [
        Channel::Time,
        Channel::XRef,
        Channel::X,
        Channel::Z,
        Channel::Error,
        Channel::Force,
        Channel::T1,
        Channel::T2,
    ];

    /// The energy channels every run has, after the model's own [J].
    pub const ENERGY: [Channel; 6] = [
        Channel::EKinetic,
        Channel::EElastic,
        Channel::EGravity,
        Channel::WReel,
        Channel::EDissipated,
        Channel::EResidual,
    ];

    /// The channels every massive-cable model provides as its own, named alike so that the report
    /// and the cross-model tests compare them.
    pub const CABLE: [Channel; 8] = [
        Channel::TEffector(Cable::One),
        Channel::TEffector(Cable::Two),
        Channel::TPulley(Cable::One),
        Channel::TPulley(Cable::Two),
        Channel::LFree(Cable::One),
        Channel::LFree(Cable::Two),
        Channel::Stored(Cable::One),
        Channel::Stored(Cable::Two),
    ];

    /// The column's name in the time series and its CSV header.
    pub fn name(self) -> &'static str {
        use Cable::{One, Two};
        match self {
            Channel::Time => "t",
            Channel::XRef => "x_ref",
            Channel::X => "x",
            Channel::Z => "z",
            Channel::Error => "error",
            Channel::Force => "F",
            Channel::T1 => "T1",
            Channel::T2 => "T2",
            Channel::EKinetic => "e_kinetic",
            Channel::EElastic => "e_elastic",
            Channel::EGravity => "e_gravity",
            Channel::WReel => "w_reel",
            Channel::EDissipated => "e_dissipated",
            Channel::EResidual => "e_residual",
            Channel::TEffector(One) => "T_effector_1",
            Channel::TEffector(Two) => "T_effector_2",
            Channel::TPulley(One) => "T_pulley_1",
            Channel::TPulley(Two) => "T_pulley_2",
            Channel::LFree(One) => "l_free_1",
            Channel::LFree(Two) => "l_free_2",
            Channel::Stored(One) => "stored_1",
            Channel::Stored(Two) => "stored_2",
        }
    }
}

impl Channel {
    /// The channel's SI unit ("" where a model sets it: lumped storage counts nodes, FE's is a
    /// length).
    pub fn unit(self) -> &'static str {
        match self {
            Channel::Time => "s",
            Channel::XRef | Channel::X | Channel::Z | Channel::Error | Channel::LFree(_) => "m",
            Channel::Force | Channel::T1 | Channel::T2 => "N",
            Channel::TEffector(_) | Channel::TPulley(_) => "N",
            Channel::EKinetic
            | Channel::EElastic
            | Channel::EGravity
            | Channel::WReel
            | Channel::EDissipated
            | Channel::EResidual => "J",
            Channel::Stored(_) => "",
        }
    }

    /// The channel called `name`, if it is one of these.
    pub fn named(name: &str) -> Option<Channel> {
        Self::COMMON
            .into_iter()
            .chain(Self::ENERGY)
            .chain(Self::CABLE)
            .find(|c| c.name() == name)
    }
}

/// A CSV column heading: the channel's name and, where it has one, its unit in brackets
/// ("t [s]", "stored_1 [nodes]").
pub fn heading(name: &str, unit: &str) -> String {
    if unit.is_empty() {
        name.to_owned()
    } else {
        format!("{name} [{unit}]")
    }
}

impl std::fmt::Display for Channel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
