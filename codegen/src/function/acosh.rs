//! acosh: 1/√(x² − 1) is its derivative; its series is that integrated
//! ([`Recurrences::arc`] with w = √(a² − 1)).

use super::{Algebra, Elementary, Fold, Function, Recurrences, Rules};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Acosh;

impl Rules for Acosh {
    const NAME: &'static str = "acosh";
    const AT_ZERO: Option<i64> = None;
    fn value(x: f64) -> f64 {
        libm::acosh(x)
    }
    fn interval(x: Interval) -> Interval {
        x.acosh()
    }
    fn fold(x: f64, error: f64) -> Result<Fold, String> {
        const EPS: f64 = f64::EPSILON / 2.0;
        if x < 1.0 - error {
            return Err(format!("acosh of {x:.3e}, below 1, which is not real"));
        }
        if x - error <= 1.0 {
            // At 1 to within rounding the slope is unbounded; acosh(1 + δ)
            // ≤ √(2δ) bounds the error.
            let value = libm::acosh(x.max(1.0));
            return Ok(Fold::Within {
                value,
                error: 2.0 * libm::sqrt(error + EPS) + EPS * value,
            });
        }
        Ok(Fold::Slope {
            value: libm::acosh(x),
            slope: 1.0 / libm::sqrt(x * x - 1.0),
        })
    }
    fn derivative<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Vec<A::E> {
        let (square, one) = (a.pow(x, 2, 1), a.number(1, 1));
        let w = a.sub(square, one);
        vec![a.pow(w, -1, 2)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        let square = r.product(a, a);
        let rest = r.sum(&[square], &[-1.0]);
        let w = r.sqrt(rest);
        r.arc(Function::Acosh, a, w, false)
    }
    fn elementary<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Elementary<A::E> {
        // ln(x + √(x² − 1))
        let (square, one) = (a.pow(x.clone(), 2, 1), a.number(1, 1));
        let w = a.sub(square, one);
        let root = a.pow(w, 1, 2);
        let sum = a.add(vec![x, root]);
        Elementary::Closed(a.call(Function::Log, sum))
    }
}
