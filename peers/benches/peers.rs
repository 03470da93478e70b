//! The generated collision maps side by side with peer code generators and
//! the hand-written anchors, in one run:
//!
//! - `peers_3_1` / `peers_3_2`: the paper's §3.1 and §3.2 maps, generated
//!   (through `Walls::collide`), by hand recomputing the parameter
//!   combinations and with them computed once (`benches/common/hand.rs`),
//!   SymForce's C++ and CasADi's C (P simplified; peers/generate.py).
//! - `peers_chain`: the n-link chain family, n = 1..8, at the model file's
//!   configuration: generated, SymForce and CasADi (the elimination
//!   G = LDLᵀ written symbolically, unsimplified).
//!
//! Every path is checked to agree with the generated map on every input
//! first; time is the thread's CPU time. Run (from the repository root,
//! after `python3 peers/generate.py`):
//! `cargo bench --manifest-path peers/Cargo.toml`.

use std::hint::black_box;

use criterion::{BenchmarkGroup, Criterion, criterion_group, criterion_main};
use dalembert::models::*;
use dalembert::runtime::prelude::*;
use dalembert_peers::*;

#[path = "../../benches/common/cpu_time.rs"]
mod cpu_time;
use cpu_time::ThreadCpuTime;

#[path = "../../benches/common/hand.rs"]
#[allow(dead_code)]
mod hand;
use hand::{Hand31, Hand32, hand_3_1, hand_3_2};

#[path = "../../benches/common/inputs.rs"]
mod inputs;
use inputs::{cycle, inputs};

/// One way of computing a map, by name.
type Path<'a, const N: usize> = (&'a str, &'a dyn Fn(&[f64; N]) -> [f64; N]);

/// Asserts that every path agrees with the generated map on every input.
fn agree<const N: usize>(
    group: &str,
    vs: &[[f64; N]],
    generated: impl Fn(&[f64; N]) -> [f64; N],
    paths: &[Path<'_, N>],
) {
    for v in vs {
        let want = generated(v);
        for (name, path) in paths {
            let got = path(v);
            for i in 0..N {
                assert!(
                    (want[i] - got[i]).abs() <= 1e-12 * (1.0 + want[i].abs()),
                    "{group}: {name} differs at {i} for {v:?}: {got:?} vs {want:?}"
                );
            }
        }
    }
}

/// The paths of one ball (`make` turns uniform numbers into its inputs):
/// checked against the generated map, then timed in turn.
#[allow(clippy::too_many_arguments)]
fn ball<M: Walls<0, N>, const N: usize>(
    c: &mut Criterion<ThreadCpuTime>,
    group: &str,
    model: &M,
    vs: &[[f64; N]],
    hand: &dyn Fn(&[f64; N]) -> [f64; N],
    precomputed: &dyn Fn(&[f64; N]) -> [f64; N],
    symforce: &dyn Fn(&[f64; N]) -> [f64; N],
    casadi: &dyn Fn(&[f64; N]) -> [f64; N],
) {
    let wall = model.walls()[0];
    let generated = |v: &[f64; N]| black_box(model).collide(wall, &[], v);
    let paths = [
        ("hand", hand),
        ("hand_precomputed", precomputed),
        ("symforce", symforce),
        ("casadi", casadi),
    ];
    agree(group, vs, generated, &paths);
    let mut g = c.benchmark_group(group);
    cycle(&mut g, "generated", vs, generated);
    for (name, path) in paths {
        cycle(&mut g, name, vs, path);
    }
    g.finish();
}

fn section_3_1(c: &mut Criterion<ThreadCpuTime>) {
    let model = BallWall::default();
    let p = *model.params();
    // Admissible velocities: w1 = -v2/r, w2 = v1/r.
    let vs = inputs(|[v1, v2, _, _, w3]| [v1, v2, -v2 / p.r, v1 / p.r, w3]);
    let once = Hand31::new(p.m, p.r, p.J);
    let (m, r, j) = (p.m, p.r, p.J);
    ball(
        c,
        "peers_3_1",
        &model,
        &vs,
        &|v| hand_3_1(black_box(m), black_box(r), black_box(j), v),
        &|v| black_box(&once).collide(v),
        &|v| symforce_ball_wall(black_box(m), black_box(r), black_box(j), v),
        &|v| casadi_ball_wall(black_box(m), black_box(r), black_box(j), v),
    );
}

fn section_3_2(c: &mut Criterion<ThreadCpuTime>) {
    let model = BallFloor::default();
    let p = *model.params();
    let vs = inputs(|v: [f64; 6]| v);
    let once = Hand32::new(p.m, p.r, p.J);
    let (m, r, j) = (p.m, p.r, p.J);
    ball(
        c,
        "peers_3_2",
        &model,
        &vs,
        &|v| hand_3_2(black_box(m), black_box(r), black_box(j), v),
        &|v| black_box(&once).collide(v),
        &|v| symforce_ball_floor(black_box(m), black_box(r), black_box(j), v),
        &|v| casadi_ball_floor(black_box(m), black_box(r), black_box(j), v),
    );
}

fn chain<M: Surfaces<N> + Default, const N: usize>(g: &mut BenchmarkGroup<'_, ThreadCpuTime>) {
    let c = Chain::<M, N>::new();
    let vs = inputs(Chain::<M, N>::velocity);
    let name = c.model.name();
    let (symforce, casadi) = (|v: &[f64; N]| c.symforce(v), |v: &[f64; N]| c.casadi(v));
    agree(
        name,
        &vs,
        |v| c.generated(v),
        &[("symforce", &symforce), ("casadi", &casadi)],
    );
    cycle(g, &format!("{name}/generated"), &vs, |v| c.generated(v));
    cycle(g, &format!("{name}/symforce"), &vs, symforce);
    cycle(g, &format!("{name}/casadi"), &vs, casadi);
}

fn chains(c: &mut Criterion<ThreadCpuTime>) {
    let mut g = c.benchmark_group("peers_chain");
    macro_rules! each {
        ($($model:ident $n:literal),*) => { $(chain::<$model, $n>(&mut g);)* };
    }
    each!(Chain1 1, Chain2 2, Chain3 3, Chain4 4, Chain5 5, Chain6 6, Chain7 7, Chain8 8);
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpuTime);
    targets = section_3_1, section_3_2, chains
}
criterion_main!(benches);
