//! The derivative of each function of the language, written once.
//!
//! Three representations of expressions differentiate through the
//! functions: the bodies layer's trees (`ir/bodies/sym.rs`), symbolica's
//! expressions for the functions it lacks (`derive/build.rs`), and the
//! tangents of straight-line programs (`program/tangent.rs`). Each
//! implements [`Algebra`], the few operations a rule is written in, and
//! calls [`derivative`]; a new function's rule goes here and nowhere else.

use super::Function;

/// The operations a derivative rule is written in.
pub trait Algebra {
    /// An expression (or a program's value).
    type E: Clone;
    /// The number `num/den`.
    fn number(&mut self, num: i64, den: i64) -> Self::E;
    /// The sum of `terms`.
    fn add(&mut self, terms: Vec<Self::E>) -> Self::E;
    /// `a − b`.
    fn sub(&mut self, a: Self::E, b: Self::E) -> Self::E;
    /// `x` to the power `num/den`.
    fn pow(&mut self, x: Self::E, num: i64, den: i64) -> Self::E;
    /// `f(x)`.
    fn call(&mut self, f: Function, x: Self::E) -> Self::E;
}

/// f′ at `x` as a product of factors (to which the caller appends the
/// inner derivative), where `y` is f(`x`): rules that read f(x) take it
/// from there instead of computing it again.
pub fn derivative<A: Algebra>(a: &mut A, f: Function, x: A::E, y: A::E) -> Vec<A::E> {
    // 1 ± z²
    let one_plus = |a: &mut A, z: A::E| {
        let (one, square) = (a.number(1, 1), a.pow(z, 2, 1));
        a.add(vec![one, square])
    };
    let one_minus = |a: &mut A, z: A::E| {
        let (one, square) = (a.number(1, 1), a.pow(z, 2, 1));
        a.sub(one, square)
    };
    match f {
        Function::Sin => vec![a.call(Function::Cos, x)],
        Function::Cos => vec![a.number(-1, 1), a.call(Function::Sin, x)],
        // 1 + tan²
        Function::Tan => vec![one_plus(a, y)],
        Function::Exp => vec![y],
        Function::Log => vec![a.pow(x, -1, 1)],
        // 1 / (2√x)
        Function::Sqrt => vec![a.number(1, 2), a.pow(y, -1, 1)],
        // 1 / (1 + x²)
        Function::Atan => {
            let w = one_plus(a, x);
            vec![a.pow(w, -1, 1)]
        }
        // ±1 / √(1 − x²)
        Function::Asin | Function::Acos => {
            let w = one_minus(a, x);
            let over = a.pow(w, -1, 2);
            if f == Function::Acos {
                vec![a.number(-1, 1), over]
            } else {
                vec![over]
            }
        }
        Function::Sinh => vec![a.call(Function::Cosh, x)],
        Function::Cosh => vec![a.call(Function::Sinh, x)],
        // 1 − tanh²
        Function::Tanh => vec![one_minus(a, y)],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Numbers: the rule evaluated.
    struct Numbers;

    impl Algebra for Numbers {
        type E = f64;
        fn number(&mut self, num: i64, den: i64) -> f64 {
            num as f64 / den as f64
        }
        fn add(&mut self, terms: Vec<f64>) -> f64 {
            terms.iter().sum()
        }
        fn sub(&mut self, a: f64, b: f64) -> f64 {
            a - b
        }
        fn pow(&mut self, x: f64, num: i64, den: i64) -> f64 {
            x.powf(num as f64 / den as f64)
        }
        fn call(&mut self, f: Function, x: f64) -> f64 {
            f.value(x)
        }
    }

    /// Every function's rule against central differences of its value,
    /// at points inside each one's domain.
    #[test]
    fn rules_agree_with_differences() {
        let h = 1e-6;
        for f in Function::ALL {
            for x in [-0.7, -0.2, 0.3, 0.9] {
                let x = if matches!(f, Function::Log | Function::Sqrt) {
                    x + 1.0
                } else {
                    x
                };
                let got: f64 = derivative(&mut Numbers, f, x, f.value(x)).iter().product();
                let want = (f.value(x + h) - f.value(x - h)) / (2.0 * h);
                assert!(
                    (got - want).abs() <= 1e-8 * want.abs().max(1.0),
                    "{}′({x}) = {got}, differences say {want}",
                    f.name()
                );
            }
        }
    }
}
