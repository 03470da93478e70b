//! Events on a step: where the motion is predicted to meet a wall (so that
//! adaptive steps end there), and where a step actually crosses one,
//! located by evaluating each wall's f itself along the step's motion (a
//! Runge–Kutta step's dense output, or the polynomial of a step of
//! Taylor's method whose walls' series disagree with f at its end).

use super::integrator::{Method, RungeKutta, Trial};
use super::phase::Phase;
use super::thresholds::{ROOT_ITERATIONS, SHORTEST_AIM_ULPS};
use super::{SimError, Simulator};
use crate::taylor::Series;
use crate::{Surfaces, libm, linalg};

/// The motion over one step, at θ ∈ [0, 1] of it.
pub(super) trait Path<const N: usize> {
    /// (q, q̇) at θ.
    fn state(&self, theta: f64) -> Phase<N>;

    /// q at θ (a wall's f needs no more).
    fn position(&self, theta: f64) -> [f64; N] {
        self.state(theta).q
    }
}

/// A Runge–Kutta step of length `h` from `y0`: its ends, and its dense
/// output between them.
pub(super) struct RkStep<'a, const N: usize> {
    pub y0: &'a Phase<N>,
    pub trial: &'a Trial<N>,
    pub h: f64,
}

impl<const N: usize> Path<N> for RkStep<'_, N> {
    fn state(&self, theta: f64) -> Phase<N> {
        if theta == 0.0 {
            *self.y0
        } else if theta == 1.0 {
            self.trial.y1
        } else {
            self.trial.dense.at(theta, self.h)
        }
    }

    fn position(&self, theta: f64) -> [f64; N] {
        if theta == 0.0 {
            self.y0.q
        } else if theta == 1.0 {
            self.trial.y1.q
        } else {
            self.trial.dense.position(theta, self.h)
        }
    }
}

/// A step of Taylor's method of length `tau` along `series`.
pub(super) struct SeriesStep<'a, const N: usize> {
    pub series: &'a Series<N>,
    pub tau: f64,
}

impl<const N: usize> Path<N> for SeriesStep<'_, N> {
    fn state(&self, theta: f64) -> Phase<N> {
        let (q, v) = self.series.state(theta * self.tau);
        Phase { q, v }
    }
}

/// A collision predicted from f's second-order Taylor polynomial.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Aim {
    /// Index into the model's `walls()`.
    pub wall: usize,
    /// How long from now.
    pub tau: f64,
}

/// A wall crossed on a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Crossing {
    /// Index into the model's `walls()`.
    pub wall: usize,
    /// When, and where on the step (θ ∈ [0, 1]).
    pub t: f64,
    pub theta: f64,
}

impl<M: Surfaces<N>, const N: usize> Simulator<'_, M, N> {
    /// The wall the motion from y0 is predicted to meet first and when, from
    /// f's second-order Taylor polynomial in time (adaptive integrator
    /// only): the next step is made to end there. A motion whose f is
    /// quadratic in time (a flight in uniform gravity to a plane) then meets
    /// the wall at the end of one step, with no step across it to redo; for
    /// other motions the prediction only shortens a step, and the crossing
    /// is found on the step as usual.
    pub(super) fn aim(&self, method: &RungeKutta, y0: &Phase<N>) -> Option<Aim> {
        if !method.adaptive() {
            return None;
        }
        let m = self.model;
        let shortest = SHORTEST_AIM_ULPS * f64::EPSILON * self.state.t.abs().max(1.0);
        let mut best: Option<Aim> = None;
        for (k, &wall) in m.walls().iter().enumerate() {
            let Some(hessian) = m.surface_hessian(wall, &y0.q, &y0.v) else {
                continue;
            };
            let f = m.surface(wall, &y0.q);
            let normal = m.normal(wall, &y0.q);
            let rate = linalg::dot(&normal, &y0.v);
            let accel = linalg::dot(&normal, &self.f0.v) + hessian;
            if let Some(tau) = descending_root(f, rate, accel)
                && tau > shortest
                && best.is_none_or(|b| tau < b.tau)
            {
                best = Some(Aim { wall: k, tau });
            }
        }
        best
    }

    /// The first wall crossed on the step of length `h` from t0 whose motion
    /// is `path` (index into the model's `walls()`, time on the path), if
    /// any.
    pub(super) fn first_crossing(
        &self,
        path: &impl Path<N>,
        t0: f64,
        h: f64,
    ) -> Result<Option<Crossing>, SimError<M::Wall>> {
        let mut best: Option<Crossing> = None;
        let mut second: Option<Crossing> = None;
        for k in 0..self.model.walls().len() {
            let Some(theta) = self.wall_crossing(k, path, t0, h)? else {
                continue;
            };
            let now = Crossing {
                wall: k,
                t: t0 + theta * h,
                theta,
            };
            match best {
                Some(b) if b.t <= now.t => {
                    if second.is_none_or(|s| now.t < s.t) {
                        second = Some(now);
                    }
                }
                _ => {
                    second = best;
                    best = Some(now);
                }
            }
        }
        if let (Some(a), Some(b)) = (best, second)
            && b.t - a.t <= self.settings.simultaneity_window(a.t, h)
        {
            return Err(SimError::Simultaneous {
                first: self.model.walls()[a.wall],
                second: self.model.walls()[b.wall],
                t: a.t,
            });
        }
        Ok(best)
    }

    /// Where on the step (θ ∈ [0, 1]) wall `k` is first met, if it is.
    ///
    /// f and its rate df·q̇ are sampled along the path. Met means f
    /// goes from > 0 to ≤ 0 between samples; a dip below zero between two
    /// positive samples is caught by the rate changing sign (its bottom is
    /// located first). A wall just collided with starts at f ≈ 0 moving
    /// away: it is met again only after f has been positive, which is also
    /// checked between samples through the top of the excursion.
    fn wall_crossing(
        &self,
        k: usize,
        path: &impl Path<N>,
        t0: f64,
        h: f64,
    ) -> Result<Option<f64>, SimError<M::Wall>> {
        let on = OnStep {
            model: self.model,
            wall: self.model.walls()[k],
            path,
        };
        let (f, rate) = (|theta| on.f(theta), |theta| on.rate(theta));
        let n = self.settings.samples + 1;
        let mut prev = on.sample(0.0);
        let mut leaving = self.departing & (1 << k) != 0 && prev.f <= 0.0 && prev.rate > 0.0;
        if !leaving && prev.f <= 0.0 {
            // At or beyond the wall at the step's start and not leaving it
            // (a projection can move q by rounding-sized amounts).
            return Ok(Some(0.0));
        }
        for j in 1..=n {
            let now = on.sample(j as f64 / n as f64);
            if leaving {
                if now.f > 0.0 {
                    leaving = false;
                } else if now.rate <= 0.0 {
                    // Turned back before a sample saw it off the wall: find
                    // the top of the excursion.
                    let top = illinois(&rate, (prev.theta, prev.rate), (now.theta, now.rate));
                    let f_top = f(top);
                    if f_top > 0.0 {
                        return Ok(Some(illinois(&f, (top, f_top), (now.theta, now.f))));
                    }
                    return Err(SimError::Grazing {
                        wall: on.wall,
                        t: t0 + top * h,
                        normal_velocity: rate(top),
                    });
                }
            } else if now.f <= 0.0 {
                return Ok(Some(illinois(&f, (prev.theta, prev.f), (now.theta, now.f))));
            } else if prev.rate < 0.0 && now.rate > 0.0 {
                // f stays positive at both samples but turns: check the
                // bottom of the dip.
                let falling = |theta: f64| -rate(theta);
                let bottom = illinois(&falling, (prev.theta, -prev.rate), (now.theta, -now.rate));
                let f_bottom = f(bottom);
                if f_bottom <= 0.0 {
                    return Ok(Some(illinois(&f, (prev.theta, prev.f), (bottom, f_bottom))));
                }
            }
            prev = now;
        }
        Ok(None)
    }
}

/// One wall seen along one step: f and its rate at any θ ∈ [0, 1].
struct OnStep<'a, M: Surfaces<N>, P, const N: usize> {
    model: &'a M,
    wall: M::Wall,
    path: &'a P,
}

/// f and its rate at one θ of a step.
#[derive(Clone, Copy)]
struct Sample {
    theta: f64,
    f: f64,
    rate: f64,
}

impl<M: Surfaces<N>, P: Path<N>, const N: usize> OnStep<'_, M, P, N> {
    /// f alone.
    fn f(&self, theta: f64) -> f64 {
        self.model.surface(self.wall, &self.path.position(theta))
    }

    fn rate(&self, theta: f64) -> f64 {
        let y = self.path.state(theta);
        self.model.normal_velocity(self.wall, &y.q, &y.v)
    }

    /// f and its rate from one state on the path.
    fn sample(&self, theta: f64) -> Sample {
        let y = self.path.state(theta);
        Sample {
            theta,
            f: self.model.surface(self.wall, &y.q),
            rate: self.model.normal_velocity(self.wall, &y.q, &y.v),
        }
    }
}

/// The first τ > 0 at which f + rate·τ + accel·τ²/2 falls through zero
/// (its slope there negative), if there is one.
fn descending_root(f: f64, rate: f64, accel: f64) -> Option<f64> {
    // The descending root is (−rate − s)/accel with s = √(rate² − 2·accel·f);
    // for rate ≤ 0 the same value in the form 2f/(s − rate), which does not
    // cancel (and covers accel = 0).
    let disc = rate * rate - 2.0 * accel * f;
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    let s = libm::sqrt(disc);
    let tau = if rate > 0.0 {
        (-rate - s) / accel
    } else {
        2.0 * f / (s - rate)
    };
    (tau > 0.0 && tau.is_finite()).then_some(tau)
}

/// The root of `f` in [a, b] with f(a) > 0 ≥ f(b), by the Illinois variant
/// of regula falsi; returns θ.
fn illinois(f: &impl Fn(f64) -> f64, a: (f64, f64), b: (f64, f64)) -> f64 {
    let ((mut a, mut fa), (mut b, mut fb)) = (a, b);
    let mut side = 0;
    for _ in 0..ROOT_ITERATIONS {
        if fb == 0.0 || b - a <= 2.0 * f64::EPSILON * b.abs().max(1e-300) {
            break;
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        if !(c > a && c < b) {
            c = 0.5 * (a + b);
        }
        let fc = f(c);
        if fc > 0.0 {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::descending_root;

    fn close(a: Option<f64>, b: f64) -> bool {
        a.is_some_and(|a| (a - b).abs() <= 1e-14 * b.abs())
    }

    #[test]
    fn descending_roots() {
        // Thrown up from the wall: back after 2·rate/|accel|, not at the
        // start (where f rises through zero), also a rounding below it.
        assert!(close(descending_root(0.0, 2.0, -10.0), 0.4));
        assert!(close(descending_root(-1e-17, 2.0, -10.0), 0.4));
        // Falling from height 5 at rest: √(2·5/10) = 1.
        assert!(close(descending_root(5.0, 0.0, -10.0), 1.0));
        // Approaching at constant speed: f/|rate|.
        assert!(close(descending_root(3.0, -2.0, 0.0), 1.5));
        // Approaching while pushed back: the earlier of the two roots of
        // 1 − 3τ + τ² (τ = (3 − √5)/2), not the later one where f rises.
        assert!(close(
            descending_root(1.0, -3.0, 2.0),
            (3.0 - 5f64.sqrt()) / 2.0
        ));
        // Turning back before the wall, moving away, or already beyond it
        // and approaching: no meeting ahead.
        assert_eq!(descending_root(1.0, -1.0, 2.0), None);
        assert_eq!(descending_root(1.0, 1.0, 0.0), None);
        assert_eq!(descending_root(1.0, 1.0, 2.0), None);
        assert_eq!(descending_root(-1.0, -1.0, 0.0), None);
        assert_eq!(descending_root(f64::NAN, -1.0, 0.0), None);
    }
}
