//! A collision located on a step: polished to rounding level by Newton's
//! method on f, checked (grazing, a singular wall, another wall at once),
//! and resolved by the collision map v⁺ = (I − 2P)v⁻.

use super::integrator::RungeKutta;
use super::phase::{Phase, norm};
use super::thresholds::{POLISH_STEPS, REVERSAL, TAYLOR_REACH};
use super::{Collision, Located, SimError, Simulator, State};
use crate::Surfaces;

impl<M: Surfaces<N>, const N: usize> Simulator<'_, M, N> {
    /// Resolves the collision located on the step from (t0, y0): polished
    /// to the wall, checked, mapped by v⁺ = (I − 2P)v⁻; the simulator goes
    /// on from there.
    pub(super) fn collide(
        &mut self,
        method: &RungeKutta,
        y0: &Phase<N>,
        t0: f64,
        located: Located<N>,
    ) -> Result<Collision<M::Wall, N>, SimError<M::Wall>> {
        let k = located.wall;
        let step = located.t_hi - t0;
        let (tc, y) = self.polish(method, y0, t0, located)?;
        let settings = self.settings;
        let window = || settings.simultaneity_window(tc, step);
        let collision = self.land(k, (tc, 0.0), &y, t0, window)?;
        self.f0 = self.rhs(tc, &self.phase())?;
        Ok(collision)
    }

    /// The collision with wall `k` at (tc, y), found on a step from t0:
    /// checked, mapped, and the simulator's state set to just after it
    /// (projected onto the constraints). `tc` comes with its rounding term
    /// (the compensated clock of Taylor's method, zero otherwise), which
    /// becomes the clock's with the state. `window` gives the
    /// simultaneity window of the step (see [`Simulator::resolve`]).
    pub(super) fn land(
        &mut self,
        k: usize,
        (tc, t_low): (f64, f64),
        y: &Phase<N>,
        t0: f64,
        window: impl FnMut() -> f64,
    ) -> Result<Collision<M::Wall, N>, SimError<M::Wall>> {
        let collision = self.resolve(k, tc, y, window)?;
        self.state = State {
            t: tc,
            q: y.q,
            v: collision.v_plus,
        };
        self.t_low = t_low;
        self.departing |= 1 << k;
        // Go on with steps of at most twice the time since the previous
        // collision: an error-free stretch (a parabola) would otherwise let
        // the proposal grow without bound, and a step far longer than the
        // motion between collisions locates the next crossing less well;
        // twice that time usually reaches the next collision in one step.
        let since = tc - self.last_collision.unwrap_or(t0);
        if since > 0.0 {
            self.proposal = self.proposal.min(2.0 * since);
        }
        self.last_collision = Some(tc);
        self.project()?;
        Ok(collision)
    }

    /// Newton's method on f from where the collision was located, along
    /// real steps from (t0, y0) or, for tiny corrections, Taylor steps,
    /// staying in [t0, t_hi]: the instant and the state at the wall.
    fn polish(
        &mut self,
        method: &RungeKutta,
        y0: &Phase<N>,
        t0: f64,
        located: Located<N>,
    ) -> Result<(f64, Phase<N>), SimError<M::Wall>> {
        let m = self.model;
        let Located {
            wall: k,
            t: mut tc,
            mut y,
            f: mut fy,
            t_hi,
        } = located;
        let wall = m.walls()[k];
        let reach = TAYLOR_REACH * (t_hi - t0);
        for _ in 0..POLISH_STEPS {
            let f = m.surface(wall, &y.q);
            let nv = m.normal_velocity(wall, &y.q, &y.v);
            if f == 0.0 || nv >= 0.0 {
                break;
            }
            let next = (tc - f / nv).clamp(t0, t_hi);
            if (next - tc).abs() <= 2.0 * f64::EPSILON * tc.abs().max(1.0) || next <= t0 {
                break;
            }
            let delta = next - tc;
            let (candidate, f_candidate) = if delta.abs() <= reach {
                // A tiny correction: second-order Taylor from y (at most one
                // evaluation instead of a step; the error is O(δ³)).
                let d = match fy {
                    Some(d) => d,
                    None => self.rhs(tc, &y)?,
                };
                let taylor = Phase {
                    q: core::array::from_fn(|i| y.q[i] + delta * (y.v[i] + 0.5 * delta * d.v[i])),
                    v: core::array::from_fn(|i| y.v[i] + delta * d.v[i]),
                };
                (taylor, None)
            } else {
                self.advance(method, y0, t0, next - t0)?
            };
            if m.surface(wall, &candidate.q).abs() >= f.abs() {
                break;
            }
            tc = next;
            y = candidate;
            fy = f_candidate;
        }
        Ok((tc, y))
    }

    /// The collision with wall `k` at (tc, y): refused when grazing, when
    /// the map does not reverse the normal velocity (B loses rank there) or
    /// when another wall is met within the simultaneity window of tc (which
    /// `window` gives, called only where there is another wall: for
    /// Taylor's method it may take the step's length, not otherwise
    /// needed).
    fn resolve(
        &self,
        k: usize,
        tc: f64,
        y: &Phase<N>,
        mut window: impl FnMut() -> f64,
    ) -> Result<Collision<M::Wall, N>, SimError<M::Wall>> {
        let m = self.model;
        let wall = m.walls()[k];
        let normal = norm(&m.normal(wall, &y.q));
        let nv = m.normal_velocity(wall, &y.q, &y.v);
        if -nv <= self.settings.grazing * normal * norm(&y.v) {
            return Err(SimError::Grazing {
                wall,
                t: tc,
                normal_velocity: nv,
            });
        }
        let v_plus = m.collide(wall, &y.q, &y.v);
        let nv_plus = m.normal_velocity(wall, &y.q, &v_plus);
        if !v_plus.iter().all(|x| x.is_finite()) || (nv_plus + nv).abs() > REVERSAL * nv.abs() {
            return Err(SimError::SingularWall { wall, t: tc });
        }
        // Another wall at or beyond reach within the window, moving as after
        // this collision?
        let mut within = None;
        for (j, &other) in m.walls().iter().enumerate() {
            if j == k {
                continue;
            }
            let window = *within.get_or_insert_with(&mut window);
            let rate = m.normal_velocity(other, &y.q, &v_plus).min(0.0);
            if m.surface(other, &y.q) + window * rate <= 0.0 {
                return Err(SimError::Simultaneous {
                    first: wall,
                    second: other,
                    t: tc,
                });
            }
        }
        Ok(Collision {
            wall,
            t: tc,
            q: y.q,
            v_minus: y.v,
            v_plus,
            surface: m.surface(wall, &y.q),
        })
    }
}
