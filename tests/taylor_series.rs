//! The generated Taylor series of the motion and of each wall's f,
//! against known series (the ball in flight, the pendulum), against finite
//! differences of q̈ along a tightly integrated motion (orders 2 to 4,
//! every model), and against themselves on every model (the series
//! re-expanded at a later instant is the series computed there; the energy
//! is constant along the series; coefficient 1 of q̇ is the closed-form q̈;
//! the wall's series is f along the state's series; the room kept between
//! calls changes no bit).
//! Taylor's method in the simulator is `tests/taylor.rs`.

use dalembert::for_each_model;
use dalembert::models::*;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{Simulator, Taylor};
use dalembert::runtime::taylor::{CAPACITY, MAX_ORDER, Series, eval};

mod common;
use common::{dormand_prince, for_random_cases, initial, onto_kernel};

/// Binomial coefficient C(n, k) as f64.
fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// The checks of one model at one random case (parameters, q, v).
fn check_series<M: TaylorSeries<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: [f64; N],
) -> Result<(), proptest::test_runner::TestCaseError> {
    let v = onto_kernel(&m.constraints(q), v);
    let order = 16;
    let mut s = Series::at(q, &v);
    let mut scratch = M::SeriesScratch::default();
    if !m.taylor_series(&mut s, &mut scratch, order) {
        return Ok(());
    }
    let Some(acc) = m.closed_form_accelerations(q, &v) else {
        panic!("a model with series has q̈ in closed form");
    };
    let scale = 1.0 + acc.iter().chain(&v).fold(0.0f64, |a, x| a.max(x.abs()));
    if scale.is_nan() || scale >= 1e3 {
        // Near a coordinate singularity: nothing to compare at this case.
        return Ok(());
    }
    assert_eq!(s.order, order);
    for i in 0..N {
        assert_eq!(s.q[i][1], v[i]);
        let want = acc[i] / 1.0;
        assert!(
            (s.v[i][1] - want).abs() <= 1e-13 * scale,
            "q̈ {i}: {} vs {want}",
            s.v[i][1]
        );
        assert!((s.q[i][2] - s.v[i][1] / 2.0).abs() <= 1e-15 * scale);
    }
    // Re-expanded at τ, the series is the series computed at τ:
    // x_k(τ) = Σ_j C(j, k) x_j τ^(j−k), for the orders that the
    // truncation leaves accurate: τ a tenth of the step Taylor's method
    // would take (its radius of convergence estimated from the last
    // coefficients, over e²), compared at the size of the sum's terms (and
    // at rounding of the state's scale, for coefficients that vanish).
    let tau = 0.1 * Taylor::default().step(&s).min(1.0 / scale);
    let (q1, v1) = s.state(tau);
    let mut s1 = Series::at(&q1, &v1);
    assert!(m.taylor_series(&mut s1, &mut scratch, order));
    let shifted = |c: &[f64; CAPACITY], k: usize| -> (f64, f64) {
        (k..=order)
            .map(|j| binomial(j, k) * c[j] * tau.powi((j - k) as i32))
            .fold((0.0, 0.0), |(sum, size), x| (sum + x, size + x.abs()))
    };
    for k in 0..6 {
        for i in 0..N {
            for (c, c1, what) in [(&s.q[i], &s1.q[i], "q"), (&s.v[i], &s1.v[i], "v")] {
                let ((want, size), got) = (shifted(c, k), c1[k]);
                assert!(
                    (got - want).abs() <= 1e-11 * size + 1e-15 * scale.powi(k as i32 + 1),
                    "{} {what}{i} order {k}: {got} vs {want}",
                    m.name()
                );
            }
        }
    }
    // The energy is a constant of the motion: constant along the series.
    let e0 = m.energy(q, &v);
    for j in 1..=4 {
        let (qq, vv) = s.state(j as f64 * tau);
        let e = m.energy(&qq, &vv);
        assert!(
            (e - e0).abs() <= 1e-10 * (1.0 + e0.abs()) * scale * scale,
            "{}: energy {e} vs {e0}",
            m.name()
        );
    }
    // Each wall's series is f along the state's series.
    let mut f = [0.0; CAPACITY];
    for &w in m.walls() {
        assert!(m.surface_series(w, &s, &mut scratch, &mut f));
        for j in 0..=4 {
            let t = j as f64 * tau;
            let (qq, _) = s.state(t);
            let want = m.surface(w, &qq);
            let got = eval(&f, s.order, t);
            assert!(
                (got - want).abs() <= 1e-11 * (1.0 + want.abs()),
                "{} wall {w:?} at {t}: {got} vs {want}",
                m.name()
            );
        }
    }
    // The room for the intermediate series, kept from call to call: in
    // room that other calls have left full (another state to the highest
    // order, the walls' series), the series has the same bits as in fresh
    // room.
    assert!(m.taylor_series(&mut Series::at(&q1, &v1), &mut scratch, MAX_ORDER));
    let mut again = Series::at(q, &v);
    assert!(m.taylor_series(&mut again, &mut scratch, order));
    assert_eq!(again, s, "{}: the series in used room", m.name());
    for &w in m.walls() {
        let mut fresh = [0.0; CAPACITY];
        assert!(m.surface_series(w, &s, &mut M::SeriesScratch::default(), &mut fresh));
        assert!(m.surface_series(w, &s, &mut scratch, &mut f));
        assert_eq!(f, fresh, "{} wall {w:?}: the series in used room", m.name());
    }
    Ok(())
}

macro_rules! series_test {
    ($module:ident, $ty:ident, 0, $n:literal) => {};
    ($module:ident, $ty:ident, $q:literal, $n:literal) => {
        #[test]
        fn $module() {
            for_random_cases::<$ty, $n, $n>(64, |m, q, v| check_series(m, q, v));
        }
    };
}

mod series_agree_with_themselves {
    use super::*;
    for_each_model!(series_test);
}

/// A model has series exactly where q̈ is written out (every built-in
/// model with coordinates: in closed form, or by elimination).
#[test]
fn series_exist_where_closed_forms_do() {
    fn both<M: TaylorSeries<N> + Default, const N: usize>() -> (bool, bool) {
        let m = M::default();
        let (q, v) = ([0.5; N], [0.0; N]);
        let mut s = Series::at(&q, &v);
        (
            m.taylor_series(&mut s, &mut Default::default(), 4),
            m.closed_form_accelerations(&q, &v).is_some(),
        )
    }
    macro_rules! same {
        ($module:ident, $ty:ident, 0, $n:literal) => {};
        ($module:ident, $ty:ident, $q:literal, $n:literal) => {
            let (series, closed) = both::<$ty, $n>();
            assert_eq!(series, closed, "{}", stringify!($ty));
        };
    }
    for_each_model!(same);
}

/// The ball in flight: its centre's series is the parabola (order 2 and
/// no more), its spin about a fixed axis keeps ω constant, and the floor's
/// series is z − r.
#[test]
fn ball_in_flight_is_a_parabola() {
    let ball = BallBounce::default();
    let (r, g) = (ball.params().r, ball.params().g);
    let q = [0.3, -0.2, 2.0, 0.0, std::f64::consts::FRAC_PI_2, 0.0];
    let v = [1.0, 0.5, 2.0, 0.0, 0.0, 5.0];
    let mut s = Series::at(&q, &v);
    let mut scratch = ball_bounce::SeriesScratch::default();
    assert!(ball.taylor_series(&mut s, &mut scratch, 20));
    for k in 2..=20 {
        assert_eq!(s.q[0][k], 0.0, "x, order {k}");
        assert_eq!(s.q[1][k], 0.0, "y, order {k}");
    }
    assert_eq!(s.q[2][2], -g / 2.0);
    for k in 3..=20 {
        assert_eq!(s.q[2][k], 0.0, "z, order {k}");
    }
    // φ = φ' = 0, θ = π/2, ψ' = 5: ω = (0, −5, 0) is a rotation about the
    // fixed y axis, ψ(t) = 5t: the series of ψ is 5τ exactly to rounding.
    for k in 2..=20 {
        assert!(s.q[5][k].abs() < 1e-14, "ψ, order {k}: {}", s.q[5][k]);
        assert!(s.q[4][k].abs() < 1e-14, "θ, order {k}: {}", s.q[4][k]);
    }
    let mut f = [0.0; CAPACITY];
    assert!(ball.surface_series(ball_bounce::Wall::Floor, &s, &mut scratch, &mut f));
    assert_eq!(&f[..3], &[2.0 - r, 2.0, -g / 2.0]);
}

/// The Cartesian pendulum's series, against the angle's: x = l sin θ,
/// y = −l cos θ with θ̈ = −(g/l) sin θ, whose series at rest at θ₀ begins
/// θ₀ − (g/l) sin θ₀ τ²/2 + (g/l)² sin θ₀ cos θ₀ τ⁴/24.
#[test]
fn pendulum_series_is_the_angles() {
    let p = PendulumWall::default();
    let (l, g) = (p.params().l, p.params().g);
    let th0: f64 = 0.9;
    let q = [l * th0.sin(), -l * th0.cos()];
    let mut s = Series::at(&q, &[0.0, 0.0]);
    assert!(p.taylor_series(&mut s, &mut Default::default(), 12));
    let w = g / l;
    let theta = |t: f64| {
        th0 - w * th0.sin() * t * t / 2.0 + w * w * th0.sin() * th0.cos() * t.powi(4) / 24.0
    };
    for t in [0.001, 0.002, 0.004] {
        let (qq, _) = s.state(t);
        let want = [l * theta(t).sin(), -l * theta(t).cos()];
        for i in 0..2 {
            // The angle's series is cut after τ⁴: its error is O(τ⁶).
            assert!((qq[i] - want[i]).abs() < 1e-12, "{t}: {qq:?} vs {want:?}");
        }
    }
}

/// Coefficients 2 to 4 of q̇'s series against the derivatives of q̈ along
/// the motion by finite differences: the closed-form q̈ at five states a
/// step h apart on a Dormand–Prince run at rtol 1e-13 from the model
/// file's start, about the middle one, where the series is computed
/// (q̇ₖ = q̈⁽ᵏ⁻¹⁾/k!). The differences are of orders h⁴, h⁴ and h², and
/// the run's error weighs on them as 1/h, 1/h² and 1/h³.
fn against_differences<M: TaylorSeries<N> + Default, const N: usize>() {
    let m = M::default();
    let start = initial(&m);
    let mut s = Series::at(&start.q, &start.v);
    if !m.taylor_series(&mut s, &mut Default::default(), 16) {
        // No closed-form q̈ to differentiate either (see
        // `series_exist_where_closed_forms_do`).
        return;
    }
    // A twentieth of Taylor's step at the start (infinite for a motion
    // whose series ends, so at most 10 ms).
    let h = (0.05 * Taylor::default().step(&s)).min(1e-2);
    let mut sim = Simulator::new(&m, start, dormand_prince(1e-13)).unwrap();
    let mut states = vec![start];
    for j in 1..=4 {
        let stats = sim.run(j as f64 * h, |s| s.collision.is_none()).unwrap();
        assert_eq!(stats.collisions, 0, "{}: a collision within 4h", m.name());
        states.push(*sim.state());
    }
    let a: Vec<[f64; N]> = states
        .iter()
        .map(|x| m.closed_form_accelerations(&x.q, &x.v).unwrap())
        .collect();
    let c = states[2];
    let mut s = Series::at(&c.q, &c.v);
    assert!(m.taylor_series(&mut s, &mut Default::default(), 8));
    let differences: [[f64; N]; 3] = [
        core::array::from_fn(|i| {
            (-a[4][i] + 8.0 * a[3][i] - 8.0 * a[1][i] + a[0][i]) / (12.0 * h) / 2.0
        }),
        core::array::from_fn(|i| {
            (-a[4][i] + 16.0 * a[3][i] - 30.0 * a[2][i] + 16.0 * a[1][i] - a[0][i])
                / (12.0 * h * h)
                / 6.0
        }),
        core::array::from_fn(|i| {
            (a[4][i] - 2.0 * a[3][i] + 2.0 * a[1][i] - a[0][i]) / (2.0 * h * h * h) / 24.0
        }),
    ];
    // Seen (2026-12-04), relative to the largest component of the order:
    // at most 1.8e-8 at orders 2 and 3, 1.7e-4 at order 4; where the
    // coefficients vanish (a parabola, no force), at most 2.5e-13.
    for ((k, d), tolerance) in (2..=4).zip(&differences).zip([1e-6, 1e-6, 2e-3]) {
        let size = (0..N).fold(0.0f64, |x, i| x.max(s.v[i][k].abs()));
        let off = (0..N).fold(0.0f64, |x, i| x.max((s.v[i][k] - d[i]).abs()));
        assert!(
            off <= tolerance * size + 1e-10,
            "{} (h = {h:e}) order {k}: {:?} against {d:?}",
            m.name(),
            (0..N).map(|i| s.v[i][k]).collect::<Vec<_>>()
        );
    }
}

/// [`against_differences`] on every model with coordinates.
#[test]
fn series_agree_with_differences_of_the_accelerations() {
    macro_rules! check {
        ($module:ident, $ty:ident, 0, $n:literal) => {};
        ($module:ident, $ty:ident, $q:literal, $n:literal) => {
            against_differences::<$ty, $n>();
        };
    }
    for_each_model!(check);
}
