//! Collision maps of the paper's models, side by side in one run:
//!
//! - `generated`: the code dalembert generates from `models/ball_*.toml`;
//! - `hand`: the paper's closed forms (Theorems 3.1 and 3.2) written by hand,
//!   recomputing the parameter combinations on every call as generated code does;
//! - `generic_static`: P from G and B by the runtime's heap-free generic path
//!   (Cholesky + Gram–Schmidt on fixed-size arrays), then (I − 2P)v;
//! - `generic_dynamic`: P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B with nalgebra's heap-allocated
//!   dynamic matrices on every call, then (I − 2P)v.
//!
//! - `chain_collide/chain_N`: the n-link chain family's collision map.
//!
//! Run: `cargo bench --bench collision`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use dalembert::models::{BallFloor, BallWall};
use dalembert::runtime::linalg::{projector, reflect};
use dalembert::runtime::prelude::*;
use nalgebra::{DMatrix, DVector};

/// Theorem 3.1 for admissible v = (v1, v2, w1, w2, w3), with w1, w2 of v⁺ from
/// the rolling constraints (3.1).
fn hand_3_1(m: f64, r: f64, j: f64, v: &[f64; 5]) -> [f64; 5] {
    let jt = j + 0.5 * r * r * m; // J~
    let jp = j + r * r * m; // J'
    let inv = 1.0 / jt;
    let a = 0.5 * r * r * m * inv;
    let v1 = -v[0];
    let v2 = a * v[1] + r * j * inv * v[4];
    let w3 = jp * inv / r * v[1] - a * v[4];
    [v1, v2, -v2 / r, v1 / r, w3]
}

/// Theorem 3.2.
fn hand_3_2(m: f64, r: f64, j: f64, v: &[f64; 6]) -> [f64; 6] {
    let inv = 1.0 / (j + r * r * m); // 1/J'
    let a = (m * r * r - j) * inv;
    let b = 2.0 * j * r * inv;
    let c = 2.0 * r * m * inv;
    [
        a * v[0] + b * v[4],
        a * v[1] - b * v[3],
        -v[2],
        -c * v[1] - a * v[3],
        c * v[0] - a * v[4],
        v[5],
    ]
}

/// P from G and B with dynamic matrices, then (I − 2P)v.
fn generic_dynamic(g: &DMatrix<f64>, b: &DMatrix<f64>, v: &DVector<f64>) -> DVector<f64> {
    let g_inv = g.clone().cholesky().expect("G > 0").inverse();
    let x = &g_inv * b.transpose();
    let m = b * &x;
    let p = x * m.try_inverse().expect("B full rank") * b;
    v - 2.0 * p * v
}

fn dynamic_inputs<M: Walls<0, N>, const N: usize>(
    model: &M,
    wall: M::Wall,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let g = model.mass_matrix(&[]);
    let rows = model.wall_rows(wall, &[]);
    let gd = DMatrix::from_fn(N, N, |i, j| g[i][j]);
    let bd = DMatrix::from_fn(rows.len(), N, |i, j| rows.as_slice()[i][j]);
    (gd, bd)
}

/// The four paths for one instantaneous model's first wall, after checking
/// that the generated and hand-written maps agree at `v`.
fn compare<M: Walls<0, N>, const N: usize>(
    c: &mut Criterion,
    group: &str,
    model: &M,
    v: [f64; N],
    hand: impl Fn(&[f64; N]) -> [f64; N],
) {
    let wall = model.walls()[0];
    let generated = model.collide(wall, &[], &v);
    let by_hand = hand(&v);
    for i in 0..N {
        assert!(
            (generated[i] - by_hand[i]).abs() < 1e-12,
            "{group}: hand-written differs at {i}"
        );
    }
    let mut g = c.benchmark_group(group);
    g.bench_function("generated", |b| {
        b.iter(|| black_box(model).collide(wall, &[], black_box(&v)))
    });
    g.bench_function("hand", |b| b.iter(|| hand(black_box(&v))));
    g.bench_function("generic_static", |b| {
        b.iter(|| {
            let m = black_box(model);
            let rows = m.wall_rows(wall, &[]);
            let p = projector(&m.mass_matrix(&[]), rows.as_slice()).expect("P");
            reflect(&p, black_box(&v))
        })
    });
    let (gd, bd) = dynamic_inputs(model, wall);
    let vd = DVector::from_row_slice(&v);
    g.bench_function("generic_dynamic", |b| {
        b.iter(|| generic_dynamic(black_box(&gd), black_box(&bd), black_box(&vd)))
    });
    g.finish();
}

fn section_3_1(c: &mut Criterion) {
    let ball = BallWall::default();
    let p = ball.params;
    // An admissible velocity: w1 = -v2/r, w2 = v1/r.
    let v = [-0.7, 0.4, -0.4 / p.r, -0.7 / p.r, 1.3];
    let hand = |v: &[f64; 5]| hand_3_1(black_box(p.m), black_box(p.r), black_box(p.J), v);
    compare(c, "collision_3_1", &ball, v, hand);
}

fn section_3_2(c: &mut Criterion) {
    let ball = BallFloor::default();
    let p = ball.params;
    let v = [-1.5, 0.3, -2.0, 0.2, 7.5, -0.4];
    let hand = |v: &[f64; 6]| hand_3_2(black_box(p.m), black_box(p.r), black_box(p.J), v);
    compare(c, "collision_3_2", &ball, v, hand);
}

/// The n-link chain family: the collision map at the model file's initial
/// configuration, n = 1…8 (closed forms for n ≤ 3, structured above), and
/// chain_4 with its closed form for comparison.
fn chains(c: &mut Criterion) {
    fn one<M: Surfaces<N> + Default, const N: usize>(
        g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    ) {
        let m = M::default();
        let q = m.initial_coordinates();
        let v: [f64; N] = std::array::from_fn(|i| 0.3 - 0.1 * i as f64);
        let w = m.walls()[0];
        assert!(m.collide(w, &q, &v).iter().all(|x| x.is_finite()));
        g.bench_function(m.name(), |b| {
            b.iter(|| m.collide(w, black_box(&q), black_box(&v)))
        });
    }
    use dalembert::models::*;
    let mut g = c.benchmark_group("chain_collide");
    one::<Chain1, 1>(&mut g);
    one::<Chain2, 2>(&mut g);
    one::<Chain3, 3>(&mut g);
    one::<Chain4, 4>(&mut g);
    one::<Chain4Symbolic, 4>(&mut g);
    one::<Chain5, 5>(&mut g);
    one::<Chain6, 6>(&mut g);
    one::<Chain7, 7>(&mut g);
    one::<Chain8, 8>(&mut g);
    g.finish();
}

criterion_group!(benches, section_3_1, section_3_2, chains);
criterion_main!(benches);
