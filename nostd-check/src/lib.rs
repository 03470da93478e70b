//! A crate without `std` that links the runtime and generated models.
//!
//! `.ci/run` builds it as a static library for the host with
//! `panic = abort`:
//!
//! ```sh
//! cargo rustc --release -p dalembert-nostd-check --crate-type staticlib -- -C panic=abort
//! ```
//!
//! It defines its own panic handler, so if anything it links (the runtime,
//! the generated models, their dependencies) pulls in `std`, the build fails
//! with a duplicate `panic_impl`; a generated function that calls a `std`-only
//! method (`f64::sin`) fails to compile. Searching sources for `#![no_std]`
//! would miss both.
#![no_std]

use dalembert::models::{BallBounce, BallFloor, Chain4, PendulumWall};
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{Integrator, SeriesRoom, Settings, Simulator, State, Taylor};

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}

/// The §3.2 collision map at the paper's §3.2.1 data (closed-form P).
#[unsafe(no_mangle)]
pub extern "C" fn dalembert_nostd_collide(out: &mut [f64; 6]) {
    let ball = BallFloor::default();
    *out = ball.floor_collide(&[], &[-1.5, 0.0, -2.0, 0.0, 7.5, 0.0]);
}

/// A structured collision map (P solved at run time from G and B).
#[unsafe(no_mangle)]
pub extern "C" fn dalembert_nostd_chain(out: &mut [f64; 4]) {
    let chain = Chain4::default();
    let q = [0.3, 0.7, 1.1, 1.5];
    *out = chain.collide(Chain4::WALLS[0], &q, &[0.1, -0.2, 0.3, -0.4]);
}

/// The hybrid simulator through collisions: the ball in flight over a
/// second, and the pendulum with its holonomic projection; returns the
/// number of collisions, or −1 on a simulation error.
#[unsafe(no_mangle)]
pub extern "C" fn dalembert_nostd_simulate() -> i64 {
    fn run<M: Surfaces<N>, const N: usize>(m: &M) -> i64 {
        let start = State {
            t: 0.0,
            q: m.initial_coordinates(),
            v: m.initial_velocities(),
        };
        let Ok(mut sim) = Simulator::new(m, start, Settings::default()) else {
            return -1;
        };
        match sim.run(1.0, |_| true) {
            Ok(stats) => stats.collisions as i64,
            Err(_) => -1,
        }
    }
    let a = run(&BallBounce::default());
    let b = run(&PendulumWall::default());
    if a < 0 || b < 0 { -1 } else { a + b }
}

/// Taylor's method, its series and scratch in a room on the stack: the
/// ball through a second of flight; the number of collisions, or −1 on a
/// simulation error.
#[unsafe(no_mangle)]
pub extern "C" fn dalembert_nostd_taylor() -> i64 {
    let ball = BallBounce::default();
    let start = State {
        t: 0.0,
        q: ball.initial_coordinates(),
        v: ball.initial_velocities(),
    };
    let settings = Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    };
    let mut room = SeriesRoom::new(&ball);
    let Ok(mut sim) = Simulator::with_series(&mut room, start, settings) else {
        return -1;
    };
    match sim.run(1.0, |_| true) {
        Ok(stats) => stats.collisions as i64,
        Err(_) => -1,
    }
}
