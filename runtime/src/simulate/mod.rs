//! The hybrid simulator: the paper's generalized solutions.
//!
//! Between collisions the state (q, q̇) follows the Lagrange–d'Alembert
//! equations ([`crate::dynamics::qdd`]: the generated closed form, or a
//! numeric solve), integrated by fixed-step RK4 or by the adaptive
//! Dormand–Prince 5(4) pair, both with dense output
//! (cubic Hermite for RK4; Shampine's fourth-order continuous extension for
//! Dormand–Prince, Hairer–Nørsett–Wanner, *Solving ODEs I*, §II.6). After
//! every step each wall's f(q) is sampled on the dense output; a sign change
//! from f > 0 to f ≤ 0 is bracketed, located on the dense output by the
//! Illinois method, then polished by Newton's method on f along *real*
//! integrator steps from the step's start, so that |f(q)| at the collision is
//! at the level of rounding. There the collision map v⁺ = (I − 2P)v⁻ is
//! applied and the integration resumes.
//!
//! Adaptive steps are also *aimed*: before a step, each wall's f is
//! predicted by its second-order Taylor polynomial in time (f, df·q̇ and
//! f̈ = df·q̈ + q̇ᵀ∇²f q̇, from [`Surfaces::surface_hessian`]) and the step is
//! made to end where that polynomial first falls through zero. Where f is
//! quadratic in time (a flight in uniform gravity to a plane) the step ends
//! on the wall and the collision is polished from its end by a Taylor step,
//! so no step across the wall has to be redone; elsewhere the prediction
//! only shortens a step and the crossing is found as above.
//!
//! With [`Integrator::Taylor`] the step is instead the truncated Taylor
//! series of the motion, from the model's generated series
//! ([`crate::TaylorSeries::taylor_series`]), of the order and length the
//! tolerance asks for (Jorba & Zou); each wall's f along the step is a
//! polynomial too ([`crate::TaylorSeries::surface_series`]), and its first descending
//! root on the step is found on that polynomial to rounding, so a collision
//! needs no further steps. A wall's series bounds the step as the motion's
//! does (a wall through a square root or a quotient may converge on a far
//! shorter interval than the motion), and at the end of every step each
//! wall's f is evaluated itself: a step that would end beyond a wall, or at
//! a collision off it, is searched again by f along the step's polynomial,
//! as a Runge–Kutta step is on its dense output
//! ([`Stats::direct_crossings`]). So no method reports a state beyond a
//! wall. Time is summed in compensated arithmetic.
//!
//! Nothing is silently wrong: two walls met within a fraction
//! [`Settings::simultaneous`] of a step of each other, a contact whose normal velocity
//! is too small to tell whether the wall is met ([`Settings::grazing`]), a
//! collision map that does not reverse the normal velocity (a configuration
//! where B loses rank), non-finite states and singular mass matrices are all
//! typed errors carrying where they happened.
//!
//! After every step the velocities are projected back onto ker A(q) and the
//! coordinates onto h(q) = 0 (when the model has holonomic constraints), in
//! the metric of G, so constraint drift stays at rounding level; the energy
//! and the constraint residuals are reported with every step.
//!
//! The parts, one file each: [`integrator`] (the methods, their tableaux,
//! dense output and step control), `events` (aiming and crossing
//! detection), `collision` (locating and resolving a collision),
//! `projection` (back onto the constraints), [`thresholds`] (every
//! numerical judgement in one place).
//!
//! No heap allocation; `#![no_std]`.

mod collision;
mod control;
mod dense_output;
mod enclosure;
mod events;
pub mod integrator;
mod path;
mod phase;
mod projection;
mod return_map;
mod room;
mod roots;
mod series;
pub mod thresholds;
mod types;
mod variational;

pub use integrator::{DormandPrince, Integrator, Rk4, Taylor};
pub use projection::{
    StartRule, admissible, onto_holonomic, residual, starting_velocity, starting_velocity_with,
    tangent_direction,
};
pub use return_map::{Return, ReturnError, Section, return_map};
pub use room::SeriesRoom;
pub use types::{Collision, Residual, Settings, SimError, State, Stats, Step};
pub use variational::{ParameterSensitivity, Variational, VariationalError};

use crate::Surfaces;
use crate::dynamics::{accelerations, qdd};
use dense_output::LastStep;
use events::Scan;
use integrator::{Engine, Method, RungeKutta};
use path::RkStep;
use phase::{Phase, norm};
use room::Room;
use thresholds::{ADMISSIBLE, MAX_WALLS, ON_WALL, TAYLOR_REACH};

/// The hybrid simulator for a model with coordinates (`Q = N`).
pub struct Simulator<'m, M: Surfaces<N>, const N: usize> {
    model: &'m M,
    settings: Settings,
    engine: Engine,
    state: State<N>,
    /// The rounding error of `state.t` (compensated summation of the
    /// steps of Taylor's method; zero otherwise).
    t_low: f64,
    /// (q̇, q̈) at `state`.
    f0: Phase<N>,
    /// The length proposed for the next trial step.
    proposal: f64,
    /// Walls (bit per index into the model's `walls()`) just collided with and not yet
    /// left: their f starts at ≈ 0 and must become positive first.
    departing: u64,
    /// When the last collision happened.
    last_collision: Option<f64>,
    /// Taylor's method: whether the next step tries a lower order first,
    /// and which (`series.rs`).
    low_order_first: bool,
    low_order: usize,
    /// Taylor's method: the series of the current step, a buffer reused
    /// by every step, and the room for the model's intermediate series
    /// (only in a simulator built by [`Simulator::with_series`]).
    room: Option<&'m mut dyn Room<N>>,
    /// The last step's motion ([`Simulator::state_at`]).
    last: Option<LastStep<N>>,
    stats: Stats,
}

/// Where a collision found on a step is polished from.
#[derive(Clone, Copy, Debug)]
struct Located<const N: usize> {
    /// Index into the model's `walls()`.
    wall: usize,
    /// A time near the collision, the state there from a real step, and
    /// the derivative there when known.
    t: f64,
    y: Phase<N>,
    f: Option<Phase<N>>,
    /// Newton's method stays in [t₀, t_hi].
    t_hi: f64,
}

/// (q̇, q̈) of `m` at y, counted.
fn derivative<M: Surfaces<N>, const N: usize>(
    m: &M,
    stats: &mut Stats,
    t: f64,
    y: &Phase<N>,
) -> Result<Phase<N>, SimError<M::Wall>> {
    stats.evaluations += 1;
    let qdd = qdd(m, &y.q, &y.v).map_err(|error| SimError::Dynamics { t, error })?;
    Ok(Phase { q: y.v, v: qdd })
}

impl<'m, M: Surfaces<N>, const N: usize> Simulator<'m, M, N> {
    /// A simulator from `start`, for the Runge–Kutta methods (Taylor's
    /// method needs [`Simulator::with_series`]: with it this is
    /// [`SimError::NoSeries`]). The state must be admissible (A q̇ = 0 and
    /// h(q) = 0 to within [`thresholds::ADMISSIBLE`] relative) and in f ≥ 0
    /// for every wall; on a wall (f = 0) it must be moving away from it.
    pub fn new(
        model: &'m M,
        start: State<N>,
        settings: Settings,
    ) -> Result<Self, SimError<M::Wall>> {
        Self::build(model, None, start, settings)
    }

    /// A simulator from `start` for any of the methods, Taylor's too, with
    /// `room` for the series of its steps (see [`Simulator::new`] for what
    /// `start` must be). The room is used only by Taylor's method, and is
    /// the only place its buffers live.
    pub fn with_series<'r>(
        room: &'m mut SeriesRoom<'r, M, N>,
        start: State<N>,
        settings: Settings,
    ) -> Result<Self, SimError<M::Wall>>
    where
        M: crate::TaylorSeries<N>,
        'r: 'm,
    {
        let model = room.model();
        Self::build(model, Some(room as &mut dyn Room<N>), start, settings)
    }

    fn build(
        model: &'m M,
        mut room: Option<&'m mut dyn Room<N>>,
        start: State<N>,
        settings: Settings,
    ) -> Result<Self, SimError<M::Wall>> {
        if !settings.integrator.valid()
            || settings.grazing.is_nan()
            || !(settings.simultaneous >= 0.0 && settings.simultaneous < 1.0)
        {
            return Err(SimError::BadSettings);
        }
        if model.walls().len() > MAX_WALLS {
            return Err(SimError::TooManyWalls {
                walls: model.walls().len(),
            });
        }
        let residual = residual(model, &start.q, &start.v);
        let scale = 1.0 + norm(&start.v) + norm(&start.q);
        let y = Phase {
            q: start.q,
            v: start.v,
        };
        let finite = start.t.is_finite() && y.finite();
        // NaN residuals fail `within` too.
        let within = |x: f64| x <= ADMISSIBLE * scale;
        if !finite || !within(residual.velocity) || !within(residual.position) {
            return Err(SimError::Inadmissible { residual });
        }
        let mut departing = 0;
        for (k, &wall) in model.walls().iter().enumerate() {
            let f = model.surface(wall, &start.q);
            if f <= 0.0 {
                if f < -ON_WALL * scale || model.normal_velocity(wall, &start.q, &start.v) <= 0.0 {
                    return Err(SimError::StartsBeyondWall { wall, surface: f });
                }
                departing |= 1 << k;
            }
        }
        // The numeric solve checks that G (and A G⁻¹Aᵀ) is positive definite
        // with these parameters, which a closed form used later does not.
        accelerations(model, &start.q, &start.v)
            .map_err(|error| SimError::Dynamics { t: start.t, error })?;
        let mut stats = Stats::default();
        let f0 = derivative(model, &mut stats, start.t, &y)?;
        let mut engine = settings.integrator.engine();
        let (proposal, low_order) = match &mut engine {
            Engine::RungeKutta(m) => (m.initial_step(&y, &f0), 0),
            Engine::Taylor(t) => {
                let room = room.as_deref_mut().ok_or(SimError::NoSeries)?;
                series::offered(room, &start, model.walls().len())?;
                *t = t.fitted(room.work(), N, model.walls().len());
                (f64::INFINITY, Taylor::FIRST_TRIAL_ORDER)
            }
        };
        Ok(Self {
            model,
            settings,
            engine,
            state: start,
            t_low: 0.0,
            f0,
            proposal,
            departing,
            last_collision: None,
            low_order_first: true,
            low_order,
            room,
            last: None,
            stats,
        })
    }

    /// The current state.
    pub fn state(&self) -> &State<N> {
        &self.state
    }

    /// Counters so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// The model simulated.
    pub fn model(&self) -> &'m M {
        self.model
    }

    /// The order Taylor's method steps at for this model
    /// ([`Taylor::order_for`]); `None` for the other methods.
    pub fn taylor_order(&self) -> Option<usize> {
        match self.engine {
            Engine::Taylor(t) => Some(t.order),
            Engine::RungeKutta(_) => None,
        }
    }

    /// Constraint residuals of the current state.
    pub fn residual(&self) -> Residual {
        residual(self.model, &self.state.q, &self.state.v)
    }

    /// Advances by one accepted step, ending at the first collision in it or
    /// at `t_end`, whichever comes first. At `t_end` already, returns the
    /// current state as a step of length zero.
    pub fn step(&mut self, t_end: f64) -> Result<Step<M::Wall, N>, SimError<M::Wall>> {
        let t0 = self.state.t;
        if t_end <= t0 {
            return Ok(self.report(t0, None));
        }
        match self.engine {
            Engine::RungeKutta(m) => self.runge_kutta_step(&m, t_end),
            Engine::Taylor(t) => self.series_step(&t, t_end),
        }
    }

    /// [`Simulator::step`] by a Runge–Kutta method.
    fn runge_kutta_step(
        &mut self,
        method: &RungeKutta,
        t_end: f64,
    ) -> Result<Step<M::Wall, N>, SimError<M::Wall>> {
        let t0 = self.state.t;
        let y0 = self.phase();
        let aim = self.aim(method, &y0);
        let mut limit = aim.map_or(f64::INFINITY, |a| a.tau);
        // A step along which a wall's f is not resolved is tried again,
        // shorter (counted as rejected), from a proposal no longer than
        // that: the next steps grow from there as the method allows.
        let (h, trial, crossing) = loop {
            let (h, trial) = self.accepted_trial(method, &y0, t_end, limit)?;
            let path = RkStep {
                y0: &y0,
                trial: &trial,
                h,
            };
            match self.scan(&path, t0, h)? {
                Scan::Clear => break (h, trial, None),
                Scan::Crossing(c) => break (h, trial, Some(c)),
                Scan::Unresolved(u) => {
                    limit = u.shorter(h);
                    self.proposal = self.proposal.min(limit);
                    self.stats.rejected += 1;
                }
            }
        };
        let t1 = if t0 + h >= t_end { t_end } else { t0 + h };
        let reach = TAYLOR_REACH * h;
        let at_end = |wall: usize, t_hi: f64| Located {
            wall,
            t: t1,
            y: trial.y1,
            f: Some(trial.f1),
            t_hi,
        };
        let found = match crossing {
            // Met at the very end of the step: polish from there.
            Some(c) if t1 - c.t <= reach => Some(at_end(c.wall, t1)),
            Some(c) => {
                let (y, f) = self.advance(method, &y0, t0, c.t - t0)?;
                Some(Located {
                    wall: c.wall,
                    t: c.t,
                    y,
                    f,
                    t_hi: t1,
                })
            }
            // A step aimed at a predicted collision that ends just short of
            // the wall: the collision is a Taylor step ahead.
            None => aim.filter(|a| a.tau == h).and_then(|a| {
                let wall = self.model.walls()[a.wall];
                let f = self.model.surface(wall, &trial.y1.q);
                let nv = self.model.normal_velocity(wall, &trial.y1.q, &trial.y1.v);
                let ahead = -f / nv;
                (f > 0.0 && nv < 0.0 && ahead <= reach && t1 + ahead <= t_end)
                    .then(|| at_end(a.wall, t1 + ahead))
            }),
        };
        let mut last = LastStep {
            t0,
            t0_low: 0.0,
            stop: t1,
            interpolant: Some((h, trial.dense)),
        };
        match found {
            Some(located) => {
                let collision = self.collide(method, &y0, t0, located)?;
                self.stats.steps += 1;
                self.stats.collisions += 1;
                last.stop = collision.t;
                self.last = Some(last);
                Ok(self.report(t0, Some(collision)))
            }
            None => {
                self.last = Some(last);
                self.state = State {
                    t: t1,
                    q: trial.y1.q,
                    v: trial.y1.v,
                };
                self.f0 = trial.f1;
                self.leave_walls();
                self.project()?;
                self.stats.steps += 1;
                Ok(self.report(t0, None))
            }
        }
    }

    /// Runs to `t_end`, calling `on_step` after every accepted step; stops
    /// early (and returns `Ok`) when `on_step` returns `false`.
    pub fn run(
        &mut self,
        t_end: f64,
        mut on_step: impl FnMut(&Step<M::Wall, N>) -> bool,
    ) -> Result<Stats, SimError<M::Wall>> {
        while self.state.t < t_end {
            let step = self.step(t_end)?;
            if !on_step(&step) {
                break;
            }
        }
        Ok(self.stats)
    }

    fn report(&self, t0: f64, collision: Option<Collision<M::Wall, N>>) -> Step<M::Wall, N> {
        Step {
            t0,
            state: self.state,
            collision,
        }
    }

    /// The current state as a phase point.
    fn phase(&self) -> Phase<N> {
        Phase {
            q: self.state.q,
            v: self.state.v,
        }
    }

    /// (q̇, q̈) at y.
    fn rhs(&mut self, t: f64, y: &Phase<N>) -> Result<Phase<N>, SimError<M::Wall>> {
        derivative(self.model, &mut self.stats, t, y)
    }

    /// Forgets walls that the state has left (f > 0).
    fn leave_walls(&mut self) {
        for (k, &wall) in self.model.walls().iter().enumerate() {
            if self.departing & (1 << k) != 0 && self.model.surface(wall, &self.state.q) > 0.0 {
                self.departing &= !(1 << k);
            }
        }
    }
}

/// Numbers uniform in [0, 1) from a xorshift generator: the unit tests'
/// random cases, the same on every run.
#[cfg(test)]
pub(crate) fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}
