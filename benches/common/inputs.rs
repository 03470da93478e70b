//! The inputs every collision-map path is timed on, cycled so that no path
//! is timed on one value the branch predictor or the compiler could learn.

use std::hint::black_box;

use criterion::BenchmarkGroup;
use criterion::measurement::Measurement;

/// How many inputs each path cycles through.
pub const INPUTS: usize = 1024;

/// `INPUTS` velocities from `make` fed uniform numbers in [-2, 2).
pub fn inputs<const N: usize>(make: impl Fn([f64; N]) -> [f64; N]) -> Vec<[f64; N]> {
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
pub fn cycle<M: Measurement, const N: usize>(
    g: &mut BenchmarkGroup<'_, M>,
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
