//! asin: 1/√(1 − x²) is its derivative; its series is that integrated
//! ([`Recurrences::arc`] with w = √(1 − a²)).

use super::{
    Algebra, Elementary, Fold, Function, Recurrences, Rules, arc_fold, one_minus, one_plus_square,
};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Asin;

impl Rules for Asin {
    const NAME: &'static str = "asin";
    const AT_ZERO: Option<i64> = Some(0);
    fn value(x: f64) -> f64 {
        libm::asin(x)
    }
    fn interval(x: Interval) -> Interval {
        x.asin()
    }
    fn fold(x: f64, error: f64) -> Result<Fold, String> {
        arc_fold(Self::NAME, libm::asin, x, error)
    }
    fn derivative<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Vec<A::E> {
        let w = one_minus(a, x);
        vec![a.pow(w, -1, 2)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        let rest = one_plus_square(r, a, -1.0);
        let w = r.sqrt(rest);
        r.arc(Function::Asin, a, w, false)
    }
    fn elementary<A: Algebra>(a: &mut A, x: A::E, y: A::E) -> Elementary<A::E> {
        // g = sin y − x: g/g′ = (sin y − x)/cos y
        let (s, c) = (a.call(Function::Sin, y.clone()), a.call(Function::Cos, y));
        let g = a.sub(s, x);
        let over = a.pow(c, -1, 1);
        Elementary::Newton(a.mul(vec![g, over]))
    }
}
