//! The saltation matrix of a collision (`runtime::saltation`) against an
//! independent answer: a point in gravity inside a disk or an oval whose
//! wall is written through a square root, a logarithm, a sine, a quotient
//! or an exponential (`tests/walls/`). Between collisions its motion is a
//! parabola, so the state at a time T after one collision is known in
//! closed form as a function of the starting state (the collision instant
//! found on the conic x² + k y² = 1 itself, by bisection, not from the
//! model's f); central differences of that map, Richardson-extrapolated,
//! must equal Φ(T − t*) S Φ(t*), with Φ(τ) = [[I, τI], [0, I]] the flight's
//! own sensitivity and S the saltation matrix; and the instant's
//! differences must equal `dt_dq` applied to the state's shift at the
//! wall. A grazing motion is an error.
//!
//! Uses the symbolic engine (the models are interpreted): run one test at a
//! time (`RUST_TEST_THREADS=1`).

mod common;

use std::path::Path;

use dalembert::runtime::prelude::*;
use dalembert::runtime::saltation::{SaltationError, StateMatrix, saltation};
use dalembert_codegen::interpret::Interpreted;

use common::lcg;

const G: f64 = 3.0;

/// `tests/walls/{name}.toml`, interpreted, with gravity `G` along −y.
fn model(name: &str) -> Interpreted<2> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/walls")
        .join(format!("{name}.toml"));
    let d = dalembert_codegen::derive(&file).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut m = Interpreted::new(&d).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert!(m.set_parameter_named("g", G));
    m
}

type State = ([f64; 2], [f64; 2]);

/// The flight for a time τ: q + vτ + aτ²/2, v + aτ, a = (0, −G).
fn fly((q, v): State, tau: f64) -> State {
    let a = [0.0, -G];
    (
        std::array::from_fn(|i| q[i] + v[i] * tau + 0.5 * a[i] * tau * tau),
        std::array::from_fn(|i| v[i] + a[i] * tau),
    )
}

/// x² + k y² − 1: negative inside the wall.
fn conic(k: f64, q: [f64; 2]) -> f64 {
    q[0] * q[0] + k * q[1] * q[1] - 1.0
}

/// The first instant in (0, limit] at which the flight from `x` meets the
/// conic, to rounding (sampled, then bisected).
fn first_meeting(k: f64, x: State, limit: f64) -> Option<f64> {
    let steps = 2000;
    let mut lo = 0.0;
    for i in 1..=steps {
        let t = limit * i as f64 / steps as f64;
        if conic(k, fly(x, t).0) >= 0.0 {
            let mut hi = t;
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if conic(k, fly(x, mid).0) >= 0.0 {
                    hi = mid
                } else {
                    lo = mid
                }
            }
            return Some(hi);
        }
        lo = t;
    }
    None
}

/// The state at time `t_end` from `x`, through one collision, and the
/// collision instant.
fn through<M: Walls<2, 2>>(m: &M, wall: M::Wall, k: f64, x: State, t_end: f64) -> (State, f64) {
    let t = first_meeting(k, x, t_end).expect("a collision before t_end");
    let (q, v) = fly(x, t);
    let v_plus = m.collide(wall, &q, &v);
    (fly((q, v_plus), t_end - t), t)
}

fn flight(tau: f64) -> StateMatrix<2> {
    let mut phi = StateMatrix::identity();
    phi.qv = [[tau, 0.0], [0.0, tau]];
    phi
}

#[test]
fn saltation_matches_differences_of_the_flow_through_a_collision() {
    for (name, k) in [
        ("disk_sqrt", 1.0),
        ("disk_log", 1.0),
        ("disk_sin", 1.0),
        ("disk_quotient", 1.0),
        ("disk_thin_ring", 1.0),
        ("oval_exp", 2.0),
        ("disk_atan", 1.0),
        ("disk_asin", 1.0),
        ("disk_acos", 1.0),
        ("disk_sinh", 1.0),
        ("disk_cosh", 1.0),
        ("disk_tanh", 1.0),
        ("disk_asinh", 1.0),
        ("disk_acosh", 1.0),
        ("disk_atanh", 1.0),
    ] {
        let m = model(name);
        let wall = m.walls()[0];
        let mut s = 3_u64;
        let mut cases = 0;
        while cases < 20 {
            let q0 = [lcg(&mut s) - 0.5, lcg(&mut s) - 0.5];
            let v0 = [4.0 * lcg(&mut s) - 2.0, 4.0 * lcg(&mut s) - 2.0];
            let x0 = (q0, v0);
            let Some(t_star) = first_meeting(k, x0, 3.0) else {
                continue;
            };
            let (q, v) = fly(x0, t_star);
            // Clear of grazing, and no second collision before t_end.
            let normal = [2.0 * q[0], 2.0 * k * q[1]];
            let along = (normal[0] * v[0] + normal[1] * v[1])
                / ((normal[0].hypot(normal[1])) * v[0].hypot(v[1]));
            if along < 0.3 {
                continue;
            }
            let t_end = t_star + 0.1;
            let after = (q, m.collide(wall, &q, &v));
            if first_meeting(k, (after.0, after.1), 0.1).is_some_and(|t| t > 1e-9) {
                continue;
            }
            cases += 1;
            let sal = saltation(&m, wall, &q, &v).unwrap_or_else(|e| panic!("{name}: {e}"));
            let phi = flight(t_end - t_star).mul(&sal.matrix).mul(&flight(t_star));
            for j in 0..4 {
                let shifted = |h: f64| {
                    let (mut q, mut v) = x0;
                    if j < 2 {
                        q[j] += h
                    } else {
                        v[j - 2] += h
                    }
                    let ((q, v), t) = through(&m, wall, k, (q, v), t_end);
                    [q[0], q[1], v[0], v[1], t]
                };
                let fd = common::richardson(|h| shifted(h).to_vec(), 1e-4);
                let mut unit = ([0.0; 2], [0.0; 2]);
                if j < 2 {
                    unit.0[j] = 1.0
                } else {
                    unit.1[j - 2] = 1.0
                }
                let (dq, dv) = phi.apply(&unit.0, &unit.1);
                let got = [dq[0], dq[1], dv[0], dv[1]];
                let scale = 1.0 + fd.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
                for i in 0..4 {
                    assert!(
                        (got[i] - fd[i]).abs() <= 1e-6 * scale,
                        "{name} case {cases}: ∂x(T)_{i}/∂x0_{j}: saltation {}, differences {}",
                        got[i],
                        fd[i]
                    );
                }
                // The instant: dt* = dt_dq · δq at the wall, δq = Φ(t*) δx0.
                let (dq_wall, _) = flight(t_star).apply(&unit.0, &unit.1);
                let dt = sal.dt_dq[0] * dq_wall[0] + sal.dt_dq[1] * dq_wall[1];
                assert!(
                    (dt - fd[4]).abs() <= 1e-6 * (1.0 + fd[4].abs()),
                    "{name} case {cases}: ∂t*/∂x0_{j}: {dt} against {}",
                    fd[4]
                );
            }
        }
    }
}

#[test]
fn a_grazing_collision_has_no_saltation_matrix() {
    let m = model("disk_sqrt");
    let wall = m.walls()[0];
    match saltation(&m, wall, &[1.0, 0.0], &[0.0, 1.0]) {
        Err(SaltationError::Grazing { normal_velocity }) => assert_eq!(normal_velocity, 0.0),
        other => panic!("grazing: {other:?}"),
    }
}
