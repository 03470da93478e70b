//! atanh: 1/(1 − x²) is its derivative; its series is that integrated
//! ([`Recurrences::arc`] with w = 1 − a²).

use super::{Algebra, Elementary, Fold, Function, Recurrences, Rules, one_minus, one_plus_square};
use dalembert_runtime::{interval::Interval, libm};

pub(super) struct Atanh;

impl Rules for Atanh {
    const NAME: &'static str = "atanh";
    const AT_ZERO: Option<i64> = Some(0);
    fn value(x: f64) -> f64 {
        libm::atanh(x)
    }
    fn interval(x: Interval) -> Interval {
        x.atanh()
    }
    fn fold(x: f64, error: f64) -> Result<Fold, String> {
        if x.abs() + error >= 1.0 {
            return Err(format!(
                "atanh of {x:.3e}, at or outside ±1 (to within rounding), which is not finite"
            ));
        }
        Ok(Fold::Slope {
            value: libm::atanh(x),
            slope: 1.0 / (1.0 - x * x),
        })
    }
    fn derivative<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Vec<A::E> {
        let w = one_minus(a, x);
        vec![a.pow(w, -1, 1)]
    }
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series {
        let w = one_plus_square(r, a, -1.0);
        r.arc(Function::Atanh, a, w, false)
    }
    fn elementary<A: Algebra>(a: &mut A, x: A::E, _: A::E) -> Elementary<A::E> {
        // ln((1 + x)/(1 − x))/2
        let one = a.number(1, 1);
        let (up, down) = (a.add(vec![one.clone(), x.clone()]), a.sub(one, x));
        let over = a.pow(down, -1, 1);
        let ratio = a.mul(vec![up, over]);
        let log = a.call(Function::Log, ratio);
        let half = a.number(1, 2);
        Elementary::Closed(a.mul(vec![half, log]))
    }
}
