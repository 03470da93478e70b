//! The n-link chain family (models/chain_N.toml): the generator evaluates P
//! in closed form for n ≤ 3 and structured (G and B generated, P solved at
//! run time) above; the collision map is emitted in the cheapest form per
//! call, which for n ≥ 2 is the elimination written out. Every evaluation
//! of the same map must agree, and the choice must be the documented one.

use dalembert::models::{Chain3, Chain4, Chain4Symbolic};
use dalembert::models::{chain_3, chain_4, chain_4_symbolic};
use dalembert::runtime::linalg::{correction, reflect};
use dalembert::runtime::prelude::*;

mod common;
use common::lcg;

/// Random parameters (0.5…1.5), configuration and velocity.
fn case<M: Model<N, N>, const N: usize>(m: &mut M, s: &mut u64) -> ([f64; N], [f64; N]) {
    for i in 0..m.parameter_names().len() {
        assert!(m.set_parameter(i, 0.5 + lcg(s)));
    }
    let q = std::array::from_fn(|_| -3.0 + 6.0 * lcg(s));
    let v = std::array::from_fn(|_| -2.0 + 4.0 * lcg(s));
    (q, v)
}

/// The runtime's solve from G and B: v − 2G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹Bv.
fn solved<M: Surfaces<N>, const N: usize>(m: &M, q: &[f64; N], v: &[f64; N]) -> [f64; N] {
    let w = m.walls()[0];
    let b = m.wall_rows(w, q);
    let d = correction(&m.mass_matrix(q), b.as_slice(), b.apply(v).as_slice()).unwrap();
    std::array::from_fn(|i| v[i] - 2.0 * d[i])
}

fn close<const N: usize>(a: &[f64; N], b: &[f64; N], scale: f64, what: &str) {
    for i in 0..N {
        assert!(
            (a[i] - b[i]).abs() < 1e-11 * scale,
            "{what}, component {i}: {a:?} vs {b:?}"
        );
    }
}

/// chain_4 structured vs chain_4_symbolic (the same model with its
/// closed-form P): P agrees, and the generated collision map (by
/// elimination) agrees with (I − 2P)v of the exact closed form and with the
/// runtime's solve, at random configurations, velocities and parameters.
#[test]
fn structured_and_symbolic_evaluation_agree() {
    let mut s = 11;
    for _ in 0..500 {
        let mut a = Chain4::default();
        let mut b = Chain4Symbolic::default();
        let (q, v) = case(&mut a, &mut s);
        for i in 0..a.parameter_names().len() {
            assert!(b.set_parameter(i, a.parameter(i).unwrap()));
        }
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
        let vs = v.iter().fold(1.0f64, |m, x| m.max(x.abs())) * scale;
        let exact = reflect(&pb, &v);
        let va = a.collide(chain_4::Wall::Floor, &q, &v);
        let vb = b.collide(chain_4_symbolic::Wall::Floor, &q, &v);
        close(
            &va,
            &exact,
            vs,
            "chain_4 collide vs (I - 2P)v, P closed form",
        );
        close(&vb, &exact, vs, "chain_4_symbolic collide vs (I - 2P)v");
        close(
            &va,
            &solved(&a, &q, &v),
            vs,
            "chain_4 collide vs runtime solve",
        );
    }
}

/// chain_3 keeps its closed-form P but collides by elimination: the two
/// agree.
#[test]
fn elimination_agrees_with_the_closed_form() {
    let mut s = 5;
    for _ in 0..500 {
        let mut m = Chain3::default();
        let (q, v) = case(&mut m, &mut s);
        let p = m.projector(chain_3::Wall::Floor, &q);
        let scale = p.iter().flatten().fold(1.0f64, |m, x| m.max(x.abs()));
        let vs = v.iter().fold(1.0f64, |m, x| m.max(x.abs())) * scale;
        let got = m.collide(chain_3::Wall::Floor, &q, &v);
        close(&got, &reflect(&p, &v), vs, "chain_3 collide vs (I - 2P)v");
        close(
            &got,
            &solved(&m, &q, &v),
            vs,
            "chain_3 collide vs runtime solve",
        );
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
        let form = if n == 1 {
            "M v, M = I - 2P"
        } else {
            "floor_collide                elimination"
        };
        assert!(text.contains(form), "chain_{n}: {form}");
    }
    assert!(!read("chain_4_symbolic").contains("structured: solved at run time"));
}

/// The chain's G entries are (Σₖ mₖ) lᵢ lⱼ cos(qᵢ − qⱼ) expanded into one
/// term per mass and per product of sines or cosines. Per call the generator
/// must not redo the parameters' share of that: with the parameter-only
/// coefficient of each entry computed once, an off-diagonal entry is
/// K·(sᵢsⱼ + cᵢcⱼ), three multiplications and an addition, and the diagonal
/// is parameters alone. (Expanded as it comes, chain_8's G took 258
/// operations per call besides its sines and cosines.)
#[test]
fn mass_matrix_entries_keep_their_parameter_factor_once() {
    for n in [3usize, 8] {
        let path = std::path::PathBuf::from(format!("models/chain_{n}.toml"));
        let d = dalembert_codegen::derive(&path).unwrap();
        let g = d
            .functions
            .iter()
            .find(|f| f.quantity == dalembert_codegen::quantity::Quantity::MassMatrix)
            .unwrap();
        let params = d.model.params.len();
        let (per_call, _) = g.program.split(params, 0).op_counts(&g.program);
        let off_diagonal = n * (n - 1) / 2;
        assert!(
            per_call.mul <= 3 * off_diagonal && per_call.add <= off_diagonal,
            "chain_{n}: G per call {per_call}"
        );
    }
}

/// Taylor's series need not follow q̈'s closed form: chain_4_symbolic's
/// (its q̈ a closed form of hundreds of operations) solves G per order as
/// chain_4's does, so the same model costs the same whichever way its
/// parameters are written; and chain_3's closed form gives way to the
/// solve as well, so the shorter chain's series costs less (its closed
/// form's transform cost more than chain_4's solve).
#[test]
fn series_of_a_closed_form_solve_per_order_where_cheaper() {
    let work = |w: Option<dalembert::runtime::taylor::SeriesWork>| {
        w.expect("the chains have series").motion
    };
    let structured = work(Chain4::default().series_work());
    let symbolic = work(Chain4Symbolic::default().series_work());
    assert_eq!(symbolic, structured);
    let chain_3 = work(Chain3::default().series_work());
    let order = 21;
    assert!(
        chain_3.multiply_adds(order) < structured.multiply_adds(order),
        "chain_3 {chain_3:?}, chain_4 {structured:?}"
    );
}
