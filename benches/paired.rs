//! The generated collision maps against the hand-written theorems,
//! interleaved: a ratio that the machine's drift cannot move.
//!
//! Criterion times one path after another, so on a shared machine a path
//! timed while another process runs, or after the CPU's clock changed,
//! reads slower than its rival by tens of per cent (`docs/performance.md`).
//! Here both paths are timed in alternating batches, many rounds of them in
//! one process, and each round gives one ratio: the generated map's CPU
//! time over the hand map's, each over all 1024 inputs a few times. The
//! order within a round alternates (AB, then BA) so that neither path
//! always runs second, after the other has warmed caches and predictors.
//! Whatever slows the machine for longer than a round slows both sides of
//! that ratio alike. Printed: the median ratio over the rounds and its
//! quartiles, and each path's median time per call.
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
use cpu_time::now_ns;

#[path = "common/hand.rs"]
mod hand;
use hand::{Hand31, Hand32, hand_3_1, hand_3_2};

#[path = "common/inputs.rs"]
#[allow(dead_code)] // criterion's `cycle` is not used here
mod inputs;
use inputs::inputs;

/// Passes over the inputs per timed batch: a batch of 1024 × 16 calls of a
/// few nanoseconds is tens of microseconds, far above the clock's cost.
const PASSES: usize = 16;

/// The CPU time of `PASSES` passes of `f` over `vs`, in nanoseconds.
fn batch<const N: usize>(vs: &[[f64; N]], f: &impl Fn(&[f64; N]) -> [f64; N]) -> u64 {
    let start = now_ns();
    for _ in 0..PASSES {
        for v in vs {
            black_box(f(black_box(v)));
        }
    }
    now_ns() - start
}

/// The value at fraction `p` of the sorted `xs`.
fn quantile(xs: &mut [f64], p: f64) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[((xs.len() - 1) as f64 * p).round() as usize]
}

/// Times `a` against `b` over `rounds` interleaved rounds and prints the
/// median ratio a/b with its quartiles and the median time per call of each.
fn pair<const N: usize>(
    name: &str,
    rounds: usize,
    vs: &[[f64; N]],
    a: impl Fn(&[f64; N]) -> [f64; N],
    b: impl Fn(&[f64; N]) -> [f64; N],
) {
    for v in vs {
        let (x, y) = (a(v), b(v));
        for i in 0..N {
            assert!(
                (x[i] - y[i]).abs() <= 1e-12 * (1.0 + x[i].abs()),
                "{name}: the paths differ at component {i} for {v:?}: {x:?} vs {y:?}"
            );
        }
    }
    // Warm-up: a few rounds untimed.
    for _ in 0..8 {
        batch(vs, &a);
        batch(vs, &b);
    }
    let calls = (PASSES * vs.len()) as f64;
    let (mut ratios, mut ta, mut tb) = (Vec::new(), Vec::new(), Vec::new());
    for round in 0..rounds {
        let (x, y) = if round % 2 == 0 {
            let x = batch(vs, &a);
            (x, batch(vs, &b))
        } else {
            let y = batch(vs, &b);
            (batch(vs, &a), y)
        };
        ratios.push(x as f64 / y as f64);
        ta.push(x as f64 / calls);
        tb.push(y as f64 / calls);
    }
    let (q1, med, q3) = (
        quantile(&mut ratios, 0.25),
        quantile(&mut ratios, 0.5),
        quantile(&mut ratios, 0.75),
    );
    println!(
        "{name:<44} ratio {med:.3} (quartiles {q1:.3}–{q3:.3}); per call {:.2} vs {:.2} ns (cpu, medians of {rounds} rounds)",
        quantile(&mut ta, 0.5),
        quantile(&mut tb, 0.5),
    );
}

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
    // `cargo bench` passes `--bench`; `--rounds N` sets the rounds.
    let args: Vec<String> = std::env::args().collect();
    let rounds = args
        .iter()
        .position(|a| a == "--rounds")
        .and_then(|i| args.get(i + 1))
        .map_or(2001, |n| n.parse().expect("--rounds takes a whole number"));

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
