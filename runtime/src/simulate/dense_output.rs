//! The motion on the last step, for any time inside it
//! ([`Simulator::state_at`]): output on a grid of times without cutting the
//! steps at the grid.

use super::integrator::Dense;
use super::{Simulator, State};
use crate::Surfaces;

/// The last step's motion.
#[derive(Clone, Copy, Debug)]
pub(super) struct LastStep<const N: usize> {
    /// Its start, and the start's rounding error (the compensated time of
    /// Taylor's method; zero otherwise).
    pub t0: f64,
    pub t0_low: f64,
    /// Its end: where it stopped, or the collision that ended it.
    pub stop: f64,
    /// A Runge–Kutta step's length and interpolant; `None` for a step of
    /// Taylor's method, whose motion is the simulator's series.
    pub interpolant: Option<(f64, Dense<N>)>,
}

impl<M: Surfaces<N>, const N: usize> Simulator<'_, M, N> {
    /// The state at time `t` on the last step's dense output, for `t` from
    /// the step's start to its end ([`Step::t0`](super::Step::t0) to
    /// [`Step::state`](super::Step::state)`.t`); for a step that ended at a
    /// collision, up to its instant, the motion just before it. `None`
    /// outside that span and before the first step.
    ///
    /// With Taylor's method it is the step's own polynomial, as accurate as
    /// the step; with Dormand–Prince, Shampine's continuous extension (of
    /// order 4); with RK4, the cubic Hermite interpolant. So output at
    /// chosen times needs no step cut short: step to the end with
    /// [`Simulator::step`] and read the times each step covers. The state
    /// is not projected onto the constraints, as the steps' ends are; its
    /// residuals are those of the method between steps.
    pub fn state_at(&self, t: f64) -> Option<State<N>> {
        let last = self.last.as_ref()?;
        if !(t >= last.t0 && t <= last.stop) {
            return None;
        }
        let tau = (t - last.t0) - last.t0_low;
        let (q, v) = match &last.interpolant {
            Some((h, dense)) => {
                let y = dense.at(tau / h, *h);
                (y.q, y.v)
            }
            None => self.series()?.state(tau),
        };
        Some(State { t, q, v })
    }
}
