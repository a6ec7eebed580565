//! `cargo xtask statics-sweep`: the static equilibrium of MODELS.md §2 at every start of a grid of
//! effector positions x and tension sums ΣT, counting the starts where it fails and printing why.
//! The evidence behind docs/numerics.md's claim for the lumped statics beside a pulley (0 failures in
//! 500 000 starts on the default grid, the property test's ranges), and a way to re-check it.

use crate::output::Progress;
use crate::simulate::{load_scenario, model_kind};
use anyhow::{Result, bail};
use cdpr_bench::core::model::{CableModel, SplitRule};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::{ModelKind, ModelVisitor};
use std::path::PathBuf;

/// The command's options.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario file (TOML, MODELS.md §9); absent = the paper's scenario.
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// Cable model, overriding the scenario's [model] kind.
    #[arg(long, value_enum)]
    pub model: Option<ModelKind>,
    /// Effector x range [m] and its number of points.
    #[arg(long, default_value_t = 0.15)]
    pub x_min: f64,
    #[arg(long, default_value_t = 0.85)]
    pub x_max: f64,
    #[arg(long, default_value_t = 2000)]
    pub x_steps: usize,
    /// Tension sum ΣT range [N] and its number of points.
    #[arg(long, default_value_t = 120.0)]
    pub tension_min: f64,
    #[arg(long, default_value_t = 400.0)]
    pub tension_max: f64,
    #[arg(long, default_value_t = 250)]
    pub tension_steps: usize,
}

/// An interval [min, max] sampled at the midpoints of `steps` equal cells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    pub min: f64,
    pub max: f64,
    pub steps: usize,
}

impl Axis {
    fn at(&self, i: usize) -> f64 {
        self.min + (self.max - self.min) * (i as f64 + 0.5) / self.steps as f64
    }

    /// `name` is the option pair the person typed, for the error.
    fn check(&self, name: &str, low: f64, high: f64) -> Result<()> {
        if !(self.min.is_finite() && self.max.is_finite() && low < self.min && self.min < self.max)
            || self.max >= high
        {
            bail!(
                "--{name}-min < --{name}-max must lie inside ({low}, {high}); got [{}, {}]",
                self.min,
                self.max
            );
        }
        if self.steps == 0 {
            bail!("--{name}-steps must be at least 1");
        }
        Ok(())
    }
}

/// A start that found no equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    pub x: f64,
    pub tension_sum: f64,
    pub why: String,
}

/// Every start of the grid, in order (x outer, ΣT inner): the failures, and the number of starts.
/// `progress` gets the fraction done.
pub fn sweep(
    scenario: &Scenario,
    x: Axis,
    tension_sum: Axis,
    progress: &mut dyn FnMut(f64),
) -> Result<(Vec<Failure>, usize)> {
    /// The grid on the scenario's model, built (and its scenario checked) once.
    struct Grid<'a> {
        x: Axis,
        tension_sum: Axis,
        progress: &'a mut dyn FnMut(f64),
    }
    impl ModelVisitor for Grid<'_> {
        type Output = Vec<Failure>;
        fn visit<M: CableModel<2> + Clone + Send + 'static>(self, built: M) -> Vec<Failure> {
            let mut failures = Vec::new();
            for i in 0..self.x.steps {
                for j in 0..self.tension_sum.steps {
                    let (at, sum) = (self.x.at(i), self.tension_sum.at(j));
                    // A fresh copy per start: the lumped model's stored/free split is part of
                    // its state, and an equilibrium changes it.
                    if let Err(e) = built.clone().equilibrium(&SplitRule::new(at, sum)) {
                        failures.push(Failure {
                            x: at,
                            tension_sum: sum,
                            why: e.to_string(),
                        });
                    }
                }
                (self.progress)((i + 1) as f64 / self.x.steps as f64);
            }
            failures
        }
    }
    let failures = cdpr_bench::with_model(
        scenario,
        Grid {
            x,
            tension_sum,
            progress,
        },
    )?;
    Ok((failures, x.steps * tension_sum.steps))
}

pub fn run(args: &Args) -> Result<()> {
    let x = Axis {
        min: args.x_min,
        max: args.x_max,
        steps: args.x_steps,
    };
    let tension_sum = Axis {
        min: args.tension_min,
        max: args.tension_max,
        steps: args.tension_steps,
    };
    let scenario = load_scenario(args.scenario.as_deref(), args.model)?;
    x.check("x", 0.0, scenario.robot.anchor_distance)?;
    tension_sum.check("tension", 0.0, f64::INFINITY)?;
    let kind = model_kind(&scenario)?.name();
    let mut progress = Progress::new(kind);
    let (failures, starts) = sweep(&scenario, x, tension_sum, &mut |f| progress.set(f))?;
    progress.finish();
    for f in &failures {
        println!("x = {} m, ΣT = {} N: {}", f.x, f.tension_sum, f.why);
    }
    println!(
        "{kind}: {} of {starts} starts found no equilibrium (x ∈ [{}, {}] m at {} points, \
         ΣT ∈ [{}, {}] N at {} points)",
        failures.len(),
        x.min,
        x.max,
        x.steps,
        tension_sum.min,
        tension_sum.max,
        tension_sum.steps
    );
    if !failures.is_empty() {
        bail!("{} of {starts} starts found no equilibrium", failures.len());
    }
    Ok(())
}
