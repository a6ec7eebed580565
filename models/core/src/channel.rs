//! The named channels of a run's time series (MODELS.md §7): those every run has, in this order
//! before the model's own, the energy terms after them, and the cable channels every
//! massive-cable model provides. Naming a channel by this enum, not by its string, makes a
//! misspelt channel a compile error instead of an empty column.

use crate::robot::{CableId, axis_name};
use std::fmt;

/// A channel of the time series.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    /// Time t [s].
    Time,
    /// Reference x_ref [m].
    XRef,
    /// Effector x [m].
    X,
    /// Effector y [m] (spatial robots).
    Y,
    /// Effector z [m].
    Z,
    /// Error e = x_ref − x [m].
    Error,
    /// The horizontal force F the controller asks of the cables [N].
    Force,
    /// Commanded tension of a cable [N].
    Tension(CableId),
    /// 1 where the tension limits clamped the controller's tensions by more than the
    /// distribution's 1e-9 N tolerance, else 0 (spatial robots: the distribution found no
    /// tensions in the box for the controller's wrench, or feedback left it).
    Saturated,
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
    /// Tension at the effector end of a cable [N] (massive-cable models).
    TEffector(CableId),
    /// Tension next to a cable's pulley [N] (massive-cable models).
    TPulley(CableId),
    /// Free unstrained length of a cable [m] (massive-cable models).
    LFree(CableId),
    /// Stored amount of a cable (lumped: nodes; FE: length ρ_i [m]).
    Stored(CableId),
}

impl Channel {
    /// The commanded tension of cable 1.
    pub const T1: Channel = Channel::Tension(CableId(0));
    /// The commanded tension of cable 2.
    pub const T2: Channel = Channel::Tension(CableId(1));

    /// The energy channels every run has, after the model's own [J].
    pub const ENERGY: [Channel; 6] = [
        Channel::EKinetic,
        Channel::EElastic,
        Channel::EGravity,
        Channel::WReel,
        Channel::EDissipated,
        Channel::EResidual,
    ];

    /// The effector's coordinate along axis `k` of a D-dimensional robot.
    pub fn axis<const D: usize>(k: usize) -> Channel {
        match axis_name::<D>(k) {
            "x" => Channel::X,
            "y" => Channel::Y,
            _ => Channel::Z,
        }
    }

    /// The channels every run of a D-dimensional robot with `cables` cables has, in order,
    /// before the model's own: t, x_ref, the effector's coordinates, the error, the force, T1 …
    /// Tm, in space `saturated` (the plane: `t, x_ref, x, z, error, F, T1, T2`).
    pub fn common<const D: usize>(cables: usize) -> Vec<Channel> {
        let mut channels = vec![Channel::Time, Channel::XRef];
        channels.extend((0..D).map(Channel::axis::<D>));
        channels.extend([Channel::Error, Channel::Force]);
        channels.extend(CableId::all(cables).map(Channel::Tension));
        if D == 3 {
            channels.push(Channel::Saturated);
        }
        channels
    }

    /// The channels every massive-cable model provides as its own, named alike so that the
    /// report and the cross-model tests compare them: per kind, cable 1 … m.
    pub fn cable_channels(cables: usize) -> Vec<Channel> {
        let kinds: [fn(CableId) -> Channel; 4] = [
            Channel::TEffector,
            Channel::TPulley,
            Channel::LFree,
            Channel::Stored,
        ];
        kinds
            .iter()
            .flat_map(|kind| CableId::all(cables).map(kind))
            .collect()
    }

    /// The names of [`Channel::cable_channels`] (a massive model's own channels).
    pub fn cable_channel_names(cables: usize) -> Vec<String> {
        Self::cable_channels(cables)
            .into_iter()
            .map(Channel::name)
            .collect()
    }

    /// The units of [`Channel::cable_channels`], the stored cable counted in `stored_unit` (the
    /// lumped model's "nodes", the FE model's "m").
    pub fn cable_channel_units(cables: usize, stored_unit: &'static str) -> Vec<&'static str> {
        Self::cable_channels(cables)
            .into_iter()
            .map(|c| match c {
                Channel::Stored(_) => stored_unit,
                c => c.unit(),
            })
            .collect()
    }

    /// The column's name in the time series and its CSV heading.
    pub fn name(self) -> String {
        match self {
            Channel::Time => "t".into(),
            Channel::XRef => "x_ref".into(),
            Channel::X => "x".into(),
            Channel::Y => "y".into(),
            Channel::Z => "z".into(),
            Channel::Error => "error".into(),
            Channel::Force => "F".into(),
            Channel::Tension(c) => format!("T{c}"),
            Channel::Saturated => "saturated".into(),
            Channel::EKinetic => "e_kinetic".into(),
            Channel::EElastic => "e_elastic".into(),
            Channel::EGravity => "e_gravity".into(),
            Channel::WReel => "w_reel".into(),
            Channel::EDissipated => "e_dissipated".into(),
            Channel::EResidual => "e_residual".into(),
            Channel::TEffector(c) => format!("T_effector_{c}"),
            Channel::TPulley(c) => format!("T_pulley_{c}"),
            Channel::LFree(c) => format!("l_free_{c}"),
            Channel::Stored(c) => format!("stored_{c}"),
        }
    }

    /// The channel's SI unit ("" where a model sets it: lumped storage counts nodes, FE's is a
    /// length).
    pub fn unit(self) -> &'static str {
        match self {
            Channel::Time => "s",
            Channel::XRef
            | Channel::X
            | Channel::Y
            | Channel::Z
            | Channel::Error
            | Channel::LFree(_) => "m",
            Channel::Force | Channel::Tension(_) => "N",
            Channel::TEffector(_) | Channel::TPulley(_) => "N",
            Channel::EKinetic
            | Channel::EElastic
            | Channel::EGravity
            | Channel::WReel
            | Channel::EDissipated
            | Channel::EResidual => "J",
            Channel::Stored(_) | Channel::Saturated => "",
        }
    }

    /// The channel called `name`, if it is one of these (cables up to
    /// [`crate::robot::MAX_CABLES`]).
    pub fn named(name: &str) -> Option<Channel> {
        let m = crate::robot::MAX_CABLES;
        Self::common::<3>(m)
            .into_iter()
            .chain(Self::ENERGY)
            .chain(Self::cable_channels(m))
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

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}
