//! `Simulator::state_at`: the motion inside the last step, against the
//! exact §3.2.1 flights, for Taylor's method (the step's polynomial) and
//! Dormand–Prince (Shampine's interpolant; exact for the flights' parabolas
//! up to the steps' own error).

use dalembert::models::*;
use dalembert::runtime::simulate::{
    DormandPrince, Integrator, SeriesRoom, Settings, SimError, Simulator, State, Taylor,
};

#[path = "common/bounce.rs"]
mod bounce;

/// §3.2.1's exact motion from the bounce at t = 0 at time t of flight n
/// (from the n-th bounce to the next; each bounce reverses the velocity;
/// φ = 0 and θ = π/2 throughout).
fn exact(ball: &BallBounce, t: f64, n: f64) -> ([f64; 6], [f64; 6]) {
    let p = ball.params();
    let flight = 2.0 * bounce::U / p.g;
    let s = t - n * flight;
    let sign = if n as i64 % 2 == 0 { 1.0 } else { -1.0 };
    let (vx, wz) = (sign * bounce::V, sign * p.r * p.m * bounce::V / p.J);
    let x = if sign > 0.0 { s } else { flight - s } * bounce::V;
    let psi = if sign > 0.0 { s } else { flight - s } * wz.abs();
    let z = p.r + bounce::U * s - 0.5 * p.g * s * s;
    let q = [x, 0.0, z, 0.0, core::f64::consts::FRAC_PI_2, psi];
    let v = [vx, 0.0, bounce::U - p.g * s, 0.0, 0.0, wz];
    (q, v)
}

/// Runs 20 bounces with `integrator`, reading the state at 7 times inside
/// every step; the largest gap from the exact motion. Checks that no state
/// is given outside the last step.
fn inside_the_steps(integrator: Integrator) -> f64 {
    let ball = BallBounce::default();
    let (q, v) = bounce::after_bounce(&ball);
    let settings = Settings {
        integrator,
        ..Settings::default()
    };
    let mut room = SeriesRoom::new(&ball);
    let mut sim = Simulator::with_series(&mut room, State { t: 0.0, q, v }, settings).unwrap();
    assert!(sim.state_at(0.0).is_none(), "no step yet");
    let t_end = 20.5 * 2.0 * bounce::U / ball.params().g;
    let mut gap = 0.0f64;
    while sim.state().t < t_end {
        let step = sim.step(t_end).unwrap();
        let stop = step.collision.as_ref().map_or(step.state.t, |c| c.t);
        let flight = ((step.t0 + stop) / 2.0 / (2.0 * bounce::U / ball.params().g)).floor();
        for i in 0..=6 {
            let t = step.t0 + (stop - step.t0) * i as f64 / 6.0;
            let s = sim.state_at(t).expect("inside the step");
            assert_eq!(s.t, t);
            let (q, v) = exact(&ball, t, flight);
            for (a, b) in s.q.iter().chain(&s.v).zip(q.iter().chain(&v)) {
                gap = gap.max((a - b).abs());
            }
        }
        // Just before the collision: its state before the map.
        if let Some(c) = &step.collision {
            let s = sim.state_at(c.t).unwrap();
            for (a, b) in s.q.iter().chain(&s.v).zip(c.q.iter().chain(&c.v_minus)) {
                assert!((a - b).abs() < 1e-13, "{a} against {b} at the collision");
            }
        }
        let span = stop - step.t0;
        assert!(sim.state_at(step.t0 - 0.01 * span).is_none());
        assert!(sim.state_at(stop + 0.01 * span).is_none());
    }
    gap
}

#[test]
fn taylor_steps_polynomial_is_the_motion_to_rounding() {
    let gap = inside_the_steps(Integrator::Taylor(Taylor::default()));
    assert!(gap < 1e-13, "{gap:e}");
}

#[test]
fn dormand_prince_interpolant_is_the_motion_to_its_tolerance() {
    let gap = inside_the_steps(Integrator::DormandPrince(DormandPrince::default()));
    assert!(gap < 1e-11, "{gap:e}");
}

/// A Taylor run of the ball from just above the floor at t, moving along
/// it: the flight grazes the floor (as `tests/simulation_errors.rs` sets it
/// up), and the first step fails there.
fn grazing<'r>(
    room: &'r mut SeriesRoom<'_, BallBounce, 6>,
    t: f64,
) -> Simulator<'r, BallBounce, 6> {
    let ball = room.model();
    let r = ball.params().r;
    let q = [0.0, 0.0, r + 1e-15, 0.0, core::f64::consts::FRAC_PI_2, 0.0];
    let start = State {
        t,
        q,
        v: [100.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    };
    let settings = Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    };
    Simulator::with_series(room, start, settings).unwrap()
}

/// A step that fails (here at a grazing contact found on the step's
/// polynomial) leaves no motion to read: the simulator stays where it was,
/// and so does `state_at`.
#[test]
fn a_failed_step_leaves_no_motion() {
    let ball = BallBounce::default();
    let mut room = SeriesRoom::new(&ball);
    let mut sim = grazing(&mut room, 0.0);
    let Err(SimError::Grazing { t, .. }) = sim.step(1.0) else {
        panic!("expected a grazing contact");
    };
    assert_eq!(sim.state().t, 0.0);
    assert!(sim.state_at(0.5 * t).is_none());
}

/// A collision that fails to resolve leaves no trace in the simulator's
/// clock either: the step's instant is summed in compensated arithmetic,
/// and the rounding error of a step that did not happen must not be kept.
/// Tried again, the step fails the same way at the same instant (from
/// t = 0.1, where t + τ rounds).
#[test]
fn a_failed_collision_leaves_the_clock_as_it_was() {
    let ball = BallBounce::default();
    let mut room = SeriesRoom::new(&ball);
    let mut sim = grazing(&mut room, 0.1);
    let mut instants = Vec::new();
    for _ in 0..8 {
        let Err(SimError::Grazing { t, .. }) = sim.step(1.0) else {
            panic!("expected a grazing contact");
        };
        assert_eq!(sim.state().t, 0.1);
        instants.push(t);
    }
    assert!(instants[0] > 0.1);
    assert!(instants.iter().all(|&t| t == instants[0]), "{instants:?}");
}
