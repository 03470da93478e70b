//! Taylor's method in the simulator, on the models' generated series
//! (checked in `tests/taylor_series.rs`): the paper's §3.2.1 run in two
//! states of the ball, the Cartesian pendulum's elliptic period and its
//! wall hits, the triple pendulum's tip on the floor, the rolling ball
//! meeting the wall, the typed errors of a model without series and of a
//! non-finite series, and a step's energy worked out only when asked.

use dalembert::models::*;
use dalembert::runtime::dynamics::DynamicsError;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    Integrator, SeriesRoom, Settings, SimError, Simulator, State, Stats, Taylor,
};
use dalembert::runtime::taylor::Series;
use std::cell::Cell;

#[path = "common/bounce.rs"]
mod bounce;
mod common;
use common::{dormand_prince, initial};

fn taylor() -> Settings {
    Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    }
}

/// §3.2.1 with Taylor's method from (q, q̇) just after a bounce at x = 0,
/// for 10⁴ bounces: the ball bounces every 2u/g, alternately at x = 0 and
/// x = 2uv/g. Asserts the bounce instants against 4n/g and the energy to
/// 1e-15 relative, the centre's position within `position`, and one step
/// per flight; returns the stats and every bounce (its instant and the
/// state after it), the start first.
fn bounces_with_taylor<M: TaylorSeries<6>>(
    ball: &M,
    (q, q_dot): ([f64; 6], [f64; 6]),
    r: f64,
    g: f64,
    position: f64,
) -> (Stats, Vec<Bounce>) {
    let start = State {
        t: 0.0,
        q,
        v: q_dot,
    };
    let (u, v) = (bounce::U, bounce::V);
    let e0 = ball.energy(&start.q, &start.v);
    let mut room = SeriesRoom::new(ball);
    let mut sim = Simulator::with_series(&mut room, start, taylor()).unwrap();
    let flight = 2.0 * u / g;
    let bounces = 10_000;
    let mut n = 0usize;
    let mut worst = [0.0f64; 3];
    let mut bounced = vec![(0.0, q, q_dot)];
    let stats = sim
        .run((bounces as f64 + 0.5) * flight, |s| {
            if let Some(c) = s.collision {
                n += 1;
                let x = if n % 2 == 1 { 2.0 * u * v / g } else { 0.0 };
                // n·(2u/g) with one rounding: 4n/g.
                let exact = (4 * n) as f64 / g;
                worst[0] = worst[0].max((c.t - exact).abs() / exact);
                worst[1] = worst[1].max((c.q[0] - x).abs() + c.q[1].abs() + (c.q[2] - r).abs());
                worst[2] = worst[2].max((ball.energy(&c.q, &c.v_plus) - e0).abs() / e0);
                bounced.push((c.t, c.q, c.v_plus));
            }
            true
        })
        .unwrap();
    assert_eq!(n, bounces);
    eprintln!(
        "{}: Taylor, {n} bounces, {} steps: |Δt|/t {:.1e}, |Δq| {:.1e}, |ΔE|/E {:.1e}",
        ball.name(),
        stats.steps,
        worst[0],
        worst[1],
        worst[2]
    );
    // One step per flight.
    assert_eq!(stats.steps, bounces as u64 + 1);
    assert!(worst[0] <= 1e-15, "relative time error {}", worst[0]);
    assert!(worst[1] <= position, "position error {}", worst[1]);
    assert!(worst[2] <= 1e-15, "energy error {}", worst[2]);
    (stats, bounced)
}

/// A bounce: its instant and the state after it.
type Bounce = (f64, [f64; 6], [f64; 6]);

/// For each flight, the lowest order whose own step reaches the next
/// bounce: the order a lower-order trial needs to take it. The step of the
/// series truncated at order p is Taylor's step at the fixed order p
/// (below order 19 the tolerance's asymptotic bound, e⁻², is the looser
/// one, so it is the step the trials take).
fn orders_needed<M: TaylorSeries<6>>(ball: &M, bounced: &[Bounce]) -> Vec<usize> {
    let t = Taylor::default();
    bounced
        .windows(2)
        .map(|w| {
            let ((t0, q, v), (t1, _, _)) = (w[0], w[1]);
            let mut s = Series::at(&q, &v);
            ball.taylor_series(&mut s, &mut Default::default(), t.order());
            (2..=t.order())
                .find(|&p| {
                    s.order = p;
                    let fixed = Taylor {
                        fixed_order: Some(p),
                        ..t
                    };
                    fixed.step(&s) >= t1 - t0
                })
                .unwrap_or(t.order())
        })
        .collect()
}

/// The trials' orders are learnt: each flight taken by a lower-order step
/// is taken at an order no higher than the highest any flight so far has
/// needed (`orders_needed`; the trials only learn upwards, from
/// [`Taylor::FIRST_TRIAL_ORDER`]). Every other series (the trials that
/// failed and the full-order series after them) is counted at the full
/// order (the model's, [`Taylor::order_for`]), and the last step, to the
/// end of the run, at the highest need. Each failed trial raises the order
/// learnt, so there are at most as many as orders from the first trial's
/// to the highest need, and one for the last step; each is followed by a
/// step at the full order.
fn assert_orders_learnt<M: TaylorSeries<6>>(ball: &M, stats: &Stats, bounced: &[Bounce]) {
    let t = Taylor::default();
    let full = t.order_for(ball.series_work(), 6, ball.walls().len()) as u64;
    let first = Taylor::FIRST_TRIAL_ORDER as u64;
    let mut highest = first;
    let mut bound = 0;
    for need in orders_needed(ball, bounced) {
        highest = highest.max(need as u64);
        bound += highest;
    }
    bound += highest;
    // One evaluation is the simulator's first q̈, not a series.
    let failed = stats.evaluations - 1 - stats.steps;
    assert!(failed <= highest - first + 1, "{highest}: {stats:?}");
    assert_eq!(stats.steps - stats.low_order_steps, failed, "{stats:?}");
    let others = stats.evaluations - 1 - stats.low_order_steps;
    bound += full * others;
    assert!(highest < t.order() as u64, "{highest}");
    assert!(stats.series_orders <= bound, "{bound}: {stats:?}");
}

#[test]
fn nonholonomic_pendulum_with_taylor() {
    let ball = BallBounce::default();
    let p = ball.params();
    let (stats, bounced) = bounces_with_taylor(&ball, bounce::after_bounce(&ball), p.r, p.g, 1e-13);
    // Each flight is taken on the series of a lower order (nearly
    // polynomial: even that reaches the floor), but for the few in which
    // the run learns the order it needs (one per order learnt), and no
    // higher than that.
    assert_orders_learnt(&ball, &stats, &bounced);
}

/// The same with the centre and ω as the state (`ball_bounce_omega`): the
/// flight's series is a polynomial of degree 2 with ω constant, so the
/// first flight teaches order 4 (where its last two terms vanish), and
/// every later step is taken at it, on the first series computed.
/// Observed: the same bounce instants (2.2e-16), the energy at the bounces
/// equal to the start's. The centre drifts along x by 2.8e-13 over the 10⁴
/// bounces: the collision map here is M v with M = I − 2P's entries
/// rounded once (`floor_collide`), so v⁺ = −v⁻ holds to about an ulp per
/// bounce and the error in x grows linearly (with Euler angles the map is
/// evaluated in another order, and x stays within 7.8e-16).
#[test]
fn nonholonomic_pendulum_in_centre_and_omega_with_taylor() {
    let ball = BallBounceOmega::default();
    let p = ball.params();
    let (stats, bounced) =
        bounces_with_taylor(&ball, bounce::after_bounce_omega(&ball), p.r, p.g, 1e-12);
    assert_eq!(stats.low_order_steps, stats.steps - 1, "{stats:?}");
    assert_eq!(stats.evaluations, stats.steps + 2, "{stats:?}");
    // The first trial (2), the full series, then 4 for each step.
    let full = Taylor::default().order_for(ball.series_work(), 6, 1) as u64;
    assert_eq!(
        stats.series_orders,
        2 + full + 4 * (stats.steps - 1),
        "{stats:?}"
    );
    assert_orders_learnt(&ball, &stats, &bounced);
}

/// The free Cartesian pendulum (wall out of reach) with Taylor's method:
/// back at rest at its start after the elliptic-integral period, on the
/// circle, energy constant.
#[test]
fn pendulum_period_with_taylor() {
    let mut p = PendulumWall::default();
    assert!(p.set_parameter_named("d", 2.0));
    let (l, g) = (p.params().l, p.params().g);
    let theta0: f64 = 1.2;
    // K(k) by the arithmetic-geometric mean: period 4√(l/g) K(sin(θ₀/2)).
    let k = (theta0 / 2.0).sin();
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..20 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    let period = 4.0 * (l / g).sqrt() * std::f64::consts::FRAC_PI_2 / a;
    let start = State {
        t: 0.0,
        q: [-l * theta0.sin(), -l * theta0.cos()],
        v: [0.0, 0.0],
    };
    let e0 = p.energy(&start.q, &start.v);
    let mut room = SeriesRoom::new(&p);
    let mut sim = Simulator::with_series(&mut room, start, taylor()).unwrap();
    let mut worst = 0.0f64;
    let stats = sim
        .run(period, |s| {
            worst = worst.max((s.energy(&p) - e0).abs());
            true
        })
        .unwrap();
    let end = sim.state();
    let miss = ((end.q[0] - start.q[0]).powi(2) + (end.q[1] - start.q[1]).powi(2)).sqrt();
    eprintln!(
        "pendulum period, Taylor: {} steps, miss {miss:.1e}, energy {worst:.1e}",
        stats.steps
    );
    assert!(
        miss < 1e-12,
        "after one period the bob is {miss} from its start"
    );
    assert!(worst < 1e-14, "energy drift {worst}");
}

/// The pendulum against its wall with Taylor's method: the same collisions,
/// at the same instants, as Dormand–Prince at a tight tolerance.
#[test]
fn pendulum_hits_the_wall_where_dormand_prince_does() {
    let p = PendulumWall::default();
    let start = State {
        t: 0.0,
        q: [-0.8, -0.6],
        v: [0.0, 0.0],
    };
    let times = |settings: Settings| {
        let mut room = SeriesRoom::new(&p);
        let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
        let mut t = Vec::new();
        sim.run(10.0, |s| {
            if let Some(c) = s.collision {
                t.push(c.t);
            }
            true
        })
        .unwrap();
        t
    };
    let (a, b) = (times(taylor()), times(dormand_prince(1e-13)));
    assert!(a.len() >= 5);
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < 1e-10, "{x} vs {y}");
    }
}

/// chain_4 seen through the traits' required methods, as a hand-written
/// model would be, with the series its [`Offered`] says; it counts the
/// evaluations of its energy (T and V).
struct Plain(Chain4, Offered, Cell<u64>);

/// What [`Plain`] offers Taylor's method.
#[derive(Clone, Copy, PartialEq)]
enum Offered {
    /// No series (the traits' defaults).
    Nothing,
    /// chain_4's series, with a NaN in one velocity's coefficient of order 7.
    Poisoned,
    /// chain_4's series as they are.
    Series,
}

type W4 = chain_4::Wall;

impl Model<4, 4> for Plain {
    fn name(&self) -> &str {
        self.0.name()
    }
    fn coordinate_names(&self) -> &[&str] {
        self.0.coordinate_names()
    }
    fn velocity_names(&self) -> &[&str] {
        self.0.velocity_names()
    }
    fn parameter_names(&self) -> &[&str] {
        self.0.parameter_names()
    }
    fn parameter(&self, index: usize) -> Option<f64> {
        self.0.parameter(index)
    }
    fn set_parameter(&mut self, index: usize, value: f64) -> bool {
        self.0.set_parameter(index, value)
    }
    fn mass_matrix(&self, q: &[f64; 4]) -> [[f64; 4]; 4] {
        self.0.mass_matrix(q)
    }
    fn kinetic_energy(&self, q: &[f64; 4], v: &[f64; 4]) -> f64 {
        self.2.set(self.2.get() + 1);
        self.0.kinetic_energy(q, v)
    }
    fn constraints(&self, q: &[f64; 4]) -> dalembert::runtime::Rows<4> {
        self.0.constraints(q)
    }
}
impl Walls<4, 4> for Plain {
    type Wall = W4;
    fn walls(&self) -> &[W4] {
        self.0.walls()
    }
    fn wall_name(&self, wall: W4) -> &str {
        self.0.wall_name(wall)
    }
    fn wall_rows(&self, wall: W4, q: &[f64; 4]) -> dalembert::runtime::Rows<4> {
        self.0.wall_rows(wall, q)
    }
    fn projector(&self, wall: W4, q: &[f64; 4]) -> [[f64; 4]; 4] {
        self.0.projector(wall, q)
    }
    fn collide(&self, wall: W4, q: &[f64; 4], v: &[f64; 4]) -> [f64; 4] {
        self.0.collide(wall, q, v)
    }
}
impl Dynamics<4> for Plain {
    fn potential(&self, q: &[f64; 4]) -> f64 {
        self.2.set(self.2.get() + 1);
        self.0.potential(q)
    }
    fn forcing(&self, q: &[f64; 4], v: &[f64; 4]) -> [f64; 4] {
        self.0.forcing(q, v)
    }
    fn constraint_drift(&self, q: &[f64; 4], v: &[f64; 4]) -> [f64; 4] {
        self.0.constraint_drift(q, v)
    }
}
impl TaylorSeries<4> for Plain {
    type SeriesScratch = <Chain4 as TaylorSeries<4>>::SeriesScratch;
    fn taylor_series(
        &self,
        s: &mut Series<4>,
        scratch: &mut Self::SeriesScratch,
        order: usize,
    ) -> bool {
        if self.1 == Offered::Nothing {
            return false;
        }
        let done = self.0.taylor_series(s, scratch, order);
        if self.1 == Offered::Poisoned && order >= 7 {
            s.v[2][7] = f64::NAN;
        }
        done
    }
    fn surface_series(
        &self,
        wall: W4,
        s: &Series<4>,
        scratch: &mut Self::SeriesScratch,
        out: &mut dalembert::runtime::taylor::Coefficients,
    ) -> bool {
        self.1 != Offered::Nothing && self.0.surface_series(wall, s, scratch, out)
    }
}
impl Surfaces<4> for Plain {
    fn surface(&self, wall: W4, q: &[f64; 4]) -> f64 {
        self.0.surface(wall, q)
    }
}

/// A model without series, or a simulator without room for them: Taylor's
/// method is refused with a typed error, not run wrongly.
#[test]
fn models_without_series_refuse_taylor() {
    let chain = Chain4::default();
    let start = initial(&chain);
    // The generated model itself has them and runs, given room.
    let mut room = SeriesRoom::new(&chain);
    assert!(Simulator::with_series(&mut room, start, taylor()).is_ok());
    // A simulator built without room has none to step in.
    assert!(matches!(
        Simulator::new(&chain, start, taylor()),
        Err(SimError::NoSeries)
    ));
    let plain = Plain(chain, Offered::Nothing, Cell::default());
    let mut room = SeriesRoom::new(&plain);
    assert!(matches!(
        Simulator::with_series(&mut room, start, taylor()),
        Err(SimError::NoSeries)
    ));
}

/// A series with a NaN in one coefficient stops the run at the step's
/// start with the typed error, whatever order the NaN is at (the step
/// checks the state it evaluates on the polynomial, not each coefficient).
#[test]
fn non_finite_series_stop_the_run() {
    let chain = Chain4::default();
    let model = Plain(chain, Offered::Poisoned, Cell::default());
    let mut room = SeriesRoom::new(&model);
    let mut sim = Simulator::with_series(&mut room, initial(&chain), taylor()).unwrap();
    let err = sim.run(10.0, |_| true).unwrap_err();
    assert!(
        matches!(
            err,
            SimError::Dynamics {
                t: 0.0,
                error: DynamicsError::NonFinite
            }
        ),
        "{err:?}"
    );
}

/// A step works out its energy only when asked: a run with either method
/// evaluates T and V nowhere, and `Step::energy` is the model's energy at
/// the step's end.
#[test]
fn steps_work_out_the_energy_only_when_asked() {
    let chain = Chain4::default();
    let model = Plain(chain, Offered::Series, Cell::default());
    for settings in [taylor(), Settings::default()] {
        let mut room = SeriesRoom::new(&model);
        let mut sim = Simulator::with_series(&mut room, initial(&chain), settings).unwrap();
        let mut last = None;
        let stats = sim
            .run(2.0, |s| {
                last = Some(*s);
                true
            })
            .unwrap();
        assert!(stats.steps > 10, "{stats:?}");
        assert_eq!(
            model.2.get(),
            0,
            "T or V evaluated in a run that never asked"
        );
        let s = last.unwrap();
        assert_eq!(s.energy(&model), chain.energy(&s.state.q, &s.state.v));
        assert_eq!(model.2.get(), 2, "one T and one V");
        model.2.set(0);
    }
}

/// The triple pendulum's tip on the floor (`chain_3` from its model file's
/// start, f along the tip's curved path): Taylor's method meets the tip
/// impacts of the first 3 s where Dormand–Prince does at rtol 1e-13 (the
/// high-precision answer), at the same instants and states, with the tip
/// on the floor and the energy kept through every impact.
#[test]
fn triple_pendulum_tip_meets_the_floor_with_taylor() {
    let chain = Chain3::default();
    let start = initial(&chain);
    let e0 = chain.energy(&start.q, &start.v);
    let impacts = |settings: Settings| {
        let mut room = SeriesRoom::new(&chain);
        let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
        let (mut found, mut de) = (Vec::new(), 0.0f64);
        sim.run(3.0, |s| {
            de = de.max((s.energy(&chain) - e0).abs() / e0.abs());
            found.extend(s.collision);
            true
        })
        .unwrap();
        (found, de)
    };
    let (taylor, de) = impacts(taylor());
    let (reference, _) = impacts(dormand_prince(1e-13));
    eprintln!("{} impacts, energy {de:.1e}", taylor.len());
    // Seen (2026-12-04): 4 impacts; |Δt| ≤ 1.8e-14, |Δq| ≤ 8.7e-14,
    // |Δv⁺| ≤ 6.9e-13, the energy within 1.6e-14 relative.
    assert!(taylor.len() >= 4, "{taylor:?}");
    assert_eq!(taylor.len(), reference.len());
    assert!(de < 1e-12, "energy {de:e}");
    for (a, b) in taylor.iter().zip(&reference) {
        let dq = (0..3).map(|i| (a.q[i] - b.q[i]).abs()).fold(0.0, f64::max);
        let dv = (0..3)
            .map(|i| (a.v_plus[i] - b.v_plus[i]).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "t {} vs {}: |Δt| {:.1e}, |Δq| {dq:.1e}, |Δv⁺| {dv:.1e}, f {:.1e}",
            a.t,
            b.t,
            (a.t - b.t).abs(),
            a.surface
        );
        assert!((a.t - b.t).abs() < 1e-12, "{} vs {}", a.t, b.t);
        assert!(dq < 1e-11 && dv < 1e-10, "at t = {}: {dq:e}, {dv:e}", a.t);
        assert!(a.surface.abs() < 1e-13, "f = {:e}", a.surface);
    }
}

/// The §3.1 ball rolling into the wall, in Euler angles and with a unit
/// quaternion: two coordinate systems for one motion. With Taylor's method
/// the first impact comes at the analytic instant (the centre rolls with
/// constant acceleration −a m r²/(J + m r²) from x = 3/2, x' = −1/2 to
/// x = r), and both models then meet the wall at the same instants with the
/// same centre velocities, impact after impact, with the energy constant
/// and |e| = 1 kept.
#[test]
fn rolling_ball_in_euler_angles_and_quaternions_with_taylor() {
    let euler = BallWallEuler::default();
    let quat = BallWallQuaternion::default();
    let p = euler.params();
    let alpha = p.a * p.m * p.r * p.r / (p.J + p.m * p.r * p.r);
    let first = (-0.5 + (0.25 + 2.0 * alpha * (1.5 - p.r)).sqrt()) / alpha;
    fn run<M: TaylorSeries<N> + Default, const N: usize>(
        m: &M,
    ) -> (Vec<(f64, f64, f64)>, f64, f64) {
        let start = initial(m);
        let e0 = m.energy(&start.q, &start.v);
        let mut room = SeriesRoom::new(m);
        let mut sim = Simulator::with_series(&mut room, start, taylor()).unwrap();
        let (mut out, mut de, mut dh) = (Vec::new(), 0.0f64, 0.0f64);
        let stats = sim
            .run(f64::INFINITY, |s| {
                de = de.max((s.energy(m) - e0).abs() / e0);
                dh = dh.max(s.residual(m).position);
                if let Some(c) = s.collision {
                    out.push((c.t, c.v_minus[0], c.v_plus[1]));
                }
                out.len() < 20
            })
            .unwrap();
        // Rolling steps do not reach the wall at the lower order, and no
        // lower order steps as far as the full one: the trials stop after
        // the first, the one series computed in vain.
        assert!(
            stats.evaluations <= stats.steps + 1 + 1,
            "{}: {stats:?}",
            m.name()
        );
        (out, de, dh)
    }
    let (a, de_a, _) = run(&euler);
    let (b, de_b, dh_b) = run(&quat);
    assert!(
        (a[0].0 - first).abs() <= 1e-14 * first,
        "{} vs {first}",
        a[0].0
    );
    assert!(
        (b[0].0 - first).abs() <= 1e-14 * first,
        "{} vs {first}",
        b[0].0
    );
    for (n, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!(
            (x.0 - y.0).abs() <= 1e-12 * x.0,
            "impact {n}: t {} vs {}",
            x.0,
            y.0
        );
        assert!(
            (x.1 - y.1).abs() <= 1e-12,
            "impact {n}: x' {} vs {}",
            x.1,
            y.1
        );
        assert!(
            (x.2 - y.2).abs() <= 1e-12,
            "impact {n}: y'⁺ {} vs {}",
            x.2,
            y.2
        );
    }
    eprintln!(
        "20 impacts: energy drift {de_a:.1e} (Euler), {de_b:.1e} (quaternion), |h| {dh_b:.1e}"
    );
    assert!(
        de_a < 1e-13 && de_b < 1e-13,
        "energy drift {de_a:e}, {de_b:e}"
    );
    assert!(dh_b < 1e-14, "|e| − 1 drifted by {dh_b:e}");
}

/// The rolling ball in Euler angles through 100 impacts: its steps are
/// bounded by the radius of convergence (1/sin θ in q̈), not by the
/// tolerance, so an order above the tolerance's 20 steps further. The
/// simulator picks one from the series' work ([`Taylor::order_for`]): the
/// run takes at least 10× fewer steps than Dormand–Prince at the CLI's
/// default tolerances and fewer than at a fixed order 20, keeps the energy
/// within 1e-13, and meets the same impacts at the same instants as at
/// order 20 and at order 28.
#[test]
fn rolling_ball_in_euler_angles_at_the_models_order() {
    use dalembert::runtime::simulate::DormandPrince;
    let ball = BallWallEuler::default();
    let start = initial(&ball);
    let e0 = ball.energy(&start.q, &start.v);
    let run = |integrator| {
        let settings = Settings {
            integrator,
            ..Settings::default()
        };
        let mut room = SeriesRoom::new(&ball);
        let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
        let (mut impacts, mut de) = (Vec::new(), 0.0f64);
        let stats = sim
            .run(f64::INFINITY, |s| {
                de = de.max((s.energy(&ball) - e0).abs() / e0);
                if let Some(c) = s.collision {
                    impacts.push(c.t);
                }
                impacts.len() < 100
            })
            .unwrap();
        (stats, impacts, de)
    };
    let fixed = |p| {
        Integrator::Taylor(Taylor {
            fixed_order: Some(p),
            ..Taylor::default()
        })
    };
    let (dp, _, _) = run(Integrator::DormandPrince(DormandPrince::default()));
    let (default, at_default, de) = run(Integrator::Taylor(Taylor::default()));
    let (at_20, impacts_20, _) = run(fixed(20));
    let (_, impacts_28, de_28) = run(fixed(28));
    let order = Simulator::with_series(&mut SeriesRoom::new(&ball), start, taylor())
        .unwrap()
        .taylor_order()
        .unwrap();
    eprintln!(
        "100 impacts: {} steps (Dormand–Prince), {} (Taylor at order {order}), {} (order 20); energy {de:.1e}, {de_28:.1e} at order 28",
        dp.steps, default.steps, at_20.steps
    );
    assert!(order > Taylor::default().order(), "{order}");
    assert!(10 * default.steps <= dp.steps, "{default:?} vs {dp:?}");
    assert!(default.steps < at_20.steps, "{default:?} vs {at_20:?}");
    assert!(
        de < 1e-13 && de_28 < 1e-13,
        "energy drift {de:e}, {de_28:e}"
    );
    for other in [&impacts_20, &impacts_28] {
        assert_eq!(other.len(), at_default.len());
        for (n, (a, b)) in other.iter().zip(&at_default).enumerate() {
            assert!((a - b).abs() <= 1e-12 * b, "impact {n}: t {a} vs {b}");
        }
    }
}
