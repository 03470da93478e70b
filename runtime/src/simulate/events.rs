//! Events on a step: where the motion is predicted to meet a wall (so that
//! adaptive steps end there), and where a step actually crosses one,
//! located by evaluating each wall's f itself along the step's motion (a
//! Runge–Kutta step's dense output, or the polynomial of a step of
//! Taylor's method whose walls' series disagree with f at its end).

use super::enclosure::Ends;
use super::integrator::{Method, RungeKutta};
use super::path::Path;
use super::phase::Phase;
use super::thresholds::{
    RESOLVE_DEPTH, RESOLVED_DEFECT, RESOLVED_ROUNDING_ULPS, ROOT_ITERATIONS, SHORTEST_AIM_ULPS,
};
use super::{SimError, Simulator};
use crate::{Surfaces, libm, linalg};

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

    /// What the step of length `h` from t0 whose motion is `path` meets
    /// first: the earliest wall crossed on it, or a wall whose f its
    /// samples do not resolve before that.
    pub(super) fn scan(
        &self,
        path: &impl Path<N>,
        t0: f64,
        h: f64,
    ) -> Result<Scan, SimError<M::Wall>> {
        let mut best: Option<Crossing> = None;
        let mut second: Option<Crossing> = None;
        let mut unresolved: Option<Unresolved> = None;
        for k in 0..self.model.walls().len() {
            let theta = match self.wall_crossing(k, path, t0, h)? {
                None => continue,
                Some(Met::Crossing(theta)) => theta,
                Some(Met::Unresolved(u)) => {
                    if unresolved.is_none_or(|v| u.from < v.from) {
                        unresolved = Some(u);
                    }
                    continue;
                }
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
        if let Some(u) = unresolved
            && best.is_none_or(|b| b.theta >= u.from)
        {
            return Ok(Scan::Unresolved(u));
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
        Ok(best.map_or(Scan::Clear, Scan::Crossing))
    }

    /// Where on the step (θ ∈ [0, 1]) wall `k` is first met, if it is, or
    /// where its f stops being resolved.
    ///
    /// f and its rate df·q̇ are sampled along the path, at the step's
    /// settings' points, and between two of them wherever the rates do not
    /// explain f's change ([`explained`]): a pole of f (a tangent's, a
    /// quotient's) or a narrow excursion jumped between two samples shows
    /// as such a change. The interval is halved until they do, at most
    /// [`RESOLVE_DEPTH`] times; past that the step is too long for this
    /// wall, and the caller shortens it ([`Met::Unresolved`]).
    ///
    /// Met means f goes from > 0 to ≤ 0 between samples; a dip below zero
    /// between two positive samples is caught by the rate changing sign
    /// (its bottom is located first). A wall just collided with starts at
    /// f ≈ 0 moving away: it is met again only after f has been positive,
    /// which is also checked between samples through the top of the
    /// excursion.
    ///
    /// Samples can step over a dip narrower than their spacing whose
    /// rates show nothing; so the stretch before what they find (the whole
    /// step, or up to the crossing) is then proven clear on boxes that
    /// enclose the motion ([`Simulator::earlier_crossing`]), and a crossing
    /// found there comes first.
    fn wall_crossing(
        &self,
        k: usize,
        path: &impl Path<N>,
        t0: f64,
        h: f64,
    ) -> Result<Option<Met>, SimError<M::Wall>> {
        let on = OnStep {
            model: self.model,
            wall: self.model.walls()[k],
            path,
        };
        let sampled = self.sampled_crossing(k, &on, t0, h)?;
        let (end, f_end) = match sampled.met {
            None => (1.0, sampled.f_last),
            Some(Met::Crossing(theta)) if theta > 0.0 => (theta, on.f(theta)),
            Some(_) => return Ok(sampled.met),
        };
        let ends = Ends {
            f0: sampled.f0,
            leaving: sampled.leaving,
            end,
            f_end,
        };
        Ok(match self.earlier_crossing(k, path, &ends) {
            Some(b) => {
                let theta = illinois(&|theta| on.f(theta), (b.a, b.fa), (b.b, b.fb));
                Some(Met::Crossing(theta))
            }
            None => sampled.met,
        })
    }

    /// What the samples of wall `k`'s f along the step meet first (see
    /// [`Simulator::wall_crossing`]).
    fn sampled_crossing<P: Path<N>>(
        &self,
        k: usize,
        on: &OnStep<'_, M, P, N>,
        t0: f64,
        h: f64,
    ) -> Result<Sampled, SimError<M::Wall>> {
        let n = self.settings.samples + 1;
        let first = on.sample(0.0);
        let leaving = self.departing & (1 << k) != 0 && first.f <= 0.0 && first.rate > 0.0;
        let sampled = |met, last: &Sample| Sampled {
            met,
            f0: first.f,
            leaving,
            f_last: last.f,
        };
        if !leaving && first.f <= 0.0 {
            // At or beyond the wall at the step's start and not leaving it
            // (a projection can move q by rounding-sized amounts).
            return Ok(sampled(Some(Met::Crossing(0.0)), &first));
        }
        let mut walk = Walk {
            prev: first,
            leaving,
        };
        for j in 1..=n {
            let now = on.sample(j as f64 / n as f64);
            if !explained(&walk.prev, &now, h) {
                match walk.refined(on, now, t0, h)? {
                    Some(met) => return Ok(sampled(Some(met), &walk.prev)),
                    None => continue,
                }
            }
            if let Some(theta) = walk.to(on, now, t0, h)? {
                return Ok(sampled(Some(Met::Crossing(theta)), &walk.prev));
            }
        }
        Ok(sampled(None, &walk.prev))
    }
}

/// What a step meets first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Scan {
    /// No wall.
    Clear,
    /// A wall crossed.
    Crossing(Crossing),
    /// A wall whose f the step's samples do not resolve, before any
    /// crossing: the step must be shorter ([`Unresolved::shorter`]).
    Unresolved(Unresolved),
}

/// An interval of a step (θ from `from` to `to`) on which a wall's f is
/// not resolved by samples [`RESOLVE_DEPTH`] halvings apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Unresolved {
    pub from: f64,
    pub to: f64,
}

impl Unresolved {
    /// The length of a step from the same start that ends before the
    /// interval, from the length `h` of the one that did not: up to its
    /// beginning, or halfway into it where it begins at the start.
    pub fn shorter(&self, h: f64) -> f64 {
        if self.from > 0.0 {
            self.from * h
        } else {
            0.5 * self.to * h
        }
    }
}

/// What the samples of one wall's f along a step found: what they met
/// first, f at θ = 0 and whether the motion is leaving the wall there, and
/// the last sample's f (at θ = 1 where nothing was met).
struct Sampled {
    met: Option<Met>,
    f0: f64,
    leaving: bool,
    f_last: f64,
}

/// One wall's verdict on a step.
enum Met {
    Crossing(f64),
    Unresolved(Unresolved),
}

/// Whether f's change between samples `a` and `b` of a step of length `h`
/// is what their rates say: the trapezoid rule's defect, (f_b − f_a) −
/// Δt (ḟ_a + ḟ_b)/2, at most [`RESOLVED_DEFECT`] of the change's size
/// (|f_b − f_a| + Δt (|ḟ_a| + |ḟ_b|)/2), or within rounding of f. For f
/// smooth on the interval the defect is Δt³ f⁽³⁾/12 and vanishes faster
/// than the size as the interval is halved; across a pole (f falling to
/// −∞ and back from +∞ while ḟ < 0 throughout) it is the size itself.
/// A non-finite sample is never explained.
#[inline(always)]
fn explained(a: &Sample, b: &Sample, h: f64) -> bool {
    let dt = (b.theta - a.theta) * h;
    let change = b.f - a.f;
    let defect = change - 0.5 * dt * (a.rate + b.rate);
    let size = libm::fabs(change) + 0.5 * dt * (libm::fabs(a.rate) + libm::fabs(b.rate));
    let rounding =
        RESOLVED_ROUNDING_ULPS * f64::EPSILON * libm::fabs(a.f).max(libm::fabs(b.f)).max(1.0);
    // (A NaN fails the comparison; an infinity makes the size infinite.)
    size.is_finite() && libm::fabs(defect) <= RESOLVED_DEFECT * size + rounding
}

/// The walk along one wall's samples: the last one reached, and whether
/// the motion is still leaving the wall it started on.
struct Walk {
    prev: Sample,
    leaving: bool,
}

impl Walk {
    /// Goes on to `end` through midpoints, where f's change from the last
    /// sample to `end` is not explained by their rates; returns what is
    /// met before `end` or there, or `None` to go on from `end`.
    #[cold]
    fn refined<M: Surfaces<N>, P: Path<N>, const N: usize>(
        &mut self,
        on: &OnStep<'_, M, P, N>,
        end: Sample,
        t0: f64,
        h: f64,
    ) -> Result<Option<Met>, SimError<M::Wall>> {
        // The samples still to reach, the nearest last: `end` and the
        // midpoints taken towards it.
        let mut ahead = [end; RESOLVE_DEPTH + 1];
        let mut pending = 1;
        while pending > 0 {
            let now = ahead[pending - 1];
            if !explained(&self.prev, &now, h) {
                if pending > RESOLVE_DEPTH {
                    return Ok(Some(Met::Unresolved(Unresolved {
                        from: self.prev.theta,
                        to: now.theta,
                    })));
                }
                ahead[pending] = on.sample(0.5 * (self.prev.theta + now.theta));
                pending += 1;
                continue;
            }
            pending -= 1;
            if let Some(theta) = self.to(on, now, t0, h)? {
                return Ok(Some(Met::Crossing(theta)));
            }
        }
        Ok(None)
    }

    /// Goes on to the sample `now`: θ of the crossing between, if any.
    #[inline(always)]
    fn to<M: Surfaces<N>, P: Path<N>, const N: usize>(
        &mut self,
        on: &OnStep<'_, M, P, N>,
        now: Sample,
        t0: f64,
        h: f64,
    ) -> Result<Option<f64>, SimError<M::Wall>> {
        let (f, rate) = (|theta| on.f(theta), |theta| on.rate(theta));
        let prev = core::mem::replace(&mut self.prev, now);
        if self.leaving {
            if now.f > 0.0 {
                self.leaving = false;
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
    use super::{Sample, Unresolved, descending_root, explained};

    fn at(theta: f64, f: f64, rate: f64) -> Sample {
        Sample { theta, f, rate }
    }

    #[test]
    fn changes_the_rates_explain() {
        // f = 1 − t² over a step of length 1, sampled at θ = 0, 1/4 and 1:
        // a polynomial of degree 2 is the trapezoid rule's exact case.
        let f = |t: f64| at(t, 1.0 - t * t, -2.0 * t);
        assert!(explained(&f(0.0), &f(0.25), 1.0));
        assert!(explained(&f(0.25), &f(1.0), 1.0));
        // A cubic over a short interval: defect Δt³/2 against a change of
        // about 3Δt.
        let c = |t: f64| at(t, 2.0 - t * t * t, -3.0 * t * t);
        assert!(explained(&c(0.5), &c(0.6), 1.0));
        // Across a pole: f falls at both samples but is higher at the
        // second (tan(1 − r²) from inside the disk to beyond the ring).
        assert!(!explained(&at(0.0, 0.2, -1.0), &at(0.5, 3.0, -40.0), 1.0));
        // The same samples on a step 100 times shorter: the rates no
        // longer say f must have fallen by much, but it rose.
        assert!(!explained(&at(0.0, 0.2, -1.0), &at(0.5, 3.0, -40.0), 0.01));
        // Motion along a wall: changes at rounding level are explained.
        assert!(explained(
            &at(0.0, 0.5, 0.0),
            &at(1.0, 0.5 + 1e-16, 0.0),
            1.0
        ));
        // A sample at a pole is never explained.
        assert!(!explained(
            &at(0.0, 0.5, -1.0),
            &at(1.0, f64::INFINITY, -1.0),
            1.0
        ));
        assert!(!explained(
            &at(0.0, 0.5, -1.0),
            &at(1.0, 0.4, f64::NAN),
            1.0
        ));
    }

    #[test]
    fn shorter_steps_end_before_what_is_unresolved() {
        let u = Unresolved {
            from: 0.25,
            to: 0.3,
        };
        assert_eq!(u.shorter(2.0), 0.5);
        let at_start = Unresolved { from: 0.0, to: 0.5 };
        assert_eq!(at_start.shorter(2.0), 0.5);
    }

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
