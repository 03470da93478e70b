//! What the derivation hands the emitter and front ends: plain data, no
//! symbolic engine types. Display strings (for `derive`, `check` and the
//! paper's comparison) and the straight-line [`Function`]s (for emission)
//! come from the same expressions.

use crate::ir::Model;
use crate::program::{Layout, Program};
use crate::quantity::Quantity;

/// Everything derived for one model.
#[derive(Debug, Clone)]
pub struct Derivation {
    /// The validated model.
    pub model: Model,
    /// G, entry by entry.
    pub mass_matrix: Vec<Vec<String>>,
    /// Rows of A: the differentials of the holonomic constraints first.
    pub constraint_rows: Vec<Vec<String>>,
    /// The holonomic constraints h(q).
    pub holonomic: Vec<String>,
    /// q̈ in closed form, component by component, where G⁻¹ is exact and
    /// the rows of A independent.
    pub accelerations: Option<Vec<String>>,
    /// Per wall.
    pub walls: Vec<WallDerivation>,
    /// The model-wide emitted functions, in [`crate::quantity::TABLE`]
    /// order.
    pub functions: Vec<Function>,
    /// Where the tangent functions were left out (they would have taken
    /// the model's code past [`crate::MAX_GENERATED_INSTRUCTIONS`]): the
    /// instructions they would have added. The tangents along the phase
    /// come first; these count all of them.
    pub tangents_left_out: Option<usize>,
    /// Where only the tangents by the parameters were left out (the model
    /// has those along the phase): the instructions they would have added.
    pub parameter_tangents_left_out: Option<usize>,
    /// Where q̈ is written out by elimination: the system it solves; and
    /// without constraints, closed form or not, G q̈ = −h and the same
    /// motion as the momentum's, for Taylor's method to solve per order.
    pub motion_systems: Vec<MotionSystem>,
}

/// The motion as a linear system, a program and where its outputs are:
/// G q̈ + h = Aᵀλ, A q̈ + Ȧq̇ = 0, or without constraints G q̇ = p with
/// ṗ = ∂L/∂q (L = T − V).
#[derive(Debug, Clone, PartialEq)]
pub struct MotionSystem {
    /// G's lower triangle, A's rows and the right-hand sides (h and Ȧq̇,
    /// or ∂L/∂q) over (parameters, coordinates, velocities).
    pub program: Program,
    /// Where G's entries and A's rows are among its outputs.
    pub layout: Layout,
    /// Where h's entries are, or ∂L/∂q's.
    pub rhs: Vec<Option<usize>>,
    /// Whether `rhs` is ∂L/∂q.
    pub momentum: bool,
}

/// One emitted function: which quantity, and its program.
#[derive(Debug, Clone, PartialEq)]
pub struct Function {
    /// Which row of [`crate::quantity::TABLE`].
    pub quantity: Quantity,
    /// Its straight-line program over (parameters, coordinates, velocities).
    pub program: Program,
    /// For rows and values: how many are in use (0 otherwise).
    pub rows: usize,
}

/// A wall's geometry.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    /// A model with coordinates: the surface f(q), motion in f ≥ 0.
    Surface(String),
    /// An instantaneous model: the normal velocity's row.
    NormalVelocity(Vec<String>),
}

/// How a wall's P and collision map are evaluated.
#[derive(Debug, Clone, PartialEq)]
pub enum Projection {
    /// Derived exactly and emitted as straight-line code.
    ClosedForm {
        /// P entry by entry.
        projector: Vec<Vec<String>>,
        /// v⁺ component by component, in terms of v⁻ (named as the
        /// velocities).
        collision: Vec<String>,
    },
    /// G and B are emitted and P v is solved at run time.
    Structured,
}

/// A way to evaluate a wall's collision map v⁺ = (I − 2P)v per call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Form {
    /// M v with M = I − 2P computed once per parameter set (P free of q).
    Linear,
    /// The same on admissible v only (A v = 0): M's columns of k dependent
    /// velocities folded into the others, M̃ = M − M_D A_D⁻¹ A, and
    /// dependent components of v⁺ computed from the others where cheaper.
    Admissible,
    /// The exact closed form of (I − 2P)v.
    ClosedForm,
    /// G = LDLᵀ and the solve with B's rows written out over one program
    /// for G and B ([`crate::program::Program::reflect_by_elimination`]).
    Elimination,
}

impl Form {
    /// A short name.
    pub fn label(self) -> &'static str {
        match self {
            Self::Linear => "linear",
            Self::Admissible => "admissible",
            Self::ClosedForm => "closed form",
            Self::Elimination => "elimination",
        }
    }

    /// A phrase for generated headers and reports.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Linear => "M v, M = I - 2P kept with the parameters",
            Self::Admissible => {
                "M v on admissible v (A v = 0 folds the columns of dependent velocities into the others; A v+ = 0 gives dependent outputs from the others), M kept with the parameters"
            }
            Self::ClosedForm => "the exact closed form",
            Self::Elimination => "elimination (G = LDL^T and the solve written out)",
        }
    }
}

/// How a collision map is evaluated: the cheapest form, and the per-call
/// cost of every form considered ([`crate::program::OpCount::cost`] of
/// the per-call work, parameter-only work being done once).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Choice {
    /// The form emitted.
    pub form: Form,
    /// Each form considered, with its cost.
    pub costs: Vec<(Form, usize)>,
}

/// What was derived for one wall.
#[derive(Debug, Clone)]
pub struct WallDerivation {
    /// Its name.
    pub name: String,
    /// Its doc text.
    pub doc: String,
    /// Its surface (or normal velocity).
    pub geometry: Geometry,
    /// The independent rows of B: the normal velocity, then A's, then the
    /// contact rows, dependent rows removed.
    pub b_rows: Vec<Vec<String>>,
    /// Where each kept row came from.
    pub b_origin: Vec<String>,
    /// The rows that were removed as dependent, with where they came from.
    pub dropped: Vec<String>,
    /// P and the collision map.
    pub projection: Projection,
    /// How the emitted collision map is evaluated, and why; `None` where
    /// the run time solves it from G and B.
    pub collision: Option<Choice>,
    /// The wall's emitted functions, in [`crate::quantity::TABLE`] order
    /// (the projector only in closed form; the collision map wherever
    /// [`WallDerivation::collision`] is set).
    pub functions: Vec<Function>,
}

impl WallDerivation {
    /// Whether P is solved at run time.
    pub fn structured(&self) -> bool {
        self.projection == Projection::Structured
    }

    /// The wall's function for `q`, if it has one.
    pub fn function(&self, q: Quantity) -> Option<&Function> {
        self.functions.iter().find(|f| f.quantity == q)
    }
}

impl Derivation {
    /// The model's function for `q`, if it has one.
    pub fn function(&self, q: Quantity) -> Option<&Function> {
        self.functions.iter().find(|f| f.quantity == q)
    }

    /// Every emitted function with its name in the generated code (a wall's
    /// is `{wall}_{name}`), the model's first, in file order.
    pub fn named_functions(&self) -> Vec<(String, &Function)> {
        let model = self
            .functions
            .iter()
            .map(|f| (f.quantity.spec().name.to_string(), f));
        let walls = self.walls.iter().flat_map(|w| {
            w.functions
                .iter()
                .map(move |f| (format!("{}_{}", w.name, f.quantity.spec().name), f))
        });
        model.chain(walls).collect()
    }
}
