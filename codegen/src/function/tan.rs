//! tan: 1 + tan² is its derivative; its series is sin/cos of the pair.
//! (The symbolic stage writes it as sin/cos before programs are made, so
//! programs meet it only when built by hand.)

use super::{Algebra, Elementary, Fold, Function, Recurrences, Rules, one_plus};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Tan;

impl Rules for Tan {
    const NAME: &'static str = "tan";
    const AT_ZERO: Option<i64> = Some(0);
    fn value(x: f64) -> f64 {
        libm::tan(x)
    }
    fn interval(x: Interval) -> Interval {
        x.tan()
    }
    fn fold(x: f64, error: f64) -> Result<Fold, String> {
        let c = libm::cos(x);
        if c.abs() <= error + f64::EPSILON / 2.0 {
            return Err(format!(
                "tan({x:.3e}), at a pole of tan (cos = {c:.3e} is 0 to within rounding)"
            ));
        }
        Ok(Fold::Slope {
            value: libm::tan(x),
            slope: 1.0 / (c * c),
        })
    }
    fn derivative<A: Algebra>(a: &mut A, _: A::E, y: A::E) -> Vec<A::E> {
        vec![one_plus(a, y)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        let (sin, cos) = r.sin_cos(a);
        let over = r.recip(cos);
        r.product(sin, over)
    }
    fn elementary<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Elementary<A::E> {
        let (s, c) = (a.call(Function::Sin, x.clone()), a.call(Function::Cos, x));
        let over = a.pow(c, -1, 1);
        Elementary::Closed(a.mul(vec![s, over]))
    }
}
