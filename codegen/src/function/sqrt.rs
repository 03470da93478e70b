//! sqrt: 1/(2√x) is its derivative; its own recurrence. (Programs carry a
//! root as the machine form `Sqrt`, which can fold a reciprocal in.)

use super::{Algebra, Elementary, Fold, Recurrences, Rules, not_real};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Sqrt;

impl Rules for Sqrt {
    const NAME: &'static str = "sqrt";
    const AT_ZERO: Option<i64> = Some(0);
    fn value(x: f64) -> f64 {
        libm::sqrt(x)
    }
    fn interval(x: Interval) -> Interval {
        x.sqrt()
    }
    fn fold(x: f64, error: f64) -> Result<Fold, String> {
        if x < -error {
            return not_real(Self::NAME, x);
        }
        if x <= error {
            // 0 or a rounding of it: the root of the error bounds it.
            return Ok(Fold::Within {
                value: 0.0,
                error: libm::sqrt(error),
            });
        }
        let value = libm::sqrt(x);
        Ok(Fold::Slope {
            value,
            slope: 0.5 / value,
        })
    }
    fn derivative<A: Algebra>(a: &mut A, _: A::E, y: A::E) -> Vec<A::E> {
        vec![a.number(1, 2), a.pow(y, -1, 1)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        r.sqrt(a)
    }
    fn elementary<A: Algebra>(_: &mut A, _: A::E, _: A::E) -> Elementary<A::E> {
        Elementary::Itself
    }
}
