//! Sampling the dense output on the exact grid t_k = k·Δt, with the energy balance of each
//! sample.

use super::events::check_slack;
use super::{RunError, RunOptions, channel_names};
use crate::closed_loop::ClosedLoop;
use crate::model::CableModel;
use crate::series::{SeriesBuffer, TimeSeries};
use cdpr_numerics::Stepper;

/// Samples the dense output on the grid t_k = k·Δt (computed, not accumulated, so the grid is
/// exact and reproducible).
pub(super) struct Sampler {
    pub(super) series: TimeSeries,
    pub(super) y: Vec<f64>,
    /// Number of the model's own channels.
    pub(super) model_channels: usize,
    /// Where the model's channels `l0_1` … `l0_m` sit among them (empty when it has none).
    pub(super) l0_channels: Vec<usize>,
    pub(super) energy0: f64,
    /// Sum of the energy changes of the model events so far [J].
    pub(super) event_energy: f64,
    pub(super) next: usize,
    pub(super) samples: usize,
    pub(super) period: f64,
    /// End of the run [s]: the last sample is taken there, when the integration reaches it.
    pub(super) t_final: f64,
}

impl Sampler {
    /// A sampler for `opts`' grid of the loop started from `y0`, its series in `buffer`'s
    /// memory.
    pub(super) fn new<M: CableModel<D>, const D: usize>(
        sys: &ClosedLoop<M, D>,
        y0: &[f64],
        opts: &RunOptions,
        buffer: SeriesBuffer,
    ) -> Self {
        let n = sys.model_len();
        let names = channel_names(&sys.model);
        let samples = (opts.t_final / opts.sample_period).round() as usize + 1;
        Self {
            series: TimeSeries::with_buffer(names, samples, buffer),
            y: vec![0.0; y0.len()],
            model_channels: sys.model.channel_names().len(),
            l0_channels: (1..=sys.model.cables())
                .filter_map(|i| {
                    let name = format!("l0_{i}");
                    sys.model.channel_names().iter().position(|c| *c == name)
                })
                .collect(),
            energy0: sys.model.energy(&y0[..n]).total(),
            event_energy: 0.0,
            next: 0,
            samples,
            period: opts.sample_period,
            t_final: opts.t_final,
        }
    }

    /// Appends every grid sample with t_k ≤ `t` (within the last accepted step).
    pub(super) fn sample_through<M: CableModel<D>, const D: usize>(
        &mut self,
        sys: &ClosedLoop<M, D>,
        stepper: &dyn Stepper<ClosedLoop<M, D>>,
        t: f64,
    ) -> Result<(), RunError> {
        let n = sys.model_len();
        while self.next < self.samples {
            let tk = self.next as f64 * self.period;
            // The last sample is the end point itself (t_final may not be a multiple of Δt by ulps),
            // taken once the integration has reached it.
            let tk = if self.next + 1 == self.samples {
                self.t_final
            } else {
                tk
            };
            if tk > t {
                break;
            }
            if tk == stepper.time() {
                self.y.copy_from_slice(stepper.state());
            } else {
                stepper.dense_output(tk, &mut self.y);
            }
            let y = &self.y;
            let cmd = sys.command(tk, y);
            check_slack(tk, &cmd.tensions, sys.slack_allowed())?;
            let model_state = &y[..n];
            let eff = sys.model.effector(model_state);
            if !sys.robot().in_workspace(&eff.position) {
                return Err(RunError::Workspace {
                    t: tk,
                    position: eff.position.as_slice().to_vec(),
                });
            }
            let energy = sys.model.energy(model_state);
            let c = n + sys.controller_len();
            let (work, dissipated) = (y[c], y[c + 1]);
            let residual = energy.total() - self.energy0 - work + dissipated - self.event_energy;
            let m = self.model_channels;
            let cables = cmd.tensions.len();
            let paid_out = if self.l0_channels.len() == cables {
                sys.commanded_lengths(tk)
            } else {
                None
            };
            let flag = usize::from(D == 3);
            self.series.push_row_with(|row| {
                let (common, rest) = row.split_at_mut(4 + D + cables + flag);
                let (own, energies) = rest.split_at_mut(m);
                common[0] = tk;
                common[1] = cmd.reference;
                common[2..2 + D].copy_from_slice(eff.position.as_slice());
                common[2 + D] = cmd.error;
                common[3 + D] = cmd.force;
                common[4 + D..4 + D + cables].copy_from_slice(&cmd.tensions);
                if flag == 1 {
                    common[4 + D + cables] = f64::from(u8::from(cmd.saturated));
                }
                sys.model.channels(model_state, &cmd.tensions, own);
                if let Some(l0) = &paid_out {
                    for (k, &at) in self.l0_channels.iter().enumerate() {
                        own[at] = l0[k];
                    }
                }
                energies.copy_from_slice(&[
                    energy.kinetic,
                    energy.elastic,
                    energy.gravity,
                    work,
                    dissipated,
                    residual,
                ]);
            });
            self.next += 1;
        }
        Ok(())
    }
}
