//! The functions of the language, one file each.
//!
//! A function's file holds everything the toolkit knows about it, as one
//! implementation of [`Rules`]: its name (in model files, and of the
//! runtime's libm and `Interval` functions emitted code calls), its value
//! and interval enclosure, its exact value at 0, how a constant argument
//! known to within a rounding error folds, its derivative, its Taylor
//! series, and how it is written in the elementary functions (sin, cos,
//! exp, log and powers) for the symbolic stage's zero tests at any
//! precision ([`Elementary`]). The derivative, the series and the
//! elementary form are written against small traits ([`Algebra`],
//! [`Recurrences`]) that the stages implement, so this module imports no
//! stage and every stage reads the same rule.
//!
//! A new function is one file implementing [`Rules`] and its line in the
//! `functions!` list below. What symbolica knows of it is said in one
//! place of the symbolic stage (`derive/build.rs`): the functions it has
//! natively are named there, every other one reaches it as a function of
//! ours.

mod acos;
mod acosh;
mod asin;
mod asinh;
mod atan;
mod atanh;
mod cos;
mod cosh;
mod exp;
mod log;
mod sin;
mod sinh;
mod sqrt;
mod tan;
mod tanh;

use dalembert_runtime::interval::Interval;

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
    /// The product of `factors`.
    fn mul(&mut self, factors: Vec<Self::E>) -> Self::E;
    /// `x` to the power `num/den`.
    fn pow(&mut self, x: Self::E, num: i64, den: i64) -> Self::E;
    /// `f(x)`.
    fn call(&mut self, f: Function, x: Self::E) -> Self::E;
}

/// The recurrences a Taylor series rule is written in: the series
/// transform's operations on series (the Taylor coefficients of a value
/// along the motion).
pub trait Recurrences {
    /// A series.
    type Series: Copy;
    /// Σ `series` + Σ `numbers`.
    fn sum(&mut self, series: &[Self::Series], numbers: &[f64]) -> Self::Series;
    /// `a − b`.
    fn difference(&mut self, a: Self::Series, b: Self::Series) -> Self::Series;
    /// `a·b` (a square where they are one series).
    fn product(&mut self, a: Self::Series, b: Self::Series) -> Self::Series;
    /// `x·a`.
    fn scale(&mut self, a: Self::Series, x: f64) -> Self::Series;
    /// `1/a`.
    fn recip(&mut self, a: Self::Series) -> Self::Series;
    /// `√a`.
    fn sqrt(&mut self, a: Self::Series) -> Self::Series;
    /// `eᵃ`.
    fn exp(&mut self, a: Self::Series) -> Self::Series;
    /// `ln a`.
    fn log(&mut self, a: Self::Series) -> Self::Series;
    /// `(sin a, cos a)`, one pair for each series.
    fn sin_cos(&mut self, a: Self::Series) -> (Self::Series, Self::Series);
    /// The series `c` with `c′ = a′/w` (`−a′/w` where `minus`) and
    /// `c₀ = f(a₀)`: atan, asin and acos.
    fn arc(&mut self, f: Function, a: Self::Series, w: Self::Series, minus: bool) -> Self::Series;
}

/// A function in the elementary functions that evaluators at any precision
/// have (sin, cos, exp, log and powers): how the symbolic stage's zero
/// tests value the others.
pub enum Elementary<E> {
    /// It is one of them.
    Itself,
    /// f(x) written in them.
    Closed(E),
    /// f(x) is the root of g(x, y) = 0 in y near its f64 value: Newton's
    /// step g/(∂g/∂y) at y.
    Newton(E),
}

/// A constant argument's value folded through a function.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fold {
    /// f(x), where the argument's rounding error grows by at most `slope`
    /// (a bound of |f′| over the error's reach).
    Slope {
        /// f(x)
        value: f64,
        /// the bound of |f′|
        slope: f64,
    },
    /// f(x) to within `error`, the argument's error already counted.
    Within {
        /// f(x)
        value: f64,
        /// the bound of its error
        error: f64,
    },
}

/// Everything known about one function. Each file implements it once.
trait Rules {
    /// Its name in model files, and of the runtime's libm and `Interval`
    /// functions that compute it.
    const NAME: &'static str;
    /// f(0) where it is a whole number (it is folded exactly then).
    const AT_ZERO: Option<i64>;
    /// f(x), as emitted code computes it (the runtime's libm).
    fn value(x: f64) -> f64;
    /// An enclosure of f over `x` (the runtime's `Interval`).
    fn interval(x: Interval) -> Interval;
    /// f of `x` known to within `error`; where f is undefined or infinite
    /// there (or may be, to within the error), why, in words.
    fn fold(x: f64, error: f64) -> Result<Fold, String>;
    /// f′ at `x` as a product of factors (to which the caller appends the
    /// inner derivative), where `y` is f(`x`): rules that read f(x) take
    /// it from there instead of computing it again.
    fn derivative<A: Algebra>(a: &mut A, x: A::E, y: A::E) -> Vec<A::E>;
    /// The series of f(`a`).
    fn series<R: Recurrences>(r: &mut R, a: R::Series) -> R::Series;
    /// f(`x`) in the elementary functions, `y` standing for f(`x`) in a
    /// Newton step.
    fn elementary<A: Algebra>(a: &mut A, x: A::E, y: A::E) -> Elementary<A::E>;
}

/// The registration: each function's variant and the type in its file
/// that implements [`Rules`], in the order the format documents them.
macro_rules! functions {
    ($($(#[$doc:meta])* $variant:ident => $rules:path,)*) => {
        /// A function of the language.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum Function {
            $($(#[$doc])* $variant,)*
        }

        /// How many functions the language has.
        const COUNT: usize = [$(stringify!($variant)),*].len();

        impl Function {
            /// Every function, as the format documents them.
            pub const ALL: [Function; COUNT] = [$(Self::$variant),*];

            /// Its name in model files (also the libm function's and the
            /// runtime `Interval` method's).
            pub fn name(self) -> &'static str {
                match self {
                    $(Self::$variant => <$rules as Rules>::NAME,)*
                }
            }

            /// f(0) where it is a whole number.
            pub fn at_zero(self) -> Option<i64> {
                match self {
                    $(Self::$variant => <$rules as Rules>::AT_ZERO,)*
                }
            }

            /// The runtime's libm function of that name, which emitted
            /// code calls, and so what every evaluation here calls.
            pub fn libm(self) -> fn(f64) -> f64 {
                match self {
                    $(Self::$variant => <$rules as Rules>::value,)*
                }
            }

            /// The runtime's interval function of that name, which the
            /// emitted `_bounds` functions call: an enclosure of its values.
            pub fn interval(self) -> fn(Interval) -> Interval {
                match self {
                    $(Self::$variant => <$rules as Rules>::interval,)*
                }
            }

            /// Its value at a constant `x` known to within `error`, or why
            /// it is not a finite real number there.
            pub fn fold(self, x: f64, error: f64) -> Result<Fold, String> {
                match self {
                    $(Self::$variant => <$rules as Rules>::fold(x, error),)*
                }
            }

            /// f′ at `x` as a product of factors (to which the caller
            /// appends the inner derivative), where `y` is f(`x`).
            pub fn derivative<A: Algebra>(self, a: &mut A, x: A::E, y: A::E) -> Vec<A::E> {
                match self {
                    $(Self::$variant => <$rules as Rules>::derivative(a, x, y),)*
                }
            }

            /// f(`x`) in the elementary functions, `y` standing for
            /// f(`x`) in a Newton step.
            pub fn elementary<A: Algebra>(self, a: &mut A, x: A::E, y: A::E) -> Elementary<A::E> {
                match self {
                    $(Self::$variant => <$rules as Rules>::elementary(a, x, y),)*
                }
            }

            /// The Taylor series of f(`a`) from the series of `a`.
            pub fn series<R: Recurrences>(self, r: &mut R, a: R::Series) -> R::Series {
                match self {
                    $(Self::$variant => <$rules as Rules>::series(r, a),)*
                }
            }
        }
    };
}

functions! {
    /// sin
    Sin => sin::Sin,
    /// cos
    Cos => cos::Cos,
    /// tan
    Tan => tan::Tan,
    /// exp
    Exp => exp::Exp,
    /// natural logarithm
    Log => log::Log,
    /// square root
    Sqrt => sqrt::Sqrt,
    /// arctangent
    Atan => atan::Atan,
    /// arcsine
    Asin => asin::Asin,
    /// arccosine
    Acos => acos::Acos,
    /// hyperbolic sine
    Sinh => sinh::Sinh,
    /// hyperbolic cosine
    Cosh => cosh::Cosh,
    /// hyperbolic tangent
    Tanh => tanh::Tanh,
    /// inverse hyperbolic sine
    Asinh => asinh::Asinh,
    /// inverse hyperbolic cosine
    Acosh => acosh::Acosh,
    /// inverse hyperbolic tangent
    Atanh => atanh::Atanh,
}

impl Function {
    /// By its name in model files.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Its value at `x` ([`Function::libm`]).
    pub fn value(self, x: f64) -> f64 {
        self.libm()(x)
    }

    /// Every function's name, in a sentence: "sin, cos, … and tanh".
    pub fn listed() -> String {
        let names: Vec<&str> = Self::ALL.iter().map(|f| f.name()).collect();
        let (last, rest) = names.split_last().expect("functions");
        format!("{} and {last}", rest.join(", "))
    }
}

/// 1 + z², for the rules.
fn one_plus<A: Algebra>(a: &mut A, z: A::E) -> A::E {
    let (one, square) = (a.number(1, 1), a.pow(z, 2, 1));
    a.add(vec![one, square])
}

/// 1 − z², for the rules.
fn one_minus<A: Algebra>(a: &mut A, z: A::E) -> A::E {
    let (one, square) = (a.number(1, 1), a.pow(z, 2, 1));
    a.sub(one, square)
}

/// The fold of a function that is finite everywhere, with its slope bound.
fn sloped(value: f64, slope: f64) -> Result<Fold, String> {
    Ok(Fold::Slope { value, slope })
}

/// The refusal of `name` at a negative `x` (below its error).
fn not_real(name: &str, x: f64) -> Result<Fold, String> {
    Err(format!(
        "{name} of a negative number ({x:.3e}), which is not real"
    ))
}

/// The series 1 + s·a² of `a` (`s` = ±1).
fn one_plus_square<R: Recurrences>(r: &mut R, a: R::Series, s: f64) -> R::Series {
    let square = r.product(a, a);
    let signed = if s == 1.0 { square } else { r.scale(square, s) };
    r.sum(&[signed], &[1.0])
}

/// The fold of asin or acos (`f`, named `name`) at `x` within `error`:
/// refused outside [−1, 1]; at ±1 to within rounding the slope is
/// unbounded, and the error is that of the square root it behaves as.
fn arc_fold(name: &str, f: fn(f64) -> f64, x: f64, error: f64) -> Result<Fold, String> {
    const EPS: f64 = f64::EPSILON / 2.0;
    if x.abs() > 1.0 + error {
        return Err(format!(
            "{name} of {x:.3e}, outside [-1, 1], which is not real"
        ));
    }
    if x.abs() + error >= 1.0 {
        let value = f(x.clamp(-1.0, 1.0));
        return Ok(Fold::Within {
            value,
            error: (2.0 * (error + EPS)).sqrt() * 2.0 + EPS * value.abs(),
        });
    }
    Ok(Fold::Slope {
        value: f(x),
        slope: 1.0 / (1.0 - x * x).sqrt(),
    })
}

/// sinh (`minus`) or cosh of `x` as (eˣ ∓ 1/eˣ)/2.
fn half_exponentials<A: Algebra>(a: &mut A, x: A::E, minus: bool) -> A::E {
    let e = a.call(Function::Exp, x);
    let over = a.pow(e.clone(), -1, 1);
    let both = if minus {
        a.sub(e, over)
    } else {
        a.add(vec![e, over])
    };
    let half = a.number(1, 2);
    a.mul(vec![half, both])
}

/// The series of sinh (`minus`) or cosh of `a`: (eᵃ ∓ 1/eᵃ)/2.
fn exponentials<R: Recurrences>(r: &mut R, a: R::Series, minus: bool) -> R::Series {
    let e = r.exp(a);
    let over = r.recip(e);
    let both = if minus {
        r.difference(e, over)
    } else {
        r.sum(&[e, over], &[])
    };
    r.scale(both, 0.5)
}

/// The fold of sinh or cosh (`value`) at `x` within `error`: |f′| ≤ cosh
/// over the error's reach.
fn hyperbolic_fold(value: f64, x: f64, error: f64) -> Fold {
    let c = dalembert_runtime::libm::cosh(x);
    Fold::Slope {
        value,
        slope: dalembert_runtime::libm::cosh(x.abs() + error).max(c),
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
        fn mul(&mut self, factors: Vec<f64>) -> f64 {
            factors.iter().product()
        }
        fn pow(&mut self, x: f64, num: i64, den: i64) -> f64 {
            x.powf(num as f64 / den as f64)
        }
        fn call(&mut self, f: Function, x: f64) -> f64 {
            f.value(x)
        }
    }

    /// Points inside every function's domain.
    fn points(f: Function) -> [f64; 4] {
        let shift = match f {
            Function::Log | Function::Sqrt => 1.0,
            Function::Acosh => 2.0,
            _ => 0.0,
        };
        [-0.7, -0.2, 0.3, 0.9].map(|x| x + shift)
    }

    /// Every function's rule in the elementary functions gives its value:
    /// the closed forms to rounding, Newton's step from a start off by
    /// 10⁻³ to rounding in six steps; the elementary functions are
    /// themselves.
    #[test]
    fn elementary_rules_give_the_values() {
        for f in Function::ALL {
            for x in points(f) {
                let want = f.value(x);
                let got = match f.elementary(&mut Numbers, x, f64::NAN) {
                    Elementary::Itself => {
                        use Function::*;
                        assert!([Sin, Cos, Exp, Log, Sqrt].contains(&f), "{f:?}");
                        continue;
                    }
                    Elementary::Closed(v) => v,
                    Elementary::Newton(_) => {
                        let mut y = want + 1e-3;
                        for _ in 0..6 {
                            let Elementary::Newton(step) = f.elementary(&mut Numbers, x, y) else {
                                unreachable!()
                            };
                            y -= step;
                        }
                        y
                    }
                };
                assert!(
                    (got - want).abs() <= 1e-14 * want.abs().max(1.0),
                    "{f:?} at {x}: {got} against {want}"
                );
            }
        }
    }

    /// Every function's derivative rule against central differences of
    /// its value.
    #[test]
    fn derivatives_agree_with_differences() {
        let h = 1e-6;
        for f in Function::ALL {
            for x in points(f) {
                let got: f64 = f.derivative(&mut Numbers, x, f.value(x)).iter().product();
                let want = (f.value(x + h) - f.value(x - h)) / (2.0 * h);
                assert!(
                    (got - want).abs() <= 1e-8 * want.abs().max(1.0),
                    "{}′({x}) = {got}, differences say {want}",
                    f.name()
                );
            }
        }
    }

    /// Every function's value lies in its enclosure of a small interval
    /// around it, its fold agrees with its value, and its value at 0 is
    /// the one it declares.
    #[test]
    fn value_interval_fold_and_zero_agree() {
        for f in Function::ALL {
            for x in points(f) {
                let v = f.value(x);
                let i = f.interval()(Interval::new(x - 1e-3, x + 1e-3));
                assert!(
                    i.lo <= v && v <= i.hi,
                    "{}({x}) = {v} not in {i:?}",
                    f.name()
                );
                let folded = match f.fold(x, 1e-12) {
                    Ok(Fold::Slope { value, .. } | Fold::Within { value, .. }) => value,
                    Err(why) => panic!("{}({x}) refused: {why}", f.name()),
                };
                assert_eq!(folded, v, "{}({x})", f.name());
            }
            match f.at_zero() {
                Some(z) => assert_eq!(f.value(0.0), z as f64, "{}(0)", f.name()),
                None => assert!(
                    f.value(0.0).fract() != 0.0 || !f.value(0.0).is_finite(),
                    "{}(0) is whole but not declared",
                    f.name()
                ),
            }
        }
    }
}
