//! A small exact algebra over the model language, for what the bodies
//! derive: sums, products, powers and calls built with numbers folded and
//! zeros and ones dropped, the derivative by a name, and the text the model
//! language reads back. No simplification beyond that: symbolica, later,
//! takes the derived text like any hand-written expression.

use std::fmt;

use super::super::Rational;
use super::super::expr::{Constant, Function, Node, NodeKind};
use super::super::number::{checked_add, checked_mul, checked_pow};
use crate::function::Algebra;
use std::collections::HashMap;

/// An expression under construction.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Sym {
    /// An exact number.
    Num(Rational),
    /// A name of the model.
    Name(String),
    /// π or e.
    Const(Constant),
    /// At least two terms, none a number 0 or a sum.
    Sum(Vec<Sym>),
    /// At least two factors, none a product; a number only first.
    Product(Vec<Sym>),
    /// A power with a constant exponent other than 0 and 1.
    Pow(Box<Sym>, Rational),
    /// A function call.
    Call(Function, Box<Sym>),
}

const ZERO: Rational = Rational { num: 0, den: 1 };
const ONE: Rational = Rational { num: 1, den: 1 };

/// The integer `n`.
pub(super) fn int(n: i128) -> Sym {
    Sym::Num(Rational { num: n, den: 1 })
}

/// A name.
pub(super) fn name(n: &str) -> Sym {
    Sym::Name(n.to_string())
}

/// The sum of `terms`.
pub(super) fn add(terms: impl IntoIterator<Item = Sym>) -> Sym {
    let mut number = ZERO;
    let mut out = Vec::new();
    let push = |t: Sym, out: &mut Vec<Sym>, number: &mut Rational| match t {
        Sym::Num(r) => match checked_add(*number, r) {
            Some(s) => *number = s,
            None => out.push(Sym::Num(r)),
        },
        t => out.push(t),
    };
    for t in terms {
        match t {
            Sym::Sum(inner) => {
                for t in inner {
                    push(t, &mut out, &mut number);
                }
            }
            t => push(t, &mut out, &mut number),
        }
    }
    if number != ZERO {
        out.push(Sym::Num(number));
    }
    match out.len() {
        0 => Sym::Num(ZERO),
        1 => out.pop().unwrap_or(Sym::Num(ZERO)),
        _ => Sym::Sum(out),
    }
}

/// The product of `factors`.
pub(super) fn mul(factors: impl IntoIterator<Item = Sym>) -> Sym {
    let mut number = ONE;
    let mut out = Vec::new();
    let push = |f: Sym, out: &mut Vec<Sym>, number: &mut Rational| match f {
        Sym::Num(r) => match checked_mul(*number, r) {
            Some(p) => *number = p,
            None => out.push(Sym::Num(r)),
        },
        f => out.push(f),
    };
    for f in factors {
        match f {
            Sym::Product(inner) => {
                for f in inner {
                    push(f, &mut out, &mut number);
                }
            }
            f => push(f, &mut out, &mut number),
        }
    }
    if number == ZERO {
        return Sym::Num(ZERO);
    }
    if number != ONE {
        out.insert(0, Sym::Num(number));
    }
    match out.len() {
        0 => Sym::Num(ONE),
        1 => out.pop().unwrap_or(Sym::Num(ONE)),
        _ => Sym::Product(out),
    }
}

/// −a.
pub(super) fn neg(a: Sym) -> Sym {
    mul([int(-1), a])
}

/// a − b.
pub(super) fn sub(a: Sym, b: Sym) -> Sym {
    add([a, neg(b)])
}

/// a / b.
pub(super) fn div(a: Sym, b: Sym) -> Sym {
    mul([a, pow(b, Rational { num: -1, den: 1 })])
}

/// aⁿ.
pub(super) fn pow(a: Sym, n: Rational) -> Sym {
    if n == ZERO {
        return Sym::Num(ONE);
    }
    if n == ONE {
        return a;
    }
    match a {
        Sym::Num(r) if r == ONE => Sym::Num(ONE),
        Sym::Num(r) if r == ZERO && n.num > 0 => Sym::Num(ZERO),
        Sym::Num(r) if n.den == 1 && r != ZERO => {
            let folded = if n.num > 0 {
                checked_pow(r, n.num)
            } else {
                checked_pow(
                    Rational {
                        num: r.den * r.num.signum(),
                        den: r.num.abs(),
                    },
                    -n.num,
                )
            };
            match folded {
                Some(v) => Sym::Num(v),
                None => Sym::Pow(Box::new(Sym::Num(r)), n),
            }
        }
        // (xˢ)ⁿ = xˢⁿ for an integer n.
        Sym::Pow(x, s) if n.den == 1 => match checked_mul(s, n) {
            Some(p) => pow(*x, p),
            None => Sym::Pow(Box::new(Sym::Pow(x, s)), n),
        },
        a => Sym::Pow(Box::new(a), n),
    }
}

/// a².
pub(super) fn square(a: Sym) -> Sym {
    pow(a, Rational { num: 2, den: 1 })
}

/// f(a), folded where a = 0 and f(0) is a whole number.
pub(super) fn call(f: Function, a: Sym) -> Sym {
    match (f.at_zero(), &a) {
        (Some(value), Sym::Num(r)) if *r == ZERO => Sym::Num(Rational {
            num: i128::from(value),
            den: 1,
        }),
        _ => Sym::Call(f, Box::new(a)),
    }
}

/// The trees as the derivative rules' algebra.
struct Trees;

impl Algebra for Trees {
    type E = Sym;
    fn number(&mut self, num: i64, den: i64) -> Sym {
        let (num, den) = (i128::from(num), i128::from(den));
        Sym::Num(Rational { num, den })
    }
    fn add(&mut self, terms: Vec<Sym>) -> Sym {
        add(terms)
    }
    fn sub(&mut self, a: Sym, b: Sym) -> Sym {
        sub(a, b)
    }
    fn mul(&mut self, factors: Vec<Sym>) -> Sym {
        mul(factors)
    }
    fn pow(&mut self, x: Sym, num: i64, den: i64) -> Sym {
        let (num, den) = (i128::from(num), i128::from(den));
        pow(x, Rational { num, den })
    }
    fn call(&mut self, f: Function, x: Sym) -> Sym {
        call(f, x)
    }
}

impl Sym {
    /// Whether it is the number 0.
    pub(super) fn is_zero(&self) -> bool {
        matches!(self, Sym::Num(r) if *r == ZERO)
    }

    /// Whether some name in it satisfies `varies`.
    pub(super) fn depends(&self, varies: &dyn Fn(&str) -> bool) -> bool {
        match self {
            Sym::Num(_) | Sym::Const(_) => false,
            Sym::Name(n) => varies(n),
            Sym::Sum(items) | Sym::Product(items) => items.iter().any(|x| x.depends(varies)),
            Sym::Pow(x, _) | Sym::Call(_, x) => x.depends(varies),
        }
    }

    /// ∂/∂`by`, every other name constant.
    pub(super) fn derivative(&self, by: &str) -> Sym {
        match self {
            Sym::Num(_) | Sym::Const(_) => int(0),
            Sym::Name(n) => int(i128::from(n == by)),
            Sym::Sum(items) => add(items.iter().map(|t| t.derivative(by))),
            Sym::Product(items) => add((0..items.len()).map(|i| {
                let d = items[i].derivative(by);
                if d.is_zero() {
                    return d;
                }
                mul(items
                    .iter()
                    .enumerate()
                    .map(|(j, f)| if i == j { d.clone() } else { f.clone() }))
            })),
            Sym::Pow(x, n) => {
                let d = x.derivative(by);
                if d.is_zero() {
                    return d;
                }
                let less = Rational {
                    num: n.num - n.den,
                    den: n.den,
                };
                mul([Sym::Num(*n), pow((**x).clone(), less), d])
            }
            Sym::Call(f, x) => {
                let d = x.derivative(by);
                if d.is_zero() {
                    return d;
                }
                let x = (**x).clone();
                let y = call(*f, x.clone());
                let mut factors = f.derivative(&mut Trees, x, y);
                factors.push(d);
                mul(factors)
            }
        }
    }

    /// Its value, each name's from `lookup`.
    pub(super) fn value(&self, lookup: &dyn Fn(&str) -> Option<f64>) -> Option<f64> {
        // The text round trip keeps one evaluation rule: the parser's tree's.
        let node = super::super::expr::parse(&self.to_string()).ok()?;
        node.value(lookup)
    }

    /// The expression of a parsed `node`, each name in `definitions`
    /// replaced by its expression.
    pub(super) fn from_node(node: &Node, definitions: &HashMap<String, Sym>) -> Sym {
        let inner = |x: &Node| Sym::from_node(x, definitions);
        match &node.kind {
            NodeKind::Number(r) => Sym::Num(*r),
            NodeKind::Name(n) => definitions.get(n).cloned().unwrap_or_else(|| name(n)),
            NodeKind::Constant(c) => Sym::Const(*c),
            NodeKind::Sum(items) => add(items
                .iter()
                .map(|(minus, x)| if *minus { neg(inner(x)) } else { inner(x) })),
            NodeKind::Product(items) => mul(items.iter().map(|(divide, x)| {
                if *divide {
                    pow(inner(x), Rational { num: -1, den: 1 })
                } else {
                    inner(x)
                }
            })),
            NodeKind::Neg(x) => neg(inner(x)),
            NodeKind::Pow(x, n) => pow(inner(x), *n),
            NodeKind::Call(f, x) => call(*f, inner(x)),
        }
    }

    /// Whether its text starts with a minus sign (a negative number, or a
    /// product with one first).
    fn negative(&self) -> bool {
        match self {
            Sym::Num(r) => r.num < 0,
            Sym::Product(items) => matches!(items.first(), Some(Sym::Num(r)) if r.num < 0),
            _ => false,
        }
    }

    /// How tightly its text binds: 1 a sum (or a leading minus), 2 a
    /// product or quotient, 3 a power, 4 an atom.
    fn binding(&self) -> u8 {
        match self {
            _ if self.negative() => 1,
            Sym::Sum(_) => 1,
            Sym::Num(r) if r.den != 1 => 2,
            Sym::Product(_) => 2,
            Sym::Pow(_, n) if n.num < 0 => 2,
            Sym::Pow(..) => 3,
            _ => 4,
        }
    }
}

/// `x` in parentheses when it binds less tightly than `at`.
struct Tight<'a>(&'a Sym, u8);

impl fmt::Display for Tight<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.binding() < self.1 {
            write!(f, "({})", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

impl fmt::Display for Sym {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Sym::Num(r) => write!(f, "{r}"),
            Sym::Name(n) => write!(f, "{n}"),
            Sym::Const(Constant::Pi) => write!(f, "pi"),
            Sym::Const(Constant::E) => write!(f, "e"),
            Sym::Sum(items) => {
                for (i, t) in items.iter().enumerate() {
                    if i == 0 {
                        write!(f, "{t}")?;
                    } else if t.negative() {
                        write!(f, " - {}", Tight(&neg(t.clone()), 2))?;
                    } else {
                        write!(f, " + {}", Tight(t, 2))?;
                    }
                }
                Ok(())
            }
            Sym::Pow(b, n) if n.num > 0 => {
                if n.den == 1 {
                    write!(f, "{}^{}", Tight(b, 4), n.num)
                } else {
                    write!(f, "{}^({}/{})", Tight(b, 4), n.num, n.den)
                }
            }
            Sym::Product(_) | Sym::Pow(..) => {
                let items = match self {
                    Sym::Product(items) => items.clone(),
                    other => vec![other.clone()],
                };
                let mut coefficient = ONE;
                let mut above = Vec::new();
                let mut below = Vec::new();
                for x in items {
                    match x {
                        Sym::Num(r) => coefficient = r,
                        Sym::Pow(b, n) if n.num < 0 => below.push(pow(
                            *b,
                            Rational {
                                num: -n.num,
                                den: n.den,
                            },
                        )),
                        x => above.push(x),
                    }
                }
                let mut text = String::new();
                if coefficient.num < 0 {
                    text.push('-');
                }
                let magnitude = coefficient.num.abs();
                if magnitude != 1 || above.is_empty() {
                    text.push_str(&magnitude.to_string());
                    if !above.is_empty() {
                        text.push('*');
                    }
                }
                let factors: Vec<String> = above.iter().map(|x| Tight(x, 3).to_string()).collect();
                text.push_str(&factors.join("*"));
                for x in &below {
                    text.push('/');
                    text.push_str(&Tight(x, 3).to_string());
                }
                if coefficient.den != 1 {
                    text.push_str(&format!("/{}", coefficient.den));
                }
                write!(f, "{text}")
            }
            Sym::Call(func, x) => write!(f, "{}({x})", func.name()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Sym {
        Sym::from_node(&crate::ir::expr::parse(text).unwrap(), &HashMap::new())
    }

    #[test]
    fn folds_numbers_and_drops_zeros_and_ones() {
        assert_eq!(add([int(0), name("x"), int(0)]), name("x"));
        assert_eq!(mul([int(1), name("x")]), name("x"));
        assert!(mul([int(0), name("x")]).is_zero());
        assert_eq!(add([int(2), int(3)]), int(5));
        assert_eq!(read("2*x*3").to_string(), "6*x");
    }

    #[test]
    fn prints_what_reads_back() {
        for text in [
            "x - r*y",
            "m/2*(x_dot^2 + y_dot^2)",
            "-sin(phi)*x_dot + cos(phi)*y_dot",
            "(a + b)^(1/2)/(c*d)",
            "x^(-2)",
            "-(a - b)*c",
            "2*(e0*e1 - e3)",
            "1/2 - x/3",
        ] {
            let once = read(text);
            let again = read(&once.to_string());
            assert_eq!(once, again, "{text} printed as {once}");
        }
        assert_eq!(read("x - r*y").to_string(), "x - r*y");
        assert_eq!(read("m/2*x").to_string(), "m*x/2");
        assert_eq!(read("a^-1").to_string(), "1/a");
    }

    #[test]
    fn derivatives_agree_with_differences() {
        let e = read(
            "x^3*sin(x*y) + exp(x)/(1 + x^2) - log(x)*sqrt(x) + tan(2*x)*cos(y) \
             + atan(x*y) + asin(x/2)*acos(x*y/3) + sinh(x)*cosh(x*y) - tanh(3*x)",
        );
        let d = e.derivative("x");
        let at = |x: f64| {
            e.value(&|n| if n == "x" { Some(x) } else { Some(0.7) })
                .unwrap()
        };
        let h = 1e-5;
        let fd = (at(0.9 + h) - at(0.9 - h)) / (2.0 * h);
        let exact = d
            .value(&|n| if n == "x" { Some(0.9) } else { Some(0.7) })
            .unwrap();
        assert!(
            (fd - exact).abs() < 1e-8 * exact.abs().max(1.0),
            "{fd} vs {exact}"
        );
        assert!(e.derivative("z").is_zero());
    }
}
