//! The generated collision maps against SymForce's code, interleaved
//! (`benches/common/interleaved.rs`): for each model, the generated map and
//! SymForce's are timed in alternating batches over many rounds, and the
//! median of the per-round ratios is printed with its quartiles, so that
//! the machine's drift, which moves criterion's sequential timings by
//! ±10–20 %, cannot decide which is faster.
//!
//! Pairs: §3.1 and §3.2 (P simplified in SymForce's) and the n-link chain,
//! n = 1..8, at the model file's configuration (the elimination written in
//! SymForce's symbols), each checked equal on every input first.
//!
//! Run (from the repository root, after `python3 peers/generate.py`):
//! `cargo bench --manifest-path peers/Cargo.toml --bench paired`
//! (options: `--rounds N`, default 2001).

use std::hint::black_box;

use dalembert::models::*;
use dalembert::runtime::prelude::*;
use dalembert_peers::*;

#[path = "../../benches/common/cpu_time.rs"]
#[allow(dead_code)] // the criterion measurement is not used here
mod cpu_time;

#[path = "../../benches/common/interleaved.rs"]
mod interleaved;
use interleaved::{pair, rounds};

#[path = "../../benches/common/inputs.rs"]
#[allow(dead_code)] // criterion's `cycle` is not used here
mod inputs;
use inputs::inputs;

/// Chain n: generated against SymForce, over the velocities of
/// `peers.rs`'s chain bench.
fn chain<M: Surfaces<N> + Default, const N: usize>(rounds: usize) {
    let c = Chain::<M, N>::new();
    pair(
        &format!("{} generated / SymForce", c.model.name()),
        rounds,
        &inputs(Chain::<M, N>::velocity),
        |v| c.generated(v),
        |v| c.symforce(v),
    );
}

fn main() {
    let rounds = rounds();

    let ball = BallWall::default();
    let p = *ball.params();
    // Admissible velocities: w1 = -v2/r, w2 = v1/r.
    let vs = inputs(|[v1, v2, _, _, w3]| [v1, v2, -v2 / p.r, v1 / p.r, w3]);
    let wall = ball.walls()[0];
    pair(
        "3.1 generated / SymForce",
        rounds,
        &vs,
        |v| black_box(&ball).collide(wall, &[], v),
        |v| symforce_ball_wall(black_box(p.m), black_box(p.r), black_box(p.J), v),
    );

    let ball = BallFloor::default();
    let p = *ball.params();
    let vs = inputs(|v: [f64; 6]| v);
    let wall = ball.walls()[0];
    pair(
        "3.2 generated / SymForce",
        rounds,
        &vs,
        |v| black_box(&ball).collide(wall, &[], v),
        |v| symforce_ball_floor(black_box(p.m), black_box(p.r), black_box(p.J), v),
    );

    macro_rules! each {
        ($($model:ident $n:literal),*) => { $(chain::<$model, $n>(rounds);)* };
    }
    each!(Chain1 1, Chain2 2, Chain3 3, Chain4 4, Chain5 5, Chain6 6, Chain7 7, Chain8 8);
}
