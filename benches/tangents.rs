//! The cost of derivatives: for q̈ and a wall's collision map of
//! `ball_wall_euler`, `chain_3` and `chain_8`, side by side in one run,
//!
//! - `value`: the function itself (`closed_form_accelerations`, `collide`);
//! - `tangent`: the value and its derivative along one direction
//!   (`accelerations_tangent`, `collide_tangent`);
//! - `jacobian`: the whole Jacobian by 2N (resp. Q + N) tangents
//!   (`accelerations_jacobian`, `collide_jacobian`).
//!
//! And runs with and without Φ or ∂x/∂p followed (`simulate::Variational`,
//! `simulate::ParameterSensitivity`, `variational` below); §3.2.1's
//! two-bounce return map with
//! and without DΠ (`simulate::return_map`, rtol 1e-12), and the search of
//! its orbit from the paper's start with ẋ off by 1e-3 (`periodic::find`,
//! one Newton step at its default tolerance).
//!
//! The tangent's value is checked equal to the function's first. Time is
//! the thread's CPU time. Run: `cargo bench --bench tangents`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use dalembert::runtime::prelude::*;

#[path = "common/cpu_time.rs"]
mod cpu_time;
use cpu_time::ThreadCpuTime;

fn one<M: Surfaces<N> + Default, const N: usize>(c: &mut Criterion<ThreadCpuTime>) {
    let m = M::default();
    let q = m.initial_coordinates();
    let v: [f64; N] = std::array::from_fn(|i| 0.3 - 0.1 * i as f64);
    let (dq, dv): ([f64; N], [f64; N]) = (
        std::array::from_fn(|i| 0.1 * i as f64 - 0.2),
        std::array::from_fn(|i| 1.0 - 0.05 * i as f64),
    );
    let w = m.walls()[0];
    let a = m.closed_form_accelerations(&q, &v).unwrap();
    assert_eq!(m.accelerations_tangent(&q, &v, &dq, &dv).unwrap().0, a);
    let after = m.collide(w, &q, &v);
    assert_eq!(m.collide_tangent(w, &q, &v, &dq, &dv).unwrap().0, after);
    let mut g = c.benchmark_group(format!("tangents/{}", m.name()));
    g.bench_function("accelerations/value", |b| {
        b.iter(|| m.closed_form_accelerations(black_box(&q), black_box(&v)))
    });
    g.bench_function("accelerations/tangent", |b| {
        b.iter(|| m.accelerations_tangent(black_box(&q), black_box(&v), &dq, &dv))
    });
    g.bench_function("accelerations/jacobian", |b| {
        b.iter(|| m.accelerations_jacobian(black_box(&q), black_box(&v)))
    });
    g.bench_function("collide/value", |b| {
        b.iter(|| m.collide(w, black_box(&q), black_box(&v)))
    });
    g.bench_function("collide/tangent", |b| {
        b.iter(|| m.collide_tangent(w, black_box(&q), black_box(&v), &dq, &dv))
    });
    g.bench_function("collide/jacobian", |b| {
        b.iter(|| m.collide_jacobian(w, black_box(&q), black_box(&v)))
    });
    g.finish();
}

/// Runs from the models' files' starts alone, with Φ followed after every
/// step, and with ∂x/∂p along one parameter: §3.2.1's bounce
/// (`ball_bounce`, N = 6; p the ball's radius, which moves the floor and
/// the map) through 10⁴ bounces by Dormand–Prince (its default tolerance),
/// 10³ by RK4 (step 10⁻³), whose steps Φ is carried through, and 100 by
/// Taylor's method, along whose steps Φ is integrated at rtol 1e-10; and
/// the pendulum at its wall (`pendulum_wall`, N = 2, p the rod's length)
/// through 10³ collisions by Dormand–Prince. The ball's flight is a
/// polynomial in time (one Dormand–Prince step resolves it) while its
/// perturbations are not; the pendulum's flight is not polynomial either.
fn variational(c: &mut Criterion<ThreadCpuTime>) {
    use dalembert::models::{BallBounce, PendulumWall};
    use dalembert::runtime::simulate::{Integrator, Rk4, Settings, Taylor};
    let with = |integrator| Settings {
        integrator,
        ..Settings::default()
    };
    let ball = BallBounce::default();
    along_runs(
        c,
        &ball,
        "r",
        &[
            ("dormand_prince", Settings::default(), 10_000),
            ("rk4", with(Integrator::Rk4(Rk4 { step: 1e-3 })), 1_000),
            ("taylor", with(Integrator::Taylor(Taylor::default())), 100),
        ],
    );
    along_runs(
        c,
        &PendulumWall::default(),
        "l",
        &[("dormand_prince", Settings::default(), 1_000)],
    );
}

/// One model of [`variational`]: for each (method, settings, collisions),
/// the run alone, with Φ and with ∂x/∂`p`.
fn along_runs<M: TaylorSeries<N>, const N: usize>(
    c: &mut Criterion<ThreadCpuTime>,
    m: &M,
    p: &str,
    methods: &[(&str, dalembert::runtime::simulate::Settings, usize)],
) {
    use dalembert::runtime::simulate::{
        ParameterSensitivity, SeriesRoom, Simulator, State, Variational,
    };
    let start = State {
        t: 0.0,
        q: m.initial_coordinates(),
        v: m.initial_velocities(),
    };
    let k = (m.parameter_names().iter())
        .position(|name| *name == p)
        .expect("a parameter of the model");
    let dp: Vec<f64> = (0..m.parameter_names().len())
        .map(|i| f64::from(u8::from(i == k)))
        .collect();
    for &(name, settings, bounces) in methods {
        // (follow Φ, follow ∂x/∂p)
        let run = |(phi_on, dp_on): (bool, bool)| {
            let mut room = SeriesRoom::new(m);
            let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
            let mut phi = Variational::new(1e-10);
            let mut by_p = ParameterSensitivity::new(&dp, 1e-10);
            let mut met = 0;
            while met < bounces {
                let step = sim.step(f64::INFINITY).unwrap();
                met += step.collision.is_some() as usize;
                if phi_on {
                    phi.follow(&sim, &step).unwrap();
                }
                if dp_on {
                    by_p.follow(&sim, &step).unwrap();
                }
            }
            (*sim.state(), *phi.matrix(), by_p.value())
        };
        let plain = run((false, false)).0;
        assert_eq!(
            plain,
            run((true, false)).0,
            "following Φ leaves the run alone"
        );
        assert_eq!(plain, run((false, true)).0, "following ∂x/∂{p} too");
        let group = format!("variational/{}_{bounces}_collisions/{name}", m.name());
        let mut g = c.benchmark_group(group);
        g.sample_size(10);
        g.bench_function("run", |b| b.iter(|| run(black_box((false, false)))));
        g.bench_function("run_and_phi", |b| b.iter(|| run(black_box((true, false)))));
        g.bench_function(format!("run_and_d_by_{p}"), |b| {
            b.iter(|| run(black_box((false, true))))
        });
        g.finish();
    }
}

/// §3.2.1's return map over two bounces, alone and with DΠ, and the
/// orbit's search.
fn periodic(c: &mut Criterion<ThreadCpuTime>) {
    use dalembert::models::BallBounce;
    use dalembert::runtime::simulate::{Section, State, return_map};
    use dalembert_periodic::{Search, find};
    let m = BallBounce::default();
    let start = State {
        t: 0.0,
        q: m.initial_coordinates(),
        v: m.initial_velocities(),
    };
    let section = Section {
        wall: BallBounce::WALLS[0],
        returns: 2,
        t_max: 100.0,
    };
    let search = Search::default();
    let map = |jacobian| return_map(&m, start, &section, search.settings, jacobian).unwrap();
    assert_eq!(map(None).state, map(Some(1e-12)).state, "DΠ leaves Π alone");
    let mut off = start;
    off.v[0] += 1e-3;
    let orbit = find(&m, off, &section, &search).unwrap();
    assert_eq!(
        orbit.iterations, 1,
        "one Newton step at the default tolerance"
    );
    let mut g = c.benchmark_group("periodic/ball_bounce_two_bounces");
    g.bench_function("return_map", |b| b.iter(|| map(black_box(None))));
    g.bench_function("return_map_and_jacobian", |b| {
        b.iter(|| map(black_box(Some(1e-12))))
    });
    g.bench_function("find_from_1e-3_off", |b| {
        b.iter(|| find(&m, black_box(off), &section, &search).unwrap())
    });
    g.finish();
}

fn models(c: &mut Criterion<ThreadCpuTime>) {
    use dalembert::models::*;
    one::<BallWallEuler, 5>(c);
    one::<Chain3, 3>(c);
    one::<Chain8, 8>(c);
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpuTime);
    targets = models, variational, periodic
}
criterion_main!(benches);
