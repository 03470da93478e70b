//! §3.2.1's nonholonomic pendulum, the start every bounce test and bench
//! uses (a file of its own so that benches can include it without the test
//! helpers' dependencies).

#![allow(dead_code)] // each includer uses some of these

use dalembert::models::{BallBounce, BallBounceOmega, ball_bounce, ball_bounce_omega};
use dalembert::runtime::Walls;

/// The centre's speed up (u) and along x (v) at the bounce.
pub const U: f64 = 2.0;
pub const V: f64 = 1.0;

/// The ball at the floor at φ = ψ = 0, θ = π/2 (where ω = (θ', −ψ', φ'))
/// about to bounce: q and v⁻ = (−v, 0, −u, 0, 0, −r m v / J), whose image
/// under Theorem 3.2's map is −v⁻ for every m, r, J.
pub fn before_bounce(ball: &BallBounce) -> ([f64; 6], [f64; 6]) {
    let p = ball.params();
    let q = [0.0, 0.0, p.r, 0.0, core::f64::consts::FRAC_PI_2, 0.0];
    let v_minus = [-V, 0.0, -U, 0.0, 0.0, -p.r * p.m * V / p.J];
    (q, v_minus)
}

/// The same just after the bounce: q and v⁺.
pub fn after_bounce(ball: &BallBounce) -> ([f64; 6], [f64; 6]) {
    let (q, v_minus) = before_bounce(ball);
    (q, ball.collide(ball_bounce::Wall::Floor, &q, &v_minus))
}

/// The same in `ball_bounce_omega`'s state, the centre and ω (where
/// ω = (θ', −ψ', φ') above): q and v⁻ = (−v, 0, −u, 0, r m v / J, 0).
pub fn before_bounce_omega(ball: &BallBounceOmega) -> ([f64; 6], [f64; 6]) {
    let p = ball.params();
    let q = [0.0, 0.0, p.r, 0.0, 0.0, 0.0];
    let v_minus = [-V, 0.0, -U, 0.0, p.r * p.m * V / p.J, 0.0];
    (q, v_minus)
}

/// The same just after the bounce: q and v⁺.
pub fn after_bounce_omega(ball: &BallBounceOmega) -> ([f64; 6], [f64; 6]) {
    let (q, v_minus) = before_bounce_omega(ball);
    (
        q,
        ball.collide(ball_bounce_omega::Wall::Floor, &q, &v_minus),
    )
}
