//! cos: −sin is its derivative, and sin and cos of one series are one pair
//! of series.

use super::{Algebra, Elementary, Fold, Function, Recurrences, Rules, sloped};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Cos;

impl Rules for Cos {
    const NAME: &'static str = "cos";
    const AT_ZERO: Option<i64> = Some(1);
    fn value(x: f64) -> f64 {
        libm::cos(x)
    }
    fn interval(x: Interval) -> Interval {
        x.cos()
    }
    fn fold(x: f64, _: f64) -> Result<Fold, String> {
        sloped(libm::cos(x), 1.0)
    }
    fn derivative<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Vec<A::E> {
        vec![a.number(-1, 1), a.call(Function::Sin, x)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        r.sin_cos(a).1
    }
    fn elementary<A: Algebra>(_: &mut A, _: A::E, _: A::E) -> Elementary<A::E> {
        Elementary::Itself
    }
}
