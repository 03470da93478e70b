//! A derivation run without compiling: the straight-line programs of a
//! [`Derivation`] evaluated by a small register machine, behind the same
//! runtime traits as a generated model. It is what lets the CLI simulate a
//! user's model file at once (`dalembert simulate path/to/model.toml`).
//!
//! This is a back end beside [`crate::emit`]: it reads only the plain data
//! that the derivation hands on (no symbolic engine). Each program runs the
//! operations the emitted Rust performs, in the same order and with the same
//! libm functions ([`tape`]), so an interpreted model and its generated
//! code give the same numbers; `tests/interpreted.rs` checks this for every
//! built-in model, function by function and over simulated runs.

mod compiled;
mod series;
mod tape;

use dalembert_runtime::interval::Interval;
use dalembert_runtime::{__private, Dynamics, Model, Rows, Surfaces, Values, Walls};

use crate::derive::{Derivation, Function};
use crate::ir::Kind;
use crate::plan::{Plan, Taylor};
use crate::quantity::Quantity;
use compiled::Compiled;
use series::SeriesPrograms;
use tape::Tape;

/// A wall's programs.
#[derive(Clone, Debug)]
struct WallPrograms {
    name: String,
    surface: Compiled,
    normal: Compiled,
    normal_velocity: Compiled,
    surface_hessian: Compiled,
    rows: Compiled,
    /// P in closed form; `None`: solved at run time from G and B, as a
    /// generated model does.
    projector: Option<Compiled>,
    /// The collision map's program (closed form, linear or elimination);
    /// `None`: solved at run time from G and B, as a generated model does.
    collide: Option<Compiled>,
    /// The collision map's tangent program, where it has a program.
    collide_tangent: Option<Compiled>,
    collide_parameter_tangent: Option<Compiled>,
    surface_parameter_tangent: Option<Compiled>,
}

/// Which wall of an [`Interpreted`] model: its index in file order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct WallIndex(pub usize);

/// A model with `N` coordinates evaluated from its derivation's programs.
/// Implements [`Model`], [`Walls`], [`Dynamics`] and [`Surfaces`], so the
/// runtime's simulator and equations of motion take it as they take a
/// generated model.
///
/// Evaluation borrows a register file per program, so the model is not
/// `Sync`; clone it for another thread.
#[derive(Clone, Debug)]
pub struct Interpreted<const N: usize> {
    name: &'static str,
    coordinates: &'static [&'static str],
    velocities: &'static [&'static str],
    parameters: &'static [&'static str],
    values: Vec<f64>,
    initial_state: Compiled,
    /// Which initial velocities the file gives.
    given: [bool; N],
    /// The rates `[initial]` gives that are not velocities, their rows and
    /// values (none: `None`).
    start_rate_names: &'static [&'static str],
    start_rows: Option<Compiled>,
    start_values: Option<Compiled>,
    mass_matrix: Compiled,
    kinetic_energy: Compiled,
    potential: Compiled,
    constraints: Compiled,
    holonomic: Option<Compiled>,
    forcing: Compiled,
    drift: Compiled,
    accelerations: Option<Compiled>,
    accelerations_tangent: Option<Compiled>,
    accelerations_parameter_tangent: Option<Compiled>,
    /// The Taylor series, where q̈ is written out.
    series: Option<SeriesPrograms>,
    walls: Vec<WallPrograms>,
    indices: Vec<WallIndex>,
}

/// Why a derivation cannot be interpreted with `N` coordinates.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InterpretError {
    /// An instantaneous model has no coordinates to move.
    #[error(
        "`{0}` is an instantaneous model (velocities at the collision instant only): it has no motion to simulate"
    )]
    Instantaneous(String),
    /// The model's size is not `N`.
    #[error("`{model}` has {coordinates} coordinates and {velocities} velocities, not {n}")]
    Size {
        /// The model.
        model: String,
        /// Its coordinates.
        coordinates: usize,
        /// Its velocities.
        velocities: usize,
        /// What was asked for.
        n: usize,
    },
    /// The derivation lacks a function a model with coordinates has.
    #[error("the derivation of `{model}` has no `{function}`")]
    Missing {
        /// The model.
        model: String,
        /// The function.
        function: &'static str,
    },
}

/// A program's outputs at `inputs`, computed as the emitted code computes
/// them (the tape).
fn run_program(p: &crate::program::Program, inputs: &[f64]) -> Vec<f64> {
    let tape = Tape::new(p);
    let mut r = tape.init.clone();
    let n = inputs.len().min(tape.inputs);
    r[..n].copy_from_slice(&inputs[..n]);
    tape.run(&mut r);
    tape.outputs(&r).to_vec()
}

/// Names live as long as the process: an interpreted model is built once
/// per model file, and the runtime's traits hand out `&[&str]`.
fn leak_names(names: impl Iterator<Item = String>) -> &'static [&'static str] {
    let names: Vec<&'static str> = names.map(|n| &*Box::leak(n.into_boxed_str())).collect();
    Box::leak(names.into_boxed_slice())
}

impl<const N: usize> Interpreted<N> {
    /// The model of `d`, with the model file's parameter values.
    pub fn new(d: &Derivation) -> Result<Self, InterpretError> {
        let m = &d.model;
        if m.kind == Kind::Instantaneous {
            return Err(InterpretError::Instantaneous(m.name.clone()));
        }
        if m.coordinates.len() != N || m.velocities.len() != N {
            return Err(InterpretError::Size {
                model: m.name.clone(),
                coordinates: m.coordinates.len(),
                velocities: m.velocities.len(),
                n: N,
            });
        }
        let values: Vec<f64> = m.params.iter().map(|p| p.value).collect();
        let missing = |function| InterpretError::Missing {
            model: m.name.clone(),
            function,
        };
        let find = |fs: &[Function], q: Quantity| {
            fs.iter()
                .find(|f| f.quantity == q)
                .map(|f| Compiled::new(f, &values))
        };
        let model_fn = |q: Quantity| find(&d.functions, q).ok_or_else(|| missing(q.spec().name));
        let mut walls = Vec::with_capacity(d.walls.len());
        for w in &d.walls {
            let wall_fn = |q: Quantity| find(&w.functions, q).ok_or_else(|| missing(q.spec().name));
            walls.push(WallPrograms {
                name: w.name.clone(),
                surface: wall_fn(Quantity::Surface)?.with_bounds(),
                normal: wall_fn(Quantity::Normal)?.with_bounds(),
                normal_velocity: wall_fn(Quantity::NormalVelocity)?,
                surface_hessian: wall_fn(Quantity::SurfaceHessian)?,
                rows: wall_fn(Quantity::WallRows)?,
                projector: find(&w.functions, Quantity::Projector),
                collide: find(&w.functions, Quantity::Collide),
                collide_tangent: find(&w.functions, Quantity::CollideTangent),
                collide_parameter_tangent: find(&w.functions, Quantity::CollideParameterTangent),
                surface_parameter_tangent: find(&w.functions, Quantity::SurfaceParameterTangent),
            });
        }
        let series = SeriesPrograms::new(Plan::new(d, Taylor::Include), &values);
        Ok(Self {
            series,
            name: leak_names(std::iter::once(m.name.clone()))[0],
            coordinates: leak_names(m.coordinates.iter().cloned()),
            velocities: leak_names(m.velocities.iter().cloned()),
            parameters: leak_names(m.params.iter().map(|p| p.name.clone())),
            initial_state: model_fn(Quantity::InitialState)?,
            given: core::array::from_fn(|i| m.velocities_given().get(i).copied().unwrap_or(true)),
            start_rate_names: leak_names(m.start_rates.iter().map(|r| r.name.clone())),
            start_rows: find(&d.functions, Quantity::StartRows),
            start_values: find(&d.functions, Quantity::StartValues),
            mass_matrix: model_fn(Quantity::MassMatrix)?,
            kinetic_energy: model_fn(Quantity::KineticEnergy)?,
            potential: model_fn(Quantity::Potential)?,
            constraints: model_fn(Quantity::Constraints)?,
            holonomic: find(&d.functions, Quantity::Holonomic),
            forcing: model_fn(Quantity::Forcing)?,
            drift: model_fn(Quantity::ConstraintDrift)?,
            accelerations: find(&d.functions, Quantity::Accelerations),
            accelerations_tangent: find(&d.functions, Quantity::AccelerationsTangent),
            accelerations_parameter_tangent: find(
                &d.functions,
                Quantity::AccelerationsParameterTangent,
            ),
            indices: (0..walls.len()).map(WallIndex).collect(),
            walls,
            values,
        })
    }

    fn programs_mut(&mut self) -> impl Iterator<Item = &mut Compiled> {
        let model = [
            &mut self.initial_state,
            &mut self.mass_matrix,
            &mut self.kinetic_energy,
            &mut self.potential,
            &mut self.constraints,
            &mut self.forcing,
            &mut self.drift,
        ]
        .into_iter()
        .chain(self.holonomic.as_mut())
        .chain(self.start_rows.as_mut())
        .chain(self.start_values.as_mut())
        .chain(self.accelerations.as_mut())
        .chain(self.accelerations_tangent.as_mut())
        .chain(self.accelerations_parameter_tangent.as_mut());
        let walls = self.walls.iter_mut().flat_map(|w| {
            [
                &mut w.surface,
                &mut w.normal,
                &mut w.normal_velocity,
                &mut w.surface_hessian,
                &mut w.rows,
            ]
            .into_iter()
            .chain(w.projector.as_mut())
            .chain(w.collide.as_mut())
            .chain(w.collide_tangent.as_mut())
            .chain(w.collide_parameter_tangent.as_mut())
            .chain(w.surface_parameter_tangent.as_mut())
        });
        model.chain(walls)
    }

    fn np(&self) -> usize {
        self.values.len()
    }

    fn scalar(&self, c: &Compiled, q: &[f64; N], v: &[f64]) -> f64 {
        c.eval(self.np(), q, v, |o| o.first().copied().unwrap_or(0.0))
    }

    fn vector(&self, c: &Compiled, q: &[f64; N], v: &[f64]) -> [f64; N] {
        c.eval(self.np(), q, v, |o| {
            let mut out = [0.0; N];
            for (x, y) in out.iter_mut().zip(o) {
                *x = *y;
            }
            out
        })
    }

    /// A tangent program's values and derivatives at (q, v) along
    /// (dq, dv).
    fn tangent(&self, c: &Compiled, parts: &[&[f64]]) -> ([f64; N], [f64; N]) {
        c.eval_parts(self.np(), parts, |o| {
            let m = o.len() / 2;
            let at = |i: usize| if i < m { o[i] } else { 0.0 };
            (
                core::array::from_fn(at),
                core::array::from_fn(|i| if i < m { o[m + i] } else { 0.0 }),
            )
        })
    }

    fn matrix(&self, c: &Compiled, q: &[f64; N]) -> [[f64; N]; N] {
        c.eval(self.np(), q, &[], |o| {
            core::array::from_fn(|i| {
                core::array::from_fn(|j| o.get(i * N + j).copied().unwrap_or(0.0))
            })
        })
    }

    fn rows(&self, c: &Compiled, q: &[f64; N]) -> Rows<N> {
        Rows::new(self.matrix(c, q), c.rows)
    }

    /// The `[initial]` state at the parameters in use.
    fn initial_state(&self) -> ([f64; N], [f64; N]) {
        self.initial_state
            .eval(self.np(), &[0.0; N], &[0.0; N], |o| {
                let at = |i: usize| o.get(i).copied().unwrap_or(0.0);
                (
                    core::array::from_fn(at),
                    core::array::from_fn(|i| at(N + i)),
                )
            })
    }

    fn wall(&self, wall: WallIndex) -> &WallPrograms {
        &self.walls[wall.0]
    }
}

impl<const N: usize> Model<N, N> for Interpreted<N> {
    fn name(&self) -> &str {
        self.name
    }
    fn coordinate_names(&self) -> &[&str] {
        self.coordinates
    }
    fn velocity_names(&self) -> &[&str] {
        self.velocities
    }
    fn parameter_names(&self) -> &[&str] {
        self.parameters
    }
    fn parameter(&self, index: usize) -> Option<f64> {
        self.values.get(index).copied()
    }
    fn set_parameter(&mut self, index: usize, value: f64) -> bool {
        if index >= self.values.len() {
            return false;
        }
        self.values[index] = value;
        for c in self.programs_mut() {
            c.set_parameter(index, value);
        }
        if let Some(s) = &mut self.series {
            s.refresh(&self.values);
        }
        true
    }
    fn mass_matrix(&self, q: &[f64; N]) -> [[f64; N]; N] {
        self.matrix(&self.mass_matrix, q)
    }
    fn kinetic_energy(&self, q: &[f64; N], v: &[f64; N]) -> f64 {
        self.scalar(&self.kinetic_energy, q, v)
    }
    fn constraints(&self, q: &[f64; N]) -> Rows<N> {
        self.rows(&self.constraints, q)
    }
}

impl<const N: usize> Walls<N, N> for Interpreted<N> {
    type Wall = WallIndex;

    fn walls(&self) -> &[WallIndex] {
        &self.indices
    }
    fn wall_name(&self, wall: WallIndex) -> &str {
        &self.wall(wall).name
    }
    fn wall_rows(&self, wall: WallIndex, q: &[f64; N]) -> Rows<N> {
        self.rows(&self.wall(wall).rows, q)
    }
    fn projector(&self, wall: WallIndex, q: &[f64; N]) -> [[f64; N]; N] {
        match &self.wall(wall).projector {
            Some(p) => self.matrix(p, q),
            None => {
                let b = self.wall_rows(wall, q);
                __private::projector(&self.mass_matrix(q), b.as_slice())
                    .unwrap_or([[f64::NAN; N]; N])
            }
        }
    }
    fn collide(&self, wall: WallIndex, q: &[f64; N], v: &[f64; N]) -> [f64; N] {
        match &self.wall(wall).collide {
            Some(c) => self.vector(c, q, v),
            None => {
                let b = self.wall_rows(wall, q);
                let r = b.apply(v);
                match __private::correction(&self.mass_matrix(q), b.as_slice(), r.as_slice()) {
                    Ok(d) => core::array::from_fn(|i| v[i] - 2.0 * d[i]),
                    Err(_) => [f64::NAN; N],
                }
            }
        }
    }
    fn collide_tangent(
        &self,
        wall: WallIndex,
        q: &[f64; N],
        v: &[f64; N],
        dq: &[f64; N],
        dv: &[f64; N],
    ) -> Option<([f64; N], [f64; N])> {
        let c = self.wall(wall).collide_tangent.as_ref()?;
        Some(self.tangent(c, &[q, v, dq, dv]))
    }
    fn collide_parameter_tangent(
        &self,
        wall: WallIndex,
        q: &[f64; N],
        v: &[f64; N],
        dp: &[f64],
    ) -> Option<([f64; N], [f64; N])> {
        let c = self.wall(wall).collide_parameter_tangent.as_ref()?;
        (dp.len() == self.np()).then(|| self.tangent(c, &[q, v, dp]))
    }
    fn normal(&self, wall: WallIndex, q: &[f64; N]) -> [f64; N] {
        self.vector(&self.wall(wall).normal, q, &[])
    }
    fn normal_velocity(&self, wall: WallIndex, q: &[f64; N], v: &[f64; N]) -> f64 {
        self.scalar(&self.wall(wall).normal_velocity, q, v)
    }
}

impl<const N: usize> Dynamics<N> for Interpreted<N> {
    fn initial_coordinates(&self) -> [f64; N] {
        self.initial_state().0
    }
    fn initial_velocities(&self) -> [f64; N] {
        self.initial_state().1
    }
    fn initial_velocities_given(&self) -> [bool; N] {
        self.given
    }
    fn start_rate_names(&self) -> &[&str] {
        self.start_rate_names
    }
    fn start_rows(&self, q: &[f64; N]) -> Rows<N> {
        match &self.start_rows {
            Some(c) => self.rows(c, q),
            None => Rows::EMPTY,
        }
    }
    fn start_values(&self) -> Values<N> {
        match &self.start_values {
            Some(c) => Values::new(self.vector(c, &[0.0; N], &[]), c.rows),
            None => Values::EMPTY,
        }
    }
    fn potential(&self, q: &[f64; N]) -> f64 {
        self.scalar(&self.potential, q, &[])
    }
    fn holonomic(&self, q: &[f64; N]) -> Values<N> {
        match &self.holonomic {
            Some(c) => Values::new(self.vector(c, q, &[]), c.rows),
            None => Values::EMPTY,
        }
    }
    fn forcing(&self, q: &[f64; N], v: &[f64; N]) -> [f64; N] {
        self.vector(&self.forcing, q, v)
    }
    fn constraint_drift(&self, q: &[f64; N], v: &[f64; N]) -> [f64; N] {
        self.vector(&self.drift, q, v)
    }
    fn closed_form_accelerations(&self, q: &[f64; N], v: &[f64; N]) -> Option<[f64; N]> {
        self.accelerations.as_ref().map(|c| self.vector(c, q, v))
    }
    fn accelerations_tangent(
        &self,
        q: &[f64; N],
        v: &[f64; N],
        dq: &[f64; N],
        dv: &[f64; N],
    ) -> Option<([f64; N], [f64; N])> {
        let c = self.accelerations_tangent.as_ref()?;
        Some(self.tangent(c, &[q, v, dq, dv]))
    }
    fn accelerations_parameter_tangent(
        &self,
        q: &[f64; N],
        v: &[f64; N],
        dp: &[f64],
    ) -> Option<([f64; N], [f64; N])> {
        let c = self.accelerations_parameter_tangent.as_ref()?;
        (dp.len() == self.np()).then(|| self.tangent(c, &[q, v, dp]))
    }
}

impl<const N: usize> Surfaces<N> for Interpreted<N> {
    fn surface(&self, wall: WallIndex, q: &[f64; N]) -> f64 {
        self.scalar(&self.wall(wall).surface, q, &[])
    }
    fn surface_hessian(&self, wall: WallIndex, q: &[f64; N], v: &[f64; N]) -> Option<f64> {
        Some(self.scalar(&self.wall(wall).surface_hessian, q, v))
    }
    fn surface_parameter_tangent(
        &self,
        wall: WallIndex,
        q: &[f64; N],
        dp: &[f64],
    ) -> Option<(f64, f64)> {
        let c = self.wall(wall).surface_parameter_tangent.as_ref()?;
        (dp.len() == self.np()).then(|| {
            c.eval_parts(self.np(), &[q, dp], |o| {
                (
                    o.first().copied().unwrap_or(0.0),
                    o.get(1).copied().unwrap_or(0.0),
                )
            })
        })
    }
    fn surface_bounds(&self, wall: WallIndex, q: &[Interval; N]) -> Option<Interval> {
        let f = &self.wall(wall).surface;
        Some(f.eval_bounds(self.np(), q, |o| {
            o.first().copied().unwrap_or(Interval::point(0.0))
        }))
    }
    fn normal_bounds(&self, wall: WallIndex, q: &[Interval; N]) -> Option<[Interval; N]> {
        let f = &self.wall(wall).normal;
        Some(f.eval_bounds(self.np(), q, |o| {
            core::array::from_fn(|i| o.get(i).copied().unwrap_or(Interval::point(0.0)))
        }))
    }
}
