//! The parser's unit tests.

use super::*;

fn ok(s: &str) -> Node {
    parse(s).unwrap_or_else(|e| panic!("{s}: {e:?}"))
}

fn err(s: &str) -> ParseError {
    parse(s).expect_err(s)
}

#[test]
fn precedence_and_exact_numbers() {
    let n = ok("-x^2");
    assert!(matches!(n.kind, NodeKind::Neg(_)));
    let n = ok("2^3^2");
    let NodeKind::Pow(_, e) = n.kind else {
        panic!()
    };
    assert_eq!(e, Rational { num: 9, den: 1 });
    assert_eq!(
        ok("0.25").kind,
        NodeKind::Number(Rational { num: 1, den: 4 })
    );
    assert_eq!(
        ok("1e-3").kind,
        NodeKind::Number(Rational { num: 1, den: 1000 })
    );
    assert_eq!(ok("pi").kind, NodeKind::Constant(Constant::Pi));
    assert!(matches!(ok("2*e").kind, NodeKind::Product(_)));
    assert!(matches!(
        ok("y^(1/2)").kind,
        NodeKind::Pow(_, Rational { num: 1, den: 2 })
    ));
    assert!(matches!(
        ok("x^-1").kind,
        NodeKind::Pow(_, Rational { num: -1, den: 1 })
    ));
}

#[test]
fn malformed_text_is_reported_where_it_is() {
    assert_eq!(err("sin(x, y)").span, 5..6);
    assert_eq!(err("sin()").span, 0..3);
    assert_eq!(err("x + ").span, 4..4);
    assert_eq!(err("(x").span, 0..1);
    assert_eq!(err("x)").span, 1..2);
    assert_eq!(err("2x").span, 1..2);
    assert_eq!(err("x # y").span, 2..3);
    assert!(err("coeff(x)").message.contains("unknown function"));
    assert!(err("sin").message.contains("is a function"));
    assert!(err("").message.contains("empty"));
}

#[test]
fn exponents_are_bounded_constants() {
    assert!(err("y^x").message.contains("constant"));
    assert!(err("y^(-100000)").limit);
    assert!(err("x^65536").limit);
    assert!(err("2^2^2^2^2^2").limit);
    assert!(err("x^(1/1000)").limit);
    assert!(err("0^(0^(-1))").message.contains("negative power"));
    assert!(ok("x^(2^3)").degree(&|_| 1) == 8);
}

#[test]
fn nesting_is_bounded_without_deep_recursion_on_long_flat_input() {
    let deep = format!("{}x{}", "sin(".repeat(2000), ")".repeat(2000));
    assert!(err(&deep).limit);
    let chain = vec!["x"; 3000].join("^");
    assert!(err(&chain).limit);
    let signs = format!("{}x", "-".repeat(5000));
    assert!(err(&signs).limit);
    let flat = vec!["x"; 5000].join("+");
    assert!(matches!(ok(&flat).kind, NodeKind::Sum(ref t) if t.len() == 5000));
}

#[test]
fn numbers_do_not_wrap_around() {
    assert!(
        err("170141183460469231731687303715884105728")
            .message
            .contains("too large")
    );
    assert!(parse(&"9".repeat(400)).is_err());
}

/// Where a varying name stops being polynomial: inside a function, in a
/// divisor, under a fractional or negative power; whole powers, sums,
/// products and other names' functions are polynomial.
#[test]
fn non_polynomial_uses_are_found_where_they_are() {
    let v = |n: &str| n == "v" || n == "w";
    let place = |s: &str| ok(s).non_polynomial(&v);
    for s in [
        "v^2*sin(x) + 3*w*v/m - (v + x)^3",
        "x^(1/2)*v",
        "-v^0",
        "exp(x)/y",
    ] {
        assert_eq!(place(s), None, "{s}");
    }
    for (s, span, name, where_) in [
        ("m/2*(x + v^(41/2))", 9..17, "v", "raised to the power 41/2"),
        ("x*sin(2*w)", 2..10, "w", "inside sin(…)"),
        ("x/(1 + v)", 2..9, "v", "in a divisor"),
        ("(v*x)^-2", 0..8, "v", "raised to the power -2"),
    ] {
        assert_eq!(place(s), Some((span, name.into(), where_.into())), "{s}");
    }
    assert!(ok("x + sqrt(v)").depends(&v) && !ok("x + sqrt(y)").depends(&v));
}

/// exp(k·x) counts as the k-th power of one variable (the symbolic
/// engine's exact arithmetic takes it so, and with k in the hundred
/// thousands its exponents overflowed); other functions as one variable.
#[test]
fn exp_of_a_multiple_counts_as_a_power() {
    let one = |_: &str| 1;
    assert_eq!(ok("exp(x)").degree(&one), 1);
    assert_eq!(ok("exp(-300*x)").degree(&one), 300);
    assert_eq!(ok("exp(x/0.00001)").degree(&one), 100_000);
    assert_eq!(ok("exp(2*x*y)^3").degree(&one), 12);
    assert_eq!(ok("sin(300*x)").degree(&one), 1);
}
