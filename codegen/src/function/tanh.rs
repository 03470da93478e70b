//! tanh: 1 − tanh² is its derivative; its series is 1 − 2/(e²ᵃ + 1),
//! which stays finite where eᵃ does not.

use super::{Algebra, Elementary, Fold, Function, Recurrences, Rules, one_minus, sloped};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Tanh;

impl Rules for Tanh {
    const NAME: &'static str = "tanh";
    const AT_ZERO: Option<i64> = Some(0);
    fn value(x: f64) -> f64 {
        libm::tanh(x)
    }
    fn interval(x: Interval) -> Interval {
        x.tanh()
    }
    fn fold(x: f64, _: f64) -> Result<Fold, String> {
        sloped(libm::tanh(x), 1.0)
    }
    fn derivative<A: Algebra>(a: &mut A, _: A::E, y: A::E) -> Vec<A::E> {
        vec![one_minus(a, y)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        let twice = r.scale(a, 2.0);
        let e = r.exp(twice);
        let plus_one = r.sum(&[e], &[1.0]);
        let over = r.recip(plus_one);
        let scaled = r.scale(over, -2.0);
        r.sum(&[scaled], &[1.0])
    }
    fn elementary<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Elementary<A::E> {
        // 1 − 2/(e²ˣ + 1)
        let (one, two) = (a.number(1, 1), a.number(2, 1));
        let twice = a.mul(vec![two.clone(), x]);
        let e = a.call(Function::Exp, twice);
        let below = a.add(vec![e, one.clone()]);
        let over = a.pow(below, -1, 1);
        let part = a.mul(vec![two, over]);
        Elementary::Closed(a.sub(one, part))
    }
}
