//! The vendored copies in `examples/vendored/` are exactly what the
//! generator writes today (uses the symbolic engine: `RUST_TEST_THREADS=1`),
//! and the single-precision ones are as accurate as f32 allows.

use std::path::Path;

use dalembert::models::{BallFloor, BallWallEuler};
use dalembert::runtime::prelude::*;
use dalembert_example_vendored::single;

mod common;
use common::lcg;

fn check_current(model: &str, vendored: &str, f32: bool) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let file = root.join("models").join(model);
    let fresh = if f32 {
        dalembert_codegen::generate_f32(&file)
    } else {
        dalembert_codegen::generate(&file)
    }
    .unwrap();
    let copy = std::fs::read_to_string(root.join(vendored)).unwrap();
    let flag = if f32 { " --f32" } else { "" };
    assert!(
        fresh == copy,
        "{vendored} is stale: regenerate it with\n  cargo run --release -p dalembert-cli -- generate models/{model}{flag} -o {vendored}"
    );
}

#[test]
fn vendored_files_are_current() {
    check_current(
        "ball_floor.toml",
        "examples/vendored/src/ball_floor.rs",
        false,
    );
    check_current(
        "ball_floor.toml",
        "examples/vendored/src/single/ball_floor.rs",
        true,
    );
    check_current(
        "ball_wall_euler.toml",
        "examples/vendored/src/single/ball_wall_euler.rs",
        true,
    );
}

/// Largest error of the f32 collision map relative to the size of v, over
/// random states, against the f64 code. f32 has a unit roundoff of 6e-8;
/// the maps take a few dozen operations, so a few units of 1e-7 are
/// expected and 1e-5 is the bound asked for.
#[test]
fn single_precision_is_as_accurate_as_f32_allows() {
    let mut s = 5;
    let mut worst = [0.0f64; 2];
    for _ in 0..10_000 {
        // §3.2 at the collision instant.
        let v: [f64; 6] = std::array::from_fn(|_| -3.0 + 6.0 * lcg(&mut s));
        let exact = BallFloor::default().floor_collide(&[], &v);
        let single =
            single::ball_floor::BallFloor::default().floor_collide(&[], &v.map(|x| x as f32));
        let size = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for (a, b) in exact.iter().zip(single) {
            worst[0] = worst[0].max((a - b as f64).abs() / size);
        }
        // §3.1 in Euler angles, away from θ = 0, π.
        let q: [f64; 5] = [
            lcg(&mut s),
            lcg(&mut s),
            -3.0 + 6.0 * lcg(&mut s),
            0.3 + 2.5 * lcg(&mut s),
            -3.0 + 6.0 * lcg(&mut s),
        ];
        let v: [f64; 5] = std::array::from_fn(|_| -3.0 + 6.0 * lcg(&mut s));
        let m = BallWallEuler::default();
        let exact = m.collide(dalembert::models::ball_wall_euler::Wall::Wall, &q, &v);
        let single = single::ball_wall_euler::BallWallEuler::default()
            .wall_collide(&q.map(|x| x as f32), &v.map(|x| x as f32));
        // P has entries in 1/sin θ: scale by it.
        let size = v.iter().fold(0.0f64, |m, x| m.max(x.abs())) / q[3].sin();
        for (a, b) in exact.iter().zip(single) {
            worst[1] = worst[1].max((a - b as f64).abs() / size);
        }
    }
    eprintln!(
        "f32 against f64, largest error relative to |v|: §3.2 {:.1e}, §3.1 Euler {:.1e}",
        worst[0], worst[1]
    );
    assert!(worst[0] < 1e-5 && worst[1] < 1e-5, "{worst:?}");
}

/// The single-precision tangents of §3.1 in Euler angles (q̈'s and the
/// collision map's) against the f64 ones, relative to the size of the
/// f64 derivative.
#[test]
fn single_precision_tangents_follow_the_f64_ones() {
    use dalembert::models::ball_wall_euler::Wall;
    let mut s = 11;
    let mut worst = [0.0f64; 2];
    let (m, single) = (
        BallWallEuler::default(),
        single::ball_wall_euler::BallWallEuler::default(),
    );
    let f32s = |x: &[f64; 5]| x.map(|x| x as f32);
    for _ in 0..10_000 {
        let mut q: [f64; 5] = std::array::from_fn(|_| -3.0 + 6.0 * lcg(&mut s));
        q[3] = 0.3 + 2.5 * lcg(&mut s); // away from θ = 0, π
        let [v, dq, dv]: [[f64; 5]; 3] =
            std::array::from_fn(|_| std::array::from_fn(|_| -3.0 + 6.0 * lcg(&mut s)));
        let pairs = [
            (
                m.accelerations_tangent(&q, &v, &dq, &dv).1,
                single
                    .accelerations_tangent(&f32s(&q), &f32s(&v), &f32s(&dq), &f32s(&dv))
                    .1,
            ),
            (
                m.collide_tangent(Wall::Wall, &q, &v, &dq, &dv).unwrap().1,
                single
                    .wall_collide_tangent(&f32s(&q), &f32s(&v), &f32s(&dq), &f32s(&dv))
                    .1,
            ),
        ];
        for (k, (exact, single)) in pairs.iter().enumerate() {
            let size = exact.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            for (a, b) in exact.iter().zip(single) {
                worst[k] = worst[k].max((a - *b as f64).abs() / size);
            }
        }
    }
    eprintln!(
        "f32 tangents against f64, largest error relative to their size: q̈ {:.1e}, collision map {:.1e}",
        worst[0], worst[1]
    );
    assert!(worst[0] < 5e-5 && worst[1] < 5e-5, "{worst:?}");
}
