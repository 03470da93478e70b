//! The n-link chain family (models/chain_N.toml): the generator evaluates P
//! in closed form for n ≤ 3 and structured (G and B generated, P v solved at
//! run time) above. Both evaluations of the same model must agree, and the
//! choice must be the documented one.

use dalembert::models::{Chain4, Chain4Symbolic};
use dalembert::models::{chain_4, chain_4_symbolic};
use dalembert::runtime::prelude::*;

mod common;
use common::lcg;

/// chain_4 structured vs chain_4_symbolic (the same model with its closed-form
/// P): P and the collision map agree at random configurations, velocities
/// and parameters.
#[test]
fn structured_and_symbolic_evaluation_agree() {
    let mut s = 11;
    for _ in 0..500 {
        let mut a = Chain4::default();
        let mut b = Chain4Symbolic::default();
        for i in 0..Chain4::PARAMETERS.len() {
            let x = 0.5 + lcg(&mut s);
            assert!(a.set_parameter(i, x) && b.set_parameter(i, x));
        }
        let q: [f64; 4] = std::array::from_fn(|_| -3.0 + 6.0 * lcg(&mut s));
        let v: [f64; 4] = std::array::from_fn(|_| -2.0 + 4.0 * lcg(&mut s));
        let pa = a.projector(chain_4::Wall::Floor, &q);
        let pb = b.projector(chain_4_symbolic::Wall::Floor, &q);
        let scale = pb.iter().flatten().fold(1.0f64, |m, x| m.max(x.abs()));
        for i in 0..4 {
            for j in 0..4 {
                assert!(
                    (pa[i][j] - pb[i][j]).abs() < 1e-11 * scale,
                    "P[{i}][{j}] at q = {q:?}: {} vs {}",
                    pa[i][j],
                    pb[i][j]
                );
            }
        }
        let va = a.collide(chain_4::Wall::Floor, &q, &v);
        let vb = b.collide(chain_4_symbolic::Wall::Floor, &q, &v);
        let vs = v.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for i in 0..4 {
            assert!((va[i] - vb[i]).abs() < 1e-11 * vs * scale);
        }
    }
}

/// The generated files (their golden copies, which `tests/golden.rs` keeps
/// equal to the generator's output) say how P is evaluated: closed forms
/// for n ≤ 3, structured for n ≥ 4 unless the model asks for symbolic.
#[test]
fn the_generator_chooses_as_documented() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots");
    let read = |name: &str| {
        std::fs::read_to_string(dir.join(format!("golden__generated_{name}.snap"))).unwrap()
    };
    for n in 1..=8 {
        let text = read(&format!("chain_{n}"));
        let structured = text.contains("structured: solved at run time from G and B");
        assert_eq!(structured, n > 3, "chain_{n}");
        assert!(text.contains("pub fn floor_collide"));
    }
    assert!(!read("chain_4_symbolic").contains("structured: solved at run time"));
}
