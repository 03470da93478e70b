//! Steps of the integrator from the simulator's state: trial steps until
//! one is accepted (step-size control), and plain steps for locating a
//! collision.

use super::integrator::{Method, RungeKutta, Trial};
use super::phase::Phase;
use super::thresholds::{FAILED_STEP_RETRIES, FAILED_STEP_SHRINK, step_too_small};
use super::{SimError, Simulator, derivative};
use crate::Surfaces;

impl<M: Surfaces<N>, const N: usize> Simulator<'_, M, N> {
    /// The end of one step of length `h` from (t0, y0), and the derivative
    /// there when the method has it for free.
    pub(super) fn advance(
        &mut self,
        method: &RungeKutta,
        y0: &Phase<N>,
        t0: f64,
        h: f64,
    ) -> Result<(Phase<N>, Option<Phase<N>>), SimError<M::Wall>> {
        let (model, stats, f0) = (self.model, &mut self.stats, self.f0);
        let mut rhs = |t: f64, y: &Phase<N>| derivative(model, stats, t, y);
        method.advance(&mut rhs, y0, &f0, t0, h)
    }

    /// One step of length `h` from (t0, y0) without error control.
    fn trial(
        &mut self,
        method: &RungeKutta,
        y0: &Phase<N>,
        t0: f64,
        h: f64,
    ) -> Result<Trial<N>, SimError<M::Wall>> {
        let (model, stats, f0) = (self.model, &mut self.stats, self.f0);
        let mut rhs = |t: f64, y: &Phase<N>| derivative(model, stats, t, y);
        method.trial(&mut rhs, y0, &f0, t0, h)
    }

    /// Trial steps of at most `limit` until one is accepted; returns its
    /// length.
    pub(super) fn accepted_trial(
        &mut self,
        method: &RungeKutta,
        y0: &Phase<N>,
        t_end: f64,
        limit: f64,
    ) -> Result<(f64, Trial<N>), SimError<M::Wall>> {
        let t0 = self.state.t;
        let mut rejected = false;
        let mut failures = 0;
        loop {
            let h = self.proposal.min(t_end - t0).min(limit);
            if step_too_small(h, t0) && t0 + h < t_end {
                return Err(SimError::StepTooSmall { t: t0, step: h });
            }
            if !method.adaptive() {
                return Ok((h, self.trial(method, y0, t0, h)?));
            }
            // A stage that lands on a singular or non-finite state may only
            // mean the step is too long: shrink it a few times before
            // reporting the error.
            let trial = match self.trial(method, y0, t0, h) {
                Ok(trial) => trial,
                Err(SimError::Dynamics { .. }) if failures < FAILED_STEP_RETRIES => {
                    failures += 1;
                    self.proposal = FAILED_STEP_SHRINK * h;
                    rejected = true;
                    self.stats.rejected += 1;
                    continue;
                }
                Err(e) => return Err(e),
            };
            let fac = method.factor(trial.error);
            if trial.error <= 1.0 {
                // At most 1 right after a rejection.
                let fac = if rejected { fac.min(1.0) } else { fac };
                // A step cut short by t_end or by an aim says nothing
                // against the longer proposal: keep it if it is longer.
                let grown = h * fac;
                let proposal = if h < self.proposal {
                    self.proposal.max(grown)
                } else {
                    grown
                };
                self.proposal = proposal.min(method.max_step());
                return Ok((h, trial));
            }
            self.proposal = h * fac.min(1.0);
            rejected = true;
            self.stats.rejected += 1;
        }
    }
}
