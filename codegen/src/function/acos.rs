//! acos: −1/√(1 − x²) is its derivative; its series is that integrated
//! ([`Recurrences::arc`] with w = √(1 − a²), signed).

use super::{
    Algebra, Elementary, Fold, Function, Recurrences, Rules, arc_fold, one_minus, one_plus_square,
};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Acos;

impl Rules for Acos {
    const NAME: &'static str = "acos";
    const AT_ZERO: Option<i64> = None;
    fn value(x: f64) -> f64 {
        libm::acos(x)
    }
    fn interval(x: Interval) -> Interval {
        x.acos()
    }
    fn fold(x: f64, error: f64) -> Result<Fold, String> {
        arc_fold(Self::NAME, libm::acos, x, error)
    }
    fn derivative<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Vec<A::E> {
        let w = one_minus(a, x);
        vec![a.number(-1, 1), a.pow(w, -1, 2)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        let rest = one_plus_square(r, a, -1.0);
        let w = r.sqrt(rest);
        r.arc(Function::Acos, a, w, true)
    }
    fn elementary<A: Algebra>(a: &mut A, x: A::E, y: A::E) -> Elementary<A::E> {
        // g = cos y − x: g/g′ = (x − cos y)/sin y
        let (s, c) = (a.call(Function::Sin, y.clone()), a.call(Function::Cos, y));
        let g = a.sub(x, c);
        let over = a.pow(s, -1, 1);
        Elementary::Newton(a.mul(vec![g, over]))
    }
}
