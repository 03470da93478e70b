//! exp: its own derivative, and its own recurrence.

use super::{Algebra, Elementary, Fold, Recurrences, Rules};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Exp;

impl Rules for Exp {
    const NAME: &'static str = "exp";
    const AT_ZERO: Option<i64> = Some(1);
    fn value(x: f64) -> f64 {
        libm::exp(x)
    }
    fn interval(x: Interval) -> Interval {
        x.exp()
    }
    fn fold(x: f64, _: f64) -> Result<Fold, String> {
        let value = libm::exp(x);
        Ok(Fold::Slope {
            value,
            slope: value,
        })
    }
    fn derivative<A: Algebra>(_: &mut A, _: A::E, y: A::E) -> Vec<A::E> {
        vec![y]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        r.exp(a)
    }
    fn elementary<A: Algebra>(_: &mut A, _: A::E, _: A::E) -> Elementary<A::E> {
        Elementary::Itself
    }
}
