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
//! f̈ = df·q̈ + q̇ᵀ∇²f q̇, from [`Model::surface_hessian`]) and the step is
//! made to end where that polynomial first falls through zero. Where f is
//! quadratic in time (a flight in uniform gravity to a plane) the step ends
//! on the wall and the collision is polished from its end by a Taylor step,
//! so no step across the wall has to be redone; elsewhere the prediction
//! only shortens a step and the crossing is found as above.
//!
//! Nothing is silently wrong: two walls met within
//! [`Settings::simultaneous`] of each other, a contact whose normal velocity
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
//! No heap allocation; `#![no_std]`.

use crate::dynamics::{DynamicsError, accelerations, qdd};
use crate::linalg::{self, ProjectorError};
use crate::{Model, libm};

/// The integration method between collisions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Classical fourth-order Runge–Kutta with a fixed step (the last step
    /// before the horizon is shortened to end on it).
    Rk4 {
        /// The step.
        step: f64,
    },
    /// Dormand–Prince 5(4) with error control on every component of (q, q̇):
    /// a step is accepted when the RMS of eᵢ / (atol + rtol·|yᵢ|) is ≤ 1.
    DormandPrince {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance.
        atol: f64,
        /// Largest step allowed.
        max_step: f64,
    },
}

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
    /// Two walls met less than this much time apart are reported as
    /// [`SimError::Simultaneous`]: the paper's law is for one wall at a time.
    pub simultaneous: f64,
    /// Points per step (besides its ends) at which each wall's f is sampled
    /// for sign changes on the dense output.
    pub samples: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            integrator: Integrator::DormandPrince {
                rtol: 1e-10,
                atol: 1e-12,
                max_step: f64::INFINITY,
            },
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
    /// Total energy T + V at the end of the step.
    pub energy: f64,
    /// Constraint residuals at the end of the step.
    pub residual: Residual,
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
    /// Evaluations of the equations of motion.
    pub evaluations: u64,
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
    /// Two walls are met within [`Settings::simultaneous`] of each other.
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
    /// A setting is out of range (a non-positive step or tolerance).
    BadSettings,
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
                    "at t = {t}: projection onto the constraints failed ({error:?})"
                )
            }
            SimError::StepTooSmall { t, step } => {
                write!(f, "at t = {t}: the step size fell to {step:e}")
            }
            SimError::BadSettings => write!(f, "a step or tolerance is not positive and finite"),
        }
    }
}

/// (q, q̇) or its time derivative (q̇, q̈).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Y<const N: usize> {
    q: [f64; N],
    v: [f64; N],
}

impl<const N: usize> Y<N> {
    const ZERO: Self = Self {
        q: [0.0; N],
        v: [0.0; N],
    };

    /// self + h Σ cₖ dₖ.
    fn plus(&self, h: f64, terms: &[(f64, &Y<N>)]) -> Self {
        let mut out = *self;
        for &(c, d) in terms {
            let hc = h * c;
            for (o, x) in out.q.iter_mut().zip(&d.q) {
                *o += hc * x;
            }
            for (o, x) in out.v.iter_mut().zip(&d.v) {
                *o += hc * x;
            }
        }
        out
    }

    fn finite(&self) -> bool {
        self.q.iter().chain(&self.v).all(|x| x.is_finite())
    }
}

/// The motion on one step, for any time inside it.
#[derive(Clone, Copy, Debug)]
enum Dense<const N: usize> {
    /// Cubic Hermite through (y₀, f₀) and (y₁, f₁).
    Hermite {
        y0: Y<N>,
        y1: Y<N>,
        f0: Y<N>,
        f1: Y<N>,
    },
    /// y₀ + θ(r₁ + (1−θ)(r₂ + θ(r₃ + (1−θ)r₄))).
    Shampine { y0: Y<N>, r: [Y<N>; 4] },
}

impl<const N: usize> Dense<N> {
    /// One half of the interpolated state at θ ∈ [0, 1] of a step of length
    /// `h`: `part` picks q or v out of each stored (q, v) pair.
    fn interpolate(&self, theta: f64, h: f64, part: fn(&Y<N>) -> &[f64; N]) -> [f64; N] {
        match self {
            Dense::Hermite { y0, y1, f0, f1 } => {
                // y₀ + θ(y₁−y₀) + θ(θ−1)[(1−2θ)(y₁−y₀) + (θ−1)h f₀ + θ h f₁]
                let c = theta * (theta - 1.0);
                let (a, b, fa, fb) = (part(y0), part(y1), part(f0), part(f1));
                core::array::from_fn(|i| {
                    let d = b[i] - a[i];
                    a[i] + theta * d
                        + c * ((1.0 - 2.0 * theta) * d
                            + (theta - 1.0) * h * fa[i]
                            + theta * h * fb[i])
                })
            }
            Dense::Shampine { y0, r } => {
                // y₀ + θ(r₁ + (1−θ)(r₂ + θ(r₃ + (1−θ)r₄)))
                let s = 1.0 - theta;
                let (a, r) = (part(y0), r.each_ref().map(part));
                core::array::from_fn(|i| {
                    a[i] + theta * (r[0][i] + s * (r[1][i] + theta * (r[2][i] + s * r[3][i])))
                })
            }
        }
    }

    /// The interpolated coordinates alone (half the work of [`Dense::at`];
    /// a wall's f needs no more).
    fn position(&self, theta: f64, h: f64) -> [f64; N] {
        self.interpolate(theta, h, |y| &y.q)
    }

    /// The interpolated state at θ ∈ [0, 1] of a step of length `h`.
    fn at(&self, theta: f64, h: f64) -> Y<N> {
        Y {
            q: self.interpolate(theta, h, |y| &y.q),
            v: self.interpolate(theta, h, |y| &y.v),
        }
    }
}

// Dormand–Prince 5(4): nodes, stages, the fifth-order weights (= the last
// stage row, FSAL) and the error weights b − b̂.
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
// Shampine's dense output (1986).
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// One trial step: the new state, its derivative, the error estimate (zero
/// for RK4) and the dense output.
struct Trial<const N: usize> {
    y1: Y<N>,
    f1: Y<N>,
    error: f64,
    dense: Dense<N>,
}

/// The hybrid simulator for a model with coordinates (`Q = N`).
pub struct Simulator<'m, M: Model<N, N>, const N: usize> {
    model: &'m M,
    settings: Settings,
    state: State<N>,
    /// (q̇, q̈) at `state`.
    f0: Y<N>,
    /// The next trial step.
    h: f64,
    /// Walls (bit per index into `M::WALLS`) just collided with and not yet
    /// left: their f starts at ≈ 0 and must become positive first.
    departing: u64,
    /// When the last collision happened.
    last_collision: Option<f64>,
    stats: Stats,
}

impl<'m, M: Model<N, N>, const N: usize> Simulator<'m, M, N> {
    /// A simulator from `start`. The state must be admissible (A q̇ = 0 and
    /// h(q) = 0 to within 1e-8 relative) and in f ≥ 0 for every wall; on a
    /// wall (f = 0) it must be moving away from it.
    pub fn new(
        model: &'m M,
        start: State<N>,
        settings: Settings,
    ) -> Result<Self, SimError<M::Wall>> {
        let ok = match settings.integrator {
            Integrator::Rk4 { step } => step > 0.0 && step.is_finite(),
            Integrator::DormandPrince {
                rtol,
                atol,
                max_step,
            } => rtol > 0.0 && atol > 0.0 && max_step > 0.0,
        };
        if !ok || M::WALLS.len() > 64 || settings.grazing.is_nan() || settings.simultaneous.is_nan()
        {
            return Err(SimError::BadSettings);
        }
        let residual = residual(model, &start.q, &start.v);
        let scale = 1.0 + norm(&start.v) + norm(&start.q);
        let finite = start.t.is_finite()
            && Y {
                q: start.q,
                v: start.v,
            }
            .finite();
        // NaN residuals fail `within` too.
        let within = |x: f64| x <= 1e-8 * scale;
        if !finite || !within(residual.velocity) || !within(residual.position) {
            return Err(SimError::Inadmissible { residual });
        }
        let mut departing = 0;
        for (k, &wall) in M::WALLS.iter().enumerate() {
            let f = model.surface(wall, &start.q);
            if f <= 0.0 {
                if f < -1e-12 * scale || model.normal_velocity(wall, &start.q, &start.v) <= 0.0 {
                    return Err(SimError::StartsBeyondWall { wall, surface: f });
                }
                departing |= 1 << k;
            }
        }
        // The numeric solve checks that G (and A G⁻¹Aᵀ) is positive definite
        // with these parameters, which a closed form used later does not.
        accelerations(model, &start.q, &start.v)
            .map_err(|error| SimError::Dynamics { t: start.t, error })?;
        let mut sim = Self {
            model,
            settings,
            state: start,
            f0: Y::ZERO,
            h: 0.0,
            departing,
            last_collision: None,
            stats: Stats::default(),
        };
        sim.f0 = sim.rhs(
            start.t,
            &Y {
                q: start.q,
                v: start.v,
            },
        )?;
        sim.h = sim.initial_step();
        Ok(sim)
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

    /// Energy and constraint residuals of the current state.
    pub fn residual(&self) -> Residual {
        residual(self.model, &self.state.q, &self.state.v)
    }

    /// Advances by one accepted step, ending at the first collision in it or
    /// at `t_end`, whichever comes first. At `t_end` already, returns the
    /// current state as a step of length zero.
    pub fn step(&mut self, t_end: f64) -> Result<Step<M::Wall, N>, SimError<M::Wall>> {
        let t0 = self.state.t;
        let y0 = Y {
            q: self.state.q,
            v: self.state.v,
        };
        if t_end <= t0 {
            return Ok(self.report(t0, None));
        }
        let aim = self.aim(&y0);
        let (h, trial) =
            self.accepted_trial(&y0, t_end, aim.map_or(f64::INFINITY, |(_, tau)| tau))?;
        let t1 = if t0 + h >= t_end { t_end } else { t0 + h };
        let reach = TAYLOR_REACH * h;
        let found = match self.first_crossing(&y0, &trial, t0, h)? {
            Some((k, tc)) if t1 - tc <= reach => {
                // Met at the very end of the step: polish from there.
                Some((k, (t1, trial.y1, Some(trial.f1)), t1))
            }
            Some((k, tc)) => {
                let (y, fy) = self.advance(&y0, t0, tc - t0)?;
                Some((k, (tc, y, fy), t1))
            }
            // A step aimed at a predicted collision that ends just short of
            // the wall: the collision is a Taylor step ahead.
            None => aim.filter(|&(_, tau)| tau == h).and_then(|(k, _)| {
                let wall = M::WALLS[k];
                let f = self.model.surface(wall, &trial.y1.q);
                let nv = self.model.normal_velocity(wall, &trial.y1.q, &trial.y1.v);
                let ahead = -f / nv;
                (f > 0.0 && nv < 0.0 && ahead <= reach && t1 + ahead <= t_end).then_some((
                    k,
                    (t1, trial.y1, Some(trial.f1)),
                    t1 + ahead,
                ))
            }),
        };
        match found {
            Some((k, start, t_hi)) => {
                let collision = self.collide(k, &y0, t0, start, t_hi)?;
                self.stats.steps += 1;
                self.stats.collisions += 1;
                Ok(self.report(t0, Some(collision)))
            }
            None => {
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

    // ------------------------------------------------------------ pieces

    fn report(&self, t0: f64, collision: Option<Collision<M::Wall, N>>) -> Step<M::Wall, N> {
        Step {
            t0,
            state: self.state,
            collision,
            energy: self.model.energy(&self.state.q, &self.state.v),
            residual: self.residual(),
        }
    }

    /// (q̇, q̈) at y.
    fn rhs(&mut self, t: f64, y: &Y<N>) -> Result<Y<N>, SimError<M::Wall>> {
        self.stats.evaluations += 1;
        let qdd = qdd(self.model, &y.q, &y.v).map_err(|error| SimError::Dynamics { t, error })?;
        Ok(Y { q: y.v, v: qdd })
    }

    fn initial_step(&self) -> f64 {
        match self.settings.integrator {
            Integrator::Rk4 { step } => step,
            Integrator::DormandPrince {
                rtol,
                atol,
                max_step,
            } => {
                // Hairer's first guess: 1% of the ratio of the scaled norms
                // of y and y', bounded by the fifth root of the tolerance.
                let y = Y {
                    q: self.state.q,
                    v: self.state.v,
                };
                let d0 = scaled_norm(&y, &y, &y, rtol, atol);
                let d1 = scaled_norm(&self.f0, &y, &y, rtol, atol);
                let h = if d0 < 1e-5 || d1 < 1e-5 {
                    1e-6
                } else {
                    0.01 * d0 / d1
                };
                h.min(max_step).max(1e-10)
            }
        }
    }

    /// The stages of one step of length `h` from (t0, y0) and the step's
    /// end y₁: RK4's k₁…k₄ (k₁ = f₀, the rest zero), or Dormand–Prince's
    /// seven (the last is f(y₁), FSAL).
    fn stages(
        &mut self,
        y0: &Y<N>,
        t0: f64,
        h: f64,
        k: &mut [Y<N>; 7],
    ) -> Result<Y<N>, SimError<M::Wall>> {
        k[0] = self.f0;
        match self.settings.integrator {
            Integrator::Rk4 { .. } => {
                k[1] = self.rhs(t0 + h / 2.0, &y0.plus(h, &[(0.5, &k[0])]))?;
                k[2] = self.rhs(t0 + h / 2.0, &y0.plus(h, &[(0.5, &k[1])]))?;
                k[3] = self.rhs(t0 + h, &y0.plus(h, &[(1.0, &k[2])]))?;
                let weights = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];
                let terms: [(f64, &Y<N>); 4] = core::array::from_fn(|j| (weights[j], &k[j]));
                Ok(y0.plus(h, &terms))
            }
            Integrator::DormandPrince { .. } => {
                for s in 1..7 {
                    let terms: [(f64, &Y<N>); 6] = core::array::from_fn(|j| (A[s][j], &k[j]));
                    let ys = y0.plus(h, &terms[..s]);
                    k[s] = self.rhs(t0 + C[s] * h, &ys)?;
                }
                // The last stage was evaluated at y₁ itself.
                let terms: [(f64, &Y<N>); 6] = core::array::from_fn(|j| (A[6][j], &k[j]));
                Ok(y0.plus(h, &terms))
            }
        }
    }

    /// The end of one step of length `h` from (t0, y0), and f there when the
    /// method has it for free (Dormand–Prince); no error estimate, no dense
    /// output.
    fn advance(
        &mut self,
        y0: &Y<N>,
        t0: f64,
        h: f64,
    ) -> Result<(Y<N>, Option<Y<N>>), SimError<M::Wall>> {
        let mut k = [Y::ZERO; 7];
        let y1 = self.stages(y0, t0, h, &mut k)?;
        let f1 = match self.settings.integrator {
            Integrator::Rk4 { .. } => None,
            Integrator::DormandPrince { .. } => Some(k[6]),
        };
        Ok((y1, f1))
    }

    /// One step of length `h` from (t0, y0) without error control.
    fn trial(&mut self, y0: &Y<N>, t0: f64, h: f64) -> Result<Trial<N>, SimError<M::Wall>> {
        let mut k = [Y::ZERO; 7];
        let y1 = self.stages(y0, t0, h, &mut k)?;
        match self.settings.integrator {
            Integrator::Rk4 { .. } => {
                let f1 = self.rhs(t0 + h, &y1)?;
                Ok(Trial {
                    y1,
                    f1,
                    error: 0.0,
                    dense: Dense::Hermite {
                        y0: *y0,
                        y1,
                        f0: k[0],
                        f1,
                    },
                })
            }
            Integrator::DormandPrince { rtol, atol, .. } => {
                let e_terms: [(f64, &Y<N>); 7] = core::array::from_fn(|j| (E[j], &k[j]));
                let err = Y::ZERO.plus(h, &e_terms);
                let error = scaled_norm(&err, y0, &y1, rtol, atol);
                let d_terms: [(f64, &Y<N>); 7] = core::array::from_fn(|j| (D[j], &k[j]));
                let r1 = Y::ZERO.plus(1.0, &[(1.0, &y1), (-1.0, y0)]);
                let r2 = Y::ZERO.plus(h, &[(1.0, &k[0])]).plus(1.0, &[(-1.0, &r1)]);
                let r3 = r1.plus(h, &[(-1.0, &k[6])]).plus(1.0, &[(-1.0, &r2)]);
                let r4 = Y::ZERO.plus(h, &d_terms);
                Ok(Trial {
                    y1,
                    f1: k[6],
                    error,
                    dense: Dense::Shampine {
                        y0: *y0,
                        r: [r1, r2, r3, r4],
                    },
                })
            }
        }
    }

    /// The wall the motion from y0 is predicted to meet first and when, from
    /// f's second-order Taylor polynomial in time (adaptive integrator
    /// only): the next step is made to end there. A motion whose f is
    /// quadratic in time (a flight in uniform gravity to a plane) then meets
    /// the wall at the end of one step, with no step across it to redo; for
    /// other motions the prediction only shortens a step, and the crossing
    /// is found on the step as usual.
    fn aim(&self, y0: &Y<N>) -> Option<(usize, f64)> {
        if !matches!(self.settings.integrator, Integrator::DormandPrince { .. }) {
            return None;
        }
        let m = self.model;
        let shortest = 16.0 * f64::EPSILON * self.state.t.abs().max(1.0);
        let mut best: Option<(usize, f64)> = None;
        for (k, &wall) in M::WALLS.iter().enumerate() {
            let Some(hessian) = m.surface_hessian(wall, &y0.q, &y0.v) else {
                continue;
            };
            let f = m.surface(wall, &y0.q);
            let normal = m.normal(wall, &y0.q);
            let rate = linalg::dot(&normal, &y0.v);
            let accel = linalg::dot(&normal, &self.f0.v) + hessian;
            if let Some(tau) = descending_root(f, rate, accel)
                && tau > shortest
                && best.is_none_or(|(_, b)| tau < b)
            {
                best = Some((k, tau));
            }
        }
        best
    }

    /// Trial steps of at most `limit` until one is accepted; returns its
    /// length.
    fn accepted_trial(
        &mut self,
        y0: &Y<N>,
        t_end: f64,
        limit: f64,
    ) -> Result<(f64, Trial<N>), SimError<M::Wall>> {
        let t0 = self.state.t;
        let mut rejected = false;
        let mut failures = 0;
        loop {
            let h = self.h.min(t_end - t0).min(limit);
            if h <= 4.0 * f64::EPSILON * t0.abs().max(1.0) && t0 + h < t_end {
                return Err(SimError::StepTooSmall { t: t0, step: h });
            }
            let Integrator::DormandPrince { max_step, .. } = self.settings.integrator else {
                return Ok((h, self.trial(y0, t0, h)?));
            };
            // A stage that lands on a singular or non-finite state may only
            // mean the step is too long: shrink it a few times before
            // reporting the error.
            let trial = match self.trial(y0, t0, h) {
                Ok(trial) => trial,
                Err(SimError::Dynamics { .. }) if failures < 8 => {
                    failures += 1;
                    self.h = 0.2 * h;
                    rejected = true;
                    self.stats.rejected += 1;
                    continue;
                }
                Err(e) => return Err(e),
            };
            let err = trial.error;
            // Standard controller: safety 0.9, exponent 1/5, factor in
            // [0.2, 5] (at most 1 right after a rejection).
            // 0.9·err^(−1/5) reaches 5 for err ≤ (0.9/5)⁵ and 0.2 for
            // err ≥ 4.5⁵: the power (by exp and log, faster than pow) is
            // needed only in between.
            let fac = if err <= 1.889568e-4 {
                5.0
            } else if err < 1845.28125 {
                (0.9 * libm::exp(-0.2 * libm::log(err))).clamp(0.2, 5.0)
            } else {
                0.2
            };
            if err <= 1.0 {
                let fac = if rejected { fac.min(1.0) } else { fac };
                // A step cut short by t_end or by an aim says nothing
                // against the longer proposal: keep it if it is longer.
                let grown = h * fac;
                let proposal = if h < self.h { self.h.max(grown) } else { grown };
                self.h = proposal.min(max_step);
                return Ok((h, trial));
            }
            self.h = h * fac.min(1.0);
            rejected = true;
            self.stats.rejected += 1;
        }
    }

    /// The first wall crossed on the step (index into `M::WALLS`, time on
    /// the dense output), if any.
    fn first_crossing(
        &mut self,
        y0: &Y<N>,
        trial: &Trial<N>,
        t0: f64,
        h: f64,
    ) -> Result<Option<(usize, f64)>, SimError<M::Wall>> {
        let mut best: Option<(usize, f64)> = None;
        let mut second: Option<(usize, f64)> = None;
        for k in 0..M::WALLS.len() {
            let Some(theta) = self.wall_crossing(k, y0, trial, t0, h)? else {
                continue;
            };
            let t = t0 + theta * h;
            match best {
                Some((_, tb)) if tb <= t => {
                    if second.is_none_or(|(_, ts)| t < ts) {
                        second = Some((k, t));
                    }
                }
                _ => {
                    second = best;
                    best = Some((k, t));
                }
            }
        }
        if let (Some((a, ta)), Some((b, tb))) = (best, second)
            && tb - ta <= self.settings.simultaneous
        {
            return Err(SimError::Simultaneous {
                first: M::WALLS[a],
                second: M::WALLS[b],
                t: ta,
            });
        }
        Ok(best)
    }

    /// Where on the step (θ ∈ [0, 1]) wall `k` is first met, if it is.
    ///
    /// f and its rate df·q̇ are sampled on the dense output. Met means f
    /// goes from > 0 to ≤ 0 between samples; a dip below zero between two
    /// positive samples is caught by the rate changing sign (its bottom is
    /// located first). A wall just collided with starts at f ≈ 0 moving
    /// away: it is met again only after f has been positive, which is also
    /// checked between samples through the top of the excursion.
    fn wall_crossing(
        &self,
        k: usize,
        y0: &Y<N>,
        trial: &Trial<N>,
        t0: f64,
        h: f64,
    ) -> Result<Option<f64>, SimError<M::Wall>> {
        let m = self.model;
        let wall = M::WALLS[k];
        let state = |theta: f64| -> Y<N> {
            if theta == 0.0 {
                *y0
            } else if theta == 1.0 {
                trial.y1
            } else {
                trial.dense.at(theta, h)
            }
        };
        let f = |theta: f64| {
            let q = if theta == 0.0 {
                y0.q
            } else if theta == 1.0 {
                trial.y1.q
            } else {
                trial.dense.position(theta, h)
            };
            m.surface(wall, &q)
        };
        let rate = |theta: f64| {
            let y = state(theta);
            m.normal_velocity(wall, &y.q, &y.v)
        };
        // One dense-output evaluation per sample for both f and its rate.
        let sample = |theta: f64| {
            let y = state(theta);
            (
                theta,
                m.surface(wall, &y.q),
                m.normal_velocity(wall, &y.q, &y.v),
            )
        };
        let n = self.settings.samples + 1;
        let mut prev = sample(0.0);
        let mut leaving = self.departing & (1 << k) != 0 && prev.1 <= 0.0 && prev.2 > 0.0;
        if !leaving && prev.1 <= 0.0 {
            // At or beyond the wall at the step's start and not leaving it
            // (a projection can move q by rounding-sized amounts).
            return Ok(Some(0.0));
        }
        for j in 1..=n {
            let now = sample(j as f64 / n as f64);
            if leaving {
                if now.1 > 0.0 {
                    leaving = false;
                } else if now.2 <= 0.0 {
                    // Turned back before a sample saw it off the wall: find
                    // the top of the excursion.
                    let top = illinois(&rate, (prev.0, prev.2), (now.0, now.2));
                    let f_top = f(top);
                    if f_top > 0.0 {
                        return Ok(Some(illinois(&f, (top, f_top), (now.0, now.1))));
                    }
                    return Err(SimError::Grazing {
                        wall,
                        t: t0 + top * h,
                        normal_velocity: rate(top),
                    });
                }
            } else if now.1 <= 0.0 {
                return Ok(Some(illinois(&f, (prev.0, prev.1), (now.0, now.1))));
            } else if prev.2 < 0.0 && now.2 > 0.0 {
                // f stays positive at both samples but turns: check the
                // bottom of the dip.
                let falling = |theta: f64| -rate(theta);
                let bottom = illinois(&falling, (prev.0, -prev.2), (now.0, -now.2));
                let f_bottom = f(bottom);
                if f_bottom <= 0.0 {
                    return Ok(Some(illinois(&f, (prev.0, prev.1), (bottom, f_bottom))));
                }
            }
            prev = now;
        }
        Ok(None)
    }

    /// Resolves the collision with wall `k` met on the step from (t0, y0):
    /// Newton's method on f from `start` (a time, the state there from a
    /// real step, and f there when known) along real steps or, for tiny
    /// corrections, Taylor steps, staying in [t0, t_hi]; then the collision
    /// map.
    fn collide(
        &mut self,
        k: usize,
        y0: &Y<N>,
        t0: f64,
        start: (f64, Y<N>, Option<Y<N>>),
        t_hi: f64,
    ) -> Result<Collision<M::Wall, N>, SimError<M::Wall>> {
        let m = self.model;
        let wall = M::WALLS[k];
        let (mut tc, mut y, mut fy) = start;
        let reach = TAYLOR_REACH * (t_hi - t0);
        for _ in 0..6 {
            let f = m.surface(wall, &y.q);
            let nv = m.normal_velocity(wall, &y.q, &y.v);
            if f == 0.0 || nv >= 0.0 {
                break;
            }
            let next = (tc - f / nv).clamp(t0, t_hi);
            if (next - tc).abs() <= 2.0 * f64::EPSILON * tc.abs().max(1.0) || next <= t0 {
                break;
            }
            let delta = next - tc;
            let (candidate, f_candidate) = if delta.abs() <= reach {
                // A tiny correction: second-order Taylor from y (at most one
                // evaluation instead of a step; the error is O(δ³)).
                let d = match fy {
                    Some(d) => d,
                    None => self.rhs(tc, &y)?,
                };
                let taylor = Y {
                    q: core::array::from_fn(|i| y.q[i] + delta * (y.v[i] + 0.5 * delta * d.v[i])),
                    v: core::array::from_fn(|i| y.v[i] + delta * d.v[i]),
                };
                (taylor, None)
            } else {
                self.advance(y0, t0, next - t0)?
            };
            if m.surface(wall, &candidate.q).abs() >= f.abs() {
                break;
            }
            tc = next;
            y = candidate;
            fy = f_candidate;
        }
        let normal = norm(&m.normal(wall, &y.q));
        let nv = m.normal_velocity(wall, &y.q, &y.v);
        if -nv <= self.settings.grazing * normal * norm(&y.v) {
            return Err(SimError::Grazing {
                wall,
                t: tc,
                normal_velocity: nv,
            });
        }
        let v_plus = m.collide(wall, &y.q, &y.v);
        let nv_plus = m.normal_velocity(wall, &y.q, &v_plus);
        if !v_plus.iter().all(|x| x.is_finite()) || (nv_plus + nv).abs() > 1e-6 * nv.abs() {
            return Err(SimError::SingularWall { wall, t: tc });
        }
        // Another wall at or beyond reach within the simultaneity window,
        // moving as after this collision?
        for (j, &other) in M::WALLS.iter().enumerate() {
            let rate = m.normal_velocity(other, &y.q, &v_plus).min(0.0);
            if j != k && m.surface(other, &y.q) + self.settings.simultaneous * rate <= 0.0 {
                return Err(SimError::Simultaneous {
                    first: wall,
                    second: other,
                    t: tc,
                });
            }
        }
        let collision = Collision {
            wall,
            t: tc,
            q: y.q,
            v_minus: y.v,
            v_plus,
            surface: m.surface(wall, &y.q),
        };
        self.state = State {
            t: tc,
            q: y.q,
            v: v_plus,
        };
        self.departing |= 1 << k;
        // Go on with steps of at most twice the time since the previous
        // collision: an error-free stretch (a parabola) would otherwise let
        // the proposal grow without bound, and a step far longer than the
        // motion between collisions locates the next crossing less well;
        // twice that time usually reaches the next collision in one step.
        let since = tc - self.last_collision.unwrap_or(t0);
        if since > 0.0 {
            self.h = self.h.min(2.0 * since);
        }
        self.last_collision = Some(tc);
        self.project()?;
        self.f0 = self.rhs(
            tc,
            &Y {
                q: self.state.q,
                v: self.state.v,
            },
        )?;
        Ok(collision)
    }

    /// Forgets walls that the state has left (f > 0).
    fn leave_walls(&mut self) {
        for (k, &wall) in M::WALLS.iter().enumerate() {
            if self.departing & (1 << k) != 0 && self.model.surface(wall, &self.state.q) > 0.0 {
                self.departing &= !(1 << k);
            }
        }
    }

    /// q onto h(q) = 0 (Gauss–Newton in the metric of G), then q̇ onto
    /// ker A(q) (G-orthogonally). Recomputes (q̇, q̈) when anything moved.
    fn project(&mut self) -> Result<(), SimError<M::Wall>> {
        if !self.settings.project {
            return Ok(());
        }
        let m = self.model;
        let t = self.state.t;
        let fail = |error| SimError::Projection { t, error };
        let mut moved = false;
        let h = m.holonomic(&self.state.q);
        if !h.as_slice().is_empty() {
            let mut q = self.state.q;
            let mut r = h;
            let mut done = false;
            for _ in 0..8 {
                if r.max_abs() <= 4.0 * f64::EPSILON * (1.0 + norm(&q)) {
                    done = true;
                    break;
                }
                let g = m.mass_matrix(&q);
                let a = m.constraints(&q);
                let rows = &a.as_slice()[..r.as_slice().len()];
                let d = linalg::correction(&g, rows, r.as_slice()).map_err(fail)?;
                for (qi, di) in q.iter_mut().zip(d) {
                    *qi -= di;
                }
                r = m.holonomic(&q);
                moved = true;
            }
            if !done && r.max_abs() > 1e-10 * (1.0 + norm(&q)) {
                return Err(fail(ProjectorError::DependentRows));
            }
            self.state.q = q;
        }
        let a = m.constraints(&self.state.q);
        if !a.is_empty() {
            let g = m.mass_matrix(&self.state.q);
            let r = a.apply(&self.state.v);
            let d = linalg::correction(&g, a.as_slice(), r.as_slice()).map_err(fail)?;
            for (vi, di) in self.state.v.iter_mut().zip(d) {
                *vi -= di;
            }
            moved = true;
        }
        if moved {
            let y = Y {
                q: self.state.q,
                v: self.state.v,
            };
            self.f0 = self.rhs(t, &y)?;
        }
        Ok(())
    }
}

/// Constraint residuals of model `m` at (q, v).
pub fn residual<M: Model<N, N>, const N: usize>(m: &M, q: &[f64; N], v: &[f64; N]) -> Residual {
    Residual {
        velocity: m.constraints(q).apply(v).max_abs(),
        position: m.holonomic(q).max_abs(),
    }
}

/// The admissible velocity nearest to `v` in the metric of G(q): v minus its
/// G-orthogonal component off ker A(q). Use it to build initial states.
pub fn admissible<M: Model<N, N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: &[f64; N],
) -> Result<[f64; N], ProjectorError> {
    let a = m.constraints(q);
    if a.is_empty() {
        return Ok(*v);
    }
    let d = linalg::correction(&m.mass_matrix(q), a.as_slice(), a.apply(v).as_slice())?;
    Ok(core::array::from_fn(|i| v[i] - d[i]))
}

fn norm(x: &[f64]) -> f64 {
    libm::sqrt(x.iter().map(|v| v * v).sum())
}

/// RMS of eᵢ / (atol + rtol·max(|aᵢ|, |bᵢ|)) over all components.
fn scaled_norm<const N: usize>(e: &Y<N>, a: &Y<N>, b: &Y<N>, rtol: f64, atol: f64) -> f64 {
    let mut sum = 0.0;
    let parts = [(&e.q, &a.q, &b.q), (&e.v, &a.v, &b.v)];
    for (e, a, b) in parts {
        for i in 0..N {
            let sc = atol + rtol * a[i].abs().max(b[i].abs());
            sum += (e[i] / sc) * (e[i] / sc);
        }
    }
    if N == 0 {
        0.0
    } else {
        libm::sqrt(sum / (2 * N) as f64)
    }
}

/// A Newton or Taylor correction from a point on a step of length h is
/// trusted up to this fraction of h (its error is O(δ³) in q, O(δ²) in q̇).
const TAYLOR_REACH: f64 = 1e-6;

/// The first τ > 0 at which f + rate·τ + accel·τ²/2 falls through zero
/// (its slope there negative), if there is one.
fn descending_root(f: f64, rate: f64, accel: f64) -> Option<f64> {
    // The descending root is (−rate − s)/accel with s = √(rate² − 2·accel·f);
    // for rate ≤ 0 the same value in the form 2f/(s − rate), which does not
    // cancel (and covers accel = 0).
    let disc = rate * rate - 2.0 * accel * f;
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    let s = libm::sqrt(disc);
    let tau = if rate > 0.0 {
        (-rate - s) / accel
    } else {
        2.0 * f / (s - rate)
    };
    (tau > 0.0 && tau.is_finite()).then_some(tau)
}

/// The root of `f` in [a, b] with f(a) > 0 ≥ f(b), by the Illinois variant
/// of regula falsi; returns θ.
fn illinois(f: &impl Fn(f64) -> f64, a: (f64, f64), b: (f64, f64)) -> f64 {
    let ((mut a, mut fa), (mut b, mut fb)) = (a, b);
    let mut side = 0;
    for _ in 0..200 {
        if fb == 0.0 || b - a <= 2.0 * f64::EPSILON * b.abs().max(1e-300) {
            break;
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        if !(c > a && c < b) {
            c = 0.5 * (a + b);
        }
        let fc = f(c);
        if fc > 0.0 {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::descending_root;

    fn close(a: Option<f64>, b: f64) -> bool {
        a.is_some_and(|a| (a - b).abs() <= 1e-14 * b.abs())
    }

    #[test]
    fn descending_roots() {
        // Thrown up from the wall: back after 2·rate/|accel|, not at the
        // start (where f rises through zero), also a rounding below it.
        assert!(close(descending_root(0.0, 2.0, -10.0), 0.4));
        assert!(close(descending_root(-1e-17, 2.0, -10.0), 0.4));
        // Falling from height 5 at rest: √(2·5/10) = 1.
        assert!(close(descending_root(5.0, 0.0, -10.0), 1.0));
        // Approaching at constant speed: f/|rate|.
        assert!(close(descending_root(3.0, -2.0, 0.0), 1.5));
        // Approaching while pushed back: the earlier of the two roots of
        // 1 − 3τ + τ² (τ = (3 − √5)/2), not the later one where f rises.
        assert!(close(
            descending_root(1.0, -3.0, 2.0),
            (3.0 - 5f64.sqrt()) / 2.0
        ));
        // Turning back before the wall, moving away, or already beyond it
        // and approaching: no meeting ahead.
        assert_eq!(descending_root(1.0, -1.0, 2.0), None);
        assert_eq!(descending_root(1.0, 1.0, 0.0), None);
        assert_eq!(descending_root(1.0, 1.0, 2.0), None);
        assert_eq!(descending_root(-1.0, -1.0, 0.0), None);
        assert_eq!(descending_root(f64::NAN, -1.0, 0.0), None);
    }
}
