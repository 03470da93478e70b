//! sinh: cosh is its derivative; its series is (eᵃ − 1/eᵃ)/2.

use super::{
    Algebra, Elementary, Fold, Function, Recurrences, Rules, exponentials, half_exponentials,
    hyperbolic_fold,
};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Sinh;

impl Rules for Sinh {
    const NAME: &'static str = "sinh";
    const AT_ZERO: Option<i64> = Some(0);
    fn value(x: f64) -> f64 {
        libm::sinh(x)
    }
    fn interval(x: Interval) -> Interval {
        x.sinh()
    }
    fn fold(x: f64, error: f64) -> Result<Fold, String> {
        Ok(hyperbolic_fold(libm::sinh(x), x, error))
    }
    fn derivative<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Vec<A::E> {
        vec![a.call(Function::Cosh, x)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        exponentials(r, a, true)
    }
    fn elementary<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Elementary<A::E> {
        Elementary::Closed(half_exponentials(a, x, true))
    }
}
