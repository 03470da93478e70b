//! The vendored §3.2 code reverses the paper's §3.2.1 data.

use dalembert_example_vendored::BallFloor;

#[test]
fn pendulum_data_is_reversed() {
    let ball = BallFloor::default();
    let p = *ball.params();
    let v = [-1.0, 0.0, -2.0, 0.0, p.r * p.m / p.J, 0.0];
    let w = ball.floor_collide(&[], &v);
    for i in 0..6 {
        assert!((w[i] + v[i]).abs() < 1e-12);
    }
}
