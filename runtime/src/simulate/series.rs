//! Steps of Taylor's method: the series of the motion from the state, the
//! step from its last coefficients, each wall's f along the step as a
//! polynomial, and the first collision found on that polynomial to
//! rounding (samples for a sign change or a turn towards the wall, then
//! Newton's method kept inside the bracket). The state at the collision is
//! the step's polynomial there, so a collision costs no further steps.

use super::dense_output::LastStep;
use super::enclosure::Ends;
use super::events::Scan;
use super::integrator::{Plan, Reach};
use super::path::SeriesStep;
use super::phase::Phase;
use super::room::Room;
use super::roots::first_root;
use super::thresholds::{
    LONGEST_SERIES_STEP, ON_WALL_ULPS, POLISH_STEPS, SERIES_CHECK, TAYLOR_REACH, step_too_small,
};
use super::{SimError, Simulator, State, Step};
use crate::dynamics::DynamicsError;
use crate::taylor::{CAPACITY, Coefficients, Series, degree, eval_with_derivative};
use crate::{Surfaces, libm};

/// Whether the model of `room` has the series Taylor's method needs (of
/// the motion and of each of its `walls` walls' f), tried from `start`.
pub(super) fn offered<W, const N: usize>(
    room: &mut dyn Room<N>,
    start: &State<N>,
    walls: usize,
) -> Result<(), SimError<W>> {
    let mut f = [0.0; CAPACITY];
    let all = room.expand(&start.q, &start.v, 1) && (0..walls).all(|k| room.surface(k, &mut f));
    all.then_some(()).ok_or(SimError::NoSeries)
}

impl<M: Surfaces<N>, const N: usize> Simulator<'_, M, N> {
    /// [`Simulator::step`] by Taylor's method. Where the step is likely to
    /// end at a wall (the first step, and after a step that ended at one or
    /// was taken at a lower order) the series is first computed only to a
    /// lower order: if its own step, short enough for the tolerance at that
    /// order, already reaches a collision or the end of the run, no order
    /// could step further, and the step is taken on it. Otherwise the
    /// series is computed again to the full order, and the lower order is
    /// raised (from [`Taylor::FIRST_TRIAL_ORDER`] up to the full order,
    /// where the trials stop) to the lowest order whose own step, read off
    /// the same coefficients ([`Plan::reach`], [`Plan::covers`]), reaches as
    /// far as the full one went: to the wall it meets at τ, else to the end
    /// of its step. So each run learns from its first flight the lowest
    /// order its flights need, and again, in one trial, each time a flight
    /// needs more; a motion whose steps the radius of convergence bounds
    /// (where no lower order steps as far) wastes one trial. A flight in
    /// uniform gravity is the case in point: its motion is nearly
    /// polynomial, so a lower order reaches the floor at a fraction of the
    /// cost (a parabola's at order 4, where its last two terms vanish), and
    /// the cost of a series grows as the square of its order.
    ///
    /// [`Taylor::FIRST_TRIAL_ORDER`]: super::Taylor::FIRST_TRIAL_ORDER
    pub(super) fn series_step(
        &mut self,
        method: &Plan,
        t_end: f64,
    ) -> Result<Step<M::Wall, N>, SimError<M::Wall>> {
        let t0 = self.state.t;
        let left = (t_end - t0) - self.t_low;
        let tried = self.low_order_first && self.low_order < method.order;
        if tried {
            let mut limit = self.expand(method, self.low_order, left)?;
            let found = self.first_collision(&mut limit)?;
            if found.is_some() || limit.length(t0)? >= left {
                self.stats.low_order_steps += 1;
                return self.take(&mut limit, t_end, found);
            }
        }
        let mut limit = self.expand(method, method.order, left)?;
        let found = self.first_collision(&mut limit)?;
        let h = limit.length(t0)?;
        // The Runge–Kutta steps' rule (a fixed order far below the
        // tolerance's steps by about ε/‖q̇‖ at order 2).
        if step_too_small(h, t0) && h < left {
            return Err(SimError::StepTooSmall { t: t0, step: h });
        }
        if tried {
            // (From the motion's series alone: where a wall's series
            // bounds the step, a lower order may fall short of it and cost
            // a trial at the next landing.)
            let reach = found.map_or(h, |f| f.tau);
            self.low_order = (self.low_order + 1..method.order)
                .find(|&p| {
                    self.series()
                        .is_some_and(|s| method.covers(&method.reach(s, p), reach))
                })
                .unwrap_or(method.order);
        }
        self.low_order_first = found.is_some();
        self.take(&mut limit, t_end, found)
    }

    /// The series of the step last expanded (`None` only in a simulator
    /// without room for series, which never takes a step of Taylor's
    /// method).
    pub(super) fn series(&self) -> Option<&Series<N>> {
        self.room.as_deref().map(|r| r.series())
    }

    /// Columns of the variational flow along the last step's series,
    /// extended to `order` where that is higher than its own
    /// ([`TaylorSeries::variational_series`](crate::TaylorSeries::variational_series));
    /// `false` where there is no room or the model has no such series.
    pub(super) fn variational_series(&self, columns: &mut [Series<N>], order: usize) -> bool {
        self.room
            .as_deref()
            .is_some_and(|r| r.variational(columns, order))
    }

    /// The state (q, q̇) at τ on the step's series.
    fn series_state(&self, tau: f64) -> Result<QV<N>, SimError<M::Wall>> {
        Ok(self.series().ok_or(SimError::NoSeries)?.state(tau))
    }

    /// The series of the motion from the current state to `order`, into
    /// the room, and the step it allows (at most `left`).
    fn expand<'p>(
        &mut self,
        method: &'p Plan,
        order: usize,
        left: f64,
    ) -> Result<Limit<'p>, SimError<M::Wall>> {
        // NaN fails too.
        if left.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return Err(SimError::StepTooSmall {
                t: self.state.t,
                step: left,
            });
        }
        let room = self.room.as_deref_mut().ok_or(SimError::NoSeries)?;
        if !room.expand(&self.state.q, &self.state.v, order) {
            return Err(SimError::NoSeries);
        }
        let s = room.series();
        self.stats.evaluations += 1;
        self.stats.series_orders += order as u64;
        // Non-finite coefficients are caught where the step is evaluated
        // (`finite` below): Horner's scheme carries an infinity or a NaN in
        // any coefficient into the value at any τ > 0, so checking the 2N
        // values there costs far less than checking every coefficient.
        Ok(Limit {
            plan: method,
            reach: method.reach(s, order),
            left,
            length: None,
        })
    }

    /// The first collision on the step `limit` allows along
    /// the room's series; grazing and simultaneous contacts as errors. Each
    /// wall's series also bounds the step (its roots are searched only
    /// where it converges: [`Plan::tighten`]), so a wall met beyond where a
    /// later wall's series converges is not on the step.
    fn first_collision(&mut self, limit: &mut Limit) -> Result<Option<Found>, SimError<M::Wall>> {
        let (t0, m) = (self.state.t, self.model);
        let room = self.room.as_deref_mut().ok_or(SimError::NoSeries)?;
        let order = room.series().order;
        // The earliest and the next event: (wall, τ, what, the step's
        // bounds then): what is Ok(f's scale) for a collision, Err(normal
        // velocity) for a departure that turns back first.
        let mut best: Option<(usize, f64, Result<f64, f64>, Reach)> = None;
        let mut second: Option<(usize, f64, Reach)> = None;
        let mut f = [0.0; CAPACITY];
        for k in 0..m.walls().len() {
            room.surface(k, &mut f);
            limit.tighten(&f);
            let departing = self.departing & (1 << k) != 0;
            let (tau, what) = match limit.first_root(&f, order, departing, t0)? {
                Ok(Some(tau)) => (tau, Ok(libm::fabs(f[0]).max(1.0))),
                Ok(None) => continue,
                Err(top) => (top, Err(eval_with_derivative(&f, order, top).1)),
            };
            let reach = limit.reach;
            match best {
                Some((_, b, _, _)) if b <= tau => {
                    if second.is_none_or(|(_, x, _)| tau < x) {
                        second = Some((k, tau, reach));
                    }
                }
                _ => {
                    second = best.map(|(j, b, _, r)| (j, b, r));
                    best = Some((k, tau, what, reach));
                }
            }
        }
        // An event found before a later wall's series shortened the step
        // may lie beyond it, and is then not on the step (the second comes
        // no earlier than the first).
        let on_step = |tau: f64, then: Reach| then == limit.reach || limit.covers(tau);
        let Some((k, a, what, _)) = best.filter(|&(_, tau, _, r)| on_step(tau, r)) else {
            return Ok(None);
        };
        let scale = match what {
            Ok(scale) => scale,
            Err(normal_velocity) => {
                return Err(SimError::Grazing {
                    wall: m.walls()[k],
                    t: t0 + a,
                    normal_velocity,
                });
            }
        };
        if let Some((j, b, _)) = second.filter(|&(_, tau, r)| on_step(tau, r))
            && b - a <= self.settings.simultaneity_window(t0 + a, limit.length(t0)?)
        {
            return Err(SimError::Simultaneous {
                first: m.walls()[k],
                second: m.walls()[j],
                t: t0 + a,
            });
        }
        Ok(Some(Found {
            wall: k,
            tau: a,
            scale,
        }))
    }

    /// Whether every wall, its f evaluated directly at the state (q, v)
    /// where the step along the series ends, agrees with what was found on
    /// the walls' series: on the wall `found` met (|f| within
    /// [`SERIES_CHECK`] times the tolerance, at least the unit roundoff, of
    /// max(1, |f₀|)), and not beyond any other (f > 0, or leaving a wall
    /// just collided with). A series that converges on the step always
    /// agrees; one that was trusted beyond where it describes f would
    /// otherwise let the state through a wall. `Some(f)` where they agree,
    /// with the f of the wall met (0 where none was).
    fn agrees(
        &self,
        found: Option<Found>,
        q: &[f64; N],
        v: &[f64; N],
        tolerance: f64,
    ) -> Option<f64> {
        let m = self.model;
        let mut met = 0.0;
        for (j, &wall) in m.walls().iter().enumerate() {
            let f = m.surface(wall, q);
            let fine = match found {
                Some(c) if c.wall == j => {
                    met = f;
                    libm::fabs(f) <= SERIES_CHECK * tolerance.max(f64::EPSILON) * c.scale
                }
                _ => {
                    f > 0.0
                        || (self.departing & (1 << j) != 0 && m.normal_velocity(wall, q, v) > 0.0)
                }
            };
            if !fine {
                return None;
            }
        }
        Some(met)
    }

    /// Whether no wall is crossed before τ = `end` on the step's
    /// polynomial as far as the bounds on each wall's f can tell
    /// ([`Simulator::earlier_crossing`]): the walls' series are searched
    /// for roots at samples, and a series that is exact but flat at the
    /// step's start (a narrow bump of the floor far ahead) shows nothing.
    /// `q1` is q at τ = `end`; the step starts at `self.state`.
    fn clear_before(&self, end: f64, q1: &[f64; N]) -> bool {
        let m = self.model;
        let Some(series) = self.series() else {
            return false;
        };
        let path = SeriesStep { series, tau: end };
        let y0 = &self.state;
        m.walls().iter().enumerate().all(|(k, &wall)| {
            let f0 = m.surface(wall, &y0.q);
            let departing = self.departing & (1 << k) != 0;
            let ends = Ends {
                f0,
                leaving: departing && f0 <= 0.0 && m.normal_velocity(wall, &y0.q, &y0.v) > 0.0,
                end: 1.0,
                f_end: m.surface(wall, q1),
            };
            self.earlier_crossing(k, &path, &ends).is_none()
        })
    }

    /// The collision with wall `k` found at τ on the step's polynomial
    /// (where the state is `y` and the wall's f is `f`), moved onto the wall
    /// as f itself has it: Newton's method on f along the polynomial, as a
    /// Runge–Kutta step's collision is polished. f's series and f agree to
    /// the tolerance, so the instant moves by about that over the normal
    /// velocity; a correction is kept only while it brings f closer to 0
    /// and stays within [`TAYLOR_REACH`] of τ.
    fn onto_wall(
        &self,
        k: usize,
        mut tau: f64,
        mut y: ([f64; N], [f64; N]),
        mut f: f64,
    ) -> (f64, ([f64; N], [f64; N])) {
        let (m, wall) = (self.model, self.model.walls()[k]);
        let reach = TAYLOR_REACH * tau;
        let start = tau;
        for _ in 0..POLISH_STEPS {
            let nv = m.normal_velocity(wall, &y.0, &y.1);
            if f == 0.0 || nv.is_nan() || nv >= 0.0 {
                break;
            }
            let next = tau - f / nv;
            if !(next > 0.0 && libm::fabs(next - start) <= reach) || next == tau {
                break;
            }
            let Ok(candidate) = self.series_state(next) else {
                break;
            };
            let f_next = m.surface(wall, &candidate.0);
            if f_next.is_nan() || libm::fabs(f_next) >= libm::fabs(f) {
                break;
            }
            (tau, y, f) = (next, candidate, f_next);
        }
        (tau, y)
    }

    /// The step along the room's series: to the collision `found`, else as
    /// far as `limit` allows (to `t_end` if that reaches it).
    ///
    /// The walls are checked where the step ends ([`Simulator::agrees`]);
    /// where one disagrees, the step's first crossing is searched as a
    /// Runge–Kutta step's is, by f itself along the step's polynomial
    /// over the whole step
    /// ([`Stats::direct_crossings`](super::Stats::direct_crossings)).
    fn take(
        &mut self,
        limit: &mut Limit,
        t_end: f64,
        mut found: Option<Found>,
    ) -> Result<Step<M::Wall, N>, SimError<M::Wall>> {
        let t0 = self.state.t;
        let left = limit.left;
        let mut end = match found {
            Some(c) => c.tau,
            None => limit.length(t0)?,
        };
        let mut y = finite(self.series_state(end)?, t0)?;
        let agreed = self
            .agrees(found, &y.0, &y.1, limit.plan.method.tolerance)
            .filter(|_| self.clear_before(end, &y.0));
        if let (Some(c), Some(f)) = (found, agreed)
            && libm::fabs(f) > ON_WALL_ULPS * f64::EPSILON * c.scale
        {
            (end, y) = self.onto_wall(c.wall, c.tau, y, f);
            found = Some(Found { tau: end, ..c });
        }
        if agreed.is_none() {
            // The whole step is searched (a collision found on a series
            // that f contradicts says nothing of where the wall is).
            self.stats.direct_crossings += 1;
            let h = limit.length(t0)?;
            let path = SeriesStep {
                series: self.series().ok_or(SimError::NoSeries)?,
                tau: h,
            };
            (found, end) = match self.scan(&path, t0, h)? {
                Scan::Clear => (None, h),
                Scan::Crossing(c) => {
                    let tau = c.theta * h;
                    let wall = c.wall;
                    (
                        Some(Found {
                            wall,
                            tau,
                            scale: 1.0,
                        }),
                        tau,
                    )
                }
                // The polynomial holds the motion over the whole step: it
                // ends before the interval instead.
                Scan::Unresolved(u) => (None, u.shorter(h)),
            };
            y = finite(self.series_state(end)?, t0)?;
        }
        let (q, v) = y;
        self.stats.steps += 1;
        let t0_low = self.t_low;
        let last = |stop| LastStep {
            t0,
            t0_low,
            stop,
            interpolant: None,
        };
        match found {
            Some(Found { wall: k, tau, .. }) => {
                let tc = self.time_after(tau);
                let settings = self.settings;
                let window = || settings.simultaneity_window(tc.0, limit.length_or_nan());
                let collision = self.land(k, tc, &Phase { q, v }, t0, window)?;
                self.last = Some(last(tc.0));
                self.stats.collisions += 1;
                Ok(self.report(t0, Some(collision)))
            }
            None => {
                let h = end;
                let (t1, low) = if h >= left {
                    (t_end, 0.0)
                } else {
                    self.time_after(h)
                };
                self.last = Some(last(t1));
                self.state = State { t: t1, q, v };
                self.t_low = low;
                self.leave_walls();
                self.project()?;
                Ok(self.report(t0, None))
            }
        }
    }

    /// t + tau in compensated arithmetic, with its error term for
    /// `t_low`: the rounded sum of every step so far, not of the rounded
    /// partial sums. Nothing is kept here: the pair becomes the clock only
    /// with the state it belongs to, so a step that fails leaves no
    /// rounding term behind.
    fn time_after(&self, tau: f64) -> (f64, f64) {
        let t = self.state.t;
        let hi = t + tau;
        // Knuth's two-sum: the exact error of t + tau.
        let b = hi - t;
        let err = (t - (hi - b)) + (tau - b);
        let low = self.t_low + err;
        let sum = hi + low;
        (sum, low - (sum - hi))
    }
}

/// A state (q, q̇) on a step's series.
type QV<const N: usize> = ([f64; N], [f64; N]);

/// A collision found on a step of Taylor's method: the wall's index, τ
/// from the step's start, and the scale of its f there, max(1, |f₀|).
#[derive(Clone, Copy, Debug)]
struct Found {
    wall: usize,
    tau: f64,
    scale: f64,
}

/// How far a step on a series may go: within the tolerance (the
/// [`Reach`] of its [`Plan`]) and the run's end (`left`). Its length,
/// Jorba & Zou's estimate, takes two logarithms and an exponential, so it
/// is computed only where a step needs it: whether a collision's instant is
/// within the step is decided without them ([`Plan::covers`]), and a
/// polynomial of degree 2 or less is searched for roots exactly on any
/// window ([`first_root`]), so a cheap window at least as long as the step
/// ([`Plan::beyond`]) serves. A flight's f is of that kind, and its step
/// ends at the wall.
struct Limit<'p> {
    plan: &'p Plan,
    reach: Reach,
    left: f64,
    length: Option<f64>,
}

impl Limit<'_> {
    /// The step's length, at most `left`; positive, else the step is too
    /// small (a NaN or an infinite coefficient among the last two).
    fn length<W>(&mut self, t: f64) -> Result<f64, SimError<W>> {
        let h = self.length_or_nan();
        // NaN fails too.
        if h.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return Err(SimError::StepTooSmall { t, step: h });
        }
        Ok(h)
    }

    /// The step's length, at most `left` and [`LONGEST_SERIES_STEP`],
    /// unchecked.
    fn length_or_nan(&mut self) -> f64 {
        let (plan, reach, left) = (self.plan, &self.reach, self.left);
        *self
            .length
            .get_or_insert_with(|| plan.length(reach).min(left).min(LONGEST_SERIES_STEP))
    }

    /// Bounds the step by one more series along it, a wall's f
    /// ([`Plan::tighten`]).
    fn tighten(&mut self, f: &Coefficients) {
        let before = self.reach;
        self.plan.tighten(&mut self.reach, f);
        if self.reach != before {
            self.length = None;
        }
    }

    /// Whether τ is within the step.
    fn covers(&self, tau: f64) -> bool {
        tau <= self.left && self.plan.covers(&self.reach, tau)
    }

    /// [`first_root`] of `c` (of `order`) on this step, from t.
    fn first_root<W>(
        &mut self,
        c: &Coefficients,
        order: usize,
        departing: bool,
        t: f64,
    ) -> Result<Result<Option<f64>, f64>, SimError<W>> {
        // Trailing zeros cost evaluations and say nothing (a flight's f is
        // often of degree 2).
        let order = degree(c, order);
        if order <= 2 {
            let window = self.plan.beyond(&self.reach).min(self.left);
            if window < f64::INFINITY {
                return Ok(match first_root(c, order, window, departing) {
                    Ok(Some(tau)) if !self.covers(tau) => Ok(None),
                    Err(top) if !self.covers(top) => Ok(None),
                    found => found,
                });
            }
        }
        Ok(first_root(c, order, self.length(t)?, departing))
    }
}

/// The state on the step's polynomial, if finite (a non-finite series
/// gives a non-finite state at every τ > 0).
fn finite<W, const N: usize>((q, v): QV<N>, t0: f64) -> Result<QV<N>, SimError<W>> {
    if q.iter().chain(&v).all(|x| x.is_finite()) {
        Ok((q, v))
    } else {
        Err(SimError::Dynamics {
            t: t0,
            error: DynamicsError::NonFinite,
        })
    }
}
