//! The variational flow along a simulation: Φ(t) = ∂x(t)/∂x(t₀) for the
//! state x = (q, q̇), through collisions.
//!
//! [`Variational::follow`] takes each step the simulator has just made and
//! carries Φ over it; at a collision it applies the saltation matrix
//! ([`saltation`]), Φ⁺ = S Φ⁻. Between collisions:
//!
//! - after a Runge–Kutta step (RK4, Dormand–Prince), Φ is carried through
//!   *the step itself*: the method's stages are run again on pairs
//!   (x, δx), each stage's δ one tangent of q̈
//!   ([`Dynamics::accelerations_tangent`]), from the step's start over its
//!   length (up to the collision instant for a step that ends at one). So
//!   each column of Φ is the derivative of the computed solution, with
//!   no tolerance of its own, at 2N tangents a stage;
//! - after a step of Taylor's method, the variational equation Φ̇ =
//!   J(x(t)) Φ, J = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]], is integrated column by
//!   column along the step's polynomial ([`Simulator::state_at`]) by
//!   Dormand–Prince 5(4) with its own error control.
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
//! [`Dynamics::accelerations_tangent`]: crate::Dynamics::accelerations_tangent

use super::integrator::{DormandPrince, Engine, Method, RungeKutta};
use super::phase::{Combine, Dual, Phase};
use super::{Simulator, Step};
use crate::Surfaces;
use crate::saltation::{SaltationError, StateMatrix, saltation};

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
    /// is `None`).
    ///
    /// [`Dynamics::accelerations_tangent`]: crate::Dynamics::accelerations_tangent
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
    /// entries that start at one) of Φ's own integration along steps of
    /// Taylor's method; a Runge–Kutta step is differentiated itself and
    /// needs none (module doc).
    pub fn new(rtol: f64) -> Self {
        Self {
            phi: StateMatrix::identity(),
            before: StateMatrix::identity(),
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

    /// Advances Φ over `step`, the step `sim` has just made: along its
    /// motion, then through its collision if it ended at one.
    pub fn follow<M: Surfaces<N>>(
        &mut self,
        sim: &Simulator<'_, M, N>,
        step: &Step<M::Wall, N>,
    ) -> Result<(), VariationalError<M::Wall>> {
        let t1 = step.collision.as_ref().map_or(step.state.t, |c| c.t);
        if t1 > step.t0 {
            let last = sim
                .last
                .as_ref()
                .filter(|last| last.t0 == step.t0)
                .ok_or(VariationalError::NotTheLastStep)?;
            let model = sim.model();
            for j in 0..2 * N {
                let column = self.column(j);
                let column = match (&sim.engine, &last.interpolant) {
                    (Engine::RungeKutta(method), Some((_, dense))) => {
                        // The simulator's method, held to Φ's tolerance
                        // (Dormand–Prince; RK4 has no error estimate), tried
                        // first over the simulator's own step.
                        let method = match method {
                            RungeKutta::DormandPrince(_) => RungeKutta::DormandPrince(self.method),
                            rk4 => *rk4,
                        };
                        let start = Dual {
                            x: *dense.start(),
                            dx: column,
                        };
                        let mut rhs = |_: f64, y: &Dual<N>| tangent(model, y);
                        controlled(&method, &mut rhs, start, step.t0, t1, t1 - step.t0)?
                            .0
                            .dx
                    }
                    _ => {
                        let (t0, method) = (step.t0, RungeKutta::DormandPrince(self.method));
                        let mut rhs = |t: f64, d: &Phase<N>| {
                            let x = sim
                                .state_at(t.clamp(t0, t1))
                                .ok_or(VariationalError::NotTheLastStep)?;
                            let (x, dx) = (Phase { q: x.q, v: x.v }, *d);
                            Ok(tangent(model, &Dual { x, dx })?.dx)
                        };
                        let (column, h) = controlled(&method, &mut rhs, column, t0, t1, self.h)?;
                        self.h = h;
                        column
                    }
                };
                self.set_column(j, &column);
            }
        }
        self.before = self.phi;
        if let Some(c) = &step.collision {
            let s = saltation(sim.model(), c.wall, &c.q, &c.v_minus).map_err(|error| {
                VariationalError::Saltation {
                    wall: c.wall,
                    error,
                }
            })?;
            self.phi = s.matrix.mul(&self.phi);
        }
        Ok(())
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

/// y from t0 to t1 by `method` under its error control (one step of the
/// span for a method without any), the first step at most `first`: the
/// end, and the last step's length.
fn controlled<Y: Combine, W>(
    method: &RungeKutta,
    rhs: &mut impl FnMut(f64, &Y) -> Result<Y, VariationalError<W>>,
    mut y: Y,
    t0: f64,
    t1: f64,
    first: f64,
) -> Result<(Y, f64), VariationalError<W>> {
    let span = t1 - t0;
    let (mut t, mut h, mut accepted) = (t0, first.min(span), span);
    let mut tries = 0;
    while t < t1 {
        let last = t + h >= t1 - 1e-12 * span;
        let h_now = if last { t1 - t } else { h };
        let f0 = rhs(t, &y)?;
        let (y1, error) = method.estimate(rhs, &y, &f0, t, h_now)?;
        if error <= 1.0 && y1.finite() {
            y = y1;
            t = if last { t1 } else { t + h_now };
            accepted = h_now;
            tries = 0;
        } else {
            tries += 1;
            if tries > 50 || !error.is_finite() {
                return Err(VariationalError::Integration { t });
            }
        }
        h = h_now * method.factor(error);
    }
    Ok((y, accepted))
}
