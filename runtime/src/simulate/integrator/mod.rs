//! Integration methods between collisions. Each is one file. The
//! Runge–Kutta methods have their tableau, dense output and step-size
//! control and implement `Method` over evaluations of (q̇, q̈); Taylor's
//! method steps along the model's own series (`taylor.rs`, and the
//! simulator's `series.rs` for its events). [`Integrator`] names them in
//! [`super::Settings`].
//!
//! Adding a Runge–Kutta method: a file here implementing `Method`, a
//! variant of [`Integrator`] and of `RungeKutta`, and its arm in
//! `with_method!`.

mod dense;
mod dopri;
mod rk4;
mod taylor;

pub(crate) use dense::Dense;
pub use dopri::DormandPrince;
pub use rk4::Rk4;
pub use taylor::Taylor;
pub(crate) use taylor::{Plan, Reach};

use super::phase::{Combine, Phase};

/// The integration method between collisions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Classical fourth-order Runge–Kutta with a fixed step.
    Rk4(Rk4),
    /// Dormand–Prince 5(4) with error control.
    DormandPrince(DormandPrince),
    /// Taylor's method on the model's generated series, with events found
    /// on the step's polynomial.
    Taylor(Taylor),
}

/// How the simulator steps: by evaluations of (q̇, q̈), or along series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Engine {
    RungeKutta(RungeKutta),
    Taylor(Plan),
}

impl Integrator {
    /// Whether the settings are usable (positive, finite steps and
    /// tolerances).
    pub fn valid(&self) -> bool {
        match self.engine() {
            Engine::RungeKutta(m) => m.valid(),
            Engine::Taylor(t) => t.method.valid(),
        }
    }

    pub(crate) fn engine(&self) -> Engine {
        match *self {
            Integrator::Rk4(m) => Engine::RungeKutta(RungeKutta::Rk4(m)),
            Integrator::DormandPrince(m) => Engine::RungeKutta(RungeKutta::DormandPrince(m)),
            Integrator::Taylor(t) => Engine::Taylor(Plan::new(t)),
        }
    }
}

/// The methods that step by evaluations of (q̇, q̈).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum RungeKutta {
    Rk4(Rk4),
    DormandPrince(DormandPrince),
}

/// One trial step: the new state, its derivative, the error estimate (zero
/// for a method without one) and the dense output.
pub(crate) struct Trial<const N: usize> {
    pub y1: Phase<N>,
    pub f1: Phase<N>,
    pub error: f64,
    pub dense: Dense<N>,
}

/// What the simulator needs of a method. `rhs` evaluates (q̇, q̈) at a time
/// and state; its error type is the simulator's.
pub(crate) trait Method {
    /// Whether the settings are usable (positive, finite steps and
    /// tolerances).
    fn valid(&self) -> bool;

    /// Whether steps are chosen by error control (and so can be aimed at
    /// predicted collisions and retried when too long).
    fn adaptive(&self) -> bool;

    /// The first step from y, where the derivative is f0.
    fn initial_step<const N: usize>(&self, y: &Phase<N>, f0: &Phase<N>) -> f64;

    /// The longest step allowed.
    fn max_step(&self) -> f64;

    /// The factor by which the step changes after a trial with scaled
    /// error `err` (adaptive methods; 1 otherwise).
    fn factor(&self, err: f64) -> f64;

    /// The end of one step of length `h` from (t0, y0), and the derivative
    /// there when the method has it for free; no error estimate, no dense
    /// output. Over [`Dual`](super::phase::Dual)s it is also the step's
    /// derivative along a tangent.
    fn advance<Y: Combine, E>(
        &self,
        rhs: &mut impl FnMut(f64, &Y) -> Result<Y, E>,
        y0: &Y,
        f0: &Y,
        t0: f64,
        h: f64,
    ) -> Result<(Y, Option<Y>), E>;

    /// The end of one step of length `h` from (t0, y0) and its error
    /// estimate, scaled as the method's error control holds it to 1 (zero
    /// for a method without one); no dense output.
    fn estimate<Y: Combine, E>(
        &self,
        rhs: &mut impl FnMut(f64, &Y) -> Result<Y, E>,
        y0: &Y,
        f0: &Y,
        t0: f64,
        h: f64,
    ) -> Result<(Y, f64), E>;

    /// One step of length `h` from (t0, y0), with its error estimate and
    /// dense output, and without error control.
    fn trial<const N: usize, E>(
        &self,
        rhs: &mut impl FnMut(f64, &Phase<N>) -> Result<Phase<N>, E>,
        y0: &Phase<N>,
        f0: &Phase<N>,
        t0: f64,
        h: f64,
    ) -> Result<Trial<N>, E>;
}

/// `$body` with `$m` bound to the method of `$integrator`: the one place
/// where the integrators are listed.
macro_rules! with_method {
    ($integrator:expr, $m:ident => $body:expr) => {
        match $integrator {
            RungeKutta::Rk4($m) => $body,
            RungeKutta::DormandPrince($m) => $body,
        }
    };
}

impl Method for RungeKutta {
    fn valid(&self) -> bool {
        with_method!(self, m => m.valid())
    }
    fn adaptive(&self) -> bool {
        with_method!(self, m => m.adaptive())
    }
    fn initial_step<const N: usize>(&self, y: &Phase<N>, f0: &Phase<N>) -> f64 {
        with_method!(self, m => m.initial_step(y, f0))
    }
    fn max_step(&self) -> f64 {
        with_method!(self, m => m.max_step())
    }
    fn factor(&self, err: f64) -> f64 {
        with_method!(self, m => m.factor(err))
    }
    fn advance<Y: Combine, E>(
        &self,
        rhs: &mut impl FnMut(f64, &Y) -> Result<Y, E>,
        y0: &Y,
        f0: &Y,
        t0: f64,
        h: f64,
    ) -> Result<(Y, Option<Y>), E> {
        with_method!(self, m => m.advance(rhs, y0, f0, t0, h))
    }
    fn estimate<Y: Combine, E>(
        &self,
        rhs: &mut impl FnMut(f64, &Y) -> Result<Y, E>,
        y0: &Y,
        f0: &Y,
        t0: f64,
        h: f64,
    ) -> Result<(Y, f64), E> {
        with_method!(self, m => m.estimate(rhs, y0, f0, t0, h))
    }
    fn trial<const N: usize, E>(
        &self,
        rhs: &mut impl FnMut(f64, &Phase<N>) -> Result<Phase<N>, E>,
        y0: &Phase<N>,
        f0: &Phase<N>,
        t0: f64,
        h: f64,
    ) -> Result<Trial<N>, E> {
        with_method!(self, m => m.trial(rhs, y0, f0, t0, h))
    }
}
