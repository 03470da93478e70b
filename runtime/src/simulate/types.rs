//! What the simulator takes and reports: settings, states, steps,
//! collisions, counters and errors.

use super::integrator::{DormandPrince, Integrator};
use super::projection::residual;
use super::thresholds::SIMULTANEOUS_ULPS;
use crate::dynamics::DynamicsError;
use crate::linalg::ProjectorError;
use crate::model::Dynamics;

/// How the simulator runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// The integration method.
    pub integrator: Integrator,
    /// Project q onto h(q) = 0 and q̇ onto ker A(q) after every step.
    pub project: bool,
    /// A contact is *grazing* when |df·v| ≤ grazing · |df| · |v| there; it is
    /// reported as [`SimError::Grazing`] rather than resolved.
    pub grazing: f64,
    /// Two walls met less than this fraction of the step that finds them
    /// apart (and at least [`SIMULTANEOUS_ULPS`](super::thresholds::SIMULTANEOUS_ULPS)
    /// ulps of t) are reported as [`SimError::Simultaneous`]: the paper's
    /// law is for one wall at a time. Relative to the step, so that the
    /// judgement does not change when lengths or times are rescaled: a box
    /// 1e-12 wide is the same box as one 1 wide, seen faster.
    pub simultaneous: f64,
    /// Points per step (besides its ends) at which each wall's f is sampled
    /// for sign changes on the dense output; more are taken between two
    /// whose change of f their rates do not explain (a pole), and a step
    /// that those do not resolve is shortened.
    pub samples: usize,
}

impl Settings {
    /// How close in time two wall contacts found on a step of length h
    /// ending near t may be before they count as one simultaneous contact.
    pub(super) fn simultaneity_window(&self, t: f64, h: f64) -> f64 {
        (self.simultaneous * h.abs()).max(SIMULTANEOUS_ULPS * f64::EPSILON * t.abs())
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            integrator: Integrator::DormandPrince(DormandPrince::default()),
            project: true,
            grazing: 1e-8,
            simultaneous: 1e-9,
            samples: 3,
        }
    }
}

/// A state of the system: time, coordinates and velocities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State<const N: usize> {
    /// Time.
    pub t: f64,
    /// Coordinates q.
    pub q: [f64; N],
    /// Velocities q̇.
    pub v: [f64; N],
}

/// One collision, as resolved by the simulator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Collision<W, const N: usize> {
    /// The wall met.
    pub wall: W,
    /// When.
    pub t: f64,
    /// Where.
    pub q: [f64; N],
    /// Velocity before (v⁻).
    pub v_minus: [f64; N],
    /// Velocity after (v⁺ = (I − 2P)v⁻).
    pub v_plus: [f64; N],
    /// f(q) at the located instant: how close to the wall it was found.
    pub surface: f64,
}

/// How far the state is from satisfying the constraints.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Residual {
    /// max |(A(q) q̇)ᵣ|.
    pub velocity: f64,
    /// max |hᵣ(q)| over the holonomic constraints.
    pub position: f64,
}

/// One accepted step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step<W, const N: usize> {
    /// Time at the start of the step.
    pub t0: f64,
    /// The state at its end (after the collision, if there was one).
    pub state: State<N>,
    /// The collision that ended the step, if any.
    pub collision: Option<Collision<W, N>>,
}

impl<W, const N: usize> Step<W, N> {
    /// Total energy T + V of `model` at the end of the step. Worked out
    /// when asked, not by the step: a step's own work is the motion, and a
    /// caller that does not read the energy does not pay for it (in
    /// §3.2.1's bounces in Euler angles it would be about 3 % of a step).
    pub fn energy<M: Dynamics<N>>(&self, model: &M) -> f64 {
        model.energy(&self.state.q, &self.state.v)
    }

    /// The constraint residuals of `model` at the end of the step, when
    /// asked (as [`Step::energy`]).
    pub fn residual<M: Dynamics<N>>(&self, model: &M) -> Residual {
        residual(model, &self.state.q, &self.state.v)
    }
}

/// Counters since the simulator was made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected trial steps (adaptive integrator only).
    pub rejected: u64,
    /// Collisions resolved.
    pub collisions: u64,
    /// Evaluations of the equations of motion (with Taylor's method: series
    /// computed, the lower-order trials included).
    pub evaluations: u64,
    /// Steps of Taylor's method taken on a lower-order trial's series,
    /// below the full order (see [`super::Taylor::FIRST_TRIAL_ORDER`]).
    pub low_order_steps: u64,
    /// Taylor's method: the sum of the orders of every series computed
    /// (zero with the other methods). Over the series computed
    /// (`evaluations` less the one q̈ at the start) it is their mean order,
    /// the measure of the work: each order runs every operation of the
    /// series once, and each convolution sums more products the higher the
    /// order.
    pub series_orders: u64,
    /// Steps of Taylor's method at whose end a wall's f, evaluated
    /// directly, disagreed with the wall's series (beyond the wall, or off
    /// it at the collision found on the series), so that the step's first
    /// crossing was searched by f itself along the step. Zero where every
    /// wall's series describes f on the steps, as it should.
    pub direct_crossings: u64,
}

/// Why the simulation stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SimError<W> {
    /// The equations of motion could not be solved at time `t`: a
    /// non-finite state, a singular mass matrix or dependent constraints.
    Dynamics {
        /// When.
        t: f64,
        /// What.
        error: DynamicsError,
    },
    /// The initial state is not admissible: A(q)q̇ or h(q) is not zero
    /// (within `residual`), or it is not finite.
    Inadmissible {
        /// The residuals found.
        residual: Residual,
    },
    /// The initial state is beyond a wall (f < 0), or on it and moving in.
    StartsBeyondWall {
        /// The wall.
        wall: W,
        /// f(q).
        surface: f64,
    },
    /// Two walls are met within a fraction [`Settings::simultaneous`] of a
    /// step of each other.
    Simultaneous {
        /// The wall met first.
        first: W,
        /// The other one.
        second: W,
        /// When.
        t: f64,
    },
    /// The wall is met (or left) with almost no normal velocity.
    Grazing {
        /// The wall.
        wall: W,
        /// When.
        t: f64,
        /// df·v there.
        normal_velocity: f64,
    },
    /// The collision map is not finite or does not reverse the normal
    /// velocity: the wall's B loses rank at this configuration.
    SingularWall {
        /// The wall.
        wall: W,
        /// When.
        t: f64,
    },
    /// Projection onto the constraints failed (dependent rows, or Newton's
    /// method on h(q) = 0 did not converge).
    Projection {
        /// When.
        t: f64,
        /// What.
        error: ProjectorError,
    },
    /// The adaptive step fell below the resolution of the time axis.
    StepTooSmall {
        /// When.
        t: f64,
        /// The step.
        step: f64,
    },
    /// A setting is out of range: a step or tolerance not positive and
    /// finite, a Taylor tolerance or fixed order outside
    /// [`super::Taylor::valid`]'s ranges, a grazing or simultaneity
    /// threshold out of range.
    BadSettings,
    /// Taylor's method was asked for, but the simulator has no room for
    /// series (it was built with [`super::Simulator::new`]; use
    /// [`super::Simulator::with_series`]), or the model has no Taylor
    /// series of its motion or of a wall's f (generated models with
    /// coordinates have them; a hand-written model may not).
    NoSeries,
    /// The model has more walls than the simulator tracks
    /// ([`super::thresholds::MAX_WALLS`]).
    TooManyWalls {
        /// How many it has.
        walls: usize,
    },
}

impl<W> SimError<W> {
    /// The same error with each wall replaced by `f(wall)`: for a message
    /// that names the walls as the model file does,
    /// `e.map_wall(|w| model.wall_name(w))`.
    pub fn map_wall<V>(self, mut f: impl FnMut(W) -> V) -> SimError<V> {
        match self {
            SimError::Dynamics { t, error } => SimError::Dynamics { t, error },
            SimError::Inadmissible { residual } => SimError::Inadmissible { residual },
            SimError::StartsBeyondWall { wall, surface } => SimError::StartsBeyondWall {
                wall: f(wall),
                surface,
            },
            SimError::Simultaneous { first, second, t } => SimError::Simultaneous {
                first: f(first),
                second: f(second),
                t,
            },
            SimError::Grazing {
                wall,
                t,
                normal_velocity,
            } => SimError::Grazing {
                wall: f(wall),
                t,
                normal_velocity,
            },
            SimError::SingularWall { wall, t } => SimError::SingularWall { wall: f(wall), t },
            SimError::Projection { t, error } => SimError::Projection { t, error },
            SimError::StepTooSmall { t, step } => SimError::StepTooSmall { t, step },
            SimError::BadSettings => SimError::BadSettings,
            SimError::NoSeries => SimError::NoSeries,
            SimError::TooManyWalls { walls } => SimError::TooManyWalls { walls },
        }
    }
}

impl<W: core::fmt::Debug> core::fmt::Display for SimError<W> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SimError::Dynamics { t, error } => {
                let what = match error {
                    DynamicsError::NonFinite => "the state or the model's functions are not finite",
                    DynamicsError::SingularMassMatrix => {
                        "the mass matrix G(q) is singular (a coordinate singularity?)"
                    }
                    DynamicsError::DependentConstraints => "the constraint rows A(q) are dependent",
                };
                write!(f, "at t = {t}: {what}")
            }
            SimError::Inadmissible { residual } => write!(
                f,
                "the initial state is not admissible: |A q̇| = {:e}, |h(q)| = {:e} (or it is not finite)",
                residual.velocity, residual.position
            ),
            SimError::StartsBeyondWall { wall, surface } => write!(
                f,
                "the initial state is beyond wall {wall:?} (f = {surface:e}) or on it moving in"
            ),
            SimError::Simultaneous { first, second, t } => write!(
                f,
                "at t = {t}: walls {first:?} and {second:?} are met at the same time; the collision law is for one wall at a time"
            ),
            SimError::Grazing {
                wall,
                t,
                normal_velocity,
            } => write!(
                f,
                "at t = {t}: grazing contact with wall {wall:?} (normal velocity {normal_velocity:e})"
            ),
            SimError::SingularWall { wall, t } => write!(
                f,
                "at t = {t}: the collision map of wall {wall:?} is singular here (B loses rank)"
            ),
            SimError::Projection { t, error } => {
                write!(
                    f,
                    "at t = {t}: projection onto the constraints failed: {error}"
                )
            }
            SimError::StepTooSmall { t, step } => {
                write!(f, "at t = {t}: the step size fell to {step:e}")
            }
            SimError::BadSettings => write!(
                f,
                "a setting is out of range (a step or tolerance not positive and finite, or a Taylor tolerance or order outside its range)"
            ),
            SimError::NoSeries => write!(
                f,
                "Taylor's method needs the model's Taylor series (TaylorSeries::taylor_series and surface_series) and a simulator built with Simulator::with_series to hold them; this one has none"
            ),
            SimError::TooManyWalls { walls } => write!(
                f,
                "the model has {walls} walls; the simulator handles at most {}",
                super::thresholds::MAX_WALLS
            ),
        }
    }
}
