//! The table of emitted quantities: one row per function a generated model
//! has, shared by the derivation (which fills in a [`Program`] for each row)
//! and the emitter (which writes the inherent function, the `Model` trait
//! method that forwards to it, and its line of operation counts).
//!
//! Adding a quantity is one row here and its derivation in `derive/`.
//!
//! [`Program`]: crate::program::Program

/// A function every generated model (or every wall of it) has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// G(q).
    MassMatrix,
    /// T(q, v).
    KineticEnergy,
    /// V(q).
    Potential,
    /// The rows of A(q).
    Constraints,
    /// h(q) of the holonomic constraints.
    Holonomic,
    /// h(q, q̇) of G q̈ + h = Aᵀλ.
    Forcing,
    /// Ȧq̇.
    ConstraintDrift,
    /// q̈ written out: the exact closed form where G⁻¹ is exact, else the
    /// solve of the equations of motion by elimination.
    Accelerations,
    /// A wall's f(q).
    Surface,
    /// A wall's df(q).
    Normal,
    /// A wall's df(q)·v.
    NormalVelocity,
    /// A wall's vᵀ∇²f(q)v.
    SurfaceHessian,
    /// A wall's independent rows of B(q).
    WallRows,
    /// A wall's P, in closed form.
    Projector,
    /// A wall's (I − 2P)v, in closed form.
    Collide,
    /// q̈ and its derivative along a direction (δq, δv) of the phase.
    AccelerationsTangent,
    /// A wall's (I − 2P)v and its derivative along a direction (δq, δv).
    CollideTangent,
    /// q̈ and its derivative along a direction δp of the parameters.
    AccelerationsParameterTangent,
    /// A wall's (I − 2P)v and its derivative along a direction δp of the
    /// parameters.
    CollideParameterTangent,
    /// A wall's f(q) and its derivative along a direction δp of the
    /// parameters.
    SurfaceParameterTangent,
    /// The starting state of the file's `[initial]`, at the parameters in
    /// use.
    InitialState,
    /// The rows L(q) of the rates `[initial]` gives that are not velocities
    /// (definitions linear in them): the start has L(q) q̇ = c.
    StartRows,
    /// Their values c, at the parameters in use.
    StartValues,
}

/// What an emitted function takes besides the model's parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inputs {
    /// Nothing: a function of the parameters alone.
    Parameters,
    /// The coordinates q.
    Coordinates,
    /// The coordinates q and the velocities v.
    Phase,
    /// The coordinates q, the velocities v, and a direction (δq, δv).
    Tangent,
    /// The coordinates q and a direction δp of the parameters.
    CoordinatesByParameters,
    /// The coordinates q, the velocities v, and a direction δp of the
    /// parameters.
    PhaseByParameters,
}

/// One array an emitted function takes besides the parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Array {
    /// The coordinates q (Q numbers).
    Q,
    /// The velocities v (N numbers).
    V,
    /// A direction δq of the coordinates (Q numbers).
    Dq,
    /// A direction δv of the velocities (N numbers).
    Dv,
    /// A direction δp of the parameters (one number each).
    Dp,
}

impl Array {
    /// Its argument's name in emitted code.
    pub fn name(self) -> &'static str {
        match self {
            Self::Q => "q",
            Self::V => "v",
            Self::Dq => "dq",
            Self::Dv => "dv",
            Self::Dp => "dp",
        }
    }

    /// How many numbers it holds, in a model with `params` parameters,
    /// `q` coordinates and `n` velocities.
    pub fn len(self, params: usize, q: usize, n: usize) -> usize {
        match self {
            Self::Q | Self::Dq => q,
            Self::V | Self::Dv => n,
            Self::Dp => params,
        }
    }
}

impl Inputs {
    /// The arrays it takes, in the order the program's inputs follow the
    /// parameters: the one layout the emitted arguments, the trait
    /// methods and the interpreter read.
    pub fn arrays(self) -> &'static [Array] {
        match self {
            Self::Parameters => &[],
            Self::Coordinates => &[Array::Q],
            Self::Phase => &[Array::Q, Array::V],
            Self::Tangent => &[Array::Q, Array::V, Array::Dq, Array::Dv],
            Self::CoordinatesByParameters => &[Array::Q, Array::Dp],
            Self::PhaseByParameters => &[Array::Q, Array::V, Array::Dp],
        }
    }

    /// How many inputs a program of this quantity reads: the parameters
    /// and its arrays.
    pub fn width(self, params: usize, q: usize, n: usize) -> usize {
        params
            + self
                .arrays()
                .iter()
                .map(|a| a.len(params, q, n))
                .sum::<usize>()
    }

    /// The array holding input `i` of a program (after the `params`
    /// parameters), and the index in it; `None` for a parameter.
    pub fn array_of(self, i: usize, params: usize, q: usize, n: usize) -> Option<(Array, usize)> {
        let mut at = i.checked_sub(params)?;
        for &a in self.arrays() {
            let len = a.len(params, q, n);
            if at < len {
                return Some((a, at));
            }
            at -= len;
        }
        None
    }
}

/// What an emitted function returns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// One number.
    Scalar,
    /// N numbers (fewer outputs are padded with zeros).
    Vector,
    /// N×N numbers, row-major outputs.
    Matrix,
    /// Up to N rows of N numbers, with how many are in use.
    Rows,
    /// Up to N numbers, with how many are in use.
    Values,
    /// A state: the coordinates, then the velocities.
    State,
    /// N numbers and their derivatives along a direction: the program's
    /// outputs are the values, then the derivatives (each padded to N).
    Tangent,
    /// One number and its derivative along a direction.
    ScalarTangent,
}

/// How the `Model` trait method returns the inherent function's value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Forward {
    /// As it is.
    Plain,
    /// Wrapped in `Some` (a trait method whose default is `None`).
    Some,
}

/// The runtime trait a quantity's method belongs to (`dalembert_runtime`'s
/// capability traits).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Capability {
    /// `Model`: every model.
    Model,
    /// `Walls`: every model.
    Walls,
    /// `Dynamics`: models with coordinates.
    Dynamics,
    /// `Surfaces`: models with coordinates.
    Surfaces,
}

impl Capability {
    /// The trait's name in `dalembert_runtime`.
    pub fn trait_name(self) -> &'static str {
        match self {
            Self::Model => "Model",
            Self::Walls => "Walls",
            Self::Dynamics => "Dynamics",
            Self::Surfaces => "Surfaces",
        }
    }

    /// Whether its quantities are one per wall (named `{wall}_{name}`)
    /// rather than one for the model.
    pub fn per_wall(self) -> bool {
        matches!(self, Self::Walls | Self::Surfaces)
    }

    /// Whether an instantaneous model (no coordinates) has it.
    pub fn instantaneous(self) -> bool {
        matches!(self, Self::Model | Self::Walls)
    }
}

/// One row of the table.
#[derive(Clone, Copy, Debug)]
pub struct Spec {
    /// Which quantity.
    pub quantity: Quantity,
    /// The inherent function's name (for a wall, after `{wall}_`).
    pub name: &'static str,
    /// What it takes besides the model's parameters.
    pub inputs: Inputs,
    /// What it returns.
    pub shape: Shape,
    /// Its doc text; `{wall}` stands for the wall's name.
    pub doc: &'static str,
    /// The runtime trait whose method forwards to it; an instantaneous
    /// model has the quantity only if it has the trait.
    pub capability: Capability,
    /// That method's name and how it returns the value, if it has one.
    pub method: Option<(&'static str, Forward)>,
}

/// Every emitted quantity, in the order the generated file lists them.
pub const TABLE: &[Spec] = &[
    Spec {
        quantity: Quantity::MassMatrix,
        name: "mass_matrix",
        inputs: Inputs::Coordinates,
        shape: Shape::Matrix,
        doc: "The mass matrix G(q).",
        capability: Capability::Model,
        method: Some(("mass_matrix", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::KineticEnergy,
        name: "kinetic_energy",
        inputs: Inputs::Phase,
        shape: Shape::Scalar,
        doc: "Kinetic energy T(q, v).",
        capability: Capability::Model,
        method: Some(("kinetic_energy", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::Potential,
        name: "potential",
        inputs: Inputs::Coordinates,
        shape: Shape::Scalar,
        doc: "Potential energy V(q).",
        capability: Capability::Dynamics,
        method: Some(("potential", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::Constraints,
        name: "constraints",
        inputs: Inputs::Coordinates,
        shape: Shape::Rows,
        doc: "Rows of A(q).",
        capability: Capability::Model,
        method: Some(("constraints", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::Holonomic,
        name: "holonomic",
        inputs: Inputs::Coordinates,
        shape: Shape::Values,
        doc: "The holonomic constraints h(q) (zero on the constraint manifold); their differentials are the first rows of A.",
        capability: Capability::Dynamics,
        method: Some(("holonomic", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::Forcing,
        name: "forcing",
        inputs: Inputs::Phase,
        shape: Shape::Vector,
        doc: "h(q, q̇): the equations of motion are G(q) q̈ + h(q, q̇) = A(q)ᵀλ.",
        capability: Capability::Dynamics,
        method: Some(("forcing", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::ConstraintDrift,
        name: "constraint_drift",
        inputs: Inputs::Phase,
        shape: Shape::Vector,
        doc: "Ȧq̇, one entry per row of A (the rest zero): A q̈ + Ȧq̇ = 0 along the motion.",
        capability: Capability::Dynamics,
        method: Some(("constraint_drift", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::Accelerations,
        name: "accelerations",
        inputs: Inputs::Phase,
        shape: Shape::Vector,
        doc: "q̈ of the equations of motion G(q) q̈ + h(q, q̇) = A(q)ᵀλ, A(q) q̈ + Ȧq̇ = 0, written out: in exact closed form where G⁻¹ is exact, else as the solve by elimination (G = LDLᵀ, then the constraints' Schur complement; q̇ should satisfy A(q) q̇ = 0). Non-finite where G is singular.",
        capability: Capability::Dynamics,
        method: Some(("closed_form_accelerations", Forward::Some)),
    },
    Spec {
        quantity: Quantity::AccelerationsTangent,
        name: "accelerations_tangent",
        inputs: Inputs::Tangent,
        shape: Shape::Tangent,
        doc: "q̈ as `accelerations` computes it, and its derivative along (δq, δv): (q̈, ∂q̈/∂q δq + ∂q̈/∂v δv), by forward differentiation of the same program. A column of the Jacobian for a unit direction.",
        capability: Capability::Dynamics,
        method: Some(("accelerations_tangent", Forward::Some)),
    },
    Spec {
        quantity: Quantity::AccelerationsParameterTangent,
        name: "accelerations_parameter_tangent",
        inputs: Inputs::PhaseByParameters,
        shape: Shape::Tangent,
        doc: "q̈ as `accelerations` computes it, and its derivative along a direction δp of the parameters (in `PARAMETERS` order) at fixed (q, v): (q̈, ∂q̈/∂p δp), by forward differentiation of the same program.",
        capability: Capability::Dynamics,
        method: Some(("accelerations_parameter_tangent", Forward::Some)),
    },
    Spec {
        quantity: Quantity::InitialState,
        name: "initial_state",
        inputs: Inputs::Parameters,
        shape: Shape::State,
        doc: "The starting state of the model file's `[initial]` (zero where it is silent), at these parameters: (q, q̇). The velocities it is silent on follow from the constraints (`VELOCITIES_GIVEN`, `dalembert_runtime::simulate::starting_velocity`).",
        capability: Capability::Dynamics,
        method: None,
    },
    Spec {
        quantity: Quantity::StartRows,
        name: "start_rows",
        inputs: Inputs::Coordinates,
        shape: Shape::Rows,
        doc: "The rows L(q) of the rates the model file's `[initial]` gives that are not velocities (`START_RATES`, definitions linear in them): the start's velocity has L(q) q̇ = `start_values()`, and the constraints (`dalembert_runtime::simulate::starting_velocity`).",
        capability: Capability::Dynamics,
        method: Some(("start_rows", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::StartValues,
        name: "start_values",
        inputs: Inputs::Parameters,
        shape: Shape::Values,
        doc: "The values the model file's `[initial]` gives the rates of `start_rows`, at these parameters.",
        capability: Capability::Dynamics,
        method: Some(("start_values", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::Surface,
        name: "surface",
        inputs: Inputs::Coordinates,
        shape: Shape::Scalar,
        doc: "Wall `{wall}`: the surface function f(q).",
        capability: Capability::Surfaces,
        method: Some(("surface", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::Normal,
        name: "normal",
        inputs: Inputs::Coordinates,
        shape: Shape::Vector,
        doc: "Wall `{wall}`: its normal df(q), the first row of B.",
        capability: Capability::Walls,
        method: Some(("normal", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::NormalVelocity,
        name: "normal_velocity",
        inputs: Inputs::Phase,
        shape: Shape::Scalar,
        doc: "Wall `{wall}`: the normal velocity df(q)·v, negative while approaching.",
        capability: Capability::Walls,
        method: Some(("normal_velocity", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::SurfaceHessian,
        name: "surface_hessian",
        inputs: Inputs::Phase,
        shape: Shape::Scalar,
        doc: "Wall `{wall}`: vᵀ∇²f(q)v; along a motion f̈ = df(q)·q̈ + vᵀ∇²f(q)v.",
        capability: Capability::Surfaces,
        method: Some(("surface_hessian", Forward::Some)),
    },
    Spec {
        quantity: Quantity::WallRows,
        name: "b_rows",
        inputs: Inputs::Coordinates,
        shape: Shape::Rows,
        doc: "Wall `{wall}`: the independent rows of B(q), the normal velocity first.",
        capability: Capability::Walls,
        method: Some(("wall_rows", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::Projector,
        name: "projector",
        inputs: Inputs::Coordinates,
        shape: Shape::Matrix,
        doc: "Wall `{wall}`: the projector P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B.",
        capability: Capability::Walls,
        method: Some(("projector", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::Collide,
        name: "collide",
        inputs: Inputs::Phase,
        shape: Shape::Vector,
        doc: "Wall `{wall}`: the collision map v⁺ = (I − 2P)v⁻ for admissible v⁻ (A v⁻ = 0; elsewhere it may differ from (I − 2P)v⁻, see the header's solves).",
        capability: Capability::Walls,
        method: Some(("collide", Forward::Plain)),
    },
    Spec {
        quantity: Quantity::CollideTangent,
        name: "collide_tangent",
        inputs: Inputs::Tangent,
        shape: Shape::Tangent,
        doc: "Wall `{wall}`: v⁺ as `collide` computes it, and its derivative along (δq, δv⁻): (v⁺, ∂v⁺/∂q δq + ∂v⁺/∂v⁻ δv⁻), by forward differentiation of the same program.",
        capability: Capability::Walls,
        method: Some(("collide_tangent", Forward::Some)),
    },
    Spec {
        quantity: Quantity::CollideParameterTangent,
        name: "collide_parameter_tangent",
        inputs: Inputs::PhaseByParameters,
        shape: Shape::Tangent,
        doc: "Wall `{wall}`: v⁺ as `collide` computes it, and its derivative along a direction δp of the parameters (in `PARAMETERS` order) at fixed (q, v⁻): (v⁺, ∂v⁺/∂p δp), by forward differentiation of the same program.",
        capability: Capability::Walls,
        method: Some(("collide_parameter_tangent", Forward::Some)),
    },
    Spec {
        quantity: Quantity::SurfaceParameterTangent,
        name: "surface_parameter_tangent",
        inputs: Inputs::CoordinatesByParameters,
        shape: Shape::ScalarTangent,
        doc: "Wall `{wall}`: f(q) as `surface` computes it, and its derivative along a direction δp of the parameters (in `PARAMETERS` order) at fixed q: (f, ∂f/∂p δp).",
        capability: Capability::Surfaces,
        method: Some(("surface_parameter_tangent", Forward::Some)),
    },
];

impl Quantity {
    /// Its row of [`TABLE`].
    pub fn spec(self) -> &'static Spec {
        TABLE
            .iter()
            .find(|s| s.quantity == self)
            .expect("every quantity has a row in TABLE")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every quantity has exactly one row, and names are unique among the
    /// model's and among each wall's functions.
    #[test]
    fn one_row_per_quantity() {
        for (i, a) in TABLE.iter().enumerate() {
            for b in &TABLE[i + 1..] {
                assert_ne!(a.quantity, b.quantity);
                let same_scope = a.capability.per_wall() == b.capability.per_wall();
                assert!(!same_scope || a.name != b.name, "{}", a.name);
            }
            assert_eq!(a.quantity.spec().name, a.name);
        }
    }
}
