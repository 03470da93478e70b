//! The hybrid simulator's contacts and states that must be reported
//! rather than resolved, each as its typed error: two walls met at once, a
//! wall met at a grazing speed, and bad starts (non-finite, beyond a wall,
//! a singular mass matrix, a velocity off the constraints, a bad setting,
//! steps that could not end a run).

use dalembert::models::{BallBounce, BallWallEuler, MassesOnLine};
use dalembert::runtime::dynamics::DynamicsError;
use dalembert::runtime::simulate::{
    Integrator, Rk4, SeriesRoom, Settings, SimError, Simulator, State, Taylor,
};

#[test]
fn simultaneous_contacts_are_reported() {
    use dalembert::models::masses_on_line::Wall;
    let sys = MassesOnLine::default();
    // x1 meets the left wall when x2 meets the right one.
    let start = State {
        t: 0.0,
        q: [0.25, 0.75],
        v: [-1.0, 1.0],
    };
    let mut sim = Simulator::new(&sys, start, Settings::default()).unwrap();
    match sim.run(1.0, |_| true) {
        Err(SimError::Simultaneous { first, second, t }) => {
            assert!((t - 0.25).abs() < 1e-12);
            let mut pair = [first, second];
            pair.sort_by_key(|w| *w as u8);
            assert_eq!(pair, [Wall::Left, Wall::Right]);
        }
        other => panic!("expected a simultaneous contact, got {other:?}"),
    }
}

#[test]
fn grazing_contacts_are_reported() {
    let ball = BallBounce::default();
    let r = ball.params().r;
    // 1e-15 above the floor, fast along it: the floor is met at a normal
    // speed √(2g·1e-15) ≈ 1.4e-7, about 1e-9 of the speed.
    let q = [0.0, 0.0, r + 1e-15, 0.0, std::f64::consts::FRAC_PI_2, 0.0];
    let start = State {
        t: 0.0,
        q,
        v: [100.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    };
    let mut sim = Simulator::new(&ball, start, Settings::default()).unwrap();
    match sim.run(1.0, |_| true) {
        Err(SimError::Grazing {
            t, normal_velocity, ..
        }) => {
            assert!(t < 1e-6 && normal_velocity < 0.0 && normal_velocity > -1e-6);
        }
        other => panic!("expected a grazing contact, got {other:?}"),
    }
}

#[test]
fn bad_states_are_typed_errors() {
    let ball = BallBounce::default();
    let r = ball.params().r;
    let fly = |q: [f64; 6], v: [f64; 6]| {
        Simulator::new(&ball, State { t: 0.0, q, v }, Settings::default())
            .and_then(|mut s| s.run(2.0, |_| true))
    };
    // Non-finite.
    let q = [0.0, 0.0, 1.0, 0.0, 1.0, 0.0];
    assert!(matches!(
        fly([f64::NAN; 6], [0.0; 6]),
        Err(SimError::Inadmissible { .. })
    ));
    // Below the floor.
    let below = [0.0, 0.0, r - 0.1, 0.0, 1.0, 0.0];
    assert!(matches!(
        fly(below, [0.0; 6]),
        Err(SimError::StartsBeyondWall { .. })
    ));
    // At the Euler angles' singularity θ = 0, G is singular: a typed
    // error from the start, never NaN.
    let singular = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    assert!(matches!(
        fly(singular, [0.0; 6]),
        Err(SimError::Dynamics {
            error: DynamicsError::SingularMassMatrix,
            ..
        })
    ));
    // Inadmissible: the rolling ball's velocity off ker A.
    let rolling = BallWallEuler::default();
    let q5 = [1.0, 0.0, 0.0, 1.0, 0.0];
    let bad = Simulator::new(
        &rolling,
        State {
            t: 0.0,
            q: q5,
            v: [1.0, 0.0, 0.0, 0.0, 0.0],
        },
        Settings::default(),
    );
    assert!(matches!(bad, Err(SimError::Inadmissible { .. })));
    // A bad setting.
    let rk0 = Settings {
        integrator: Integrator::Rk4(Rk4 { step: 0.0 }),
        ..Settings::default()
    };
    assert!(matches!(
        Simulator::new(
            &ball,
            State {
                t: 0.0,
                q,
                v: [0.0; 6]
            },
            rk0
        ),
        Err(SimError::BadSettings)
    ));
}

/// Taylor's settings that could not finish a run are errors, not endless
/// runs: a tolerance below [`Taylor::MIN_TOLERANCE`] is refused at the
/// start, and a step of a few ulps of t (at order 2 the step is about
/// ε/‖q̇‖, since its last two terms are q̇ and q̈) is `StepTooSmall`, as
/// with the Runge–Kutta methods. Before, both stepped on for ever.
#[test]
fn taylor_steps_that_cannot_end_a_run_are_errors() {
    let ball = BallBounce::default();
    let (q, v) = ball.initial_state();
    let start = State { t: 0.0, q, v };
    let with = |taylor: Taylor| Settings {
        integrator: Integrator::Taylor(taylor),
        ..Settings::default()
    };
    let tiny = with(Taylor {
        tolerance: 1e-300,
        ..Taylor::default()
    });
    assert!(matches!(
        Simulator::new(&ball, start, tiny),
        Err(SimError::BadSettings)
    ));
    let order_2 = with(Taylor {
        fixed_order: Some(2),
        ..Taylor::default()
    });
    let mut room = SeriesRoom::new(&ball);
    let mut sim = Simulator::with_series(&mut room, start, order_2).unwrap();
    match sim.step(1.0) {
        Err(SimError::StepTooSmall { t, step }) => {
            assert_eq!(t, 0.0);
            assert!(step > 0.0 && step < 1e-15, "{step:e}");
        }
        other => panic!("expected StepTooSmall, got {other:?}"),
    }
    // The order the tolerance asks for steps on.
    let mut room = SeriesRoom::new(&ball);
    let mut sim = Simulator::with_series(&mut room, start, with(Taylor::default())).unwrap();
    assert!(sim.step(1.0).unwrap().state.t > 0.1);
}
