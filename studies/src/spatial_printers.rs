//! What the lines' mass does to a printer (`cargo xtask spatial`, the spatial section of
//! REPORT.md, docs/spatial.md): over a grid of a robot's build volume, the effector's lowest
//! mode on each cable model and the lines' lowest string mode ([`mode_map`]); firmware's static
//! flex compensation against the sagging lines ([`crate::flex_error`]); and the robot's move
//! under every controller on every cable model ([`leaderboard`]: the leaderboard in 3-D).
//!
//! The cable models in space are the massless elastic cables, the lumped lines and the FE
//! cables (MODELS.md §11); the maps' FE columns are FE cables of [`FE_ELEMENTS`] elements.

use crate::spatial_modes::{Lines, SpatialLoop, SpatialMode, at_pose, locked_line_modes};
use crate::spatial_moves::{MoveRow, table_with};
use crate::{Result, StudyError};
use cdpr_bench::ModelKind;
use cdpr_bench::analysis::modes::ModeKind;
use cdpr_bench::core::model::{CableModel, PoseRule};
use cdpr_bench::core::robot::{Matrix, Tensions, Vector};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::lumped::spatial::LumpedSpatial;

/// The modes at one target of the grid, each the lowest of its kind [rad/s] (None: the
/// analysis found none, e.g. a sparse solve whose window held no string mode).
#[derive(Debug, Clone, serde::Serialize)]
pub struct ModePoint {
    pub pose: [f64; 3],
    /// The scenario's distribution of the effector's weight there [N].
    pub tensions: Vec<f64>,
    /// Elastic cables, the reels holding their tensions (the geometric stiffness alone).
    pub elastic_tension_reels_rad_s: f64,
    /// Elastic cables, the reels locked (what a length-driven reel holds between steps).
    pub elastic_locked_rad_s: f64,
    /// Elastic cables locked at the lumped lines' locked lengths: the lumped lines' reels hold
    /// the stored node behind the pulley, so the spring over the pulley stretches whole and the
    /// locked line is L_i = (N − r_i + 1) l0, up to one spring longer than the chord (MODELS.md
    /// §11). Against this the lumped lines differ by their mass alone.
    pub elastic_same_length_rad_s: f64,
    /// Lumped lines, the reels locked: the effector's lowest mode ([`effector_mode`]) and its
    /// share of the kinetic energy in the effector. (Where the effector's mode meets a string's
    /// they hybridise and neither is named "effector" by its largest share, so shares, not
    /// the name, find it.)
    pub lumped_locked_rad_s: Option<f64>,
    pub lumped_locked_share: Option<f64>,
    /// Lumped lines, the reels locked: the lowest string mode of any cable, in or across its
    /// vertical plane, and the largest effector share of the modes below
    /// `lumped_locked_rad_s` (how much the strings below it move the effector).
    pub lowest_string_rad_s: Option<f64>,
    pub share_below: f64,
    /// FE cables, the reels locked: the effector's lowest mode ([`effector_mode`]) and its
    /// share, the elastic lines locked at the FE cables' own
    /// unstrained lengths l_i (the mass alone), and the lowest string mode.
    pub fe_locked_rad_s: Option<f64>,
    pub fe_locked_share: Option<f64>,
    pub fe_same_length_rad_s: f64,
    pub fe_lowest_string_rad_s: Option<f64>,
}

/// The lines' effector mode is the lowest by which the effector's shares of the modes' kinetic
/// energy, summed from the lowest mode up, reach this: half of one direction's (the shares of
/// all modes sum to one per axis). On the Hangprinter-like robot a string mode has under 0.05
/// and the effector's mode over 0.9, picked alone; where strings hybridise with it (CoGiRo's
/// centre: three modes of 0.22–0.25 each on FE lines) it lands where half the effector's
/// modal mass does, which a threshold per mode would miss.
pub const EFFECTOR_SHARE: f64 = 0.5;

/// The effector's lowest mode among `modes` (any order): the lowest by which the summed
/// effector shares reach [`EFFECTOR_SHARE`].
pub fn effector_mode<'a>(
    modes: impl Iterator<Item = &'a crate::spatial_modes::SpatialMode>,
) -> Option<&'a crate::spatial_modes::SpatialMode> {
    let mut ascending: Vec<_> = modes.collect();
    ascending.sort_by(|a, b| a.omega_rad_s.total_cmp(&b.omega_rad_s));
    let mut sum = 0.0;
    ascending.into_iter().find(|m| {
        sum += m.effector_share.unwrap_or(0.0);
        sum >= EFFECTOR_SHARE
    })
}

/// [`mode_map`]'s result.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ModeMap {
    /// Springs per line of the lumped lines, elements per span of the FE cables.
    pub elements: usize,
    pub fe_elements: usize,
    /// The box [m] and the points per axis of its grid.
    pub low: [f64; 3],
    pub high: [f64; 3],
    pub per_axis: usize,
    /// Targets whose weight no tensions in the box hold (skipped).
    pub infeasible: usize,
    pub points: Vec<ModePoint>,
}

/// The modes at every target of the `per_axis`³ grid spanning `low`–`high` [m], on `scenario`'s
/// robot (its lines lumped as its `[model]` says) at rest under its distribution of the weight
/// ([`at_pose`] at each target, on every core).
pub fn mode_map(
    scenario: &Scenario,
    low: [f64; 3],
    high: [f64; 3],
    per_axis: usize,
) -> Result<ModeMap> {
    let config = cdpr_bench::ModelConfig::from_scenario(scenario)?;
    if config.kind != ModelKind::Lumped {
        return Err(StudyError::Failed(format!(
            "the mode map compares the elastic cables with the lumped lines: model.kind = \"{}\", \
             expected \"lumped\"",
            config.kind.name()
        )));
    }
    let elements = config.lumped().map_err(cdpr_bench::Error::from)?.elements;
    let model = LumpedSpatial::from_scenario(scenario, elements)
        .map_err(|e| StudyError::Failed(format!("the lumped lines: {e}")))?;
    let fe_scenario = fe_variant(scenario)?;
    let targets = crate::flex_error::grid(low, high, per_axis);
    let rows = crate::pool::map(&targets, |p| mode_point(scenario, &model, &fe_scenario, p))?;
    let (points, infeasible) = crate::flex_error::feasible(rows)?;
    Ok(ModeMap {
        elements,
        fe_elements: FE_ELEMENTS,
        low,
        high,
        per_axis,
        infeasible,
        points,
    })
}

/// One grid target's modes on every cable model at rest there (None: no tensions hold it).
fn mode_point(
    scenario: &Scenario,
    model: &LumpedSpatial,
    fe_scenario: &Scenario,
    p: &Vector<3>,
) -> Result<Option<ModePoint>> {
    let Some(tensions) = crate::flex_error::rest_tensions(scenario, model.robot(), p) else {
        return Ok(None);
    };
    let modes = at_pose(scenario, [p.x, p.y, p.z])?.modes;
    let same_length = same_length_lowest(model, p, &tensions)?;
    let lowest = |keep: &dyn Fn(&SpatialMode) -> bool| {
        modes
            .iter()
            .filter(|m| keep(m))
            .map(|m| m.omega_rad_s)
            .min_by(f64::total_cmp)
    };
    let lumped: Vec<&SpatialMode> = modes
        .iter()
        .filter(|m| m.linearisation == SpatialLoop::LumpedLockedReels)
        .collect();
    let share = |m: &SpatialMode| m.effector_share.unwrap_or(0.0);
    let effector = effector_mode(lumped.iter().copied());
    let fe = locked_line_modes(fe_scenario, Lines::Fe(FE_ELEMENTS), p, &tensions, 0.0)?;
    let fe_same_length_rad_s = fe_same_length_lowest(fe_scenario, p, &tensions)?;
    let fe_effector = effector_mode(fe.iter());
    let share_below = share_below(&lumped, effector);
    let missing =
        |what: &str| StudyError::Failed(format!("modes at {:?} m: no {what} mode", p.as_slice()));
    Ok(Some(ModePoint {
        pose: [p.x, p.y, p.z],
        tensions,
        elastic_tension_reels_rad_s: lowest(&|m| m.linearisation == SpatialLoop::TensionReels)
            .ok_or_else(|| missing("tension-reel"))?,
        elastic_locked_rad_s: lowest(&|m| m.linearisation == SpatialLoop::LockedReels)
            .ok_or_else(|| missing("locked-reel"))?,
        elastic_same_length_rad_s: same_length,
        lumped_locked_rad_s: effector.map(|m| m.omega_rad_s),
        lumped_locked_share: effector.map(share),
        lowest_string_rad_s: lowest(&|m| {
            m.linearisation == SpatialLoop::LumpedLockedReels
                && matches!(m.kind, Some(ModeKind::InPlane(_) | ModeKind::OutOfPlane(_)))
        }),
        share_below,
        fe_locked_rad_s: fe_effector.map(|m| m.omega_rad_s),
        fe_locked_share: fe_effector.map(share),
        fe_same_length_rad_s,
        fe_lowest_string_rad_s: lowest_string(&mut fe.iter()),
    }))
}

/// How much the strings below the lumped lines' effector mode move it: their largest share.
fn share_below(lumped: &[&SpatialMode], effector: Option<&SpatialMode>) -> f64 {
    lumped
        .iter()
        .filter(|m| effector.is_some_and(|e| m.omega_rad_s < e.omega_rad_s))
        .map(|m| m.effector_share.unwrap_or(0.0))
        .fold(0.0, f64::max)
}

/// The lowest string mode [rad/s] among `modes`: any line's, in or across its vertical plane.
fn lowest_string(modes: &mut dyn Iterator<Item = &SpatialMode>) -> Option<f64> {
    modes
        .filter(|m| matches!(m.kind, Some(ModeKind::InPlane(_) | ModeKind::OutOfPlane(_))))
        .map(|m| m.omega_rad_s)
        .min_by(f64::total_cmp)
}

/// The lowest effector mode [rad/s] on massless elastic lines locked at the lengths the lumped
/// lines lock at rest at `p` under `tensions` [N]: K = Σ (EA/L_i) u_i u_iᵀ + (T_i/l_i)(I − u_i
/// u_iᵀ), L_i = (N − r_i + 1) l0, T_i the lumped line's tension at the effector.
fn same_length_lowest(model: &LumpedSpatial, p: &Vector<3>, tensions: &[f64]) -> Result<f64> {
    let mut model = model.clone();
    let rest = model
        .equilibrium(&PoseRule::new(p, Tensions::from_slice(tensions)))
        .map_err(|e| StudyError::Failed(format!("the lines at rest at {:?} m: {e}", p.as_slice())))?
        .state;
    let n = model.elements;
    let ea = model.stiffness * model.segment;
    let mut k = Matrix::<3>::zeros();
    for c in 0..model.robot().cables() {
        let d = model.pulley(c) - p;
        let (l, u) = (d.norm(), d.normalize());
        let uu = u * u.transpose();
        let locked = (n - model.stored()[c] + 1) as f64 * model.segment;
        let t = model.spring_force(&rest, c, n - 1);
        k += uu * (ea / locked) + (Matrix::<3>::identity() - uu) * (t / l);
    }
    let lowest = (k / model.robot().effector_mass)
        .symmetric_eigenvalues()
        .min();
    Ok(lowest.max(0.0).sqrt())
}

/// `scenario` on FE cables of [`FE_ELEMENTS`] elements.
fn fe_variant(scenario: &Scenario) -> Result<Scenario> {
    let mut config = cdpr_bench::ModelConfig::from_scenario(scenario)?;
    config.kind = ModelKind::Fe;
    config.elements = Some(FE_ELEMENTS as i64);
    let mut s = scenario.clone();
    s.model = config.section();
    cdpr_bench::validate(&s)?;
    Ok(s)
}

/// The lowest effector mode [rad/s] on massless elastic lines locked at the unstrained lengths
/// l_i the FE cables of `scenario` take at rest at `p` under `tensions` [N]: K = Σ (EA/l_i) u_i
/// u_iᵀ + (T_i/d_i)(I − u_i u_iᵀ), d_i the chord, T_i the FE line's tension at the effector.
fn fe_same_length_lowest(scenario: &Scenario, p: &Vector<3>, tensions: &[f64]) -> Result<f64> {
    let fail =
        |e: String| StudyError::Failed(format!("FE lines at rest at {:?} m: {e}", p.as_slice()));
    let params = cdpr_bench::ModelConfig::from_scenario(scenario)?
        .fe()
        .map_err(cdpr_bench::Error::from)?;
    let mut model = cdpr_bench::fe::spatial::FeSpatial::from_scenario(scenario, params)
        .map_err(|e| fail(e.to_string()))?;
    let rest = model
        .equilibrium(&PoseRule::new(p, Tensions::from_slice(tensions)))
        .map_err(|e| fail(e.to_string()))?
        .state;
    let mut k = Matrix::<3>::zeros();
    for c in 0..model.robot().cables() {
        let d = model.pulley(c) - p;
        let (chord, u) = (d.norm(), d.normalize());
        let uu = u * u.transpose();
        let t = model.element_tension(&rest, c, model.elements);
        let l = model.free_length(&rest, c);
        k += uu * (model.material.ea / l) + (Matrix::<3>::identity() - uu) * (t / chord);
    }
    let lowest = (k / model.robot().effector_mass)
        .symmetric_eigenvalues()
        .min();
    Ok(lowest.max(0.0).sqrt())
}

/// "min … max" of `values` [rad/s] in Hz, "—" when there are none.
fn hz_range(values: impl Iterator<Item = Option<f64>>) -> String {
    let hz: Vec<f64> = values
        .flatten()
        .map(|w| w / (2.0 * std::f64::consts::PI))
        .collect();
    if hz.is_empty() {
        return "—".into();
    }
    let (lo, hi) = hz
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    format!("{lo:.1} … {hi:.1}")
}

/// The map in Markdown: per height, the range of each mode over the targets there [Hz].
pub fn mode_markdown(map: &ModeMap) -> String {
    let mut heights: Vec<f64> = map.points.iter().map(|p| p.pose[2]).collect();
    heights.sort_by(f64::total_cmp);
    heights.dedup();
    let mut out = format!(
        "Lowest modes over {} targets ({} outside the wrench-feasible workspace), lumped lines of \
         {} springs, reels locked unless said [Hz, least … largest over the height's targets]. \
         The lines' effector mode is their lowest by which the effector's shares of the modes' \
         kinetic energy, summed from the lowest up, reach {EFFECTOR_SHARE}; it is compared with the elastic lines locked at the \
         chord and at the lumped lines' own locked length (the mass alone); the FE cables' \
         ({} elements, consistent masses) likewise, with the elastic lines at their unstrained \
         lengths:\n\n\
         | z [m] | elastic, tension reels | elastic, locked | lumped, locked | lumped / elastic \
         | lumped / elastic at its length | lowest string mode | largest effector share below \
         | FE, locked | FE / elastic at its length | FE lowest string mode |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
        map.points.len(),
        map.infeasible,
        map.elements,
        map.fe_elements
    );
    for z in heights {
        let here: Vec<&ModePoint> = map.points.iter().filter(|p| p.pose[2] == z).collect();
        out += &format!(
            "| {z:.3} | {} | {} | {} | {} | {} | {} | {:.3} | {} | {} | {} |\n",
            hz_range(here.iter().map(|p| Some(p.elastic_tension_reels_rad_s))),
            hz_range(here.iter().map(|p| Some(p.elastic_locked_rad_s))),
            hz_range(here.iter().map(|p| p.lumped_locked_rad_s)),
            ratio_range(
                here.iter()
                    .map(|p| (p.lumped_locked_rad_s, p.elastic_locked_rad_s))
            ),
            ratio_range(
                here.iter()
                    .map(|p| (p.lumped_locked_rad_s, p.elastic_same_length_rad_s))
            ),
            hz_range(here.iter().map(|p| p.lowest_string_rad_s)),
            here.iter().map(|p| p.share_below).fold(0.0, f64::max),
            hz_range(here.iter().map(|p| p.fe_locked_rad_s)),
            ratio_range(
                here.iter()
                    .map(|p| (p.fe_locked_rad_s, p.fe_same_length_rad_s))
            ),
            hz_range(here.iter().map(|p| p.fe_lowest_string_rad_s)),
        );
    }
    out
}

/// "min … max" of the ratios a / b, "—" when there are none.
fn ratio_range(pairs: impl Iterator<Item = (Option<f64>, f64)>) -> String {
    let ratios: Vec<f64> = pairs.filter_map(|(a, b)| a.map(|a| a / b)).collect();
    if ratios.is_empty() {
        return "—".into();
    }
    let lo = ratios.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ratios.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    format!("{lo:.4} … {hi:.4}")
}

/// Elements per span of the leaderboard's FE cables (the paper's discretisation).
pub const FE_ELEMENTS: usize = 10;

/// One cable model's rows of the leaderboard.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ModelMoves {
    pub model: &'static str,
    pub rows: Vec<MoveRow>,
}

/// `scenario`'s move under every controller (the `length` controller with each flex
/// compensation) with its distribution, on the elastic cables, on the lumped lines of its
/// `[model]` (a scenario on elastic cables: lumped lines of 20 springs) and on FE cables of
/// [`FE_ELEMENTS`] elements.
pub fn leaderboard(scenario: &Scenario) -> Result<Vec<ModelMoves>> {
    let method = [scenario.controller.distribution];
    let mut out = Vec::new();
    for kind in ModelKind::ALL {
        let s = if cdpr_bench::ModelConfig::from_scenario(scenario)?.kind == kind {
            scenario.clone()
        } else if kind == ModelKind::Fe {
            fe_variant(scenario)?
        } else {
            cdpr_bench::with_model_kind(scenario, kind)?
        };
        out.push(ModelMoves {
            model: kind.name(),
            rows: table_with(&s, &method)?,
        });
    }
    Ok(out)
}

/// The leaderboard in Markdown: one table, a row per cable model and controller.
pub fn leaderboard_markdown(models: &[ModelMoves]) -> String {
    let mut out = String::from(
        "| cable model | controller | path error in the move [m] | 1 s after [m] | tensions [N] \
         | saturated [s] | reel speed [m/s] | energy residual [J] | steps |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for m in models {
        for r in &m.rows {
            let x = &r.metrics;
            let reel = x.reel_speed_max.iter().copied().fold(0.0, f64::max);
            out += &format!(
                "| {} | {} | {} | {} | {:.1} … {:.1} | {:.3} | {:.3} | {:.1e} | {} |\n",
                m.model,
                r.controller,
                sci(x.path_err_max_move),
                sci(x.path_err_max_after_1s),
                x.tension_min,
                x.tension_max,
                x.saturated_s,
                reel,
                x.energy_residual_max,
                r.steps
            );
        }
    }
    out
}

/// Three significant digits ("—" where not measured).
fn sci(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2e}")
    } else {
        "—".into()
    }
}

/// One frame of a run: its time [s] and each cable's points from its pulley to the effector [m].
#[derive(Debug, Clone)]
pub struct Frame {
    pub t: f64,
    pub cables: Vec<Vec<[f64; 3]>>,
}

/// `scenario`'s move with a frame of its cables every `period` [s] (for drawings), and the run.
pub fn move_frames(
    scenario: &Scenario,
    period: f64,
) -> Result<(cdpr_bench::SpatialRun, Vec<Frame>)> {
    use cdpr_bench::core::runner::{Frames, Observer};
    let mut frames = Vec::new();
    let run = {
        let mut sink = |t: f64, paths: &[Vec<f64>]| {
            let cables = paths
                .iter()
                .map(|p| p.chunks_exact(3).map(|q| [q[0], q[1], q[2]]).collect())
                .collect();
            frames.push(Frame { t, cables });
        };
        let mut quiet = |_: f64| {};
        let mut observer = Observer {
            frames: Some(Frames {
                period,
                sink: &mut sink,
            }),
            ..Observer::progress(&mut quiet)
        };
        cdpr_bench::simulate_spatial(scenario, &mut observer)?
    };
    Ok((run, frames))
}

/// Each cable's points from its pulley to the effector [m] with the lumped lines of
/// `scenario` at rest at `pose` [m] under its distribution of the weight there.
pub fn rest_paths(scenario: &Scenario, pose: [f64; 3]) -> Result<Vec<Vec<[f64; 3]>>> {
    let elements = cdpr_bench::ModelConfig::from_scenario(scenario)?
        .lumped()
        .map_err(cdpr_bench::Error::from)?
        .elements;
    let fail = |e: String| StudyError::Failed(format!("the lines at rest at {pose:?} m: {e}"));
    let mut model =
        LumpedSpatial::from_scenario(scenario, elements).map_err(|e| fail(e.to_string()))?;
    let p = Vector::<3>::from(pose);
    let tensions = crate::flex_error::rest_tensions(scenario, model.robot(), &p)
        .ok_or_else(|| fail("no tensions in the box hold the weight there".into()))?;
    let rest = model
        .equilibrium(&PoseRule::new(&p, Tensions::from_slice(&tensions)))
        .map_err(|e| fail(e.to_string()))?;
    Ok(model
        .cable_paths(&rest.state)
        .iter()
        .map(|c| c.iter().map(|q| [q.x, q.y, q.z]).collect())
        .collect())
}
