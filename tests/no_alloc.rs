//! Every generated function runs without touching the heap: a counting
//! global allocator sees zero allocations while they run.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use dalembert::for_each_model;
use dalembert::models::*;
use dalembert::runtime::linalg::projector;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    ParameterSensitivity, SeriesRoom, Settings, Simulator, State, Variational,
};

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|a| a.set(a.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new: usize) -> *mut u8 {
        ALLOCATIONS.with(|a| a.set(a.get() + 1));
        unsafe { System.realloc(ptr, layout, new) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations_during(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.with(Cell::get);
    f();
    ALLOCATIONS.with(Cell::get) - before
}

/// A simulation of `m` from `start` to `t_end`, with Φ = ∂x/∂x₀ followed
/// ([`Variational`]) and the derivative by the parameters along
/// (1, 1, …) ([`ParameterSensitivity`]): the collisions met and the heap
/// allocations made, from the simulator's construction on.
fn simulated<M: TaylorSeries<N>, const N: usize>(
    m: &M,
    start: State<N>,
    settings: Settings,
    t_end: f64,
) -> (u64, usize) {
    let mut collisions = 0;
    let dp = [1.0; 16];
    let dp = &dp[..m.parameter_names().len()];
    let n = allocations_during(|| {
        let mut room = SeriesRoom::new(m);
        let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
        let mut phi = Variational::new(1e-10);
        let mut by_p = ParameterSensitivity::new(dp, 1e-10);
        while sim.state().t < t_end {
            let step = sim.step(t_end).unwrap();
            collisions += u64::from(step.collision.is_some());
            // Φ carried along, through the collisions.
            phi.follow(&sim, &step).unwrap();
            by_p.follow(&sim, &step).unwrap();
            // The motion inside the step, off its dense output, too.
            let inside = sim.state_at(0.5 * (step.t0 + step.state.t));
            std::hint::black_box(inside.unwrap());
        }
    });
    (collisions, n)
}

/// Calls every function of the `Model` and `Walls` traits (and the
/// runtime's generic projector) and returns a checksum so nothing is
/// optimised away.
fn exercise<M: Walls<Q, N>, const Q: usize, const N: usize>(m: &M) -> f64 {
    let q: [f64; Q] = std::array::from_fn(|i| 0.4 + 0.1 * i as f64);
    let v: [f64; N] = std::array::from_fn(|i| 0.3 - 0.2 * i as f64);
    let mut s = m.kinetic_energy(&q, &v) + m.mass_matrix(&q)[0][0];
    s += m.constraints(&q).apply(&v).max_abs();
    for &w in m.walls() {
        s += m.normal(w, &q)[0];
        s += m.wall_rows(w, &q).as_slice().len() as f64;
        s += m.projector(w, &q)[0][0];
        s += m.collide(w, &q, &v)[0];
        s += m.normal_velocity(w, &q, &v);
        let g = m.mass_matrix(&q);
        if let Ok(p) = projector(&g, m.wall_rows(w, &q).as_slice()) {
            s += p[0][0];
        }
    }
    s
}

/// The `Dynamics` and `Surfaces` functions of a model with coordinates,
/// the closed-form and numeric q̈ included.
fn exercise_motion<M: TaylorSeries<N>, const N: usize>(m: &M) -> f64 {
    let q: [f64; N] = std::array::from_fn(|i| 0.4 + 0.1 * i as f64);
    let v: [f64; N] = std::array::from_fn(|i| 0.3 - 0.2 * i as f64);
    let mut s = m.energy(&q, &v);
    s += m.forcing(&q, &v)[0] + m.constraint_drift(&q, &v)[0];
    s += m.holonomic(&q).max_abs();
    if let Some(x) = m.closed_form_accelerations(&q, &v) {
        s += x[0];
    }
    if let Ok(a) = dalembert::runtime::dynamics::accelerations(m, &q, &v) {
        s += a.qdd[0];
    }
    let mut series = dalembert::runtime::taylor::Series::at(&q, &v);
    let mut f = [0.0; dalembert::runtime::taylor::CAPACITY];
    let mut scratch = M::SeriesScratch::default();
    if m.taylor_series(&mut series, &mut scratch, 20) {
        s += series.q[0][20];
    }
    for &w in m.walls() {
        s += m.surface(w, &q);
        s += m.surface_hessian(w, &q, &v).unwrap_or(0.0);
        if m.surface_series(w, &series, &mut scratch, &mut f) {
            s += f[series.order];
        }
    }
    s
}

macro_rules! no_alloc_test {
    ($module:ident, $ty:ident, 0, $n:literal) => {
        #[test]
        fn $module() {
            let model = <$ty>::with_params(Default::default());
            let mut sum = 0.0;
            let n = allocations_during(|| sum = exercise::<$ty, 0, $n>(&model));
            assert!(sum.is_finite());
            assert_eq!(n, 0, "{} allocated {n} times", stringify!($ty));
        }
    };
    ($module:ident, $ty:ident, $q:literal, $n:literal) => {
        #[test]
        fn $module() {
            let model = <$ty>::with_params(Default::default());
            let mut sum = 0.0;
            let n = allocations_during(|| {
                sum = exercise::<$ty, $q, $n>(&model) + exercise_motion::<$ty, $n>(&model)
            });
            assert!(sum.is_finite());
            assert_eq!(n, 0, "{} allocated {n} times", stringify!($ty));
        }
    };
}

for_each_model!(no_alloc_test);

/// The simulator, collisions included, with every integrator: the
/// §3.2.1 ball over some 20 bounces and the Cartesian pendulum (holonomic
/// projection) against its wall.
#[test]
fn simulator_does_not_allocate() {
    use dalembert::runtime::simulate::{Integrator, Rk4, Taylor};
    let ball = BallBounce::default();
    let r = ball.params().r;
    let q = [0.0, 0.0, r + 1.0, 0.0, std::f64::consts::FRAC_PI_2, 0.0];
    let v = [1.0, 0.0, 0.0, 0.0, 0.0, -5.0];
    let rk4 = Settings {
        integrator: Integrator::Rk4(Rk4 { step: 1e-3 }),
        ..Settings::default()
    };
    let taylor = Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    };
    for settings in [Settings::default(), rk4, taylor] {
        let (collisions, n) = simulated(&ball, State { t: 0.0, q, v }, settings, 20.0);
        assert!(collisions >= 20, "{collisions} bounces");
        assert_eq!(n, 0, "the simulator allocated {n} times");
        let pendulum = PendulumWall::default();
        let start = State {
            t: 0.0,
            q: [-0.8, -0.6],
            v: [0.0, 0.0],
        };
        let (hits, n) = simulated(&pendulum, start, settings, 10.0);
        assert!(hits >= 5, "{hits} hits");
        assert_eq!(n, 0, "the simulator allocated {n} times");
    }
}

/// The counter works: a heap allocation is seen.
#[test]
fn the_counter_sees_allocations() {
    let n = allocations_during(|| {
        let v = std::hint::black_box(vec![1.0_f64; 16]);
        assert_eq!(v.len(), 16);
    });
    assert!(n >= 1);
}

/// A model file run by the interpreter (`dalembert simulate FILE`): once
/// its buffers are sized by a first call, the Taylor series of the motion
/// and of each wall allocate nothing, and neither does a whole run of
/// Taylor's method through collisions.
#[test]
fn interpreted_series_do_not_allocate() {
    use dalembert::runtime::simulate::{Integrator, Taylor};
    use dalembert::runtime::taylor::{CAPACITY, Series};
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/ball_bounce.toml");
    let d = dalembert_codegen::derive(&file).unwrap();
    let ball = dalembert_codegen::interpret::Interpreted::<6>::new(&d).unwrap();
    let start = State {
        t: 0.0,
        q: ball.initial_coordinates(),
        v: ball.initial_velocities(),
    };
    // The interpreter keeps the room for its intermediate series itself:
    // the first call sizes it.
    let series = || {
        let mut s = Series::at(&start.q, &start.v);
        assert!(ball.taylor_series(&mut s, &mut (), 20));
        let mut f = [0.0; CAPACITY];
        for &w in ball.walls() {
            assert!(ball.surface_series(w, &s, &mut (), &mut f));
        }
        // And the variational series along it (Φ is followed below).
        let mut columns = [Series::at(&start.v, &start.q); 1];
        assert!(ball.variational_series(&s, &mut columns));
        f[2] + columns[0].q[0][3]
    };
    let first = series();
    let mut again = 0.0;
    assert_eq!(allocations_during(|| again = series()), 0);
    assert_eq!(first, again);
    let taylor = Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    };
    let (collisions, n) = simulated(&ball, start, taylor, 5.0);
    assert!(collisions >= 10, "{collisions} bounces");
    assert_eq!(n, 0, "the interpreted run allocated {n} times");
}
