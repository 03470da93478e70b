//! The parts of an expression that name nothing (numbers, π, e and
//! functions of them): each must be a finite real number, and where one
//! divides, is raised to a negative power or is a logarithm's or a root's
//! argument it must be clearly away from where that is undefined.
//!
//! Each is evaluated in f64 with a bound on its rounding error carried
//! along (first order, each operation's own rounding added), so "zero"
//! means "zero to within that bound": sin(π) evaluates to 1.2e-16 with a
//! bound of a few 1e-16, and as a divisor it is refused, where emitted code
//! would divide by 1.2e-16.

use std::ops::Range;

use super::{Node, NodeKind};
use crate::function::Fold;

/// A value and a bound on its absolute rounding error.
#[derive(Clone, Copy, Debug)]
struct Approx {
    value: f64,
    error: f64,
}

/// Why a constant part is refused: where (relative to the expression's
/// text) and what it is, in words.
pub type ConstantProblem = (Range<usize>, String);

/// The unit roundoff.
const EPS: f64 = f64::EPSILON / 2.0;

impl Node {
    /// The first constant part of the tree (one that names nothing) that
    /// is undefined, infinite, a zero divisor, a zero raised to a negative
    /// power or to the power 0, a root or logarithm of a number not clearly
    /// above zero, or a tangent at its pole; `None` where every constant
    /// part is a finite number.
    pub fn constant_problem(&self) -> Option<ConstantProblem> {
        self.approx().err()
    }

    /// The value of a tree that names nothing, or the first problem met;
    /// `Ok(None)` where it names something (then its constant parts are
    /// checked one by one).
    fn approx(&self) -> Result<Option<Approx>, ConstantProblem> {
        let problem = |what: String| Err((self.span.clone(), what));
        let exact = |value: f64| Approx {
            value,
            error: EPS * value.abs(),
        };
        let out = match &self.kind {
            NodeKind::Name(_) => return Ok(None),
            NodeKind::Number(r) => exact(r.to_f64()),
            NodeKind::Constant(c) => exact(c.value()),
            NodeKind::Neg(x) => match x.approx()? {
                Some(a) => Approx {
                    value: -a.value,
                    error: a.error,
                },
                None => return Ok(None),
            },
            NodeKind::Sum(items) => {
                let mut parts = Vec::with_capacity(items.len());
                for (negative, x) in items {
                    parts.push(x.approx()?.map(|a| (negative, a)));
                }
                let Some(parts) = parts.into_iter().collect::<Option<Vec<_>>>() else {
                    return Ok(None);
                };
                let value: f64 = parts
                    .iter()
                    .map(|(n, a)| if **n { -a.value } else { a.value })
                    .sum();
                let magnitude: f64 = parts.iter().map(|(_, a)| a.value.abs()).sum();
                let error: f64 = parts.iter().map(|(_, a)| a.error).sum();
                Approx {
                    value,
                    error: error + parts.len() as f64 * EPS * magnitude,
                }
            }
            NodeKind::Product(items) => {
                let mut parts = Vec::with_capacity(items.len());
                for (divide, x) in items {
                    let a = x.approx()?;
                    if let Some(a) = a
                        && *divide
                        && a.value.abs() <= a.error
                    {
                        return Err((
                            x.span.clone(),
                            format!("a divisor equal to 0 (to within rounding: {:.3e})", a.value),
                        ));
                    }
                    parts.push(a.map(|a| (*divide, a)));
                }
                let Some(parts) = parts.into_iter().collect::<Option<Vec<_>>>() else {
                    return Ok(None);
                };
                let power = |(divide, a): &(bool, Approx)| {
                    if *divide { 1.0 / a.value } else { a.value }
                };
                let value: f64 = parts.iter().map(power).product();
                // ∂/∂xᵢ of Π xⱼ^±1 is ± (the others' product) / xᵢ^(0 or 2).
                let mut error = parts.len() as f64 * EPS * value.abs();
                for (i, (divide, a)) in parts.iter().enumerate() {
                    let others: f64 = parts
                        .iter()
                        .enumerate()
                        .filter(|(j, _)| *j != i)
                        .map(|(_, p)| power(p))
                        .product();
                    let slope = if *divide {
                        others / (a.value * a.value)
                    } else {
                        others
                    };
                    error += slope.abs() * a.error;
                }
                Approx { value, error }
            }
            NodeKind::Pow(x, n) => {
                let Some(a) = x.approx()? else {
                    return Ok(None);
                };
                let zero = a.value.abs() <= a.error;
                if zero && n.num <= 0 {
                    return problem(if n.num == 0 {
                        "0 to the power 0, which is undefined".into()
                    } else {
                        format!(
                            "0 (to within rounding: {:.3e}) to the negative power {n}",
                            a.value
                        )
                    });
                }
                let p = n.to_f64();
                if n.den != 1 && a.value < -a.error {
                    return problem(format!(
                        "a negative number ({:.3e}) to the fractional power {n}, which is not real or, for an odd root, evaluated as NaN by pow (write −(|x|^{n}))",
                        a.value
                    ));
                }
                if n.den != 1 && zero {
                    // A root of what may be 0 or a rounding below it: 0.
                    Approx {
                        value: 0.0,
                        error: a.error.powf(p),
                    }
                } else {
                    let value = if n.den == 1 {
                        a.value
                            .powi(n.num.clamp(i32::MIN as i128, i32::MAX as i128) as i32)
                    } else {
                        a.value.powf(p)
                    };
                    // |d(xᵖ)/dx| over the error's reach (where p ≥ 1 the
                    // slope grows with |x|; below 1 x is away from 0 here).
                    let slope = if p >= 1.0 {
                        p * (a.value.abs() + a.error).powf(p - 1.0)
                    } else {
                        (p * a.value.abs().powf(p - 1.0)).abs()
                    };
                    Approx {
                        value,
                        error: slope * a.error + EPS * value.abs(),
                    }
                }
            }
            NodeKind::Call(f, x) => {
                let Some(a) = x.approx()? else {
                    return Ok(None);
                };
                match f.fold(a.value, a.error) {
                    Err(why) => return problem(why),
                    Ok(Fold::Within { value, error }) => Approx { value, error },
                    Ok(Fold::Slope { value, slope }) => Approx {
                        value,
                        error: slope.abs() * a.error + EPS * value.abs(),
                    },
                }
            }
        };
        if !out.value.is_finite() || !out.error.is_finite() {
            return problem(format!(
                "{} in f64 (a constant part must be a finite number)",
                if out.value.is_nan() {
                    "not a number".to_string()
                } else {
                    format!("{:.3e}", out.value)
                }
            ));
        }
        Ok(Some(out))
    }
}

#[cfg(test)]
mod tests {
    use super::super::parse;

    fn problem(text: &str) -> Option<String> {
        parse(text)
            .unwrap()
            .constant_problem()
            .map(|(span, what)| format!("{}: {what}", &text[span]))
    }

    /// The cases, each refused at its constant part; their
    /// neighbours that are fine pass.
    #[test]
    fn undefined_constants_are_found() {
        for (text, part) in [
            ("sqrt(1 - pi)*y", "sqrt(1 - pi)"),
            ("log(2 - e)*y", "log(2 - e)"),
            ("y/sin(pi)", "sin(pi)"),
            ("tan(pi/2)*y", "tan(pi/2)"),
            ("exp(1000)*y", "exp(1000)"),
            ("0^0*x", "0^0"),
            ("y*(1 - 1)^(-2)", "(1 - 1)^(-2)"),
            ("x + log(0)", "log(0)"),
            ("(cos(pi/2))^(-1)*x", "(cos(pi/2))^(-1)"),
            ("x/(sqrt(2)^2 - 2)", "(sqrt(2)^2 - 2)"),
            ("(1 - pi)^(1/2)*x", "(1 - pi)^(1/2)"),
            ("(-8)^(1/3)*x", "(-8)^(1/3)"),
            ("asin(2)*y", "asin(2)"),
            ("acos(-1 - pi/100)*y", "acos(-1 - pi/100)"),
            ("sinh(1000)*y", "sinh(1000)"),
            ("y/cosh(800)", "cosh(800)"),
            ("y/tanh(0)", "tanh(0)"),
            ("y/atan(sin(pi))", "atan(sin(pi))"),
        ] {
            let found = problem(text).unwrap_or_else(|| panic!("{text} passed"));
            assert!(found.starts_with(&format!("{part}:")), "{text}: {found}");
        }
        for text in [
            "sqrt(pi - 1)*y",
            "log(e)*y",
            "y/sin(pi/2)",
            "tan(pi/4)*y",
            "exp(700)*y",
            "sin(pi)*y",
            "x^0",
            "0^2*x",
            "sqrt(1 - sin(pi/2))*x",
            "y/(sqrt(2) - 1)",
            "-(8^(1/3))*x",
            "1/x",
            "log(x)",
            "sqrt(-x)",
            "x/(1 - 1/3)",
            "asin(1)*y",
            "acos(-1)*y",
            "y/acos(0)",
            "asin(sin(pi/2))*y",
            "sinh(700)*y",
            "y/cosh(0)",
            "y/tanh(1)",
            "y/atan(1)",
        ] {
            assert_eq!(problem(text), None, "{text}");
        }
    }
}
