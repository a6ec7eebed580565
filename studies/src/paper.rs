//! The paper's scenario on every cable model (`cargo xtask report`): each model run and measured
//! on its own thread, the settled end state at x2 of each, Eq. 15, and the MODELS.md §8
//! acceptance table of them all.

use crate::{Result, StudyError};
use cdpr_bench::analysis::linearise::EndState;
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::{Assessed, ModelKind};
use cdpr_verify::acceptance::{self, Check, ModelResult};

/// The paper on every model.
pub struct PaperRuns {
    /// One per model of [`ModelKind::ALL`], in that order.
    pub outcomes: Vec<Assessed>,
    /// Each model's static equilibrium and vertical mode at x2.
    pub ends: Vec<EndState>,
    /// Eq. 15 at the end of the move [rad/s].
    pub eq15_rad_s: f64,
    /// The MODELS.md §8 rows.
    pub checks: Vec<Check>,
}

/// Runs `base` on every model, one thread per model (the results keep the models' order);
/// `progress(k, f)` reports model k's fraction f of its run. Every model's end state is required:
/// without it there is no comparison.
pub fn compute(base: &Scenario, progress: &(dyn Fn(usize, f64) + Sync)) -> Result<PaperRuns> {
    let kinds = ModelKind::ALL;
    let results: Vec<Result<Assessed>> = std::thread::scope(|scope| {
        let handles: Vec<_> = kinds
            .iter()
            .enumerate()
            .map(|(k, &kind)| {
                scope.spawn(move || {
                    let s = cdpr_bench::with_model_kind(base, kind)?;
                    cdpr_bench::assess(&s, &mut |f| progress(k, f))
                        .map_err(|e| StudyError::Failed(format!("{kind} model: {e}")))
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or(Err(StudyError::WorkerPanicked)))
            .collect()
    });
    let outcomes = results.into_iter().collect::<Result<Vec<Assessed>>>()?;
    let ends = outcomes
        .iter()
        .map(|o| {
            o.end.state().cloned().ok_or_else(|| {
                StudyError::Failed(format!(
                    "{} model: the modal analysis at x2 {}: {}",
                    o.kind,
                    o.end.status(),
                    o.end.reason().unwrap_or_default()
                ))
            })
        })
        .collect::<Result<Vec<EndState>>>()?;
    let eq15_rad_s = cdpr_bench::eq15_at_end(base);
    let axial_mode = cdpr_bench::mode_as_integrated(base, acceptance::LUMPED_AXIAL_MODE);
    let views: Vec<ModelResult> = outcomes
        .iter()
        .map(|o| ModelResult::of(o, axial_mode))
        .collect();
    let checks = acceptance::table(eq15_rad_s, &views);
    Ok(PaperRuns {
        outcomes,
        ends,
        eq15_rad_s,
        checks,
    })
}
