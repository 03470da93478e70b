//! The traits a generated model implements, layered by what it has (in the
//! manner of embedded-hal): every model is a [`Model`] with [`Walls`]; a
//! model with coordinates (`Q = N`) adds [`Dynamics`] and [`Surfaces`],
//! and one with Taylor series [`TaylorSeries`].
//! An instantaneous model (`Q = 0`, the paper's §3) implements only the
//! first two: it has no motion and no surfaces.

use crate::interval::Interval;
use crate::taylor::{Coefficients, Series, SeriesWork};
use crate::{Rows, Values, linalg};

/// What every model has: names, parameters, the mass matrix and the
/// constraints. `Q` is the number of coordinates (0 for an instantaneous
/// model) and `N` the number of velocity components.
///
/// Names and parameters are methods, not constants, so that a model known
/// only at run time (the CLI's interpreted model files) has the same traits
/// as a generated one; a generated model also has them as inherent
/// constants (`BallFloor::PARAMETERS`).
pub trait Model<const Q: usize, const N: usize> {
    /// The model's name, as in its file.
    fn name(&self) -> &str;
    /// Names of the coordinates, in order (empty for an instantaneous model).
    fn coordinate_names(&self) -> &[&str];
    /// Names of the velocity components, in order.
    fn velocity_names(&self) -> &[&str];
    /// Names of the parameters, in order.
    fn parameter_names(&self) -> &[&str];

    /// The value of parameter `index` (in [`Model::parameter_names`] order).
    fn parameter(&self, index: usize) -> Option<f64>;
    /// Sets parameter `index`; false when there is no such parameter.
    fn set_parameter(&mut self, index: usize, value: f64) -> bool;
    /// The value of the parameter called `name`, if the model has one.
    /// (Derived parameters are not parameters of the generated code: they
    /// are computed from the others wherever they are used.)
    fn parameter_named(&self, name: &str) -> Option<f64> {
        let index = self.parameter_names().iter().position(|p| *p == name)?;
        self.parameter(index)
    }
    /// Sets the parameter called `name`; false when the model has none.
    fn set_parameter_named(&mut self, name: &str, value: f64) -> bool {
        match self.parameter_names().iter().position(|p| *p == name) {
            Some(index) => self.set_parameter(index, value),
            None => false,
        }
    }

    /// The mass matrix G(q): T = ½ vᵀ G(q) v.
    fn mass_matrix(&self, q: &[f64; Q]) -> [[f64; N]; N];
    /// Kinetic energy T(q, v).
    fn kinetic_energy(&self, q: &[f64; Q], v: &[f64; N]) -> f64;
    /// Rows of the constraints A(q): admissible v have A v = 0. In a model
    /// with holonomic constraints the first rows are their differentials
    /// dh(q) (see [`Dynamics::holonomic`]), the rest the nonholonomic ones.
    fn constraints(&self, q: &[f64; Q]) -> Rows<N>;
}

/// A model built from a parameter struct: what generated models have (an
/// interpreted model is built from its derivation and has only
/// [`Model::set_parameter`]).
pub trait FromParams {
    /// The model's parameters, with the model file's values as `Default`.
    type Params: Copy + Default + core::fmt::Debug;
    /// The model with the given parameters.
    fn with_params(params: Self::Params) -> Self;
    /// The parameters in use.
    fn params(&self) -> &Self::Params;
}

/// Walls and their collision maps.
pub trait Walls<const Q: usize, const N: usize>: Model<Q, N> {
    /// The model's walls (a generated model has one enum variant each).
    type Wall: Copy + Eq + core::fmt::Debug + 'static;

    /// Every wall of the model, in file order.
    fn walls(&self) -> &[Self::Wall];
    /// A wall's name, as in the model file.
    fn wall_name(&self, wall: Self::Wall) -> &str;
    /// The wall's independent constraint rows B(q); the first is the normal
    /// velocity.
    fn wall_rows(&self, wall: Self::Wall, q: &[f64; Q]) -> Rows<N>;
    /// The G-orthogonal projector P onto (ker B)^⊥ (eq. 2.4).
    fn projector(&self, wall: Self::Wall, q: &[f64; Q]) -> [[f64; N]; N];
    /// The collision map v⁺ = (I − 2P) v⁻ (eq. 2.13) for admissible v⁻
    /// (A v⁻ = 0, the velocities a motion has). Generated code may use
    /// A v⁻ = 0 to shorten the map, so for other v it can differ from
    /// (I − 2P)v; [`Walls::projector`] gives P itself.
    fn collide(&self, wall: Self::Wall, q: &[f64; Q], v: &[f64; N]) -> [f64; N];

    /// The wall's normal row (df(q) in a model with coordinates; the first
    /// row of B). Generated models emit it directly; the default takes B's
    /// first row.
    fn normal(&self, wall: Self::Wall, q: &[f64; Q]) -> [f64; N] {
        self.wall_rows(wall, q)
            .as_slice()
            .first()
            .copied()
            .unwrap_or([0.0; N])
    }

    /// The normal velocity (df(q)·v with coordinates): negative while
    /// approaching the wall. Generated models emit it directly; the default
    /// is [`Walls::normal`] times v.
    fn normal_velocity(&self, wall: Self::Wall, q: &[f64; Q], v: &[f64; N]) -> f64 {
        linalg::dot(&self.normal(wall, q), v)
    }

    /// The collision map and its derivative along a direction (δq, δv⁻):
    /// (v⁺, ∂v⁺/∂q δq + ∂v⁺/∂v⁻ δv⁻), for admissible v⁻ as in
    /// [`Walls::collide`]. Generated models differentiate the map's own
    /// program, so the derivative is that of the numbers `collide` returns;
    /// `None` (the default, and a generated wall whose P is solved at run
    /// time) means the model has no derivative of it.
    fn collide_tangent(
        &self,
        wall: Self::Wall,
        q: &[f64; Q],
        v: &[f64; N],
        dq: &[f64; Q],
        dv: &[f64; N],
    ) -> Option<([f64; N], [f64; N])> {
        let _ = (wall, q, v, dq, dv);
        None
    }

    /// The collision map and its derivative along a direction δp of the
    /// parameters (one entry each, in [`Model::parameter_names`] order) at
    /// fixed (q, v⁻): (v⁺, ∂v⁺/∂p δp), for admissible v⁻ as in
    /// [`Walls::collide`]. Generated models differentiate the map's own
    /// program, as [`Walls::collide_tangent`]; `None` (the default, a wall
    /// whose P is solved at run time, and a `dp` whose length is not the
    /// number of parameters) means no derivative.
    fn collide_parameter_tangent(
        &self,
        wall: Self::Wall,
        q: &[f64; Q],
        v: &[f64; N],
        dp: &[f64],
    ) -> Option<([f64; N], [f64; N])> {
        let _ = (wall, q, v, dp);
        None
    }

    /// The Jacobian of the collision map at (q, v⁻): (∂v⁺/∂q, ∂v⁺/∂v⁻),
    /// entry `[i][j]` the derivative of v⁺ᵢ by qⱼ (resp. v⁻ⱼ), from Q + N
    /// calls of [`Walls::collide_tangent`]; `None` where that is.
    #[allow(clippy::type_complexity)]
    fn collide_jacobian(
        &self,
        wall: Self::Wall,
        q: &[f64; Q],
        v: &[f64; N],
    ) -> Option<([[f64; Q]; N], [[f64; N]; N])> {
        let mut by_q = [[0.0; Q]; N];
        let mut by_v = [[0.0; N]; N];
        for j in 0..Q {
            let mut dq = [0.0; Q];
            dq[j] = 1.0;
            let (_, column) = self.collide_tangent(wall, q, v, &dq, &[0.0; N])?;
            (0..N).for_each(|i| by_q[i][j] = column[i]);
        }
        for j in 0..N {
            let mut dv = [0.0; N];
            dv[j] = 1.0;
            let (_, column) = self.collide_tangent(wall, q, v, &[0.0; Q], &dv)?;
            (0..N).for_each(|i| by_v[i][j] = column[i]);
        }
        Some((by_q, by_v))
    }
}

/// The motion between collisions of a model with coordinates: the
/// Lagrange–d'Alembert equations G(q) q̈ + h(q, q̇) = A(q)ᵀλ, A(q) q̇ = 0.
pub trait Dynamics<const N: usize>: Model<N, N> {
    /// A starting configuration for simulations (the model file's
    /// `[initial]` table; zero by default).
    fn initial_coordinates(&self) -> [f64; N] {
        [0.0; N]
    }
    /// Starting velocities for simulations (the model file's `[initial]`;
    /// zero by default).
    fn initial_velocities(&self) -> [f64; N] {
        [0.0; N]
    }
    /// Which of [`Dynamics::initial_velocities`] the model file gives; the
    /// others follow from the constraints at the start
    /// ([`crate::simulate::starting_velocity`]). All by default.
    fn initial_velocities_given(&self) -> [bool; N] {
        [true; N]
    }

    /// The rates the start gives that are not velocities themselves (a
    /// body's angular velocity, from the model file's `[initial]`), by name:
    /// each is a row of [`Dynamics::start_rows`] with its value in
    /// [`Dynamics::start_values`]. None by default.
    fn start_rate_names(&self) -> &[&str] {
        &[]
    }
    /// The rows L(q) of [`Dynamics::start_rate_names`]' rates (each rate is
    /// L(q)ᵢ·q̇): the start's velocity meets L(q) q̇ = c besides
    /// A(q) q̇ = 0 ([`crate::simulate::starting_velocity`]). None by
    /// default.
    fn start_rows(&self, q: &[f64; N]) -> Rows<N> {
        let _ = q;
        Rows::EMPTY
    }
    /// The values c the start gives those rates, at the parameters in use.
    fn start_values(&self) -> Values<N> {
        Values::EMPTY
    }

    /// Potential energy V(q).
    fn potential(&self, q: &[f64; N]) -> f64;
    /// The holonomic constraints' values h(q) (zero on the constraint
    /// manifold). None unless the model file declares `holonomic`.
    fn holonomic(&self, q: &[f64; N]) -> Values<N> {
        let _ = q;
        Values::EMPTY
    }
    /// h(q, q̇) in G(q) q̈ + h(q, q̇) = A(q)ᵀλ. See
    /// [`crate::dynamics::accelerations`].
    fn forcing(&self, q: &[f64; N], v: &[f64; N]) -> [f64; N];
    /// Ȧq̇, one entry per row of A, the rest zero: along the motion
    /// A q̈ + Ȧq̇ = 0.
    fn constraint_drift(&self, q: &[f64; N], v: &[f64; N]) -> [f64; N];

    /// q̈ of the equations of motion written out by the generator: the exact
    /// closed form where G⁻¹ is exact, else the solve by elimination as
    /// straight-line code; `None` (the default) means "solve G q̈ + h = Aᵀλ
    /// numerically", as [`crate::dynamics::accelerations`] does. The result
    /// is non-finite where G is singular.
    fn closed_form_accelerations(&self, q: &[f64; N], v: &[f64; N]) -> Option<[f64; N]> {
        let _ = (q, v);
        None
    }

    /// [`Dynamics::closed_form_accelerations`] and its derivative along a
    /// direction (δq, δv): (q̈, ∂q̈/∂q δq + ∂q̈/∂v δv). Generated models
    /// differentiate q̈'s own program forward (exact up to rounding, no
    /// finite differences); `None` (the default) where the model writes no
    /// q̈ out.
    fn accelerations_tangent(
        &self,
        q: &[f64; N],
        v: &[f64; N],
        dq: &[f64; N],
        dv: &[f64; N],
    ) -> Option<([f64; N], [f64; N])> {
        let _ = (q, v, dq, dv);
        None
    }

    /// [`Dynamics::closed_form_accelerations`] and its derivative along a
    /// direction δp of the parameters (one entry each, in
    /// [`Model::parameter_names`] order) at fixed (q, v): (q̈, ∂q̈/∂p δp),
    /// by forward differentiation of q̈'s program as
    /// [`Dynamics::accelerations_tangent`]. `None` (the default) where the
    /// model writes no q̈ out, and for a `dp` whose length is not the
    /// number of parameters.
    fn accelerations_parameter_tangent(
        &self,
        q: &[f64; N],
        v: &[f64; N],
        dp: &[f64],
    ) -> Option<([f64; N], [f64; N])> {
        let _ = (q, v, dp);
        None
    }

    /// The Jacobian of q̈ at (q, v): (∂q̈/∂q, ∂q̈/∂v), entry `[i][j]` the
    /// derivative of q̈ᵢ by qⱼ (resp. vⱼ), from 2N calls of
    /// [`Dynamics::accelerations_tangent`]; `None` where that is. The
    /// derivative by q is taken with v held fixed, off the constraint
    /// manifold too.
    #[allow(clippy::type_complexity)]
    fn accelerations_jacobian(
        &self,
        q: &[f64; N],
        v: &[f64; N],
    ) -> Option<([[f64; N]; N], [[f64; N]; N])> {
        let mut by_q = [[0.0; N]; N];
        let mut by_v = [[0.0; N]; N];
        for j in 0..2 * N {
            let mut direction = [[0.0; N]; 2];
            direction[j / N][j % N] = 1.0;
            let (_, column) = self.accelerations_tangent(q, v, &direction[0], &direction[1])?;
            let target = if j < N { &mut by_q } else { &mut by_v };
            (0..N).for_each(|i| target[i][j % N] = column[i]);
        }
        Some((by_q, by_v))
    }

    /// Total energy T + V.
    fn energy(&self, q: &[f64; N], v: &[f64; N]) -> f64 {
        self.kinetic_energy(q, v) + self.potential(q)
    }
}

/// The walls of a model with coordinates as surfaces N = {f(q) = 0}: what
/// the hybrid simulator needs on top of [`Dynamics`] and [`Walls`].
pub trait Surfaces<const N: usize>: Dynamics<N> + Walls<N, N> {
    /// The wall's surface function f(q): motion in f ≥ 0, the wall is f = 0.
    fn surface(&self, wall: Self::Wall, q: &[f64; N]) -> f64;

    /// vᵀ∇²f(q)v for the wall's surface f: along a motion the second time
    /// derivative of f is f̈ = df(q)·q̈ + vᵀ∇²f(q)v. The simulator uses it to
    /// end steps where a collision is predicted. Generated models emit it;
    /// the default `None` (unknown) means steps are not aimed at this wall.
    fn surface_hessian(&self, wall: Self::Wall, q: &[f64; N], v: &[f64; N]) -> Option<f64> {
        let _ = (wall, q, v);
        None
    }

    /// The wall's f(q) and its derivative along a direction δp of the
    /// parameters (one entry each, in [`Model::parameter_names`] order) at
    /// fixed q: (f, ∂f/∂p δp); how a collision instant moves with the
    /// parameters. Generated models emit it; `None` (the default, and a
    /// `dp` whose length is not the number of parameters): unknown.
    fn surface_parameter_tangent(
        &self,
        wall: Self::Wall,
        q: &[f64; N],
        dp: &[f64],
    ) -> Option<(f64, f64)> {
        let _ = (wall, q, dp);
        None
    }

    /// Bounds on the wall's f over a box of coordinates (`q[i]` the range
    /// of coordinate i): every value f takes on the box lies in them
    /// ([`Interval::ENTIRE`] where f is undefined somewhere on it). The
    /// simulator proves stretches of a step free of the wall with them, so
    /// that no dip of f below zero between its samples goes unseen.
    /// Generated models emit it; the default `None` (unknown) leaves the
    /// wall to the samples alone.
    fn surface_bounds(&self, wall: Self::Wall, q: &[Interval; N]) -> Option<Interval> {
        let _ = (wall, q);
        None
    }

    /// Bounds on the wall's normal df(q) over a box of coordinates, as
    /// [`Surfaces::surface_bounds`] on f: with them the simulator proves f
    /// monotone along a stretch of a step. The default `None`: unknown.
    fn normal_bounds(&self, wall: Self::Wall, q: &[Interval; N]) -> Option<[Interval; N]> {
        let _ = (wall, q);
        None
    }
}

/// The Taylor series of a model's motion and of its walls' f: what
/// Taylor's method ([`crate::simulate::Integrator::Taylor`]) steps on.
/// Generated models implement it wherever they write q̈ out (the Taylor
/// transform of that program, [`Dynamics::closed_form_accelerations`]). A
/// model without series needs none of it: the Runge–Kutta methods use
/// [`Surfaces`] alone. The simulator keeps the series and the scratch room
/// in a [`crate::simulate::SeriesRoom`], which only a simulator built
/// with [`crate::simulate::Simulator::with_series`] carries.
pub trait TaylorSeries<const N: usize>: Surfaces<N> {
    /// Room for the intermediate coefficients of the model's series
    /// ([`TaylorSeries::taylor_series`], [`TaylorSeries::surface_series`]),
    /// kept by the caller from one call to the next, so that a call
    /// neither zeroes its intermediate arrays nor holds them on its stack
    /// (`chain_8`'s are 22 KiB, and 64.5 KiB of coefficient pairs, which
    /// its history loops read two at a time). A generated model's is its
    /// module's `SeriesScratch`; `()` where a model keeps none. `Default`
    /// gives room ready for any call; what a call leaves in it is only
    /// ever overwritten, never read, by the next.
    type SeriesScratch: Default;

    /// The Taylor series of the motion through the state held at order 0
    /// of `series` (q(t₀), q̇(t₀)): fills its coefficients of orders 1 to
    /// `order` (at most [`crate::taylor::MAX_ORDER`]) and sets its order,
    /// with `scratch` as room for the intermediate series (pass the same
    /// one call after call; `&mut Default::default()` for a single call).
    /// `false` (the default) means the model has none and the series is
    /// untouched.
    fn taylor_series(
        &self,
        series: &mut Series<N>,
        scratch: &mut Self::SeriesScratch,
        order: usize,
    ) -> bool {
        let _ = (series, scratch, order);
        false
    }

    /// The Taylor coefficients of t ↦ f(q(t)) along `series` (see
    /// [`TaylorSeries::taylor_series`], whose `scratch` this shares),
    /// orders 0 to `series.order`, into `out`. `false` (the default) means
    /// the model has none.
    fn surface_series(
        &self,
        wall: Self::Wall,
        series: &Series<N>,
        scratch: &mut Self::SeriesScratch,
        out: &mut Coefficients,
    ) -> bool {
        let _ = (wall, series, scratch, out);
        false
    }

    /// Columns of the variational flow along the motion's `series` (filled
    /// by [`TaylorSeries::taylor_series`]): each of `columns` holds a
    /// tangent (δq, δq̇) at order 0 and gets its coefficients of orders 1
    /// to `series.order` and that order, the series of the variational
    /// equation δq̈ = ∂q̈/∂q δq + ∂q̈/∂q̇ δq̇ along the motion (the
    /// derivative of the motion's polynomial along its start).
    /// [`crate::simulate::Variational`] carries Φ over a step of Taylor's
    /// method with it. `false` (the default) means the model has none and
    /// the columns are untouched.
    fn variational_series(&self, series: &Series<N>, columns: &mut [Series<N>]) -> bool {
        let _ = (series, columns);
        false
    }

    /// The work per order of [`TaylorSeries::taylor_series`] and of the
    /// walls' [`TaylorSeries::surface_series`], from which Taylor's method
    /// picks the order that costs least per unit of time. `None` (the
    /// default): unknown, and the method keeps the order its tolerance
    /// asks for.
    fn series_work(&self) -> Option<SeriesWork> {
        None
    }
}
