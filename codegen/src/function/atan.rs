//! atan: 1/(1 + x²) is its derivative; its series is that integrated
//! ([`Recurrences::arc`] with w = 1 + a²).

use super::{
    Algebra, Elementary, Fold, Function, Recurrences, Rules, one_plus, one_plus_square, sloped,
};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Atan;

impl Rules for Atan {
    const NAME: &'static str = "atan";
    const AT_ZERO: Option<i64> = Some(0);
    fn value(x: f64) -> f64 {
        libm::atan(x)
    }
    fn interval(x: Interval) -> Interval {
        x.atan()
    }
    fn fold(x: f64, _: f64) -> Result<Fold, String> {
        sloped(libm::atan(x), 1.0)
    }
    fn derivative<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Vec<A::E> {
        let w = one_plus(a, x);
        vec![a.pow(w, -1, 1)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        let w = one_plus_square(r, a, 1.0);
        r.arc(Function::Atan, a, w, false)
    }
    fn elementary<A: Algebra>(a: &mut A, x: A::E, y: A::E) -> Elementary<A::E> {
        // g = sin y − x cos y: g/g′ = (sin y − x cos y)/(cos y + x sin y)
        let (s, c) = (a.call(Function::Sin, y.clone()), a.call(Function::Cos, y));
        let (xc, xs) = (a.mul(vec![x.clone(), c.clone()]), a.mul(vec![x, s.clone()]));
        let (g, slope) = (a.sub(s, xc), a.add(vec![c, xs]));
        let over = a.pow(slope, -1, 1);
        Elementary::Newton(a.mul(vec![g, over]))
    }
}
