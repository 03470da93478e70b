//! log, the natural logarithm: 1/x is its derivative; its own recurrence.

use super::{Algebra, Elementary, Fold, Recurrences, Rules, not_real};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Log;

impl Rules for Log {
    const NAME: &'static str = "log";
    const AT_ZERO: Option<i64> = None;
    fn value(x: f64) -> f64 {
        libm::log(x)
    }
    fn interval(x: Interval) -> Interval {
        x.log()
    }
    fn fold(x: f64, error: f64) -> Result<Fold, String> {
        if x < -error {
            return not_real(Self::NAME, x);
        }
        if x <= error {
            return Err(format!(
                "log of 0 (to within rounding: {x:.3e}), which is not finite"
            ));
        }
        Ok(Fold::Slope {
            value: libm::log(x),
            slope: 1.0 / x,
        })
    }
    fn derivative<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Vec<A::E> {
        vec![a.pow(x, -1, 1)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        r.log(a)
    }
    fn elementary<A: Algebra>(_: &mut A, _: A::E, _: A::E) -> Elementary<A::E> {
        Elementary::Itself
    }
}
