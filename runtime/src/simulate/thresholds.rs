//! Every numerical threshold of the simulator, in one place, with what it
//! is for. Tolerances of the integrators themselves are in
//! [`super::Settings`]; these are the simulator's own judgements.

/// Most walls a model may have: the simulator keeps the walls just left in
/// a 64-bit mask (more are refused with [`super::SimError::TooManyWalls`]).
pub const MAX_WALLS: usize = 64;

/// A starting state is admissible when |A q̇| and |h(q)| are at most this
/// times (1 + |q| + |q̇|).
pub const ADMISSIBLE: f64 = 1e-8;

/// A starting state is on a wall (not beyond it) while f ≥ −this times
/// (1 + |q| + |q̇|).
pub const ON_WALL: f64 = 1e-12;

/// A Newton or Taylor correction from a point on a step of length h is
/// trusted up to this fraction of h (its error is O(δ³) in q, O(δ²) in q̇).
pub const TAYLOR_REACH: f64 = 1e-6;

/// The longest step Taylor's method takes. A series that ends (a flight
/// under uniform gravity, or a free one) bounds no step, since it is exact
/// over any; without this bound, a step towards an infinite `t_end` (to the
/// next collision, whenever it comes) would be evaluated at τ = ∞.
pub const LONGEST_SERIES_STEP: f64 = 1e6;

/// Newton steps on f at most when a collision is polished.
pub const POLISH_STEPS: usize = 6;

/// The collision map must reverse the normal velocity to this relative
/// accuracy, or B has lost rank there ([`super::SimError::SingularWall`]).
pub const REVERSAL: f64 = 1e-6;

/// An aimed step is not shorter than this many ulps of t.
pub const SHORTEST_AIM_ULPS: f64 = 16.0;

/// A step of at most this many ulps of t (not ending the run) is
/// [`super::SimError::StepTooSmall`].
pub const SMALLEST_STEP_ULPS: f64 = 4.0;

/// Whether a step of length h from t is within [`SMALLEST_STEP_ULPS`] ulps
/// of t: one that does not end the run would never end it. Every method's
/// steps are judged by it.
pub(super) fn step_too_small(h: f64, t: f64) -> bool {
    h <= SMALLEST_STEP_ULPS * f64::EPSILON * t.abs().max(1.0)
}

/// An adaptive step whose stages meet a singular or non-finite state is
/// shrunk by [`FAILED_STEP_SHRINK`] at most this many times before the
/// error is reported.
pub const FAILED_STEP_RETRIES: u32 = 8;

/// See [`FAILED_STEP_RETRIES`].
pub const FAILED_STEP_SHRINK: f64 = 0.2;

/// Gauss–Newton steps at most onto h(q) = 0 per projection.
pub const HOLONOMIC_STEPS: usize = 8;

/// h(q) counts as zero below this many ulps of (1 + |q|).
pub const HOLONOMIC_DONE_ULPS: f64 = 4.0;

/// After [`HOLONOMIC_STEPS`], |h(q)| above this times (1 + |q|) is a
/// failed projection.
pub const HOLONOMIC_FAILED: f64 = 1e-10;

/// Halvings at most of an interval between two of a step's samples of a
/// wall's f whose change their rates do not explain (a pole, or an
/// excursion narrower than the samples): past them the step is shortened.
pub const RESOLVE_DEPTH: usize = 12;

/// f's change between two samples is explained by their rates when the
/// trapezoid rule's defect is at most this fraction of the change's size
/// (see `events::explained`).
pub const RESOLVED_DEFECT: f64 = 0.5;

/// ... or within this many ulps of max(1, |f|) at the two samples.
pub const RESOLVED_ROUNDING_ULPS: f64 = 64.0;

/// Iterations at most of the Illinois root finder on the dense output.
pub const ROOT_ITERATIONS: usize = 200;

/// Two crossings at most this many ulps of t apart are simultaneous
/// whatever the step (see [`super::Settings::simultaneous`]): equal instants
/// computed by different roundings differ by about this much.
pub const SIMULTANEOUS_ULPS: f64 = 4.0;

/// Points at which Taylor's method samples each wall's f on the step's
/// polynomial for a sign change (or a turn towards the wall) before the
/// root is found by Newton's method on that polynomial.
pub const SERIES_SAMPLES: usize = 16;

/// A collision found on a wall's series is taken where f, evaluated
/// directly at it, is within this many times Taylor's tolerance (at least
/// the unit roundoff) of max(1, |f₀|); else the step's crossing is searched
/// by f itself along the step.
pub const SERIES_CHECK: f64 = 1e3;

/// A collision found on a wall's series whose f, evaluated directly, is
/// within this many ulps of max(1, |f₀|) is on the wall already (no
/// Newton step on f is tried).
pub const ON_WALL_ULPS: f64 = 4.0;

/// Newton (or bisection) steps at most on the step's polynomial.
pub const SERIES_ROOT_ITERATIONS: usize = 100;

/// How narrow, in halvings of a step, a stretch of it may get that the
/// bounds on a wall's f do not prove clear (`enclosure`): narrower ones
/// are left to the samples.
pub const CLEAR_DEPTH: usize = 16;

/// Boxes at most on which one wall is bounded along one step; past them
/// the rest of the step is left to the samples (it takes a motion that
/// grazes the wall along much of a step to need them).
pub const CLEAR_BOXES: usize = 128;
