//! Periodic orbits through collisions and their Floquet multipliers, for
//! any model of `dalembert-runtime` (dense linear algebra from nalgebra, on
//! the heap; the runtime's return map, `simulate::return_map`, needs
//! neither).
//!
//! An orbit is sought as a fixed point of a wall's return map Π
//! ([`return_map`]): a state x₀ just after a collision with the wall from
//! which the motion comes back to x₀ at its `returns`-th collision with it.
//! Coordinates declared angles ([`Search::angles`]) return modulo 2π: there
//! Π(x₀) − x₀ is taken to the nearest whole turn, so an orbit along which
//! an angle makes full turns is periodic ([`Orbit::turns`] counts them).
//! Newton's method solves Π(x₀) = x₀ over the states x₀ + Zξ, Z an
//! orthonormal basis of the perturbations along the section that the
//! constraints allow (tangent to h(q) = 0, A(q)q̇ = 0 and f(q) = 0): each
//! step is the least-squares solution of (DΠ − I)Zξ = x₀ − Π(x₀) of
//! smallest norm, singular values below a fraction [`Search::cutoff`] of the
//! largest taken as zero. Orbits of conservative systems come in families
//! (other energies, translations along a floor, the attitude of a ball), so
//! DΠ − I is singular on the orbit: the smallest-norm step moves to the
//! nearest member of the family instead of failing. A step that does not
//! lower the residual is halved, up to [`Search::halvings`] times. After
//! each step the state is put back on the section and the constraints:
//! q onto h(q) = 0 and f(q) = 0 (Gauss–Newton, smallest change in the
//! metric of G), q̇ onto ker A(q).
//!
//! The Floquet multipliers are the eigenvalues of Zᵀ DΠ Z at the orbit:
//! the monodromy restricted to the section and the constraint manifold
//! (the flow's own direction, whose multiplier is always 1, is not in
//! it). Every family and symmetry adds multipliers equal to 1.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod svd;

use nalgebra::{DMatrix, DVector};
use svd::Svd;

use dalembert_runtime::linalg::{self, ProjectorError};
use dalembert_runtime::saltation::StateMatrix;
use dalembert_runtime::simulate::{
    Return, ReturnError, Section, SeriesRoom, Settings, Simulator, State, admissible, return_map,
    tangent_direction,
};
use dalembert_runtime::{Surfaces, TaylorSeries};

/// How an orbit is searched for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Search {
    /// The simulator's settings for every evaluation of Π.
    pub settings: Settings,
    /// Relative tolerance of Φ (DΠ): of its own error estimate on
    /// Dormand–Prince steps, of its integration along steps of Taylor's
    /// method ([`Variational`](dalembert_runtime::simulate::Variational)).
    pub rtol: f64,
    /// Newton's method stops when |Π(x₀) − x₀|∞ ≤ `tolerance` · max(1, |x₀|∞).
    pub tolerance: f64,
    /// Most Newton steps.
    pub max_iterations: usize,
    /// Most halvings of a step that does not lower the residual.
    pub halvings: usize,
    /// Singular values of (DΠ − I)Z below `cutoff` times the largest are
    /// taken as zero.
    pub cutoff: f64,
    /// A multiplier within this distance of the unit circle counts as on
    /// it (and within it of 1, as 1). Multipliers of a Jordan block are
    /// only as accurate as the square root of DΠ's error.
    pub unit: f64,
    /// The coordinates that are angles, which return modulo 2π (none by
    /// default: every coordinate must come back to its own value).
    pub angles: Angles,
}

/// A set of coordinates (by index, each below 64) that are angles: a
/// return that differs from the start by whole turns, 2πk, in them is a
/// return.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Angles(u64);

impl Angles {
    /// No angles.
    pub const NONE: Self = Self(0);

    /// The coordinates `indices`; `None` if one is 64 or more.
    pub fn of(indices: &[usize]) -> Option<Self> {
        indices
            .iter()
            .try_fold(0_u64, |set, &k| {
                Some(set | 1_u64.checked_shl(u32::try_from(k).ok()?)?)
            })
            .map(Self)
    }

    /// Whether coordinate `k` is an angle.
    pub fn contains(self, k: usize) -> bool {
        u32::try_from(k)
            .ok()
            .and_then(|k| self.0.checked_shr(k))
            .is_some_and(|bits| bits & 1 == 1)
    }

    /// The whole turns in a change `d` of coordinate `k`: the nearest
    /// integer to d/2π for an angle, 0 otherwise.
    fn turns(self, k: usize, d: f64) -> f64 {
        if self.contains(k) {
            (d / core::f64::consts::TAU).round()
        } else {
            0.0
        }
    }
}

impl Default for Search {
    fn default() -> Self {
        Self {
            settings: Settings::default(),
            rtol: 1e-12,
            tolerance: 1e-10,
            max_iterations: 20,
            halvings: 12,
            cutoff: 1e-6,
            unit: 1e-5,
            angles: Angles::NONE,
        }
    }
}

/// A periodic orbit.
#[derive(Clone, Debug, PartialEq)]
pub struct Orbit<const N: usize> {
    /// The state on the section (just after the collision), at t = 0.
    pub state: State<N>,
    /// The period: the time of `returns` returns.
    pub period: f64,
    /// The Floquet multipliers (re, im), largest modulus first.
    pub multipliers: Vec<[f64; 2]>,
    /// DΠ at the orbit over (q, q̇) (2N × 2N, off the section included).
    pub monodromy: StateMatrix<N>,
    /// |Π(x₀) − x₀|∞ / max(1, |x₀|∞) at the orbit.
    pub residual: f64,
    /// Newton steps taken.
    pub iterations: usize,
    /// Collisions in one period, with every wall.
    pub collisions: u64,
    /// The whole turns each coordinate makes in one period: Π(x₀) = x₀ +
    /// 2π·turns in q (zero but for [`Search::angles`]).
    pub turns: [i64; N],
}

/// What the multipliers say about an orbit's linear stability.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stability {
    /// A multiplier outside the unit circle: perturbations grow like
    /// `largest` per period.
    Unstable {
        /// The largest modulus.
        largest: f64,
    },
    /// Every multiplier on the unit circle (within [`Search::unit`]): no
    /// perturbation grows or decays at the linear order, which alone
    /// cannot decide stability.
    Neutral,
    /// Every multiplier inside or on the unit circle, some inside.
    Stable {
        /// The largest modulus of those inside.
        largest_inside: f64,
    },
}

/// Why no orbit was found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PeriodicError<W> {
    /// The start could not be brought onto the section, or a return map
    /// could not be evaluated.
    Return(ReturnError<W>),
    /// Newton's method ran `iterations` steps without reaching the
    /// tolerance; the residual it reached.
    NoConvergence {
        /// Steps taken.
        iterations: usize,
        /// The smallest residual reached.
        residual: f64,
    },
    /// No step of Newton's direction, however short, lowered the residual.
    Stalled {
        /// Steps taken.
        iterations: usize,
        /// The residual it stalled at.
        residual: f64,
    },
    /// Newton's method stopped (as [`PeriodicError::NoConvergence`] or
    /// [`PeriodicError::Stalled`] would say), or met its tolerance, at a
    /// state that barely leaves the wall: its normal velocity is below
    /// [`GRAZING`] of the velocity's size (often its full steps land where
    /// the normal velocity is not positive, so they are taken in part; or
    /// the return map loses its accuracy as the impacts fade; or the
    /// flight between collisions is so short that the state changes less
    /// than the tolerance over it). The states it approaches move along
    /// the wall, or rest against it, not through collisions with it; more
    /// steps do not help.
    TowardsGrazing {
        /// Steps taken.
        iterations: usize,
        /// The residual reached.
        residual: f64,
        /// The normal velocity df·q̇ at the last state.
        normal_velocity: f64,
    },
    /// (DΠ − I)Z is zero or not finite: Newton's method has no direction.
    SingularJacobian {
        /// Steps taken.
        iterations: usize,
    },
    /// The state could not be put back on the constraints and the section.
    Projection(ProjectorError),
    /// The section has no perturbations the constraints allow (the wall
    /// is tangent to the constraint manifold there).
    NoSection,
    /// An eigenvalue or singular value decomposition did not converge.
    Decomposition,
}

impl<W> From<ReturnError<W>> for PeriodicError<W> {
    fn from(e: ReturnError<W>) -> Self {
        Self::Return(e)
    }
}

/// The first state of the section on the motion from `start`: `start`
/// itself if it is on the wall and moving away, else the state just after
/// the first collision with the wall.
pub fn onto_section<M: TaylorSeries<N>, const N: usize>(
    model: &M,
    start: State<N>,
    section: &Section<M::Wall>,
    settings: Settings,
) -> Result<State<N>, ReturnError<M::Wall>> {
    let (f, sigma) = (
        model.surface(section.wall, &start.q),
        model.normal_velocity(section.wall, &start.q, &start.v),
    );
    let scale = 1.0 + norm(&start.q);
    if f.abs() <= 1e-12 * scale && sigma > 0.0 {
        return Ok(start);
    }
    let mut room = SeriesRoom::new(model);
    let mut sim =
        Simulator::with_series(&mut room, start, settings).map_err(ReturnError::Simulation)?;
    let t_end = start.t + section.t_max;
    while sim.state().t < t_end {
        let step = sim.step(t_end).map_err(ReturnError::Simulation)?;
        if step.collision.is_some_and(|c| c.wall == section.wall) {
            return Ok(State {
                t: 0.0,
                ..step.state
            });
        }
    }
    Err(ReturnError::NoReturn {
        met: 0,
        t_max: section.t_max,
    })
}

/// Searches a periodic orbit of `section` from `start` (brought onto the
/// section first, [`onto_section`]); see the module doc.
pub fn find<M: TaylorSeries<N>, const N: usize>(
    model: &M,
    start: State<N>,
    section: &Section<M::Wall>,
    search: &Search,
) -> Result<Orbit<N>, PeriodicError<M::Wall>> {
    let mut x = onto_section(model, start, section, search.settings)?;
    x.t = 0.0;
    let angles = search.angles;
    let scale = |x: &State<N>| norm_inf(&x.q).max(norm_inf(&x.v)).max(1.0);
    let residual_of = |x: &State<N>, r: &Return<N>| {
        let d = difference(&r.state, x, angles);
        d.iter().fold(0.0_f64, |m, e| m.max(e.abs())) / scale(x)
    };
    // What a step must lower: |Π(x) − x|₂, for which the least-squares
    // step below is a descent direction. (Its ∞-norm need not fall: the
    // step moves x in the section only, and where (DΠ − I)Z has no full
    // rank, or more rows than columns, the part of the residual outside
    // its range stays, and may be the largest component. Judged by the
    // ∞-norm, §3.1's ball in Euler angles stalled at 1.15 after 2 steps.)
    let merit_of = |x: &State<N>, r: &Return<N>| {
        let d = difference(&r.state, x, angles);
        d.iter().map(|e| e * e).sum::<f64>().sqrt()
    };
    let mut iterations = 0;
    let stopped = |x: &State<N>, iterations, residual, stalled: bool| {
        if nearly_grazes(model, x, section.wall) {
            PeriodicError::TowardsGrazing {
                iterations,
                residual,
                normal_velocity: model.normal_velocity(section.wall, &x.q, &x.v),
            }
        } else if stalled {
            PeriodicError::Stalled {
                iterations,
                residual,
            }
        } else {
            PeriodicError::NoConvergence {
                iterations,
                residual,
            }
        }
    };
    loop {
        let map = return_map(model, x, section, search.settings, Some(search.rtol))?;
        let residual = residual_of(&x, &map);
        let merit = merit_of(&x, &map);
        let jacobian = map.jacobian.expect("asked for");
        if residual <= search.tolerance {
            if nearly_grazes(model, &x, section.wall) {
                // Converged to a state that barely leaves the wall: its
                // flight to the next collision, and with it every change
                // over a return, shrinks with its normal velocity, so any
                // such state meets the tolerance. It slides along the
                // wall; no orbit.
                return Err(stopped(&x, iterations, residual, false));
            }
            let z = section_basis(model, &x, section.wall)?;
            let multipliers = multipliers(&z, &jacobian)?;
            return Ok(Orbit {
                state: x,
                period: map.state.t - x.t,
                multipliers,
                monodromy: jacobian,
                residual,
                iterations,
                collisions: map.collisions,
                // (Whole numbers, far below 2⁶³.)
                #[allow(clippy::cast_possible_truncation)]
                turns: core::array::from_fn(|k| angles.turns(k, map.state.q[k] - x.q[k]) as i64),
            });
        }
        if iterations == search.max_iterations {
            return Err(stopped(&x, iterations, residual, false));
        }
        iterations += 1;
        let z = section_basis(model, &x, section.wall)?;
        let dpi = dense(&jacobian);
        let a = (&dpi - DMatrix::identity(2 * N, 2 * N)) * &z;
        let r = DVector::from_vec(difference(&map.state, &x, angles));
        let svd = Svd::new(&a).ok_or(PeriodicError::Decomposition)?;
        let largest = svd.singular_values.max();
        if !(largest > 0.0 && largest.is_finite()) {
            return Err(PeriodicError::SingularJacobian { iterations });
        }
        let xi = svd.solve(&(-r), search.cutoff * largest);
        let dx = &z * xi;
        // Damping: the first of the step, its half, ... that lowers the
        // residual.
        let mut lambda = 1.0;
        let mut accepted = None;
        // A trial that cannot be put back on the constraints, or whose
        // return map fails, is rejected like one that does not lower the
        // residual.
        for _ in 0..=search.halvings {
            let trial = restore(model, &x, &dx, lambda, section.wall);
            if let Ok(trial) = trial
                && let Ok(map) = return_map(model, trial, section, search.settings, None)
                && merit_of(&trial, &map) < merit
            {
                accepted = Some(trial);
                break;
            }
            lambda *= 0.5;
        }
        x = accepted.ok_or_else(|| stopped(&x, iterations, residual, true))?;
    }
}

/// Below this fraction of |df|·max(1, |q̇|∞), a normal velocity counts as
/// a motion that nearly slides along the wall
/// ([`PeriodicError::TowardsGrazing`]).
pub const GRAZING: f64 = 1e-3;

/// |df|·max(1, |q̇|∞) at `x`: the scale of its normal velocity.
fn normal_scale<M: Surfaces<N>, const N: usize>(model: &M, x: &State<N>, wall: M::Wall) -> f64 {
    norm(&model.normal(wall, &x.q)) * norm_inf(&x.v).max(1.0)
}

/// Whether `x`'s normal velocity is below [`GRAZING`] of its scale.
fn nearly_grazes<M: Surfaces<N>, const N: usize>(model: &M, x: &State<N>, wall: M::Wall) -> bool {
    model.normal_velocity(wall, &x.q, &x.v).abs() <= GRAZING * normal_scale(model, x, wall)
}

/// The linear stability the multipliers give, with `unit` the distance
/// from the unit circle that counts as on it.
pub fn stability(multipliers: &[[f64; 2]], unit: f64) -> Stability {
    let modulus = |m: &[f64; 2]| m[0].hypot(m[1]);
    let largest = multipliers.iter().map(modulus).fold(0.0, f64::max);
    if largest > 1.0 + unit {
        return Stability::Unstable { largest };
    }
    let inside = multipliers
        .iter()
        .map(modulus)
        .filter(|&m| m < 1.0 - unit)
        .fold(None, |a: Option<f64>, m| Some(a.map_or(m, |a| a.max(m))));
    match inside {
        None => Stability::Neutral,
        Some(largest_inside) => Stability::Stable { largest_inside },
    }
}

/// Π(x) − x over (q, q̇), less the whole turns of the angles.
fn difference<const N: usize>(y: &State<N>, x: &State<N>, angles: Angles) -> Vec<f64> {
    let dq = (y.q.iter().zip(&x.q).enumerate()).map(|(k, (a, b))| {
        let d = a - b;
        d - core::f64::consts::TAU * angles.turns(k, d)
    });
    let dv = y.v.iter().zip(&x.v).map(|(a, b)| a - b);
    dq.chain(dv).collect()
}

fn dense<const N: usize>(m: &StateMatrix<N>) -> DMatrix<f64> {
    DMatrix::from_fn(2 * N, 2 * N, |i, j| {
        let block = match (i < N, j < N) {
            (true, true) => &m.qq,
            (true, false) => &m.qv,
            (false, true) => &m.vq,
            (false, false) => &m.vv,
        };
        block[i % N][j % N]
    })
}

/// An orthonormal basis (columns, Euclidean in (q, q̇)) of the
/// perturbations at x tangent to the constraint manifold and to the
/// wall's section: the range of the admissible-direction projection
/// ([`tangent_direction`]) with df·δq = 0.
fn section_basis<M: Surfaces<N>, const N: usize>(
    model: &M,
    x: &State<N>,
    wall: M::Wall,
) -> Result<DMatrix<f64>, PeriodicError<M::Wall>> {
    let mut columns = DMatrix::zeros(2 * N, 2 * N);
    for j in 0..2 * N {
        let unit = |k: usize| core::array::from_fn(|i| f64::from(u8::from(i + k == j)));
        let (dq, dv) = tangent_direction(model, &x.q, &x.v, &unit(0), &unit(N))
            .map_err(PeriodicError::Projection)?;
        for i in 0..N {
            columns[(i, j)] = dq[i];
            columns[(N + i, j)] = dv[i];
        }
    }
    let svd = Svd::new(&columns).ok_or(PeriodicError::Decomposition)?;
    let u = &svd.u;
    let largest = svd.singular_values.max();
    let kept: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&k| svd.singular_values[k] > 1e-8 * largest)
        .collect();
    let range = DMatrix::from_fn(2 * N, kept.len(), |i, k| u[(i, kept[k])]);
    // Within the range, the complement of w = rangeᵀ(df, 0), by a
    // Householder reflection that takes w to |w| e₁.
    let df = model.normal(wall, &x.q);
    let mut g = DVector::zeros(2 * N);
    for i in 0..N {
        g[i] = df[i];
    }
    let w = range.transpose() * g;
    let size = w.norm();
    // NaN fails the comparison too.
    if size.partial_cmp(&(1e-12 * norm(&df))) != Some(core::cmp::Ordering::Greater)
        || kept.len() < 2
    {
        return Err(PeriodicError::NoSection);
    }
    let mut h = w.clone();
    h[0] -= if w[0] >= 0.0 { -size } else { size };
    let h = h.normalize();
    let reflection = DMatrix::identity(kept.len(), kept.len()) - 2.0 * &h * h.transpose();
    let complement = reflection.columns(1, kept.len() - 1).into_owned();
    Ok(range * complement)
}

/// x + λ Z ξ put back on the constraints and the wall's section.
fn restore<M: Surfaces<N>, const N: usize>(
    model: &M,
    x: &State<N>,
    dx: &DVector<f64>,
    lambda: f64,
    wall: M::Wall,
) -> Result<State<N>, PeriodicError<M::Wall>> {
    let moved = State {
        t: 0.0,
        q: core::array::from_fn(|i| x.q[i] + lambda * dx[i]),
        v: core::array::from_fn(|i| x.v[i] + lambda * dx[N + i]),
    };
    project(model, &moved, wall).map_err(PeriodicError::Projection)
}

/// `x` put on the constraints and on `wall`'s section: q onto h(q) = 0
/// and f(q) = 0 together (Gauss–Newton, the smallest change in the metric
/// of G), then q̇ onto ker A(q). Along a perturbation tangent to both it
/// changes the state at the second order only.
pub fn project<M: Surfaces<N>, const N: usize>(
    model: &M,
    x: &State<N>,
    wall: M::Wall,
) -> Result<State<N>, ProjectorError> {
    let mut q = x.q;
    for _ in 0..20 {
        let holonomic = model.holonomic(&q);
        let mut r: Vec<f64> = holonomic.as_slice().to_vec();
        r.push(model.surface(wall, &q));
        if r.iter()
            .all(|e| e.abs() <= 4.0 * f64::EPSILON * (1.0 + norm(&q)))
        {
            break;
        }
        let a = model.constraints(&q);
        let mut rows: Vec<[f64; N]> = a.as_slice()[..holonomic.as_slice().len()].to_vec();
        rows.push(model.normal(wall, &q));
        let d = linalg::correction(&model.mass_matrix(&q), &rows, &r)?;
        q = core::array::from_fn(|i| q[i] - d[i]);
    }
    let v = admissible(model, &q, &x.v)?;
    Ok(State { t: x.t, q, v })
}

/// Eigenvalues of Zᵀ DΠ Z, largest modulus first (then by argument).
fn multipliers<W, const N: usize>(
    z: &DMatrix<f64>,
    jacobian: &StateMatrix<N>,
) -> Result<Vec<[f64; 2]>, PeriodicError<W>> {
    let m = z.transpose() * dense(jacobian) * z;
    // Near-defective matrices (the Jordan blocks of families) can keep
    // the QR iteration from deflating at the tightest tolerance; the
    // eigenvalues are no more accurate than the square root of DΠ's error
    // there anyway.
    let schur = [1e-14, 1e-12, 1e-10]
        .into_iter()
        .find_map(|eps| m.clone().try_schur(eps, 100_000))
        .ok_or(PeriodicError::Decomposition)?;
    let mut out: Vec<[f64; 2]> = schur
        .complex_eigenvalues()
        .iter()
        .map(|c| [c.re, c.im])
        .collect();
    // Moduli equal to 1e-9 (rounding apart) sort by argument.
    out.sort_by(|a, b| {
        let key = |m: &[f64; 2]| ((1e9 * m[0].hypot(m[1])).round(), m[1].atan2(m[0]));
        let (ka, kb) = (key(a), key(b));
        kb.0.total_cmp(&ka.0).then(ka.1.total_cmp(&kb.1))
    });
    Ok(out)
}

fn norm<const N: usize>(x: &[f64; N]) -> f64 {
    linalg::dot(x, x).sqrt()
}

fn norm_inf<const N: usize>(x: &[f64; N]) -> f64 {
    x.iter().fold(0.0, |m, e| m.max(e.abs()))
}

#[cfg(test)]
mod tests {
    use super::{Angles, Stability, stability};

    #[test]
    fn angles_count_whole_turns() {
        let a = Angles::of(&[0, 2, 63]).unwrap();
        assert!(a.contains(0) && a.contains(2) && a.contains(63));
        assert!(!a.contains(1) && !a.contains(64) && !a.contains(usize::MAX));
        assert_eq!(Angles::of(&[64]), None);
        assert_eq!(Angles::of(&[]), Some(Angles::NONE));
        let tau = core::f64::consts::TAU;
        assert_eq!(a.turns(0, 3.0 * tau - 0.1), 3.0);
        assert_eq!(a.turns(2, -tau + 3.0), -1.0);
        assert_eq!(a.turns(2, 3.0), 0.0);
        assert_eq!(a.turns(1, 3.0 * tau), 0.0, "not an angle");
    }

    #[test]
    fn the_verdict_reads_the_moduli() {
        let circle = [[0.6, 0.8], [0.6, -0.8], [1.0, 0.0]];
        assert_eq!(stability(&circle, 1e-5), Stability::Neutral);
        let outside = [[1.0, 0.0], [1.5, 0.0], [1.0 / 1.5, 0.0]];
        assert_eq!(
            stability(&outside, 1e-5),
            Stability::Unstable { largest: 1.5 }
        );
        let inside = [[1.0, 0.0], [0.0, 0.5]];
        assert_eq!(
            stability(&inside, 1e-5),
            Stability::Stable {
                largest_inside: 0.5
            }
        );
        // Within the tolerance of the circle counts as on it.
        assert_eq!(stability(&[[1.0 + 1e-7, 0.0]], 1e-5), Stability::Neutral);
    }
}
