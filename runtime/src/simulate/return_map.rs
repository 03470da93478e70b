//! The return map of a wall's section and its Jacobian: a Poincaré map of
//! the hybrid system, without heap allocation.
//!
//! The section is the set of states just after a collision with one wall
//! (f(q) = 0, moving away). From such a state x₀ the simulator runs until
//! its `returns`-th collision with that wall (collisions with other walls
//! are part of the motion in between); the state just after it is Π(x₀),
//! and the time taken the return time. With the variational flow followed
//! along the run ([`Variational`]), Φ⁺ = ∂x(t)/∂x₀ just after that
//! collision gives the map's derivative, the shift of the return instant
//! included:
//!
//! DΠ = Φ⁺ + F⁺ ∂t*/∂x₀,  ∂t*/∂x₀ = −∇fᵀ Φ⁺ / (∇f · F⁺),
//!
//! with F⁺ = (v⁺, q̈(q, v⁺)) and ∇f = (df(q), 0) at the return. (The
//! saltation matrix reverses ∇fᵀΦ and the normal velocity alike, so the
//! instant's derivative reads the same from either side of the collision.)
//! DΠ maps perturbations along the section to perturbations along it:
//! ∇fᵀ DΠ = 0.

use super::variational::{Variational, VariationalError};
use super::{SeriesRoom, Settings, SimError, Simulator, State};
use crate::dynamics::{DynamicsError, qdd};
use crate::linalg;
use crate::saltation::StateMatrix;
use crate::{Surfaces, TaylorSeries};

/// Where and how long to look for returns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section<W> {
    /// The wall whose collisions make the section.
    pub wall: W,
    /// Which return ends the map: the map runs to the `returns`-th
    /// collision with `wall` (at least 1).
    pub returns: usize,
    /// The longest the map may run, in model time, before it is an error
    /// ([`ReturnError::NoReturn`]).
    pub t_max: f64,
}

/// One application of the return map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Return<const N: usize> {
    /// The state just after the last return; its `t` is the start's plus
    /// the return time.
    pub state: State<N>,
    /// DΠ = ∂Π/∂x₀ over (q, q̇), when asked for.
    pub jacobian: Option<StateMatrix<N>>,
    /// Collisions on the way, with every wall (the returns included).
    pub collisions: u64,
}

/// Why the return map could not be evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ReturnError<W> {
    /// The simulation failed.
    Simulation(SimError<W>),
    /// The variational flow could not follow it.
    Variational(VariationalError<W>),
    /// The wall was met fewer than `returns` times (`met`) before `t_max`.
    NoReturn {
        /// Returns found.
        met: usize,
        /// The time limit.
        t_max: f64,
    },
    /// q̈ just after the return could not be computed.
    Dynamics(DynamicsError),
}

/// Π(`start`) for `section`, run with `settings`; with `jacobian =
/// Some(rtol)` also DΠ, Φ integrated at relative tolerance `rtol`. The
/// start must be a state the simulator accepts (on the section: on the
/// wall, moving away). Any method may step, Taylor's too: the room for its
/// series is on this function's stack.
pub fn return_map<M: TaylorSeries<N>, const N: usize>(
    model: &M,
    start: State<N>,
    section: &Section<M::Wall>,
    settings: Settings,
    jacobian: Option<f64>,
) -> Result<Return<N>, ReturnError<M::Wall>> {
    let mut room = SeriesRoom::new(model);
    let mut sim =
        Simulator::with_series(&mut room, start, settings).map_err(ReturnError::Simulation)?;
    let mut phi = jacobian.map(Variational::<N>::new);
    let t_end = start.t + section.t_max;
    let mut met = 0;
    let mut collisions = 0;
    while met < section.returns.max(1) {
        if sim.state().t >= t_end {
            return Err(ReturnError::NoReturn {
                met,
                t_max: section.t_max,
            });
        }
        let step = sim.step(t_end).map_err(ReturnError::Simulation)?;
        if let Some(phi) = phi.as_mut() {
            phi.follow(&sim, &step).map_err(ReturnError::Variational)?;
        }
        if let Some(c) = &step.collision {
            collisions += 1;
            if c.wall == section.wall {
                met += 1;
            }
        }
    }
    let state = *sim.state();
    let jacobian = match phi {
        None => None,
        Some(phi) => Some(
            section_derivative(model, section.wall, &state, phi.matrix())
                .map_err(ReturnError::Dynamics)?,
        ),
    };
    Ok(Return {
        state,
        jacobian,
        collisions,
    })
}

/// DΠ = Φ⁺ + F⁺ ∂t*/∂x₀ at the state just after a return (module doc).
fn section_derivative<M: Surfaces<N>, const N: usize>(
    model: &M,
    wall: M::Wall,
    x: &State<N>,
    phi: &StateMatrix<N>,
) -> Result<StateMatrix<N>, DynamicsError> {
    let df = model.normal(wall, &x.q);
    let sigma = linalg::dot(&df, &x.v);
    let a = qdd(model, &x.q, &x.v)?;
    // ∂t*/∂x₀ over the columns of the q and v blocks.
    let dt = |block: &[[f64; N]; N]| -> [f64; N] {
        core::array::from_fn(|j| -(0..N).map(|i| df[i] * block[i][j]).sum::<f64>() / sigma)
    };
    let (dt_q, dt_v) = (dt(&phi.qq), dt(&phi.qv));
    // Each block plus the outer product of F⁺'s part with ∂t*/∂x₀'s.
    let plus = |block: &[[f64; N]; N], f: &[f64; N], dt: &[f64; N]| -> [[f64; N]; N] {
        core::array::from_fn(|i| core::array::from_fn(|j| block[i][j] + f[i] * dt[j]))
    };
    Ok(StateMatrix {
        qq: plus(&phi.qq, &x.v, &dt_q),
        qv: plus(&phi.qv, &x.v, &dt_v),
        vq: plus(&phi.vq, &a, &dt_q),
        vv: plus(&phi.vv, &a, &dt_v),
    })
}
