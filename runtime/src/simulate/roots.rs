//! Roots of a step's polynomial: where a wall's f, as the truncated series
//! of f along a step of Taylor's method, first falls to zero (samples for a
//! sign change or a turn towards the wall, then Newton's method kept inside
//! the bracket, from the closed form for a degree of 2 or less).

use super::thresholds::{SERIES_ROOT_ITERATIONS, SERIES_SAMPLES};
use crate::libm;
use crate::taylor::{CAPACITY, Coefficients, eval, eval_with_derivative};

/// The first τ in (0, h] where the polynomial f (of `order`, its degree:
/// see [`crate::taylor::degree`]) falls to zero from above, if any; `departing` when the
/// wall was just left (f(0) ≈ 0 rising): then a root at the start is the
/// departure, not a collision. `Err(τ)`: the motion turns back towards the
/// wall at τ before f was seen positive (grazing on departure). For a
/// degree of 2 or less the answer on (0, h] is the answer on any longer
/// window (g ≥ h) less what it finds beyond h: such an f turns at most
/// once, so one sample at the window's end settles it.
pub(super) fn first_root(
    c: &Coefficients,
    order: usize,
    h: f64,
    departing: bool,
) -> Result<Option<f64>, f64> {
    // f's turning point in [a, b] (needed after every bounce, where the
    // departure is followed over the top): for a parabola c₀ + c₁τ + c₂τ²
    // its vertex −c₁/(2c₂), else a root of f's derivative, made on demand.
    let turn = |a: f64, b: f64| {
        if order == 2 {
            let top = -c[1] / (2.0 * c[2]);
            if top >= a && top <= b {
                return top;
            }
        }
        let mut rate = [0.0; CAPACITY];
        for k in 0..order {
            rate[k] = (k + 1) as f64 * c[k + 1];
        }
        root(&rate, order.saturating_sub(1), a, b)
    };
    let at = |tau: f64| eval_with_derivative(c, order, tau);
    let (f0, r0) = (c[0], c[1]);
    let mut leaving = departing && f0 <= 0.0 && r0 > 0.0;
    if !leaving && f0 <= 0.0 {
        // At or beyond the wall at the start and not leaving it.
        return Ok(Some(0.0));
    }
    // A polynomial of degree 2 or less turns at most once, so the checks
    // below (a sign change, a turn towards the wall and its bottom) are
    // exact on the whole step at once; a flight's f is of that kind.
    let samples = if order <= 2 { 1 } else { SERIES_SAMPLES };
    let mut prev = (0.0, f0, r0);
    for j in 1..=samples {
        let tau = if j == samples {
            h
        } else {
            h * j as f64 / samples as f64
        };
        let (f, r) = at(tau);
        if leaving {
            if f > 0.0 {
                leaving = false;
            } else if r <= 0.0 {
                let top = turn(prev.0, tau);
                if eval(c, order, top) > 0.0 {
                    return Ok(Some(root(c, order, top, tau)));
                }
                return Err(top);
            }
        } else if f <= 0.0 {
            return Ok(Some(root(c, order, prev.0, tau)));
        } else if prev.2 < 0.0 && r > 0.0 {
            // Positive at both samples but turning: check the dip's bottom.
            let bottom = turn(prev.0, tau);
            if eval(c, order, bottom) <= 0.0 {
                return Ok(Some(root(c, order, prev.0, bottom)));
            }
        }
        prev = (tau, f, r);
    }
    Ok(None)
}

/// A root of the polynomial in [a, b], where its sign changes: Newton's
/// method from the closed-form root for a degree of 2 or less (then one
/// step confirms it), else from the secant point, bisection wherever Newton
/// would leave the bracket, until the step is below rounding.
fn root(c: &Coefficients, order: usize, mut a: f64, mut b: f64) -> f64 {
    let (fa, fb) = (eval(c, order, a), eval(c, order, b));
    if fa == 0.0 {
        return a;
    }
    if fb == 0.0 {
        return b;
    }
    let above_at_a = fa > 0.0;
    let closed_form = if order <= 2 {
        quadratic_root(c, order, a, b)
    } else {
        None
    };
    let mut x = closed_form.unwrap_or_else(|| a - fa * (b - a) / (fb - fa));
    if !(x > a && x < b) {
        x = 0.5 * (a + b);
    }
    for _ in 0..SERIES_ROOT_ITERATIONS {
        let (fx, dx) = eval_with_derivative(c, order, x);
        if fx == 0.0 {
            return x;
        }
        if (fx > 0.0) == above_at_a {
            a = x;
        } else {
            b = x;
        }
        let newton = x - fx / dx;
        let next = if newton > a && newton < b {
            newton
        } else {
            0.5 * (a + b)
        };
        if next == x || (next - x).abs() <= f64::EPSILON * x.abs() {
            return next;
        }
        x = next;
    }
    x
}

/// A root of c₀ + c₁τ + c₂τ² (the polynomial of `order` ≤ 2) in (a, b),
/// by the formula that loses no digits to cancellation (the larger root
/// from −(c₁ + sign(c₁)√d)/2, the other from the product of the roots);
/// `None` where no root is found there (a rounding-level discriminant, or a
/// root just outside).
fn quadratic_root(c: &Coefficients, order: usize, a: f64, b: f64) -> Option<f64> {
    let coefficient = |k: usize| if k <= order { c[k] } else { 0.0 };
    let (c0, c1, c2) = (c[0], coefficient(1), coefficient(2));
    let inside = |x: f64| (x > a && x < b).then_some(x);
    if c2 == 0.0 {
        return if c1 == 0.0 { None } else { inside(-c0 / c1) };
    }
    let d = c1 * c1 - 4.0 * c2 * c0;
    if d < 0.0 {
        return None;
    }
    let q = -0.5 * (c1 + libm::sqrt(d).copysign(c1));
    let first = q / c2;
    let second = if q == 0.0 { first } else { c0 / q };
    inside(first.min(second)).or_else(|| inside(first.max(second)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::taylor::degree;

    fn poly(c: &[f64]) -> Coefficients {
        let mut out = [0.0; CAPACITY];
        out[..c.len()].copy_from_slice(c);
        out
    }

    /// A flight z(τ) = 1 + 2τ − 4.905τ² lands at the descending root,
    /// found to rounding.
    #[test]
    fn parabola_lands_at_its_root() {
        let c = poly(&[1.0, 2.0, -4.905]);
        let want = (2.0 + (4.0f64 + 4.0 * 4.905).sqrt()) / (2.0 * 4.905);
        let tau = first_root(&c, 2, 1.0, false).unwrap().unwrap();
        assert!(
            (tau - want).abs() <= 2.0 * f64::EPSILON * want,
            "{tau} {want}"
        );
        // Not within a shorter step.
        assert_eq!(first_root(&c, 2, 0.5, false), Ok(None));
    }

    /// Just after a bounce (f(0) = 0, rising) the departure is not a
    /// collision; the landing is.
    #[test]
    fn departure_is_not_a_collision() {
        let c = poly(&[0.0, 2.0, -4.905]);
        let want = 2.0 / 4.905;
        let tau = first_root(&c, 2, 1.0, true).unwrap().unwrap();
        assert!((tau - want).abs() <= 2.0 * f64::EPSILON * want);
        // The same state not departing is at the wall already.
        assert_eq!(first_root(&c, 2, 1.0, false), Ok(Some(0.0)));
        // Leaving from just beyond the wall and turning back before f is
        // positive: grazing, reported at the parabola's vertex.
        let c = poly(&[-1e-9, 1e-5, -1.0]);
        assert_eq!(first_root(&c, 2, 1.0, true), Err(5e-6));
    }

    /// The closed-form start of the root search: the root in the bracket,
    /// to a few ulps, where the textbook formula would lose the small root
    /// to cancellation; linear and rootless cases.
    #[test]
    fn quadratic_roots() {
        // (τ − 1e-9)(τ − 1e3) = τ² − (1e3 + 1e-9)τ + 1e-6.
        let c = poly(&[1e-6, -(1e3 + 1e-9), 1.0]);
        let small = quadratic_root(&c, 2, 0.0, 1.0).unwrap();
        assert!((small - 1e-9).abs() <= 4.0 * f64::EPSILON * 1e-9, "{small}");
        let large = quadratic_root(&c, 2, 1.0, 2e3).unwrap();
        assert!((large - 1e3).abs() <= 4.0 * f64::EPSILON * 1e3, "{large}");
        // Coefficients above the order are not read.
        let c = poly(&[1.0, -2.0, 5.0]);
        assert_eq!(quadratic_root(&c, 1, 0.0, 1.0), Some(0.5));
        // No real root; a root outside the bracket.
        assert_eq!(quadratic_root(&poly(&[1.0, 0.0, 1.0]), 2, -9.0, 9.0), None);
        assert_eq!(quadratic_root(&poly(&[1.0, -2.0]), 1, 0.0, 0.4), None);
        // root() lands on the same value from the closed form.
        let c = poly(&[1e-6, -(1e3 + 1e-9), 1.0]);
        let r = root(&c, 2, 0.0, 1.0);
        assert!((r - 1e-9).abs() <= 4.0 * f64::EPSILON * 1e-9, "{r}");
    }

    /// A dip that touches down between two samples is found at its
    /// bottom's side; a dip that stays above is not a collision.
    #[test]
    fn dips_between_samples() {
        // f = (τ − 0.5)² − 1e-6: roots at 0.5 ± 0.001, between samples
        // 0.5 and 0.5625 of h = 1? (0.5 is a sample: f < 0 there.)
        let c = poly(&[0.25 - 1e-6, -1.0, 1.0]);
        let tau = first_root(&c, 2, 1.0, false).unwrap().unwrap();
        assert!((tau - 0.499).abs() < 1e-12, "{tau}");
        // Bottom at 0.53 (between samples 0.5 and 0.5625), just below 0.
        let c = poly(&[0.53 * 0.53 - 1e-8, -1.06, 1.0]);
        let tau = first_root(&c, 2, 1.0, false).unwrap().unwrap();
        assert!((tau - (0.53 - 1e-4)).abs() < 1e-12, "{tau}");
        // Bottom just above 0.
        let c = poly(&[0.53 * 0.53 + 1e-8, -1.06, 1.0]);
        assert_eq!(first_root(&c, 2, 1.0, false), Ok(None));
    }

    /// For a degree of 2 or less, the search on a longer window, less what
    /// it finds beyond the step, is the search on the step (what
    /// [`Limit::first_root`] relies on): random parabolas and lines, rising
    /// from the wall or not, steps and windows from 1e-3 to 10³.
    #[test]
    fn longer_windows_find_the_same_roots() {
        let mut uniform = crate::simulate::uniform(0x9e37_79b9_7f4a_7c15u64);
        let mut found = [0; 3];
        for case in 0..20_000 {
            let mut coefficient =
                || (2.0 * uniform() - 1.0) * libm::pow(10.0, 2.0 * uniform() - 1.0);
            let (c0, c1, c2) = (coefficient(), coefficient(), coefficient());
            let departing = case % 2 == 0;
            // Half of the departures from the wall itself.
            let c0 = if departing && case % 4 == 0 {
                -c0.abs() * 1e-9
            } else {
                c0
            };
            let c = poly(&[c0, c1, c2]);
            let order = degree(&c, if case % 7 == 0 { 1 } else { 2 });
            let h = libm::pow(10.0, 6.0 * uniform() - 3.0);
            let g = h * libm::pow(10.0, 3.0 * uniform());
            let on_step = first_root(&c, order, h, departing);
            let on_window = match first_root(&c, order, g, departing) {
                Ok(Some(tau)) if tau > h => Ok(None),
                Err(top) if top > h => Ok(None),
                other => other,
            };
            let same = match (on_step, on_window) {
                (Ok(Some(a)), Ok(Some(b))) | (Err(a), Err(b)) => {
                    (a - b).abs() <= 4.0 * f64::EPSILON * a.abs()
                }
                (a, b) => a == b,
            };
            assert!(
                same,
                "{c:?} {order} h {h} g {g} {departing}: {on_step:?} {on_window:?}"
            );
            found[match on_step {
                Ok(Some(_)) => 0,
                Ok(None) => 1,
                Err(_) => 2,
            }] += 1;
        }
        assert!(found.iter().all(|&n| n > 100), "{found:?}");
    }
}
