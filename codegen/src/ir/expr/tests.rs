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
