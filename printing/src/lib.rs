//! What a printer's firmware does before any dynamics: read the slicer's G-code
//! ([`gcode`]) and plan the toolhead's motion as Klipper does ([`planner`]): per-move speed
//! limits, junction speeds, lookahead, trapezoids. It knows no robot and no cable: a plan is
//! the Cartesian reference p(t), v(t), a(t) that a robot's controller then follows.

pub mod gcode;
pub mod planner;
pub mod shaper;
