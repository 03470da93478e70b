//! asinh: 1/√(1 + x²) is its derivative; its series is that integrated
//! ([`Recurrences::arc`] with w = √(1 + a²)).

use super::{
    Algebra, Elementary, Fold, Function, Recurrences, Rules, one_plus, one_plus_square, sloped,
};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Asinh;

impl Rules for Asinh {
    const NAME: &'static str = "asinh";
    const AT_ZERO: Option<i64> = Some(0);
    fn value(x: f64) -> f64 {
        libm::asinh(x)
    }
    fn interval(x: Interval) -> Interval {
        x.asinh()
    }
    fn fold(x: f64, _: f64) -> Result<Fold, String> {
        sloped(libm::asinh(x), 1.0)
    }
    fn derivative<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Vec<A::E> {
        let w = one_plus(a, x);
        vec![a.pow(w, -1, 2)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        let rest = one_plus_square(r, a, 1.0);
        let w = r.sqrt(rest);
        r.arc(Function::Asinh, a, w, false)
    }
    fn elementary<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Elementary<A::E> {
        // ln(x + √(x² + 1))
        let w = one_plus(a, x.clone());
        let root = a.pow(w, 1, 2);
        let sum = a.add(vec![x, root]);
        Elementary::Closed(a.call(Function::Log, sum))
    }
}
