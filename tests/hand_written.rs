//! A model written by hand against the runtime's traits, with no generator
//! and no Taylor series: a point in the unit disk, a billiard. It
//! implements `Model`, `Walls`, `Dynamics` and `Surfaces` and names no
//! scratch type; the Runge–Kutta methods run it, and Taylor's method is
//! refused with a typed error. Its collision instants are checked against
//! the closed form: the chord a free point crosses the disk along has the
//! same length after every reflection (the angular momentum about the
//! centre is kept), so the collisions are equally spaced in time.
//!
//! And the buffers of Taylor's method live only in a `SeriesRoom`: a
//! Runge–Kutta simulator of `chain_8` is smaller than one series of it.

use dalembert::models::Chain8;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    DormandPrince, Integrator, Rk4, SeriesRoom, Settings, SimError, Simulator, State, Taylor,
};
use dalembert::runtime::taylor::Series;
use dalembert::runtime::{Rows, Values};

/// A unit-mass point in the disk x² + y² ≤ 1, no forces.
struct Disk;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Rim;

impl Model<2, 2> for Disk {
    fn name(&self) -> &str {
        "disk"
    }
    fn coordinate_names(&self) -> &[&str] {
        &["x", "y"]
    }
    fn velocity_names(&self) -> &[&str] {
        &["x_dot", "y_dot"]
    }
    fn parameter_names(&self) -> &[&str] {
        &[]
    }
    fn parameter(&self, _: usize) -> Option<f64> {
        None
    }
    fn set_parameter(&mut self, _: usize, _: f64) -> bool {
        false
    }
    fn mass_matrix(&self, _: &[f64; 2]) -> [[f64; 2]; 2] {
        [[1.0, 0.0], [0.0, 1.0]]
    }
    fn kinetic_energy(&self, _: &[f64; 2], v: &[f64; 2]) -> f64 {
        0.5 * (v[0] * v[0] + v[1] * v[1])
    }
    fn constraints(&self, _: &[f64; 2]) -> Rows<2> {
        Rows::EMPTY
    }
}

impl Walls<2, 2> for Disk {
    type Wall = Rim;
    fn walls(&self) -> &[Rim] {
        &[Rim]
    }
    fn wall_name(&self, _: Rim) -> &str {
        "rim"
    }
    /// B = df = (−2x, −2y).
    fn wall_rows(&self, _: Rim, q: &[f64; 2]) -> Rows<2> {
        Rows::new([[-2.0 * q[0], -2.0 * q[1]], [0.0; 2]], 1)
    }
    /// P = n nᵀ / |n|² (G = I).
    fn projector(&self, _: Rim, q: &[f64; 2]) -> [[f64; 2]; 2] {
        let r2 = q[0] * q[0] + q[1] * q[1];
        [
            [q[0] * q[0] / r2, q[0] * q[1] / r2],
            [q[1] * q[0] / r2, q[1] * q[1] / r2],
        ]
    }
    fn collide(&self, wall: Rim, q: &[f64; 2], v: &[f64; 2]) -> [f64; 2] {
        let p = self.projector(wall, q);
        [
            v[0] - 2.0 * (p[0][0] * v[0] + p[0][1] * v[1]),
            v[1] - 2.0 * (p[1][0] * v[0] + p[1][1] * v[1]),
        ]
    }
}

impl Dynamics<2> for Disk {
    fn potential(&self, _: &[f64; 2]) -> f64 {
        0.0
    }
    fn holonomic(&self, _: &[f64; 2]) -> Values<2> {
        Values::EMPTY
    }
    fn forcing(&self, _: &[f64; 2], _: &[f64; 2]) -> [f64; 2] {
        [0.0; 2]
    }
    fn constraint_drift(&self, _: &[f64; 2], _: &[f64; 2]) -> [f64; 2] {
        [0.0; 2]
    }
}

impl Surfaces<2> for Disk {
    fn surface(&self, _: Rim, q: &[f64; 2]) -> f64 {
        1.0 - q[0] * q[0] - q[1] * q[1]
    }
    fn surface_hessian(&self, _: Rim, _: &[f64; 2], v: &[f64; 2]) -> Option<f64> {
        Some(-2.0 * (v[0] * v[0] + v[1] * v[1]))
    }
}

/// The first `n` collision instants from `q0` with velocity `u`: the first
/// where |q0 + u t| = 1, then one every chord 2√(1 − d²) over |u|, d the
/// line's distance from the centre.
fn instants(q0: [f64; 2], u: [f64; 2], n: usize) -> Vec<f64> {
    let uu = u[0] * u[0] + u[1] * u[1];
    let qu = q0[0] * u[0] + q0[1] * u[1];
    let qq = q0[0] * q0[0] + q0[1] * q0[1];
    let first = (-qu + (qu * qu + uu * (1.0 - qq)).sqrt()) / uu;
    let cross = q0[0] * u[1] - q0[1] * u[0];
    let d2 = cross * cross / uu;
    let every = 2.0 * (1.0 - d2).sqrt() / uu.sqrt();
    (0..n).map(|k| first + k as f64 * every).collect()
}

#[test]
fn a_hand_written_billiard_collides_at_its_closed_form_instants() {
    let (q, v) = ([0.5, 0.0], [1.0, 1.0 / 3.0]);
    let start = State { t: 0.0, q, v };
    let expected = instants(q, v, 40);
    for (name, integrator, within) in [
        (
            "Dormand–Prince",
            Integrator::DormandPrince(DormandPrince {
                rtol: 1e-12,
                atol: 1e-12,
                ..DormandPrince::default()
            }),
            1e-9,
        ),
        ("RK4", Integrator::Rk4(Rk4 { step: 1e-3 }), 1e-9),
    ] {
        let settings = Settings {
            integrator,
            ..Settings::default()
        };
        let mut sim = Simulator::new(&Disk, start, settings).unwrap();
        let mut found = Vec::new();
        sim.run(expected[39] + 0.1, |step| {
            if let Some(c) = &step.collision {
                found.push(c.t);
            }
            true
        })
        .unwrap();
        assert_eq!(found.len(), expected.len(), "{name}");
        for (k, (a, b)) in found.iter().zip(&expected).enumerate() {
            assert!(
                (a - b).abs() < within,
                "{name}: collision {k} at {a}, not {b}"
            );
        }
        let x = sim.state();
        let e = Disk.energy(&x.q, &x.v);
        assert!((e - Disk.energy(&q, &v)).abs() < 1e-9, "{name}: energy {e}");
    }
    // Taylor's method needs series, which this model does not have, and
    // room for them, which `Simulator::new` does not take.
    let taylor = Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    };
    assert!(matches!(
        Simulator::new(&Disk, start, taylor),
        Err(SimError::NoSeries)
    ));
}

/// A Runge–Kutta simulator of `chain_8` (N = 8) holds no buffer of
/// Taylor's method: it is smaller than one series of the motion, which
/// the room of a Taylor simulator holds along with the model's scratch.
/// Before the room, every simulator carried both inline.
#[test]
fn only_a_series_room_holds_the_buffers_of_taylors_method() {
    let simulator = size_of::<Simulator<'static, Chain8, 8>>();
    let series = size_of::<Series<8>>();
    let room = size_of::<SeriesRoom<'static, Chain8, 8>>();
    let scratch = size_of::<<Chain8 as TaylorSeries<8>>::SeriesScratch>();
    eprintln!(
        "chain_8: simulator {simulator} bytes, series {series}, scratch {scratch}, room {room}"
    );
    assert!(simulator < series, "{simulator} ≥ {series}");
    assert!(room >= series + scratch);
    // And the room makes a Taylor simulator of it that steps.
    let m = Chain8::default();
    let start = State {
        t: 0.0,
        q: m.initial_coordinates(),
        v: m.initial_velocities(),
    };
    let taylor = Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    };
    let mut room = SeriesRoom::new(&m);
    let mut sim = Simulator::with_series(&mut room, start, taylor).unwrap();
    let step = sim.step(1.0).unwrap();
    assert!(step.state.t > 0.0);
}
