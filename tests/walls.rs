//! Walls that are not polynomials in the coordinates (`tests/walls/`: the
//! unit disk's edge through a square root, a quotient, a logarithm, a sine
//! and a tangent, and through a quotient with a pole just beyond it; an
//! oval through an exponential; a Chaplygin sleigh in a round rink; a
//! pendulum against a round peg), with and without gravity: every
//! integrator meets them at the instants Dormand–Prince finds at rtol 1e-13,
//! and no state the simulator reports is ever beyond a wall.
//!
//! A wall's f along a step of Taylor's method is a series too, and one
//! through a square root or a quotient may converge on a much shorter
//! interval than the motion's (for a straight flight, about the distance
//! from the instant to its closest approach to the centre): these models
//! are the ones where a step chosen from the motion's series alone would
//! search f's polynomial far outside its radius of convergence.
//!
//! The models are interpreted (`dalembert simulate FILE`'s route; its
//! series are the generated code's, bit for bit: `tests/interpreted.rs`).
//! Uses the symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

mod common;

use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    Collision, Integrator, Rk4, SeriesRoom, Settings, SimError, Simulator, State, Stats, Taylor,
};
use dalembert::runtime::taylor::{Coefficients, Series};
use dalembert_codegen::interpret::Interpreted;

use common::{dormand_prince, initial, lcg};

fn model<const N: usize>(name: &str) -> Interpreted<N> {
    common::wall_model(name)
}

/// How far beyond a wall a reported state may be: rounding (f at a
/// collision is found to about 1e-16).
const BEYOND: f64 = 1e-12;

fn taylor(method: Taylor) -> Settings {
    Settings {
        integrator: Integrator::Taylor(method),
        ..Settings::default()
    }
}

fn rk4(step: f64) -> Settings {
    Settings {
        integrator: Integrator::Rk4(Rk4 { step }),
        ..Settings::default()
    }
}

/// The methods compared with the reference, each with how close its
/// collision instants must come to it: Taylor's method at its default
/// tolerance, at fixed orders 8 and 20 and at tolerance 1e-10;
/// Dormand–Prince at rtol 1e-10; RK4 at a step of 1e-3.
fn methods() -> Vec<(&'static str, Settings, f64)> {
    let t = Taylor::default();
    vec![
        ("taylor", taylor(t), 1e-9),
        (
            "taylor order 8",
            taylor(Taylor {
                fixed_order: Some(8),
                ..t
            }),
            1e-9,
        ),
        (
            "taylor order 20",
            taylor(Taylor {
                fixed_order: Some(20),
                ..t
            }),
            1e-9,
        ),
        (
            "taylor 1e-10",
            taylor(Taylor {
                tolerance: 1e-10,
                ..t
            }),
            1e-6,
        ),
        ("dormand-prince 1e-10", dormand_prince(1e-10), 1e-6),
        ("rk4 1e-3", rk4(1e-3), 1e-6),
    ]
}

/// A run's collisions and counters, or the error that stopped it.
type Outcome<W, const N: usize> = Result<(Vec<Collision<W, N>>, Stats), SimError<W>>;

/// A run of `m` from `start` to `t_end`: its collisions and counters.
/// Asserts that no step ends beyond a wall (f ≥ −[`BEYOND`] at every
/// step's state and at every collision, which is on its wall, and a disk's
/// state within the unit circle) and that the energy is kept to `energy`
/// relative.
fn run<M: TaylorSeries<N>, const N: usize>(
    m: &M,
    start: State<N>,
    settings: Settings,
    t_end: f64,
    energy: f64,
) -> Outcome<M::Wall, N> {
    let e0 = m.energy(&start.q, &start.v);
    let scale = e0.abs().max(1.0);
    let mut room = SeriesRoom::new(m);
    let mut sim = Simulator::with_series(&mut room, start, settings)?;
    let mut found = Vec::new();
    let mut last = start.t;
    let stats = sim.run(t_end, |s| {
        for &wall in m.walls() {
            let f = m.surface(wall, &s.state.q);
            assert!(
                f >= -BEYOND,
                "{}: at t = {} the state is beyond {} (f = {f:e}); {settings:?}",
                m.name(),
                s.state.t,
                m.wall_name(wall)
            );
        }
        // The disks' f may be positive again beyond a pole outside them:
        // their domain is also checked as what it is, the unit disk.
        if m.name().starts_with("disk_") {
            let r2 = s.state.q[0] * s.state.q[0] + s.state.q[1] * s.state.q[1];
            assert!(
                r2 <= 1.0 + BEYOND,
                "{}: at t = {} the state is outside the unit disk (|q|² = {r2}) from {start:?}; {settings:?}",
                m.name(),
                s.state.t,
            );
        }
        if let Some(c) = s.collision {
            let f = m.surface(c.wall, &c.q);
            assert!(
                f.abs() <= BEYOND,
                "{}: collision off the wall at t = {}, f = {f:e}; {settings:?}",
                m.name(),
                c.t
            );
            found.push(c);
        }
        let de = (s.energy(m) - e0).abs() / scale;
        assert!(
            de <= energy,
            "{}: energy off by {de:e} at t = {}",
            m.name(),
            s.state.t
        );
        assert!(
            s.state.t > last || s.collision.is_some(),
            "no progress at t = {last}"
        );
        last = s.state.t;
        true
    })?;
    Ok((found, stats))
}

/// `m` from its model file's start (`g` set where given) by every method
/// against Dormand–Prince at rtol 1e-13 over `t_end`: the same collisions
/// at the same instants, at least `least` of them. Taylor's method at its
/// default tolerance finds them on the walls' series alone (no step's end
/// contradicts a wall's series).
fn same_collisions<const N: usize>(name: &str, g: Option<f64>, t_end: f64, least: usize) {
    compare::<N>(name, name, g, t_end, least, methods());
}

/// [`same_collisions`] by the given methods only, against Dormand–Prince
/// at rtol 1e-13 on the model `reference` (the same motion and walls,
/// written otherwise).
fn compare<const N: usize>(
    name: &str,
    reference: &str,
    g: Option<f64>,
    t_end: f64,
    least: usize,
    methods: Vec<(&'static str, Settings, f64)>,
) {
    let (mut m, mut r) = (model::<N>(name), model::<N>(reference));
    if let Some(g) = g {
        assert!(m.set_parameter_named("g", g) && r.set_parameter_named("g", g));
    }
    let start = initial(&m);
    let (reference, _) = run(&r, start, dormand_prince(1e-13), t_end, 1e-11).unwrap();
    eprintln!("{name}, g = {g:?}: {} collisions", reference.len());
    assert!(reference.len() >= least, "{name}: {}", reference.len());
    for (what, settings, within) in methods {
        let energy = if what.starts_with("rk4") { 1e-6 } else { 1e-8 };
        let (found, stats) = run(&m, start, settings, t_end, energy)
            .unwrap_or_else(|e| panic!("{name}, {what}: {e}"));
        let worst = found
            .iter()
            .zip(&reference)
            .map(|(a, b)| (a.t - b.t).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "  {what}: {} collisions, |Δt| ≤ {worst:.1e}, {} steps, {} direct",
            found.len(),
            stats.steps,
            stats.direct_crossings
        );
        assert_eq!(found.len(), reference.len(), "{name}, {what}");
        assert!(worst <= within, "{name}, {what}: |Δt| = {worst:e}");
        if what == "taylor" {
            assert_eq!(stats.direct_crossings, 0, "{name}: {stats:?}");
        }
    }
}

#[test]
fn square_root_wall() {
    // The case: over 10 s Dormand–Prince finds 6 collisions.
    same_collisions::<2>("disk_sqrt", None, 10.0, 6);
    same_collisions::<2>("disk_sqrt", Some(9.81), 10.0, 6);
}

#[test]
fn quotient_wall() {
    same_collisions::<2>("disk_quotient", None, 10.0, 6);
    same_collisions::<2>("disk_quotient", Some(9.81), 10.0, 6);
}

#[test]
fn logarithm_wall() {
    same_collisions::<2>("disk_log", None, 10.0, 6);
    same_collisions::<2>("disk_log", Some(9.81), 10.0, 6);
}

#[test]
fn exponential_wall() {
    same_collisions::<2>("oval_exp", None, 10.0, 6);
    same_collisions::<2>("oval_exp", Some(9.81), 10.0, 6);
}

#[test]
fn sine_wall() {
    same_collisions::<2>("disk_sin", None, 10.0, 6);
    same_collisions::<2>("disk_sin", Some(9.81), 10.0, 6);
}

/// A power with a varying exponent, (x² + y²)^(1 + y²) (the evaluator's
/// form of exp((1 + y²)·log(x² + y²))): the unit circle again, with a
/// radial normal there, so the square-root disk's collisions.
#[test]
fn varying_exponent_wall() {
    compare::<2>("disk_power", "disk_sqrt", None, 10.0, 6, methods());
    compare::<2>("disk_power", "disk_sqrt", Some(9.81), 10.0, 6, methods());
}

/// The arc and hyperbolic functions: each wall is the unit circle with a
/// radial normal (`tests/walls/disk_{atan,asin,acos,sinh,cosh,tanh,asinh,
/// acosh,atanh}.toml`),
/// so every method meets it where it meets the square-root disk. Their
/// series in Taylor's method are built from other recurrences (an arc
/// function's from c′w = a′, a hyperbolic one's from exponentials).
#[test]
fn arc_and_hyperbolic_walls() {
    for name in [
        "disk_atan",
        "disk_asin",
        "disk_acos",
        "disk_sinh",
        "disk_cosh",
        "disk_tanh",
        "disk_asinh",
        "disk_acosh",
        "disk_atanh",
    ] {
        compare::<2>(name, "disk_sqrt", None, 10.0, 6, methods());
        compare::<2>(name, "disk_sqrt", Some(9.81), 10.0, 6, methods());
    }
}

/// The same functions inside the motion (`tests/walls/disk_functions.toml`:
/// in G and in V's forces, so in q̈ and in its Taylor series): every method
/// meets the unit circle where Dormand–Prince at rtol 1e-13 does. With
/// gravity the motion is sensitive: Dormand–Prince at 1e-13 and at 1e-14
/// part by 6e-12 at the 12th collision (t = 4.9) and by 3e-8 at the 20th
/// (t = 8.7), where Taylor's method at its tolerance and at 1e-18 agree to
/// 2e-10; so that run stops at t = 5.
#[test]
fn arc_and_hyperbolic_functions_in_the_motion() {
    same_collisions::<2>("disk_functions", None, 10.0, 8);
    same_collisions::<2>("disk_functions", Some(9.81), 5.0, 12);
}

/// Beyond the ring where f < 0 the tangent has a pole and is positive
/// again (see `tests/walls/disk_tan.toml`): a Runge–Kutta step whose
/// samples jumped the ring would see f > 0 at each, falling at each. The
/// reference is the same disk with its edge through a square root: the
/// same circle, the same radial normal, so the same collisions.
#[test]
fn tangent_wall() {
    compare::<2>("disk_tan", "disk_sqrt", None, 10.0, 6, methods());
    compare::<2>("disk_tan", "disk_sqrt", Some(9.81), 10.0, 6, methods());
}

/// The same with the pole just outside the wall: f < 0 only in a ring
/// 0.005 wide (`tests/walls/disk_thin_ring.toml`), which Dormand–Prince's
/// long steps of a free flight jump between samples.
#[test]
fn thin_ring_before_a_pole() {
    compare::<2>("disk_thin_ring", "disk_sqrt", None, 10.0, 6, methods());
    compare::<2>(
        "disk_thin_ring",
        "disk_sqrt",
        Some(9.81),
        10.0,
        6,
        methods(),
    );
}

/// A nonholonomic model (the sleigh's blade) and a holonomic one (the
/// pendulum's rod), each with a wall through a square root.
#[test]
fn constrained_models_with_a_square_root_wall() {
    same_collisions::<3>("sleigh_rink", None, 10.0, 4);
    same_collisions::<3>("sleigh_rink", Some(1.0), 10.0, 4);
    same_collisions::<2>("pendulum_peg", None, 10.0, 6);
}

/// Random starts inside each domain (at least 0.05 from its wall, with
/// velocities of size up to 3, on the constraints), with and without
/// gravity, by every method for 3 s: no state outside, ever (for the
/// disks, outside the unit circle too, where a pole makes f positive
/// again). Runs that stop with a typed error (a grazing contact) are
/// allowed, one in fifty at most; none did when this was written (576
/// runs, 2952 collisions).
#[test]
fn no_state_outside_from_random_starts() {
    fn starts<const N: usize>(
        m: &Interpreted<N>,
        seed: u64,
        count: usize,
        admissible: impl Fn(&mut dyn FnMut() -> f64) -> State<N>,
    ) -> Vec<State<N>> {
        let mut state = seed;
        let mut uniform = move || lcg(&mut state);
        let mut out = Vec::new();
        while out.len() < count {
            let s = admissible(&mut uniform);
            // (A disk's f may be positive beyond a pole outside it too.)
            let in_disk = !m.name().starts_with("disk_") || s.q[0].hypot(s.q[1]) < 1.0;
            if in_disk && m.walls().iter().all(|&w| m.surface(w, &s.q) > 0.05) {
                out.push(s);
            }
        }
        out
    }
    let plane = |u: &mut dyn FnMut() -> f64| State {
        t: 0.0,
        q: [2.0 * u() - 1.0, 2.0 * u() - 1.0],
        v: [6.0 * u() - 3.0, 6.0 * u() - 3.0],
    };
    let (mut runs, mut stopped, mut collisions) = (0, 0, 0);
    let mut tally = |outcome: Result<usize, String>| match outcome {
        Ok(n) => {
            runs += 1;
            collisions += n;
        }
        Err(e) => {
            eprintln!("stopped: {e}");
            stopped += 1;
        }
    };
    fn each<M: TaylorSeries<N>, const N: usize>(
        m: &M,
        start: State<N>,
        tally: &mut impl FnMut(Result<usize, String>),
    ) {
        for (what, settings, _) in methods() {
            let outcome = run(m, start, settings, 3.0, 1e-5);
            tally(
                outcome
                    .map(|(c, _)| c.len())
                    .map_err(|e| format!("{what}: {e}")),
            );
        }
    }
    for name in [
        "disk_sqrt",
        "disk_quotient",
        "disk_log",
        "disk_power",
        "oval_exp",
        "disk_sin",
        "disk_tan",
        "disk_thin_ring",
        "disk_atan",
        "disk_acos",
        "disk_tanh",
    ] {
        let mut m = model::<2>(name);
        for (seed, g) in [(1, 0.0), (2, 9.81)] {
            assert!(m.set_parameter_named("g", g));
            for start in starts(&m, seed, 6, plane) {
                each(&m, start, &mut tally);
            }
        }
    }
    let sleigh = model::<3>("sleigh_rink");
    let on_blade = |u: &mut dyn FnMut() -> f64| {
        let (phi, speed) = (6.3 * u(), 6.0 * u() - 3.0);
        State {
            t: 0.0,
            q: [2.0 * u() - 1.0, 2.0 * u() - 1.0, phi],
            v: [speed * phi.cos(), speed * phi.sin(), 4.0 * u() - 2.0],
        }
    };
    for start in starts(&sleigh, 3, 6, on_blade) {
        each(&sleigh, start, &mut tally);
    }
    let pendulum = model::<2>("pendulum_peg");
    let on_rod = |u: &mut dyn FnMut() -> f64| {
        let (angle, speed) = (6.3 * u(), 12.0 * u() - 6.0);
        State {
            t: 0.0,
            q: [angle.sin(), -angle.cos()],
            v: [speed * angle.cos(), speed * angle.sin()],
        }
    };
    for start in starts(&pendulum, 4, 6, on_rod) {
        each(&pendulum, start, &mut tally);
    }
    eprintln!("{runs} runs with {collisions} collisions, {stopped} stopped");
    assert!(
        runs >= 550 && collisions >= 2500,
        "{runs} runs, {collisions} collisions"
    );
    assert!(stopped * 50 <= runs, "{stopped} of {runs} runs stopped");
}

/// The last line of defence, alone: a model whose wall series says the
/// wall is 1/2 further out than f does (the unit disk's f + 1/2). Taylor's
/// method must not follow the series through the wall: every step's end
/// is checked against f itself, and the crossings are found by f along the
/// step, at Dormand–Prince's instants.
#[test]
fn a_wall_series_that_misleads_is_overruled_by_f() {
    let disk = model::<2>("disk_sqrt");
    let misled = Misled(&disk);
    let start = initial(&disk);
    let (reference, _) = run(&disk, start, dormand_prince(1e-13), 10.0, 1e-11).unwrap();
    let (found, stats) = run(&misled, start, taylor(Taylor::default()), 10.0, 1e-8).unwrap();
    eprintln!("{} collisions, {stats:?}", found.len());
    assert_eq!(found.len(), reference.len());
    assert!(stats.direct_crossings >= found.len() as u64, "{stats:?}");
    for (a, b) in found.iter().zip(&reference) {
        assert!((a.t - b.t).abs() <= 1e-9, "{} vs {}", a.t, b.t);
    }
}

/// The disk model with its wall's series shifted by +1/2.
struct Misled<'a>(&'a Interpreted<2>);

type Wall = <Interpreted<2> as Walls<2, 2>>::Wall;

impl Model<2, 2> for Misled<'_> {
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
    fn set_parameter(&mut self, _: usize, _: f64) -> bool {
        false
    }
    fn mass_matrix(&self, q: &[f64; 2]) -> [[f64; 2]; 2] {
        self.0.mass_matrix(q)
    }
    fn kinetic_energy(&self, q: &[f64; 2], v: &[f64; 2]) -> f64 {
        self.0.kinetic_energy(q, v)
    }
    fn constraints(&self, q: &[f64; 2]) -> dalembert::runtime::Rows<2> {
        self.0.constraints(q)
    }
}

impl Walls<2, 2> for Misled<'_> {
    type Wall = Wall;
    fn walls(&self) -> &[Wall] {
        self.0.walls()
    }
    fn wall_name(&self, wall: Wall) -> &str {
        self.0.wall_name(wall)
    }
    fn wall_rows(&self, wall: Wall, q: &[f64; 2]) -> dalembert::runtime::Rows<2> {
        self.0.wall_rows(wall, q)
    }
    fn projector(&self, wall: Wall, q: &[f64; 2]) -> [[f64; 2]; 2] {
        self.0.projector(wall, q)
    }
    fn collide(&self, wall: Wall, q: &[f64; 2], v: &[f64; 2]) -> [f64; 2] {
        self.0.collide(wall, q, v)
    }
    fn normal(&self, wall: Wall, q: &[f64; 2]) -> [f64; 2] {
        self.0.normal(wall, q)
    }
    fn normal_velocity(&self, wall: Wall, q: &[f64; 2], v: &[f64; 2]) -> f64 {
        self.0.normal_velocity(wall, q, v)
    }
}

impl Dynamics<2> for Misled<'_> {
    fn potential(&self, q: &[f64; 2]) -> f64 {
        self.0.potential(q)
    }
    fn forcing(&self, q: &[f64; 2], v: &[f64; 2]) -> [f64; 2] {
        self.0.forcing(q, v)
    }
    fn constraint_drift(&self, q: &[f64; 2], v: &[f64; 2]) -> [f64; 2] {
        self.0.constraint_drift(q, v)
    }
    fn closed_form_accelerations(&self, q: &[f64; 2], v: &[f64; 2]) -> Option<[f64; 2]> {
        self.0.closed_form_accelerations(q, v)
    }
}

impl TaylorSeries<2> for Misled<'_> {
    type SeriesScratch = <Interpreted<2> as TaylorSeries<2>>::SeriesScratch;
    fn taylor_series(
        &self,
        s: &mut Series<2>,
        scratch: &mut Self::SeriesScratch,
        order: usize,
    ) -> bool {
        self.0.taylor_series(s, scratch, order)
    }
    fn surface_series(
        &self,
        wall: Wall,
        s: &Series<2>,
        scratch: &mut Self::SeriesScratch,
        out: &mut Coefficients,
    ) -> bool {
        let done = self.0.surface_series(wall, s, scratch, out);
        out[0] += 0.5;
        done
    }
}

impl Surfaces<2> for Misled<'_> {
    fn surface(&self, wall: Wall, q: &[f64; 2]) -> f64 {
        self.0.surface(wall, q)
    }
}

/// A wall through functions the symbolic engine does not evaluate itself
/// (`tests/walls/rim_functions.toml`: atan, sinh, asin, acos and acosh of
/// x·y): whether its P depends on q, and every other zero test of the
/// derivation, is settled by the expression's values with those functions
/// valued too, not by expanding it. Before they were valued, that test
/// expanded P's derivatives: `generate` reached 1.7 GB in 3 s (stopped
/// there by an address-space limit; the same wall beside a potential with
/// asinh and atanh ran to 24 GB and was killed); without the product x·y
/// it took 12 s and 350 MB, now 0.2 s.
#[test]
fn functions_the_engine_lacks_keep_the_derivation_bounded() {
    let start = std::time::Instant::now();
    let d = common::derived("tests/walls", "rim_functions");
    let took = start.elapsed();
    assert!(took.as_secs_f64() < 30.0, "derived in {took:?}");
    assert!(!d.walls[0].structured(), "P in closed form");
}

/// A wall through six nested atan (`nested_atan.toml`): each level's
/// derivative divides by 1 + u², so the normal in lowest terms over one
/// common denominator has thousands of terms where the derivatives as
/// differentiated have a few hundred. The reduced forms were the only ones
/// compiled, and B's row (the normal) and the collision map were evaluated
/// from them: at five levels `generate` took 113 s and gave a collision
/// map of 1 056 operations; at six it ran past 120 s. Now an evaluated
/// quantity is compiled as written too, the cheaper kept (here the
/// written one), and a reduction past the budget is not made for it.
///
/// The normal and the collision map are checked against the surface's
/// gradient by central differences (G = I: v⁺ = v − 2(n·v)/(n·n) n), and
/// the motion against Dormand–Prince at rtol 1e-13.
#[test]
fn nested_functions_are_evaluated_as_written() {
    use dalembert_codegen::quantity::Quantity;
    let start = std::time::Instant::now();
    let d = common::derived("tests/walls", "nested_atan");
    let took = start.elapsed();
    assert!(took.as_secs_f64() < 30.0, "derived in {took:?}");
    let params = d.model.params.len();
    let per_call = |q: Quantity| {
        let f = d.walls[0].function(q).expect("the wall's function");
        f.program.split(params, 0).op_counts(&f.program).0.cost()
    };
    // 86 and 111 here; 2 231 and 2 256 from the reduced forms.
    for q in [Quantity::WallRows, Quantity::Collide] {
        assert!(per_call(q) < 300, "{q:?}: {} operations", per_call(q));
    }
    let m = model::<3>("nested_atan");
    let wall = m.walls()[0];
    let mut seed = 7u64;
    for _ in 0..20 {
        let q: [f64; 3] = std::array::from_fn(|_| lcg(&mut seed) - 0.5);
        let v: [f64; 3] = std::array::from_fn(|_| 2.0 * lcg(&mut seed) - 1.0);
        let h = 1e-5;
        let n: [f64; 3] = std::array::from_fn(|k| {
            let (mut a, mut b) = (q, q);
            a[k] += h;
            b[k] -= h;
            (m.surface(wall, &a) - m.surface(wall, &b)) / (2.0 * h)
        });
        let normal = m.normal(wall, &q);
        let dot = |a: &[f64; 3], b: &[f64; 3]| (0..3).map(|k| a[k] * b[k]).sum::<f64>();
        // The generated normal may be any non-zero multiple of ∇f.
        let along = dot(&normal, &n) / dot(&n, &n);
        for k in 0..3 {
            assert!(
                (normal[k] - along * n[k]).abs() <= 1e-8 * along.abs(),
                "normal at {q:?}: {normal:?} against {n:?}"
            );
        }
        let after = m.collide(wall, &q, &v);
        let s = 2.0 * dot(&n, &v) / dot(&n, &n);
        for k in 0..3 {
            let expected = v[k] - s * n[k];
            assert!(
                (after[k] - expected).abs() <= 1e-8,
                "v⁺ at {q:?}, {v:?}: {after:?}, by differences {expected}"
            );
        }
    }
    same_collisions::<3>("nested_atan", None, 10.0, 5);
}
