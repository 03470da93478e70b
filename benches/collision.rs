//! Collision maps of the paper's models, side by side in one run:
//!
//! - `generated`: the code dalembert generates from `models/ball_*.toml`;
//! - `hand`: the paper's closed forms (Theorems 3.1 and 3.2) written by hand,
//!   recomputing the parameter combinations on every call;
//! - `hand_precomputed`: the same with the parameter combinations computed
//!   once (as generated code does since it keeps its parameter-only values);
//! - `generic_static`: P from G and B by the runtime's heap-free generic path
//!   (Cholesky + Gram–Schmidt on fixed-size arrays), then (I − 2P)v;
//! - `generic_dynamic`: P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B with nalgebra's heap-allocated
//!   dynamic matrices on every call, then (I − 2P)v.
//!
//! - `chain_collide/chain_N`: the n-link chain family's collision map as
//!   generated (the form the generator found cheapest: its header says
//!   which), and `chain_collide/chain_N_runtime_solve` the same map from the
//!   generated G and B by the runtime's fixed-size Cholesky factorisation
//!   and constrained solve (how structured walls were evaluated before the
//!   generator wrote the elimination out).
//!
//! Every path runs over the same 1024 inputs in turn, after all paths are
//! checked to agree on each; time is the thread's CPU time.
//!
//! Run: `cargo bench --bench collision`.

use std::hint::black_box;

use criterion::{BenchmarkGroup, Criterion, criterion_group, criterion_main};
use dalembert::models::{BallFloor, BallWall};
use dalembert::runtime::linalg::{correction, projector, reflect};
use dalembert::runtime::prelude::*;
use nalgebra::{DMatrix, DVector};

#[path = "common/cpu_time.rs"]
mod cpu_time;
use cpu_time::ThreadCpuTime;

/// Theorem 3.1 for admissible v = (v1, v2, w1, w2, w3), with w1, w2 of v⁺ from
/// the rolling constraints (3.1), recomputing the parameter combinations.
fn hand_3_1(m: f64, r: f64, j: f64, v: &[f64; 5]) -> [f64; 5] {
    Hand31::new(m, r, j).collide(v)
}

/// Theorem 3.1 with the parameter combinations computed once.
struct Hand31 {
    a: f64,
    b: f64,
    c: f64,
    r: f64,
}

impl Hand31 {
    fn new(m: f64, r: f64, j: f64) -> Self {
        let jt = j + 0.5 * r * r * m; // J~
        let jp = j + r * r * m; // J'
        let inv = 1.0 / jt;
        Self {
            a: 0.5 * r * r * m * inv,
            b: r * j * inv,
            c: jp * inv / r,
            r,
        }
    }

    #[inline]
    fn collide(&self, v: &[f64; 5]) -> [f64; 5] {
        let v1 = -v[0];
        let v2 = self.a * v[1] + self.b * v[4];
        let w3 = self.c * v[1] - self.a * v[4];
        [v1, v2, -v2 / self.r, v1 / self.r, w3]
    }
}

/// Theorem 3.2, recomputing the parameter combinations.
fn hand_3_2(m: f64, r: f64, j: f64, v: &[f64; 6]) -> [f64; 6] {
    Hand32::new(m, r, j).collide(v)
}

/// Theorem 3.2 with the parameter combinations computed once.
struct Hand32 {
    a: f64,
    b: f64,
    c: f64,
}

impl Hand32 {
    fn new(m: f64, r: f64, j: f64) -> Self {
        let inv = 1.0 / (j + r * r * m); // 1/J'
        Self {
            a: (m * r * r - j) * inv,
            b: 2.0 * j * r * inv,
            c: 2.0 * r * m * inv,
        }
    }

    #[inline]
    fn collide(&self, v: &[f64; 6]) -> [f64; 6] {
        let (a, b, c) = (self.a, self.b, self.c);
        [
            a * v[0] + b * v[4],
            a * v[1] - b * v[3],
            -v[2],
            -c * v[1] - a * v[3],
            c * v[0] - a * v[4],
            v[5],
        ]
    }
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

/// Inputs cycled through by every path, so that no path is timed on one
/// value the branch predictor or the compiler could learn.
const INPUTS: usize = 1024;

/// `INPUTS` velocities from `make` fed uniform numbers in [-2, 2).
fn inputs<const N: usize>(make: impl Fn([f64; N]) -> [f64; N]) -> Vec<[f64; N]> {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut uniform = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
    };
    (0..INPUTS)
        .map(|_| make(std::array::from_fn(|_| uniform())))
        .collect()
}

/// Times `f` over the inputs in turn.
fn cycle<const N: usize>(
    g: &mut BenchmarkGroup<'_, ThreadCpuTime>,
    name: &str,
    vs: &[[f64; N]],
    f: impl Fn(&[f64; N]) -> [f64; N],
) {
    g.bench_function(name, |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) % INPUTS;
            f(black_box(&vs[k]))
        })
    });
}

/// The paths for one instantaneous model's first wall, after checking that
/// the generated, hand-written and generic maps agree on every input.
fn compare<M: Walls<0, N>, const N: usize>(
    c: &mut Criterion<ThreadCpuTime>,
    group: &str,
    model: &M,
    vs: &[[f64; N]],
    hand: impl Fn(&[f64; N]) -> [f64; N],
    precomputed: impl Fn(&[f64; N]) -> [f64; N],
) {
    let wall = model.walls()[0];
    let (gd, bd) = dynamic_inputs(model, wall);
    let generic_static = |v: &[f64; N]| {
        let m = black_box(model);
        let rows = m.wall_rows(wall, &[]);
        let p = projector(&m.mass_matrix(&[]), rows.as_slice()).expect("P");
        reflect(&p, v)
    };
    let generic_dynamic = |v: &[f64; N]| {
        let out = generic_dynamic(black_box(&gd), black_box(&bd), &DVector::from_row_slice(v));
        std::array::from_fn(|i| out[i])
    };
    for v in vs {
        let generated = model.collide(wall, &[], v);
        for (path, other) in [
            ("hand", hand(v)),
            ("hand, precomputed", precomputed(v)),
            ("generic static", generic_static(v)),
            ("generic dynamic", generic_dynamic(v)),
        ] {
            for i in 0..N {
                assert!(
                    (generated[i] - other[i]).abs() <= 1e-12 * (1.0 + generated[i].abs()),
                    "{group}: {path} differs at {i} for {v:?}"
                );
            }
        }
    }
    let mut g = c.benchmark_group(group);
    cycle(&mut g, "generated", vs, |v| {
        black_box(model).collide(wall, &[], v)
    });
    cycle(&mut g, "hand", vs, hand);
    cycle(&mut g, "hand_precomputed", vs, precomputed);
    cycle(&mut g, "generic_static", vs, generic_static);
    cycle(&mut g, "generic_dynamic", vs, generic_dynamic);
    g.finish();
}

fn section_3_1(c: &mut Criterion<ThreadCpuTime>) {
    let ball = BallWall::default();
    let p = *ball.params();
    // Admissible velocities: w1 = -v2/r, w2 = v1/r.
    let vs = inputs(|[v1, v2, _, _, w3]| [v1, v2, -v2 / p.r, v1 / p.r, w3]);
    let hand = |v: &[f64; 5]| hand_3_1(black_box(p.m), black_box(p.r), black_box(p.J), v);
    let once = Hand31::new(p.m, p.r, p.J);
    let precomputed = |v: &[f64; 5]| black_box(&once).collide(v);
    compare(c, "collision_3_1", &ball, &vs, hand, precomputed);
}

fn section_3_2(c: &mut Criterion<ThreadCpuTime>) {
    let ball = BallFloor::default();
    let p = *ball.params();
    let vs = inputs(|v: [f64; 6]| v);
    let hand = |v: &[f64; 6]| hand_3_2(black_box(p.m), black_box(p.r), black_box(p.J), v);
    let once = Hand32::new(p.m, p.r, p.J);
    let precomputed = |v: &[f64; 6]| black_box(&once).collide(v);
    compare(c, "collision_3_2", &ball, &vs, hand, precomputed);
}

/// The n-link chain family: the collision map at the model file's initial
/// configuration, n = 1…8, generated and by the runtime's solve from G and
/// B; both checked equal first.
fn chains(c: &mut Criterion<ThreadCpuTime>) {
    fn one<M: Surfaces<N> + Default, const N: usize>(g: &mut BenchmarkGroup<'_, ThreadCpuTime>) {
        let m = M::default();
        let q = m.initial_coordinates();
        let v: [f64; N] = std::array::from_fn(|i| 0.3 - 0.1 * i as f64);
        let w = m.walls()[0];
        let solve = |q: &[f64; N], v: &[f64; N]| -> [f64; N] {
            let b = m.wall_rows(w, q);
            let r = b.apply(v);
            let d = correction(&m.mass_matrix(q), b.as_slice(), r.as_slice())
                .expect("G > 0 and B of full rank");
            std::array::from_fn(|i| v[i] - 2.0 * d[i])
        };
        let (generated, solved) = (m.collide(w, &q, &v), solve(&q, &v));
        for (x, y) in generated.iter().zip(&solved) {
            assert!(
                (x - y).abs() <= 1e-12 * (1.0 + y.abs()),
                "{}: {generated:?} vs {solved:?}",
                m.name()
            );
        }
        g.bench_function(m.name(), |b| {
            b.iter(|| m.collide(w, black_box(&q), black_box(&v)))
        });
        g.bench_function(format!("{}_runtime_solve", m.name()), |b| {
            b.iter(|| solve(black_box(&q), black_box(&v)))
        });
    }
    use dalembert::models::*;
    let mut g = c.benchmark_group("chain_collide");
    one::<Chain1, 1>(&mut g);
    one::<Chain2, 2>(&mut g);
    one::<Chain3, 3>(&mut g);
    one::<Chain4, 4>(&mut g);
    one::<Chain5, 5>(&mut g);
    one::<Chain6, 6>(&mut g);
    one::<Chain7, 7>(&mut g);
    one::<Chain8, 8>(&mut g);
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpuTime);
    targets = section_3_1, section_3_2, chains
}
criterion_main!(benches);
