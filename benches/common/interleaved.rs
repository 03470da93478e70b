//! Two paths timed against each other in interleaved rounds: a ratio that
//! the machine's drift cannot move.
//!
//! Criterion times one path after another, so on a shared machine a path
//! timed while another process runs, or after the CPU's clock changed,
//! reads slower than its rival by tens of per cent (`docs/performance.md`).
//! Here both paths are timed in alternating batches, many rounds of them in
//! one process, and each round gives one ratio: path a's CPU time over path
//! b's, each over all the inputs a few times. The order within a round
//! alternates (AB, then BA) so that neither path always runs second, after
//! the other has warmed caches and predictors. Whatever slows the machine
//! for longer than a round slows both sides of that ratio alike. Used by
//! `benches/paired.rs` and by the peers crate's `paired` bench.

use std::hint::black_box;

use super::cpu_time::now_ns;

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

/// `--rounds N` from the command line (`cargo bench` passes `--bench`
/// too), default 2001.
pub fn rounds() -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == "--rounds")
        .and_then(|i| args.get(i + 1))
        .map_or(2001, |n| n.parse().expect("--rounds takes a whole number"))
}

/// Checks that `a` and `b` agree on every input (1e-12 relative), then
/// times `a` against `b` over `rounds` interleaved rounds and prints the
/// median ratio a/b with its quartiles and the median time per call of
/// each.
pub fn pair<const N: usize>(
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
