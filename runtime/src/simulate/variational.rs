//! The variational flow along a simulation: Φ(t) = ∂x(t)/∂x(t₀) for the
//! state x = (q, q̇), through collisions.
//!
//! [`Variational::follow`] takes each step the simulator has just made and
//! carries Φ over it; at a collision it applies the saltation matrix
//! ([`saltation`]), Φ⁺ = S Φ⁻. Between collisions:
//!
//! - after a Runge–Kutta step, Φ is carried by the same method over the
//!   same span (up to the collision instant for a step that ends at one),
//!   from the step's start, on pairs (x, δx), each stage's δ one tangent
//!   of q̈ ([`Dynamics::accelerations_tangent`]): 2N tangents a stage. For
//!   RK4 that is *the step itself* (one step of the span), so each column
//!   is the derivative of the computed solution. Dormand–Prince holds each
//!   column to Φ's own tolerance instead, in as many steps as that takes
//!   (the motion's steps can be far longer than its perturbations allow:
//!   a flight that is a parabola), each column's first step the length
//!   the control proposed last;
//! - after a step of Taylor's method, each column of Φ is carried by a
//!   polynomial: the model's series of the variational equation
//!   Φ̇ = J(x(t)) Φ, J = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]], along the step's
//!   series ([`TaylorSeries::variational_series`], the Taylor transform of
//!   the tangent of q̈), evaluated at the step's length (or the collision
//!   instant). At the step's order each column is the derivative of the
//!   step's polynomial along its start. That order was chosen for the
//!   motion's terms, and a perturbation's may fall more slowly (a flight
//!   that is a polynomial of low degree, perturbed off it), so each
//!   column's last two terms at the step's length are held to Φ's
//!   tolerance: where they are above it, the series are taken to
//!   [`MAX_ORDER`] along the motion's extended to that order, and where
//!   they still are, or the model has no such series, the variational
//!   equation is integrated along the step's polynomial
//!   ([`Simulator::state_at`]) by Dormand–Prince 5(4) with its own error
//!   control.
//!
//! The step lengths and collision instants are not differentiated: the
//! instants' dependence on x₀ is the saltation matrix's part, and a
//! step's length only moves the computed solution by the method's error.
//!
//! The simulator projects each step's end onto the constraints; Φ is not
//! projected. A perturbation tangent to the constraint manifold (h(q) = 0,
//! A(q) q̇ = 0) stays tangent to it along the flow and through collisions,
//! and on those the projection acts as the identity, so Φ δx₀ is the
//! simulation's derivative along every admissible δx₀; other columns of Φ
//! describe the flow of the equations extended off the manifold.
//!
//! [`ParameterSensitivity`] carries one more column the same way: the
//! derivative of the run along a direction δp of the parameters, whose
//! equation adds ∂q̈/∂p δp and whose collisions add the jump of
//! [`parameter_jump`].
//!
//! [`Dynamics::accelerations_tangent`]: crate::Dynamics::accelerations_tangent
//! [`TaylorSeries::variational_series`]: crate::TaylorSeries::variational_series

use super::integrator::{DormandPrince, Engine, Method, RungeKutta};
use super::phase::{Combine, Dual, Phase};
use super::{LastStep, Simulator, Step};
use crate::Surfaces;
use crate::saltation::{SaltationError, StateMatrix, parameter_jump, saltation};
use crate::taylor::{Coefficients, MAX_ORDER, Series};

/// Φ along a simulation (see the module doc). Start it at the simulator's
/// start and call [`Variational::follow`] after every step:
///
/// ```ignore
/// let mut phi = Variational::new(1e-10);
/// while sim.state().t < t_end {
///     let step = sim.step(t_end)?;
///     phi.follow(&sim, &step)?;
/// }
/// let m = phi.matrix(); // ∂x(t)/∂x(t₀)
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Variational<const N: usize> {
    phi: StateMatrix<N>,
    /// Φ at the end of the last step's flight: before its collision.
    before: StateMatrix<N>,
    /// ∂t*/∂x₀ of the last step's collision.
    instant: Option<([f64; N], [f64; N])>,
    /// Φ's own error control: Dormand–Prince at the tolerance of
    /// [`Variational::new`].
    method: DormandPrince,
    /// The last accepted length of a step of Φ's integration along a step
    /// of Taylor's method, where the next such integration starts.
    h: f64,
}

/// Why Φ could not follow a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VariationalError<W> {
    /// The model has no tangent of q̈ ([`Dynamics::accelerations_tangent`]
    /// is `None`), or, for [`ParameterSensitivity`], none by the
    /// parameters along its direction
    /// ([`Dynamics::accelerations_parameter_tangent`] is `None`: no q̈
    /// written out, or a direction whose length is not the number of
    /// parameters).
    ///
    /// [`Dynamics::accelerations_tangent`]: crate::Dynamics::accelerations_tangent
    /// [`Dynamics::accelerations_parameter_tangent`]: crate::Dynamics::accelerations_parameter_tangent
    NoDerivative,
    /// The step is not the simulator's last (its motion is gone).
    NotTheLastStep,
    /// Φ's integration failed on the step from `t` (a non-finite
    /// derivative, or steps shrinking without end).
    Integration {
        /// Where.
        t: f64,
    },
    /// The collision with `wall` has no saltation matrix.
    Saltation {
        /// The wall met.
        wall: W,
        /// Why.
        error: SaltationError,
    },
}

impl<const N: usize> Variational<N> {
    /// Φ = I. `rtol` is the relative tolerance (absolute `rtol`·1e-2 on
    /// entries that start at one) of Φ's own integration over steps of
    /// Dormand–Prince and along steps of Taylor's method; an RK4 step is
    /// differentiated itself and needs none (module doc).
    pub fn new(rtol: f64) -> Self {
        Self {
            phi: StateMatrix::identity(),
            before: StateMatrix::identity(),
            instant: None,
            method: DormandPrince {
                rtol,
                atol: rtol * 1e-2,
                max_step: f64::INFINITY,
            },
            h: f64::INFINITY,
        }
    }

    /// Φ so far: ∂x/∂x₀ over (q, q̇) as four N×N blocks.
    pub fn matrix(&self) -> &StateMatrix<N> {
        &self.phi
    }

    /// Φ just before the last step's collision, Φ⁻ (the saltation gives
    /// [`Variational::matrix`] = S Φ⁻); [`Variational::matrix`] itself
    /// when the step met no wall.
    pub fn before_collision(&self) -> &StateMatrix<N> {
        &self.before
    }

    /// How the last step's collision instant t* moves with the start:
    /// ∂t*/∂(q₀, q̇₀) = ∂t*/∂q · (the q rows of Φ⁻)
    /// ([`crate::saltation::Saltation::dt_dq`]), as (by q₀, by q̇₀);
    /// `None` when the step met no wall.
    pub fn collision_gradient(&self) -> Option<([f64; N], [f64; N])> {
        self.instant
    }

    /// Advances Φ over `step`, the step `sim` has just made: along its
    /// motion, then through its collision if it ended at one.
    pub fn follow<M: Surfaces<N>>(
        &mut self,
        sim: &Simulator<'_, M, N>,
        step: &Step<M::Wall, N>,
    ) -> Result<(), VariationalError<M::Wall>> {
        if let Some(flight) = Flight::of(sim, step)?
            && !self.along_series(&flight)?
        {
            for j in 0..2 * N {
                let column = flight.carry(self.column(j), tangent, self.method, &mut self.h)?;
                self.set_column(j, &column);
            }
        }
        self.before = self.phi;
        self.instant = None;
        if let Some(c) = &step.collision {
            let s = saltation(sim.model(), c.wall, &c.q, &c.v_minus).map_err(|error| {
                VariationalError::Saltation {
                    wall: c.wall,
                    error,
                }
            })?;
            let by = |block: &[[f64; N]; N]| -> [f64; N] {
                core::array::from_fn(|j| (0..N).map(|i| s.dt_dq[i] * block[i][j]).sum())
            };
            self.instant = Some((by(&self.phi.qq), by(&self.phi.qv)));
            self.phi = s.matrix.mul(&self.phi);
        }
        Ok(())
    }

    /// Φ carried over a step of Taylor's method by the model's variational
    /// series (module doc); `false`, with Φ untouched, for any other step,
    /// a model without that series, or columns whose series stay above
    /// Φ's tolerance at the step's length. The series are taken to the
    /// step's order first, then, where a column's last two terms are above
    /// the tolerance, to [`MAX_ORDER`] along the motion's series extended
    /// to it: a perturbation's series may converge more slowly than the
    /// motion's, whose own terms chose the step (a flight whose motion is
    /// a polynomial of low degree, perturbed off it). (An order estimated
    /// from the rate at which the terms fall was tried in between: on
    /// §3.2.1's bounce it cost 7 % more than going to [`MAX_ORDER`].)
    fn along_series<M: Surfaces<N>>(
        &mut self,
        flight: &Flight<'_, '_, M, N>,
    ) -> Result<bool, VariationalError<M::Wall>> {
        let (sim, last) = (flight.sim, flight.last);
        let Some(series) = sim.series().filter(|_| last.interpolant.is_none()) else {
            return Ok(false);
        };
        let orders = [series.order, MAX_ORDER];
        let tries = if series.order < MAX_ORDER { 2 } else { 1 };
        for &order in &orders[..tries] {
            match self.by_series(flight, order)? {
                BySeries::Carried(phi) => {
                    self.phi = phi;
                    return Ok(true);
                }
                BySeries::None => return Ok(false),
                BySeries::Inaccurate => {}
            }
        }
        Ok(false)
    }

    /// Φ over `flight` by the variational series to `order` (see
    /// [`Variational::along_series`]).
    fn by_series<M: Surfaces<N>>(
        &self,
        flight: &Flight<'_, '_, M, N>,
        order: usize,
    ) -> Result<BySeries<N>, VariationalError<M::Wall>> {
        let last = flight.last;
        let tau = (flight.t1 - last.t0) - last.t0_low;
        let (rtol, atol) = (self.method.rtol, self.method.atol);
        let mut phi = *self;
        let mut columns: [Series<N>; N] =
            core::array::from_fn(|_| Series::at(&[0.0; N], &[0.0; N]));
        for half in 0..2 {
            for (k, c) in columns.iter_mut().enumerate() {
                let column = self.column(half * N + k);
                c.restart(&column.q, &column.v);
            }
            if !flight.sim.variational_series(&mut columns, order) {
                return Ok(BySeries::None);
            }
            for (k, c) in columns.iter().enumerate() {
                let (q, v) = c.state(tau);
                if !q.iter().chain(&v).all(|x| x.is_finite()) {
                    return Err(VariationalError::Integration { t: flight.t0 });
                }
                // The last two terms at τ, against Φ's tolerance.
                let within = |(x, value): (&Coefficients, f64)| {
                    let term = |k: usize| x[k].abs() * libm::pow(tau, k as f64);
                    term(c.order) + term(c.order.saturating_sub(1)) <= atol + rtol * value.abs()
                };
                if !(c.q.iter().zip(q).chain(c.v.iter().zip(v))).all(within) {
                    return Ok(BySeries::Inaccurate);
                }
                phi.set_column(half * N + k, &Phase { q, v });
            }
        }
        Ok(BySeries::Carried(phi.phi))
    }

    fn column(&self, j: usize) -> Phase<N> {
        let (q, v) = if j < N {
            (&self.phi.qq, &self.phi.vq)
        } else {
            (&self.phi.qv, &self.phi.vv)
        };
        let k = j % N;
        Phase {
            q: core::array::from_fn(|i| q[i][k]),
            v: core::array::from_fn(|i| v[i][k]),
        }
    }

    fn set_column(&mut self, j: usize, c: &Phase<N>) {
        let (q, v) = if j < N {
            (&mut self.phi.qq, &mut self.phi.vq)
        } else {
            (&mut self.phi.qv, &mut self.phi.vv)
        };
        let k = j % N;
        for i in 0..N {
            q[i][k] = c.q[i];
            v[i][k] = c.v[i];
        }
    }
}

/// The derivative of a simulation along a direction δp of the parameters
/// (one entry each, in [`crate::Model::parameter_names`] order), with the
/// starting state held fixed: s(t) = ∂x(t)/∂p δp for x = (q, q̇), through
/// collisions. Between them s is carried as a column of Φ is
/// ([`Variational`]), with ∂q̈/∂p δp added to its equation
/// ([`Dynamics::accelerations_parameter_tangent`]); at a collision
/// s⁺ = S s⁻ + the jump of [`parameter_jump`] (the map's and the wall's
/// own change with p). For a start that depends on the parameters, give
/// its derivative along δp as the starting value ([`Self::starting_at`]).
///
/// ```ignore
/// let dp = [0.0, 1.0]; // ∂/∂ of the second parameter
/// let mut s = ParameterSensitivity::new(&dp, 1e-10);
/// while sim.state().t < t_end {
///     let step = sim.step(t_end)?;
///     s.follow(&sim, &step)?;
/// }
/// let (dq, dv) = s.value();
/// ```
///
/// [`Dynamics::accelerations_parameter_tangent`]: crate::Dynamics::accelerations_parameter_tangent
#[derive(Clone, Copy, Debug)]
pub struct ParameterSensitivity<'p, const N: usize> {
    dp: &'p [f64],
    s: Phase<N>,
    before: Phase<N>,
    /// ∂t*/∂p δp of the last step's collision.
    shift: Option<f64>,
    method: DormandPrince,
    h: f64,
}

impl<'p, const N: usize> ParameterSensitivity<'p, N> {
    /// s = 0 (the start does not move with p); `rtol` as for
    /// [`Variational::new`].
    pub fn new(dp: &'p [f64], rtol: f64) -> Self {
        let v = Variational::<N>::new(rtol);
        Self {
            dp,
            s: Phase::ZERO,
            before: Phase::ZERO,
            shift: None,
            method: v.method,
            h: v.h,
        }
    }

    /// The same, starting from s = (δq₀, δv₀): the start's own derivative
    /// along δp.
    pub fn starting_at(mut self, dq: [f64; N], dv: [f64; N]) -> Self {
        self.s = Phase { q: dq, v: dv };
        self.before = self.s;
        self
    }

    /// s so far: (∂q/∂p δp, ∂q̇/∂p δp).
    pub fn value(&self) -> ([f64; N], [f64; N]) {
        (self.s.q, self.s.v)
    }

    /// s just before the last step's collision (the value itself when the
    /// step met no wall).
    pub fn before_collision(&self) -> ([f64; N], [f64; N]) {
        (self.before.q, self.before.v)
    }

    /// How the last step's collision instant t* moves along δp,
    /// ∂t*/∂p δp = ∂t*/∂q · δq⁻ + the jump's own shift
    /// ([`crate::saltation::ParameterJump::dt`]); `None` when the step met
    /// no wall.
    pub fn collision_shift(&self) -> Option<f64> {
        self.shift
    }

    /// Advances s over `step`, the step `sim` has just made: along its
    /// motion, then through its collision if it ended at one.
    pub fn follow<M: Surfaces<N>>(
        &mut self,
        sim: &Simulator<'_, M, N>,
        step: &Step<M::Wall, N>,
    ) -> Result<(), VariationalError<M::Wall>> {
        if let Some(flight) = Flight::of(sim, step)? {
            let dp = self.dp;
            let derivative = |m: &M, y: &Dual<N>| parameter_tangent(m, y, dp);
            self.s = flight.carry(self.s, derivative, self.method, &mut self.h)?;
        }
        self.before = self.s;
        self.shift = None;
        if let Some(c) = &step.collision {
            let model = sim.model();
            let error = |error| VariationalError::Saltation {
                wall: c.wall,
                error,
            };
            let salt = saltation(model, c.wall, &c.q, &c.v_minus).map_err(error)?;
            let jump = parameter_jump(model, c.wall, &c.q, &c.v_minus, self.dp).map_err(error)?;
            let by_q: f64 = salt.dt_dq.iter().zip(&self.s.q).map(|(a, b)| a * b).sum();
            self.shift = Some(by_q + jump.dt);
            let (q, v) = salt.matrix.apply(&self.s.q, &self.s.v);
            self.s = Phase {
                q: core::array::from_fn(|i| q[i] + jump.dx.0[i]),
                v: core::array::from_fn(|i| v[i] + jump.dx.1[i]),
            };
        }
        Ok(())
    }
}

/// What the variational series gave over a step.
enum BySeries<const N: usize> {
    /// Φ at the step's end.
    Carried(StateMatrix<N>),
    /// No series (the model has none).
    None,
    /// A column's series above Φ's tolerance at the step's length.
    Inaccurate,
}

/// The motion of one step up to its collision (or its end), along which
/// tangents are carried.
struct Flight<'s, 'm, M: Surfaces<N>, const N: usize> {
    sim: &'s Simulator<'m, M, N>,
    last: &'s LastStep<N>,
    t0: f64,
    t1: f64,
}

impl<'s, 'm, M: Surfaces<N>, const N: usize> Flight<'s, 'm, M, N> {
    /// `step`'s flight, `None` when it has none (a collision at its start);
    /// an error when `step` is not `sim`'s last.
    fn of(
        sim: &'s Simulator<'m, M, N>,
        step: &Step<M::Wall, N>,
    ) -> Result<Option<Self>, VariationalError<M::Wall>> {
        let t1 = step.collision.as_ref().map_or(step.state.t, |c| c.t);
        if t1 <= step.t0 {
            return Ok(None);
        }
        let last = sim
            .last
            .as_ref()
            .filter(|last| last.t0 == step.t0)
            .ok_or(VariationalError::NotTheLastStep)?;
        Ok(Some(Self {
            sim,
            last,
            t0: step.t0,
            t1,
        }))
    }

    /// A tangent δx at the step's start carried to its flight's end by
    /// `derivative`, (ẋ, δẋ) at (x, δx) ([`tangent`], or
    /// [`parameter_tangent`] along a direction of the parameters):
    /// through the step itself for a Runge–Kutta step, else along its
    /// polynomial, by `method` from a first step of `h` (updated to the
    /// length the control proposes next: the columns and steps that follow
    /// need about the same). See the module doc.
    fn carry(
        &self,
        column: Phase<N>,
        derivative: impl Fn(&M, &Dual<N>) -> Result<Dual<N>, VariationalError<M::Wall>>,
        method: DormandPrince,
        h: &mut f64,
    ) -> Result<Phase<N>, VariationalError<M::Wall>> {
        let (sim, t0, t1) = (self.sim, self.t0, self.t1);
        let model = sim.model();
        match (&sim.engine, &self.last.interpolant) {
            (Engine::RungeKutta(rk), Some((_, dense))) => {
                // The simulator's method, held to Φ's tolerance
                // (Dormand–Prince; RK4 has no error estimate), tried first
                // over the simulator's own step.
                let (rk, first) = match rk {
                    RungeKutta::DormandPrince(_) => (RungeKutta::DormandPrince(method), *h),
                    // One step of the span: the step itself.
                    rk4 => (*rk4, t1 - t0),
                };
                let start = Dual {
                    x: *dense.start(),
                    dx: column,
                };
                let mut rhs = |_: f64, y: &Dual<N>| derivative(model, y);
                let (end, next) = controlled(&rk, &mut rhs, start, t0, t1, first)?;
                if matches!(rk, RungeKutta::DormandPrince(_)) {
                    *h = next;
                }
                Ok(end.dx)
            }
            _ => {
                let mut rhs = |t: f64, d: &Phase<N>| {
                    let x = sim
                        .state_at(t.clamp(t0, t1))
                        .ok_or(VariationalError::NotTheLastStep)?;
                    let (x, dx) = (Phase { q: x.q, v: x.v }, *d);
                    Ok(derivative(model, &Dual { x, dx })?.dx)
                };
                let rk = RungeKutta::DormandPrince(method);
                let (column, last) = controlled(&rk, &mut rhs, column, t0, t1, *h)?;
                *h = last;
                Ok(column)
            }
        }
    }
}

/// (ẋ, J(x) δx) at (x, δx): one tangent of q̈.
fn tangent<M: Surfaces<N>, const N: usize>(
    model: &M,
    y: &Dual<N>,
) -> Result<Dual<N>, VariationalError<M::Wall>> {
    let (qdd, dqdd) = model
        .accelerations_tangent(&y.x.q, &y.x.v, &y.dx.q, &y.dx.v)
        .ok_or(VariationalError::NoDerivative)?;
    Ok(Dual {
        x: Phase { q: y.x.v, v: qdd },
        dx: Phase { q: y.dx.v, v: dqdd },
    })
}

/// (ẋ, J(x) δx + ∂F/∂p δp) at (x, δx): [`tangent`] and the tangent of q̈
/// along the direction δp of the parameters.
fn parameter_tangent<M: Surfaces<N>, const N: usize>(
    model: &M,
    y: &Dual<N>,
    dp: &[f64],
) -> Result<Dual<N>, VariationalError<M::Wall>> {
    let mut d = tangent(model, y)?;
    let (_, by_p) = model
        .accelerations_parameter_tangent(&y.x.q, &y.x.v, dp)
        .ok_or(VariationalError::NoDerivative)?;
    d.dx.v.iter_mut().zip(by_p).for_each(|(d, p)| *d += p);
    Ok(d)
}

/// y from t0 to t1 by `method` under its error control (one step of the
/// span for a method without any), the first step at most `first`: the
/// end, and the step length the control proposes after it (from the last
/// step not cut short to end at t1, where there was one).
fn controlled<Y: Combine, W>(
    method: &RungeKutta,
    rhs: &mut impl FnMut(f64, &Y) -> Result<Y, VariationalError<W>>,
    mut y: Y,
    t0: f64,
    t1: f64,
    first: f64,
) -> Result<(Y, f64), VariationalError<W>> {
    let span = t1 - t0;
    let (mut t, mut h, mut proposed) = (t0, first.min(span), None);
    let mut tries = 0;
    while t < t1 {
        let last = t + h >= t1 - 1e-12 * span;
        let h_now = if last { t1 - t } else { h };
        let f0 = rhs(t, &y)?;
        let (y1, error) = method.estimate(rhs, &y, &f0, t, h_now)?;
        let next = h_now * method.factor(error);
        if error <= 1.0 && y1.finite() {
            y = y1;
            t = if last { t1 } else { t + h_now };
            tries = 0;
            if !last {
                proposed = Some(next);
            } else if proposed.is_none() {
                // Cut short: what the control asked for before, if more.
                proposed = Some(next.max(h));
            }
        } else {
            tries += 1;
            if tries > 50 || !error.is_finite() {
                return Err(VariationalError::Integration { t });
            }
        }
        h = next;
    }
    Ok((y, proposed.unwrap_or(h)))
}
