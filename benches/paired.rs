//! The generated collision maps against the hand-written theorems,
//! interleaved (`common/interleaved.rs`): a ratio that the machine's drift
//! cannot move.
//!
//! Pairs: §3.1 (`BallWall`, admissible v) and §3.2 (`BallFloor`), each
//! generated map (called through `Walls::collide`, as generic code would)
//! against Theorem 3.1 / 3.2 by hand with the parameter combinations
//! computed once (`Hand31`, `Hand32`) and recomputed on every call; every
//! pair checked equal on every input first.
//!
//! Run: `cargo bench --bench paired` (options: `--rounds N`, default 2001).

use std::hint::black_box;

use dalembert::models::{BallFloor, BallWall};
use dalembert::runtime::prelude::*;

#[path = "common/cpu_time.rs"]
#[allow(dead_code)] // the criterion measurement is not used here
mod cpu_time;

#[path = "common/interleaved.rs"]
mod interleaved;
use interleaved::{pair, rounds};

#[path = "common/hand.rs"]
mod hand;
use hand::{Hand31, Hand32, hand_3_1, hand_3_2};

#[path = "common/inputs.rs"]
#[allow(dead_code)] // criterion's `cycle` is not used here
mod inputs;
use inputs::inputs;

/// A model's generated map against its theorem by hand, computed once and
/// recomputed.
fn theorem<M: Walls<0, N>, const N: usize>(
    section: &str,
    rounds: usize,
    model: &M,
    vs: &[[f64; N]],
    once: impl Fn(&[f64; N]) -> [f64; N],
    recomputed: impl Fn(&[f64; N]) -> [f64; N],
) {
    let wall = model.walls()[0];
    let generated = |v: &[f64; N]| black_box(model).collide(wall, &[], v);
    let name = format!("{section} generated / hand, computed once");
    pair(&name, rounds, vs, generated, once);
    let name = format!("{section} generated / hand, recomputed");
    pair(&name, rounds, vs, generated, recomputed);
}

fn main() {
    let rounds = rounds();

    let ball = BallWall::default();
    let p = *ball.params();
    // Admissible velocities: w1 = -v2/r, w2 = v1/r.
    let vs = inputs(|[v1, v2, _, _, w3]| [v1, v2, -v2 / p.r, v1 / p.r, w3]);
    let once = Hand31::new(p.m, p.r, p.J);
    theorem(
        "3.1",
        rounds,
        &ball,
        &vs,
        |v| black_box(&once).collide(v),
        |v| hand_3_1(black_box(p.m), black_box(p.r), black_box(p.J), v),
    );

    let ball = BallFloor::default();
    let p = *ball.params();
    let vs = inputs(|v: [f64; 6]| v);
    let once = Hand32::new(p.m, p.r, p.J);
    theorem(
        "3.2",
        rounds,
        &ball,
        &vs,
        |v| black_box(&once).collide(v),
        |v| hand_3_2(black_box(p.m), black_box(p.r), black_box(p.J), v),
    );
}
