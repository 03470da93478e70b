//! Terms that vanish only by sin² + cos² = 1 or cosh² − sinh² = 1, of
//! plain and compound arguments, or by multiple-angle formulas: the exact
//! algebra sees them as zero. A
//! constraint ẋ = 0 written with such a term once divided by it (a
//! symbolica error unwrapped: the derivation panicked), and with a compound
//! argument the identity was not known at all. Uses the symbolic engine:
//! run one test at a time (`RUST_TEST_THREADS=1`).

use dalembert_codegen::Derivation;
use dalembert_codegen::derive::Projection;

/// A point in space under gravity above a floor, with the constraint
/// rows `rows` (which P and q̈ depend on).
fn model(rows: &[&str]) -> String {
    let rows: Vec<String> = rows.iter().map(|r| format!("\"{r}\"")).collect();
    format!(
        r#"
[model]
name = "identities"
[parameters]
m = "1"
[coordinates]
names = ["x", "y", "z"]
[dynamics]
kinetic_energy = "m/2*(x_dot^2 + y_dot^2 + z_dot^2) + m/2*(cos(x + y)^2 + sin(x + y)^2)*y_dot^2"
potential = "m*y"
constraints = [{}]
[[wall]]
name = "floor"
surface = "y + 1"
[initial]
y_dot = "-1"
"#,
        rows.join(", ")
    )
}

/// The derivation of the model file `text`, or its errors.
fn attempt(text: &str) -> Result<Derivation, String> {
    let dir = std::env::temp_dir().join(format!("dalembert-identities-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("identities.toml");
    std::fs::write(&path, text).unwrap();
    let d = dalembert_codegen::derive(&path);
    std::fs::remove_dir_all(&dir).unwrap();
    d.map_err(|e| e.to_string())
}

fn derive(text: &str) -> Derivation {
    attempt(text).unwrap_or_else(|e| panic!("{e}"))
}

/// P and the collision law, as derived.
fn projection(d: &Derivation) -> (Vec<Vec<String>>, Vec<String>) {
    match &d.walls[0].projection {
        Projection::ClosedForm {
            projector,
            collision,
        } => (projector.clone(), collision.clone()),
        Projection::Structured => panic!("P is solved at run time"),
    }
}

#[test]
fn terms_zero_by_the_identities_are_zero() {
    let plain = derive(&model(&["x_dot"]));
    let (p, law) = projection(&plain);
    assert_eq!(law, ["-x_dot", "-y_dot", "z_dot"]);
    for zero in [
        "(cos(x)^2 + sin(x)^2 - 1)",
        "(cos(2*x)^2 + sin(2*x)^2 - 1)",
        "(cosh(x - y)^2 - sinh(x - y)^2 - 1)",
        "(cosh(x)^4 - sinh(x)^4 - cosh(x)^2 - sinh(x)^2)",
    ] {
        let d = derive(&model(&[&format!("x_dot + y_dot*{zero}")]));
        assert_eq!(projection(&d), (p.clone(), law.clone()), "{zero}");
        assert_eq!(d.mass_matrix, plain.mass_matrix, "{zero}");
        assert_eq!(d.accelerations, plain.accelerations, "{zero}");
    }
}

/// Whether `rows` are refused for their second row alone, as a combination
/// of the first, at its place in the file (line 11, the constraints).
fn second_row_refused(rows: &[&str]) -> bool {
    let e = attempt(&model(rows)).expect_err("derived");
    let errors: Vec<&str> = e.lines().filter(|l| l.contains("error:")).collect();
    errors.len() == 1
        && errors[0].contains(":11:")
        && errors[0].contains("this constraint is a combination of the ones before it")
}

/// Two constraint rows equal by the identities (cos z times the first is
/// the second, cos³ z + cos z sin² z = cos z): the second is refused as a
/// combination of the first, at its place. Taken as independent, they made
/// ker A the z direction alone, and the wall was refused as one the
/// constraints forbid motion across; seen as dependent but kept, they
/// made the start's projection onto A q̇ = 0 singular at run time.
#[test]
fn rows_equal_by_the_identities_are_dependent() {
    let first = "cos(z)*x_dot + sin(z)*y_dot";
    derive(&model(&[first]));
    assert!(second_row_refused(&[
        first,
        "(cos(z)^3 + cos(z)*sin(z)^2)*x_dot + sin(z)*y_dot",
    ]));
    assert!(second_row_refused(&[
        first,
        "2*cos(z)*x_dot + 2*sin(z)*y_dot"
    ]));
    // Independent rows are not.
    derive(&model(&[first, "z_dot"]));
}

/// A second row twice the first by the double-angle formula (sin 2z / cos z
/// against 2 sin z): dependent, and refused as such. Before multiple
/// angles were written in the base angle, the rows were independent and
/// the wall was refused as one the constraints forbid motion across.
#[test]
fn rows_equal_by_a_double_angle_are_dependent() {
    let first = "cos(z)*x_dot + sin(z)*y_dot";
    assert!(second_row_refused(&[
        first,
        "2*cos(z)*x_dot + sin(2*z)/cos(z)*y_dot"
    ]));
}

/// A multiple of the first row by a factor whose terms cancel (the case
/// the property test below once drew): the row is zero and is refused as
/// having no velocity, at its place.
#[test]
fn a_row_whose_factor_cancels_is_refused_for_having_no_velocity() {
    let first = "cos(z)*x_dot + sin(z)*y_dot";
    let p = "(-2)*sin(z)*cos(z)^2 + (2)*sin(z)*cos(z)^2";
    let zero = format!("({p})*cos(z)*x_dot + ({p})*sin(z)*y_dot");
    let e = attempt(&model(&[first, &zero])).expect_err("derived");
    assert!(e.contains(":11:"), "{e}");
    assert!(e.contains("does not involve any velocity"), "{e}");
}

mod property {
    use dalembert_codegen::derive::inspect::same;
    use proptest::prelude::*;

    const ARGUMENTS: [&str; 4] = ["x", "2*x", "x + y", "x - 3*y"];

    /// A sum of up to four terms k·f(u)ⁱ·g(u)ʲ·yᵐ, f and g the pair.
    fn polynomial(pair: (&'static str, &'static str)) -> impl Strategy<Value = String> {
        let term = (
            -3i32..=3,
            0u32..4,
            0u32..4,
            0u32..3,
            0usize..ARGUMENTS.len(),
        )
            .prop_map(move |(k, i, j, m, u)| {
                let u = ARGUMENTS[u];
                format!("({k})*{}({u})^{i}*{}({u})^{j}*y^{m}", pair.0, pair.1)
            });
        proptest::collection::vec(term, 1..=4).prop_map(|t| t.join(" + "))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// q + p·(sin² u + cos² u − 1) is q, and so with cosh² u − sinh² u − 1,
        /// sin 2u − 2 sin u cos u and cosh 3u − 4 cosh³ u + 3 cosh u;
        /// q + 1 is not q.
        #[test]
        fn multiples_of_the_identities_vanish(
            q in polynomial(("sin", "cos")),
            p in polynomial(("sinh", "cosh")),
            r in polynomial(("sin", "cosh")),
            u in 0usize..ARGUMENTS.len(),
        ) {
            let u = ARGUMENTS[u];
            let trig = format!("{q} + ({r})*(sin({u})^2 + cos({u})^2 - 1)");
            let hyperbolic = format!("{q} + ({p})*(cosh({u})^2 - sinh({u})^2 - 1)");
            prop_assert_eq!(same(&trig, &q), Ok(true), "{}", trig);
            prop_assert_eq!(same(&hyperbolic, &q), Ok(true), "{}", hyperbolic);
            prop_assert_eq!(same(&format!("{q} + 1"), &q), Ok(false));
            // Multiple angles, in the base angle.
            let double = format!("{q} + ({r})*(sin(2*({u})) - 2*sin({u})*cos({u}))");
            let triple = format!("{q} + ({p})*(cosh(3*({u})) - 4*cosh({u})^3 + 3*cosh({u}))");
            prop_assert_eq!(same(&double, &q), Ok(true), "{}", double);
            prop_assert_eq!(same(&triple, &q), Ok(true), "{}", triple);
        }
    }

    /// A sum of one to three terms k·sin(z)ⁱ·cos(z)ʲ, j ≥ 1 (k ≠ 0). The
    /// terms may cancel: the sum can be zero.
    fn in_z() -> impl Strategy<Value = String> {
        let k = prop_oneof![-3i32..=-1, 1i32..=3];
        let term =
            (k, 0u32..3, 1u32..4).prop_map(|(k, i, j)| format!("({k})*sin(z)^{i}*cos(z)^{j}"));
        proptest::collection::vec(term, 1..=3).prop_map(|t| t.join(" + "))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(16))]

        /// A second constraint row p(z) times the first, each entry
        /// reduced by sin² + cos² = 1 before the rank is taken (so that
        /// the rows are proportional only through the identity), is
        /// refused as a combination of the first; with ż added it is
        /// independent and not refused as dependent. (It may still be
        /// refused by a later solve whose plain pivots vanish by the
        /// identities, with an error that says so: p = −2 cos³ z is, in the
        /// collision map on admissible velocities.) Where p is zero the
        /// second row has no velocity left and is refused for that.
        #[test]
        fn multiples_of_a_row_through_the_identities_are_dependent(p in in_z()) {
            let first = "cos(z)*x_dot + sin(z)*y_dot";
            let multiple = format!("({p})*cos(z)*x_dot + ({p})*sin(z)*y_dot");
            if same(&p, "0") == Ok(true) {
                let refused = super::attempt(&super::model(&[first, &multiple]))
                    .err()
                    .unwrap_or_default();
                prop_assert!(refused.contains("does not involve any velocity"), "{}", refused);
            } else {
                prop_assert!(super::second_row_refused(&[first, &multiple]), "{}", multiple);
            }
            let independent = format!("{multiple} + z_dot");
            let refused = super::attempt(&super::model(&[first, &independent]))
                .err()
                .unwrap_or_default();
            prop_assert!(!refused.contains("combination"), "{}", refused);
        }
    }
}
