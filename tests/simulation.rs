//! The hybrid simulator on scenarios with analytic answers: the free
//! pendulum's period (elliptic integral), the pendulum bouncing off a wall,
//! the paper's §3.2.1 nonholonomic pendulum over more than a thousand
//! bounces, the rolling ball meeting the wall (Theorem 3.1), two masses in a
//! box (the textbook law, event by event), a chain whose tip meets the
//! floor along a curved path (adaptive steps aimed at predicted collisions
//! against fixed RK4 steps). The contacts that must be reported rather
//! than resolved are `tests/simulation_errors.rs`.

use dalembert::models::{BallBounce, BallWallEuler, Chain3, MassesOnLine, PendulumWall};

#[path = "common/bounce.rs"]
mod bounce;
mod common;
use common::{dormand_prince, initial, pendulum_time};
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    Integrator, Rk4, SeriesRoom, Settings, Simulator, State, admissible,
};

// ------------------------------------------------------------ helpers

/// The bob of `PendulumWall` at rest at angle θ₀ on the left.
fn bob_at_rest(p: &PendulumWall, theta0: f64) -> State<2> {
    let l = p.params().l;
    State {
        t: 0.0,
        q: [-l * theta0.sin(), -l * theta0.cos()],
        v: [0.0, 0.0],
    }
}

// ------------------------------------------------------------ pendulum

/// With the wall out of reach (d > l) the Cartesian pendulum with its
/// holonomic rod has the elliptic-integral period, with both integrators,
/// and the projection keeps it on the circle.
#[test]
fn free_pendulum_has_the_elliptic_period() {
    let mut p = PendulumWall::default();
    assert!(p.set_parameter_named("d", 2.0));
    let (l, g) = (p.params().l, p.params().g);
    let theta0 = 1.2;
    // After one period, 4√(l/g) K(sin(θ₀/2)), the bob is back at rest at
    // its start.
    let period = 4.0 * pendulum_time(l, g, theta0, 0.0);
    for (settings, tol) in [
        (dormand_prince(1e-12), 1e-9),
        (
            Settings {
                integrator: Integrator::Rk4(Rk4 { step: 1e-3 }),
                ..Settings::default()
            },
            1e-9,
        ),
    ] {
        let start = bob_at_rest(&p, theta0);
        let mut room = SeriesRoom::new(&p);
        let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
        let mut worst = 0.0f64;
        let e0 = p.energy(&start.q, &start.v);
        sim.run(period, |s| {
            let r = s.residual(&p);
            worst = worst.max(r.position).max(r.velocity);
            let e = s.energy(&p);
            assert!((e - e0).abs() < 1e-8, "energy {e} vs {e0}");
            true
        })
        .unwrap();
        let end = sim.state();
        assert!(worst < 1e-12, "constraint residual {worst}");
        let miss = ((end.q[0] - start.q[0]).powi(2) + (end.q[1] - start.q[1]).powi(2)).sqrt();
        assert!(
            miss < tol,
            "{settings:?}: after one period the bob is {miss} from its start"
        );
    }
}

/// Released at θ₀ on the left, the bob meets the wall x = d at the
/// analytic time, bounces back with its velocity reversed (P = I), returns
/// to rest at the start at twice that time, and so on.
#[test]
fn pendulum_bounces_off_the_wall_as_the_textbook_says() {
    let p = PendulumWall::default();
    let (l, g, d) = (p.params().l, p.params().g, p.params().d);
    let theta0 = 1.0;
    let theta_w = (d / l).asin();
    let t_hit = pendulum_time(l, g, theta0, theta_w);
    let start = bob_at_rest(&p, theta0);
    let e0 = p.energy(&start.q, &start.v);
    let mut sim = Simulator::new(&p, start, dormand_prince(1e-12)).unwrap();
    let mut hits = Vec::new();
    sim.run(10.5 * t_hit, |s| {
        if let Some(c) = s.collision {
            hits.push(c);
        }
        true
    })
    .unwrap();
    assert_eq!(hits.len(), 5);
    for (j, c) in hits.iter().enumerate() {
        let expected = (2 * j + 1) as f64 * t_hit;
        assert!(
            (c.t - expected).abs() < 1e-9,
            "hit {j} at {} not {expected}",
            c.t
        );
        assert!(c.surface.abs() < 1e-14, "located at f = {}", c.surface);
        for i in 0..2 {
            assert!((c.v_plus[i] + c.v_minus[i]).abs() < 1e-12);
        }
        assert!((p.energy(&c.q, &c.v_plus) - e0).abs() < 1e-9);
    }
}

// ------------------------------------------------------------ §3.2.1

/// The paper's §3.2.1: thrown so that v_S⁻ = −v e_x − u e_z and
/// ω⁻ = (rmv/J) e_y, the ball comes back along its parabola. It bounces
/// alternately at x = 0 and x = 2uv/g, every 2u/g, forever.
///
/// Tolerance: between bounces the motion is a parabola, which the
/// fifth-order method reproduces up to rounding, and every bounce is
/// located by Newton's method to |f| ~ 1e-16. What is left is rounding in
/// a neutrally stable motion. Positions and energy do not depend on the
/// size of t; the collision instants do: each carries an error of the order
/// of the spacing of doubles near t (4.5e-13 at t ≈ 4000), so their error
/// grows with t. Observed after 10⁴ bounces (t ≈ 4077): 3.6e-12 relative in
/// time, 1.4e-12 in position, 3.2e-12 relative in energy.
/// We ask for 1e-11 relative in time, 1e-10 in position and in relative
/// energy: a few times the rounding seen, orders of magnitude below any
/// error of method or of modelling.
#[test]
fn nonholonomic_pendulum_is_periodic_over_ten_thousand_bounces() {
    let ball = BallBounce::default();
    let (r, g) = (ball.params().r, ball.params().g);
    let (u, v) = (bounce::U, bounce::V);
    let (q, v_minus) = bounce::before_bounce(&ball);
    let v_plus = ball.collide(dalembert::models::ball_bounce::Wall::Floor, &q, &v_minus);
    for i in 0..6 {
        assert!((v_plus[i] + v_minus[i]).abs() < 1e-14, "§3.2.1: v⁺ = −v⁻");
    }
    let start = State {
        t: 0.0,
        q,
        v: v_plus,
    };
    let e0 = ball.energy(&q, &v_plus);
    let mut sim = Simulator::new(&ball, start, dormand_prince(1e-10)).unwrap();
    let flight = 2.0 * u / g;
    let bounces = 10_000;
    let mut n = 0usize;
    let mut worst = [0.0f64; 3];
    sim.run((bounces as f64 + 0.5) * flight, |s| {
        if let Some(c) = s.collision {
            n += 1;
            let x = if n % 2 == 1 { 2.0 * u * v / g } else { 0.0 };
            worst[0] = worst[0].max((c.t - n as f64 * flight).abs() / c.t);
            worst[1] = worst[1].max((c.q[0] - x).abs() + c.q[1].abs() + (c.q[2] - r).abs());
            worst[2] = worst[2].max((ball.energy(&c.q, &c.v_plus) - e0).abs() / e0);
            // Each bounce sends the ball back the way it came.
            for i in 0..3 {
                assert!((c.v_plus[i] + c.v_minus[i]).abs() < 1e-9);
            }
        }
        true
    })
    .unwrap();
    assert_eq!(n, bounces);
    eprintln!(
        "after {n} bounces: |Δt|/t {:.1e}, |Δq| {:.1e}, |ΔE|/E {:.1e}",
        worst[0], worst[1], worst[2]
    );
    assert!(worst[0] < 1e-11, "relative time error {}", worst[0]);
    assert!(worst[1] < 1e-10, "position error {}", worst[1]);
    assert!(worst[2] < 1e-10, "energy error {}", worst[2]);
}

/// A flight in uniform gravity has f quadratic in time: each step is aimed
/// at the predicted bounce and ends on the floor, so a bounce costs one
/// step (six evaluations) and one evaluation after the collision map, with
/// no step across the floor to redo.
#[test]
fn parabolic_flights_end_on_the_floor_in_one_step() {
    let ball = BallBounce::default();
    let start = initial(&BallBounce::default());
    let flight = 2.0 * 2.0 / ball.params().g;
    let mut sim = Simulator::new(&ball, start, Settings::default()).unwrap();
    let mut n = 0u64;
    let stats = sim
        .run(100.5 * flight, |s| {
            if let Some(c) = s.collision {
                n += 1;
                assert!(
                    (c.t - n as f64 * flight).abs() <= 1e-12 * c.t,
                    "bounce {n} at {}",
                    c.t
                );
                assert!(c.surface.abs() <= 1e-14, "bounce {n}: f = {:e}", c.surface);
            }
            true
        })
        .unwrap();
    assert_eq!(stats.collisions, 100);
    // A few steps while the step size grows from its first guess.
    assert!(stats.steps <= 110, "{stats:?}");
    assert!(stats.evaluations <= 7 * 100 + 60, "{stats:?}");
}

/// The tip of the triple pendulum meets the floor along a curved path (f
/// has a non-zero Hessian): the adaptive integrator, whose steps are aimed
/// at predicted collisions, finds the same collisions as fixed small RK4
/// steps, which are never aimed.
#[test]
fn aimed_steps_find_the_collisions_fixed_steps_find() {
    let chain = Chain3::default();
    let start = initial(&Chain3::default());
    let collisions = |settings: Settings| {
        let mut room = SeriesRoom::new(&chain);
        let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
        let mut found = Vec::new();
        sim.run(3.0, |s| {
            found.extend(s.collision);
            true
        })
        .unwrap();
        found
    };
    let adaptive = collisions(dormand_prince(1e-11));
    let fixed = collisions(Settings {
        integrator: Integrator::Rk4(Rk4 { step: 1e-4 }),
        ..Settings::default()
    });
    eprintln!("{} collisions", adaptive.len());
    assert!(adaptive.len() >= 4, "{adaptive:?}");
    assert_eq!(adaptive.len(), fixed.len());
    let e0 = chain.energy(&start.q, &start.v);
    for (a, f) in adaptive.iter().zip(&fixed) {
        eprintln!("t {} vs {}: |Δt| {:.1e}", a.t, f.t, (a.t - f.t).abs());
        assert!((a.t - f.t).abs() < 1e-8, "{} vs {}", a.t, f.t);
        for i in 0..3 {
            assert!((a.q[i] - f.q[i]).abs() < 1e-7 && (a.v_plus[i] - f.v_plus[i]).abs() < 1e-6);
        }
        assert!(a.surface.abs() < 1e-13, "f = {:e}", a.surface);
        assert!((chain.energy(&a.q, &a.v_plus) - e0).abs() < 1e-9 * e0.abs().max(1.0));
    }
}

// ------------------------------------------------------------ §3.1

/// The angular velocity of `BallWallEuler` in the fixed frame.
fn omega(q: &[f64; 5], v: &[f64; 5]) -> [f64; 3] {
    let (phi, theta) = (q[2], q[3]);
    let (pd, td, sd) = (v[2], v[3], v[4]);
    [
        td * phi.cos() + sd * phi.sin() * theta.sin(),
        td * phi.sin() - sd * phi.cos() * theta.sin(),
        pd + sd * theta.cos(),
    ]
}

/// A spinning ball rolls under the uniform force m·a towards the wall:
/// its centre moves as x = x₀ + ẋ₀t − ½αt², α = m a r²/J', its spin ω₃ is
/// constant; it meets the wall x = r at the analytic instant, and the
/// collision is Theorem 3.1 (at whatever orientation the ball has by then).
#[test]
fn rolling_ball_meets_the_wall_as_theorem_3_1_says() {
    let ball = BallWallEuler::default();
    let p = *ball.params();
    let (m, r, j, a) = (p.m, p.r, p.J, p.a);
    let jp = j + r * r * m;
    let jt = j + r * r * m / 2.0;
    let alpha = m * a * r * r / jp;
    let (x0, speed, spin) = (1.5, 0.5, 2.0);
    // φ = ψ = 0, θ = π/2: ω = (θ', −ψ', φ'), rolling: ẋ = r ω_y.
    let q = [x0, 0.0, 0.0, std::f64::consts::FRAC_PI_2, 0.0];
    let v = admissible(&ball, &q, &[-speed, 0.0, spin, 0.0, speed / r]).unwrap();
    assert!((v[0] + speed).abs() < 1e-15 && (omega(&q, &v)[2] - spin).abs() < 1e-15);
    let start = State { t: 0.0, q, v };
    let e0 = ball.energy(&q, &v);
    let mut sim = Simulator::new(&ball, start, dormand_prince(1e-12)).unwrap();
    let t_hit = (-speed + (speed * speed + 2.0 * alpha * (x0 - r)).sqrt()) / alpha;
    let mut hit = None;
    sim.run(t_hit + 0.2, |s| {
        let e = s.energy(&ball);
        assert!((e - e0).abs() < 1e-9, "energy drift {}", e - e0);
        assert!(s.residual(&ball).velocity < 1e-12);
        let t = s.state.t;
        if hit.is_none() && s.collision.is_none() {
            let x = x0 - speed * t - 0.5 * alpha * t * t;
            assert!(
                (s.state.q[0] - x).abs() < 1e-9,
                "x({t}) = {} not {x}",
                s.state.q[0]
            );
            assert!((omega(&s.state.q, &s.state.v)[2] - spin).abs() < 1e-9);
        }
        if let Some(c) = s.collision {
            hit = Some(c);
        }
        true
    })
    .unwrap();
    let c = hit.expect("the ball reaches the wall");
    assert!((c.t - t_hit).abs() < 1e-9, "hit at {} not {t_hit}", c.t);
    assert!((c.q[0] - r).abs() < 1e-14);
    // Theorem 3.1 in the paper's variables (v₁, v₂, ω₃).
    let (v1, v2, w3) = (c.v_minus[0], c.v_minus[1], omega(&c.q, &c.v_minus)[2]);
    assert!((v1 + speed + alpha * t_hit).abs() < 1e-9);
    let expected = [
        -v1,
        r * r * m / (2.0 * jt) * v2 + r * j / jt * w3,
        jp / (r * jt) * v2 - r * r * m / (2.0 * jt) * w3,
    ];
    let got = [c.v_plus[0], c.v_plus[1], omega(&c.q, &c.v_plus)[2]];
    for i in 0..3 {
        assert!(
            (got[i] - expected[i]).abs() < 1e-12,
            "Theorem 3.1, component {i}: {got:?} vs {expected:?}"
        );
    }
    // And it keeps rolling with the new spin.
    assert!((omega(&sim.state().q, &sim.state().v)[2] - expected[2]).abs() < 1e-9);
}

// ------------------------------------------------------------ textbook

/// Two masses in a box, followed collision by collision: every event is
/// the one free flight predicts (which wall, when), and every impact of
/// the two bodies is the textbook law.
#[test]
fn two_masses_in_a_box_follow_the_textbook_event_by_event() {
    use dalembert::models::masses_on_line::Wall;
    let sys = MassesOnLine::default();
    let (m1, m2, len) = (sys.params().m1, sys.params().m2, sys.params().L);
    let start = State {
        t: 0.0,
        q: [0.2, 0.6],
        v: [1.0, -0.5],
    };
    let e0 = sys.energy(&start.q, &start.v);
    let mut sim = Simulator::new(&sys, start, dormand_prince(1e-10)).unwrap();
    let mut prev = start;
    let mut events = 0;
    sim.run(40.0, |s| {
        let Some(c) = s.collision else { return true };
        events += 1;
        // Free flight from the previous event: the first wall reached.
        let (x, u) = (prev.q, prev.v);
        let candidates = [
            (
                Wall::Left,
                if u[0] < 0.0 {
                    -x[0] / u[0]
                } else {
                    f64::INFINITY
                },
            ),
            (
                Wall::Contact,
                if u[1] - u[0] < 0.0 {
                    (x[1] - x[0]) / (u[0] - u[1])
                } else {
                    f64::INFINITY
                },
            ),
            (
                Wall::Right,
                if u[1] > 0.0 {
                    (len - x[1]) / u[1]
                } else {
                    f64::INFINITY
                },
            ),
        ];
        let (wall, dt) =
            candidates.into_iter().fold(
                (Wall::Left, f64::INFINITY),
                |b, c| if c.1 < b.1 { c } else { b },
            );
        assert_eq!(c.wall, wall, "event {events}");
        assert!(
            (c.t - (prev.t + dt)).abs() < 1e-12 * (1.0 + c.t),
            "event {events}: {} vs {}",
            c.t,
            prev.t + dt
        );
        let [u1, u2] = c.v_minus;
        let expected = match wall {
            Wall::Left => [-u1, u2],
            Wall::Right => [u1, -u2],
            Wall::Contact => [
                ((m1 - m2) * u1 + 2.0 * m2 * u2) / (m1 + m2),
                ((m2 - m1) * u2 + 2.0 * m1 * u1) / (m1 + m2),
            ],
        };
        for (got, want) in c.v_plus.iter().zip(expected) {
            assert!((got - want).abs() < 1e-13);
        }
        assert!((sys.energy(&c.q, &c.v_plus) - e0).abs() < 1e-12);
        prev = State {
            t: c.t,
            q: c.q,
            v: c.v_plus,
        };
        true
    })
    .unwrap();
    assert!(events > 50, "only {events} events");
}

/// The same box at every scale: lengths times 1e-12 or 1e12, speeds times
/// 1e12 or 1e-3, the same walls are met in the same order at the same
/// instants in units of length/speed. (A contact window in absolute time
/// made the small box "simultaneous" at its first collision.)
#[test]
fn the_box_is_the_same_box_at_every_scale() {
    use dalembert::models::masses_on_line::{Params, Wall};
    let events = |len: f64, speed: f64| -> Vec<(Wall, f64)> {
        let sys = MassesOnLine::with_params(Params {
            L: len,
            ..Params::default()
        });
        let start = State {
            t: 0.0,
            q: [0.2 * len, 0.6 * len],
            v: [speed, -0.5 * speed],
        };
        let mut settings = dormand_prince(1e-10);
        if let Integrator::DormandPrince(dp) = &mut settings.integrator {
            dp.atol = 1e-14 * len.min(speed);
        }
        let unit = len / speed;
        let mut room = SeriesRoom::new(&sys);
        let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
        let mut seen = Vec::new();
        // Events are compared up to 39.5 units, short of the run's end, so
        // that one landing at the very end of one run and just after the end
        // of another is not counted (no event is near 39.5).
        sim.run(40.0 * unit, |s| {
            if let Some(c) = s.collision.filter(|c| c.t < 39.5 * unit) {
                seen.push((c.wall, c.t / unit));
            }
            true
        })
        .unwrap_or_else(|e| panic!("length {len:e}, speed {speed:e}: {e}"));
        seen
    };
    let reference = events(1.0, 1.0);
    assert!(reference.len() > 50, "only {} events", reference.len());
    for (len, speed) in [(1e-12, 1.0), (1.0, 1e12), (1e12, 1e-3), (1e-12, 1e-12)] {
        let scaled = events(len, speed);
        assert_eq!(
            scaled.len(),
            reference.len(),
            "length {len:e}, speed {speed:e}"
        );
        for (k, (a, b)) in reference.iter().zip(&scaled).enumerate() {
            assert_eq!(a.0, b.0, "event {k}, length {len:e}, speed {speed:e}");
            assert!(
                (a.1 - b.1).abs() <= 1e-9 * (1.0 + a.1),
                "event {k}, length {len:e}, speed {speed:e}: {} vs {}",
                a.1,
                b.1
            );
        }
    }
}

/// Stepping to the next collision, whenever it comes (`t_end` infinite),
/// with every method: the same bounces at n·(2·2/g) as a run to a finite
/// end. Taylor's method evaluated a flight's exact series at τ = ∞ there
/// (its series bounds no step) and failed with a non-finite state.
#[test]
fn stepping_to_the_next_collision_needs_no_end() {
    let ball = BallBounce::default();
    let start = initial(&ball);
    let flight = 2.0 * 2.0 / ball.params().g;
    let methods = [
        Settings::default(),
        Settings {
            integrator: Integrator::Taylor(Default::default()),
            ..Settings::default()
        },
        Settings {
            integrator: Integrator::Rk4(Rk4 { step: 1e-3 }),
            ..Settings::default()
        },
    ];
    for settings in methods {
        let mut room = SeriesRoom::new(&ball);
        let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
        for n in 1..=5 {
            let step = loop {
                let step = sim
                    .step(f64::INFINITY)
                    .unwrap_or_else(|e| panic!("{:?}: {e:?}", settings.integrator));
                assert!(step.state.t.is_finite());
                if step.collision.is_some() {
                    break step;
                }
            };
            let c = step.collision.unwrap();
            assert!(
                (c.t - n as f64 * flight).abs() <= 1e-9 * c.t,
                "{:?}: bounce {n} at {}",
                settings.integrator,
                c.t
            );
        }
    }
}
