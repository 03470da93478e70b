//! How models written as bodies move, against independent answers (the
//! coin, a disk, is in `tests/coin.rs`):
//! - a bob on a spring against its harmonic motion;
//! - Chaplygin's ball (unequal principal moments) rolling into a rough wall,
//!   its attitude written three ways (z-x-z and z-y-x angles, a unit
//!   quaternion), moves the same to 1e-12 through three collisions: the
//!   starting states are converted in this file from one rotation matrix and
//!   one angular velocity, by formulas of its own;
//! - curved walls against the contact law in Cartesian velocities, and a
//!   ball rolling in a bowl against the pendulum and the spin's constancy.
//!
//! Uses the symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

mod common;

use common::derived;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    Simulator, StartRule, State, starting_velocity, starting_velocity_with,
};
use dalembert_codegen::interpret::Interpreted;

/// A bob on a spring (k, rest length L) from a fixed point H above the
/// floor, in gravity: released at rest 0.3 below its equilibrium
/// z* = H − L − m g/k, it oscillates as z* − 0.3 cos(√(k/m) t) (the spring
/// stays stretched, so |P₁ − P₂| is H − z).
#[test]
fn a_bob_on_a_spring_oscillates_as_theory_says() {
    let d = derived("tests/bodies/springs", "bob");
    let m = Interpreted::<3>::new(&d).unwrap();
    let (mass, k, rest, anchor, g) = (2.0, 50.0, 1.0, 3.0, 9.81);
    let z_eq: f64 = anchor - rest - mass * g / k;
    let omega = (k / mass).sqrt();
    let start = State {
        t: 0.0,
        q: [0.0, 0.0, z_eq - 0.3],
        v: [0.0; 3],
    };
    let mut sim = Simulator::new(&m, start, common::dormand_prince(1e-13)).unwrap();
    for t in [0.1, 0.7, 1.3, 2.0] {
        sim.run(t, |_| true).unwrap();
        let z = sim.state().q[2];
        let expected = z_eq - 0.3 * (omega * t).cos();
        assert!((z - expected).abs() < 1e-9, "t = {t}: z = {z}, {expected}");
    }
}

// --- Chaplygin's ball, three ways -------------------------------------------

type M3 = [[f64; 3]; 3];

fn mat(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn apply(a: &M3, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

fn transpose(a: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}

/// The rotation by `t` about axis `k`, and its derivative by `t`.
fn rot(k: usize, t: f64) -> (M3, M3) {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let (c, s) = (t.cos(), t.sin());
    let mut r = [[0.0; 3]; 3];
    let mut d = [[0.0; 3]; 3];
    r[k][k] = 1.0;
    r[i][i] = c;
    r[j][j] = c;
    r[i][j] = -s;
    r[j][i] = s;
    d[i][i] = -s;
    d[j][j] = -s;
    d[i][j] = -c;
    d[j][i] = c;
    (r, d)
}

/// R = R_{a₁}(α₁) R_{a₂}(α₂) R_{a₃}(α₃), and the angle rates that give the
/// fixed-frame angular velocity `w`: ω = Σ α̇ⱼ vee(∂R/∂αⱼ Rᵀ), solved.
fn angle_rates(axes: [usize; 3], angles: [f64; 3], w: [f64; 3]) -> [f64; 3] {
    let parts: Vec<(M3, M3)> = (0..3).map(|j| rot(axes[j], angles[j])).collect();
    let r = mat(&mat(&parts[0].0, &parts[1].0), &parts[2].0);
    let columns: Vec<[f64; 3]> = (0..3)
        .map(|j| {
            let f = |k: usize| if k == j { parts[k].1 } else { parts[k].0 };
            let d = mat(&mat(&f(0), &f(1)), &f(2));
            let s = mat(&d, &transpose(&r));
            [s[2][1], s[0][2], s[1][0]]
        })
        .collect();
    // Cramer's rule on the 3×3 system.
    let det = |c: [[f64; 3]; 3]| {
        c[0][0] * (c[1][1] * c[2][2] - c[2][1] * c[1][2])
            - c[1][0] * (c[0][1] * c[2][2] - c[2][1] * c[0][2])
            + c[2][0] * (c[0][1] * c[1][2] - c[1][1] * c[0][2])
    };
    let m = [columns[0], columns[1], columns[2]];
    let d = det(m);
    std::array::from_fn(|j| {
        let mut mj = m;
        mj[j] = w;
        det(mj) / d
    })
}

/// The starting state of Chaplygin's ball in each attitude convention: at
/// x = 3/2, y = 0, attitude R₀ = R_z(0.3) R_x(1.1) R_z(−0.4), angular
/// velocity ω (fixed frame), rolling (ẋ = r ω_y, ẏ = −r ω_x).
fn chaplygin_start(convention: &str, r: f64) -> (Vec<f64>, Vec<f64>) {
    let w = [0.7, -0.5, 1.3];
    let zxz = [0.3, 1.1, -0.4];
    let r0 = {
        let p = |k, t| rot(k, t).0;
        mat(&mat(&p(2, zxz[0]), &p(0, zxz[1])), &p(2, zxz[2]))
    };
    let centre = (vec![1.5, 0.0], vec![r * w[1], -r * w[0]]);
    let (attitude, rates): (Vec<f64>, Vec<f64>) = match convention {
        "zxz" => {
            let a = [
                r0[0][2].atan2(-r0[1][2]),
                r0[2][2].acos(),
                r0[2][0].atan2(r0[2][1]),
            ];
            (a.to_vec(), angle_rates([2, 0, 2], a, w).to_vec())
        }
        "zyx" => {
            let a = [
                r0[1][0].atan2(r0[0][0]),
                -r0[2][0].asin(),
                r0[2][1].atan2(r0[2][2]),
            ];
            (a.to_vec(), angle_rates([2, 1, 0], a, w).to_vec())
        }
        "quaternion" => {
            let e0 = 0.5 * (1.0 + r0[0][0] + r0[1][1] + r0[2][2]).sqrt();
            let v = [
                (r0[2][1] - r0[1][2]) / (4.0 * e0),
                (r0[0][2] - r0[2][0]) / (4.0 * e0),
                (r0[1][0] - r0[0][1]) / (4.0 * e0),
            ];
            // ė = ½ (0, ω) ⊗ e.
            let d0 = -0.5 * (w[0] * v[0] + w[1] * v[1] + w[2] * v[2]);
            let cross = [
                w[1] * v[2] - w[2] * v[1],
                w[2] * v[0] - w[0] * v[2],
                w[0] * v[1] - w[1] * v[0],
            ];
            let dv: Vec<f64> = (0..3).map(|i| 0.5 * (e0 * w[i] + cross[i])).collect();
            let mut rates = vec![d0];
            rates.extend(dv);
            (vec![e0, v[0], v[1], v[2]], rates)
        }
        other => panic!("{other}"),
    };
    let mut q = centre.0;
    q.extend(attitude);
    let mut v = centre.1;
    v.extend(rates);
    (q, v)
}

/// The centre's (x, y, ẋ, ẏ) at the end of each collision and at `t_end`,
/// with the collision instants.
fn chaplygin_run<const N: usize>(convention: &str, t_end: f64) -> (Vec<f64>, Vec<[f64; 4]>) {
    let d = derived("tests/bodies", &format!("chaplygin_{convention}"));
    let m = Interpreted::<N>::new(&d).unwrap_or_else(|e| panic!("{convention}: {e}"));
    let r = 0.5;
    let (q, v) = chaplygin_start(convention, r);
    let q: [f64; N] = q.try_into().unwrap_or_else(|_| panic!("{convention}: q"));
    let v: [f64; N] = v.try_into().unwrap_or_else(|_| panic!("{convention}: v"));
    let e0 = m.energy(&q, &v);
    let mut sim = Simulator::new(&m, State { t: 0.0, q, v }, common::dormand_prince(1e-13))
        .unwrap_or_else(|e| panic!("{convention}: {e:?}"));
    let mut instants = Vec::new();
    let mut states = Vec::new();
    let mut last = None;
    sim.run(t_end, |s| {
        if let Some(c) = &s.collision {
            instants.push(c.t);
            states.push([s.state.q[0], s.state.q[1], s.state.v[0], s.state.v[1]]);
        }
        last = Some(s.state);
        true
    })
    .unwrap_or_else(|e| panic!("{convention}: {e:?}"));
    let end = last.unwrap();
    assert!((end.t - t_end).abs() < 1e-12);
    states.push([end.q[0], end.q[1], end.v[0], end.v[1]]);
    let e1 = m.energy(&end.q, &end.v);
    assert!(
        (e1 - e0).abs() < 1e-10 * e0.abs(),
        "{convention}: energy {e0} → {e1}"
    );
    (instants, states)
}

#[test]
fn attitude_conventions_give_the_same_motion() {
    let t_end = 12.0;
    let (ti, si) = chaplygin_run::<5>("zxz", t_end);
    let others = [
        ("zyx", chaplygin_run::<5>("zyx", t_end)),
        ("quaternion", chaplygin_run::<6>("quaternion", t_end)),
    ];
    assert!(ti.len() >= 3, "only {} collisions with the wall", ti.len());
    for (name, (t, s)) in &others {
        assert_eq!(t.len(), ti.len(), "{name}: collisions {t:?} vs {ti:?}");
        for (a, b) in t.iter().zip(&ti) {
            assert!(
                (a - b).abs() < 1e-12,
                "{name}: collision at {a}, z-x-z at {b}"
            );
        }
        for (a, b) in s.iter().zip(&si) {
            for k in 0..4 {
                assert!((a[k] - b[k]).abs() < 1e-12, "{name}: {a:?}, z-x-z {b:?}");
            }
        }
    }
}

/// Chaplygin's ball started as a user states it: its attitude and its
/// angular velocity by the bodies layer's names (`ball_wx`, `ball_wy`,
/// `ball_wz` in `[initial]`, values in the fixed frame), the centre's
/// velocity and the attitude's rates left out. The velocity the runtime
/// completes from those rates and the constraints is, in every
/// convention, the one [`chaplygin_start`] converts by its own formulas.
fn start_by_rates<const N: usize>(convention: &str) {
    let (q, want) = chaplygin_start(convention, 0.5);
    let w = [0.7, -0.5, 1.3];
    let names: &[&str] = match convention {
        "quaternion" => &["x", "y", "e0", "e1", "e2", "e3"],
        _ => &["x", "y", "a1", "a2", "a3"],
    };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut text =
        std::fs::read_to_string(root.join(format!("tests/bodies/chaplygin_{convention}.toml")))
            .unwrap();
    text.push_str("\n[initial]\n");
    for (name, value) in names.iter().zip(&q) {
        text.push_str(&format!("{name} = \"{value:?}\"\n"));
    }
    for (axis, value) in ["x", "y", "z"].iter().zip(w) {
        text.push_str(&format!("ball_w{axis} = \"{value:?}\"\n"));
    }
    let file = std::env::temp_dir().join(format!(
        "dalembert_start_by_rates_{convention}_{}.toml",
        std::process::id()
    ));
    std::fs::write(&file, &text).unwrap();
    let d = dalembert_codegen::derive(&file).unwrap_or_else(|e| panic!("{convention}: {e}"));
    std::fs::remove_file(&file).unwrap();
    let m = Interpreted::<N>::new(&d).unwrap();
    assert_eq!(m.start_rate_names(), ["ball_wx", "ball_wy", "ball_wz"]);
    assert_eq!(m.start_values().as_slice(), w);
    let q = m.initial_coordinates();
    let (v, rule) = starting_velocity(
        &m,
        &q,
        &m.initial_velocities(),
        &m.initial_velocities_given(),
    )
    .unwrap();
    assert_eq!(rule, StartRule::Completed, "{convention}");
    for (got, want) in v.iter().zip(&want) {
        assert!(
            (got - want).abs() < 1e-13,
            "{convention}: started at {v:?}, converted {want:?}"
        );
    }
    // The same rates set over the file's (a front end's `--set`).
    let w2 = [-0.2, 0.9, 0.4];
    let (v2, _) =
        starting_velocity_with(&m, &q, &[0.0; N], &m.initial_velocities_given(), &w2).unwrap();
    let l = m.start_rows(&q);
    for (row, want) in l.as_slice().iter().zip(w2) {
        let got: f64 = row.iter().zip(&v2).map(|(a, b)| a * b).sum();
        assert!((got - want).abs() < 1e-13, "{convention}: {got} vs {want}");
    }
    assert!(m.constraints(&q).apply(&v2).max_abs() < 1e-13);
}

#[test]
fn a_start_given_by_the_body_rates_is_the_converted_one() {
    start_by_rates::<5>("zxz");
    start_by_rates::<5>("zyx");
    start_by_rates::<6>("quaternion");
}

// --- Curved walls -------------------------------------------------------------

/// M(angles) with ω = M α̇ for z-x-z angles, from the rotation's derivatives.
fn zxz_rates_matrix(angles: [f64; 3]) -> M3 {
    let parts: Vec<(M3, M3)> = (0..3).map(|j| rot([2, 0, 2][j], angles[j])).collect();
    let r = mat(&mat(&parts[0].0, &parts[1].0), &parts[2].0);
    let columns: Vec<[f64; 3]> = (0..3)
        .map(|j| {
            let f = |k: usize| if k == j { parts[k].1 } else { parts[k].0 };
            let s = mat(&mat(&mat(&f(0), &f(1)), &f(2)), &transpose(&r));
            [s[2][1], s[0][2], s[1][0]]
        })
        .collect();
    std::array::from_fn(|i| std::array::from_fn(|j| columns[j][i]))
}

/// The collision law in the Cartesian velocities (v, ω) of a ball (mass m,
/// moment J, radius r) touching a wall at the point r u from its centre:
/// smooth, v's component along u reversed; rough, (I − 2P) with B the
/// contact point's velocity v + ω × r u and G = diag(m, m, m, J, J, J).
fn contact_law(rough: bool, (m, j, r): (f64, f64, f64), u: [f64; 3], x: [f64; 6]) -> [f64; 6] {
    use nalgebra::{DMatrix, DVector};
    let rows: Vec<[f64; 6]> = if rough {
        // Row k of B: e_k · (v + ω × r u) = v_k + r (u × e_k) · ω.
        (0..3)
            .map(|k| {
                let e: [f64; 3] = std::array::from_fn(|i| f64::from(u8::from(i == k)));
                let c = [
                    u[1] * e[2] - u[2] * e[1],
                    u[2] * e[0] - u[0] * e[2],
                    u[0] * e[1] - u[1] * e[0],
                ];
                [e[0], e[1], e[2], r * c[0], r * c[1], r * c[2]]
            })
            .collect()
    } else {
        vec![[u[0], u[1], u[2], 0.0, 0.0, 0.0]]
    };
    let b = DMatrix::from_fn(rows.len(), 6, |i, k| rows[i][k]);
    let g_inv = DMatrix::from_diagonal(&DVector::from_vec(vec![
        1.0 / m,
        1.0 / m,
        1.0 / m,
        1.0 / j,
        1.0 / j,
        1.0 / j,
    ]));
    let gram = &b * &g_inv * b.transpose();
    let p = &g_inv * b.transpose() * gram.try_inverse().unwrap() * &b;
    let v = DVector::from_row_slice(&x);
    let after = &v - 2.0 * (p * &v);
    std::array::from_fn(|i| after[i])
}

/// A ball inside a rough sphere and a smooth cylinder (walls derived from
/// their shapes): at random points of each wall, the equator of the sphere
/// among them, and random velocities, the model's collision map equals the
/// contact law written in Cartesian velocities, to 1e-12.
#[test]
fn curved_walls_follow_the_contact_law() {
    let d = derived("tests/bodies", "ball_in_bowl");
    let model = Interpreted::<6>::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let p = |n: &str| model.parameter_named(n).unwrap();
    let (m, j, r, big, tube) = (p("m"), p("J"), p("r"), p("R"), p("rt"));
    let mut seed = 7u64;
    let mut rnd = || 2.0 * common::lcg(&mut seed) - 1.0;
    for case in 0..40 {
        for &wall in model.walls() {
            let name = model.wall_name(wall).to_string();
            // The direction u from the centre to the contact point.
            let u: [f64; 3] = if name == "bowl" {
                let mut u = [rnd(), rnd(), if case % 4 == 0 { 0.0 } else { rnd() }];
                let n = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
                u.iter_mut().for_each(|x| *x /= n);
                u
            } else {
                let a = std::f64::consts::PI * rnd();
                [a.cos(), a.sin(), 0.0]
            };
            let reach = if name == "bowl" { big - r } else { tube - r };
            let height = if name == "bowl" { 0.0 } else { rnd() };
            let centre = [reach * u[0], reach * u[1], reach * u[2] + height];
            let angles = [rnd(), 1.0 + 0.5 * rnd(), rnd()];
            let q = [
                centre[0], centre[1], centre[2], angles[0], angles[1], angles[2],
            ];
            assert!(
                model.surface(wall, &q).abs() < 1e-12,
                "{name}: off the wall"
            );
            let v: [f64; 6] = std::array::from_fn(|_| rnd());
            let after = model.collide(wall, &q, &v);
            let omega = |v: &[f64; 6]| {
                let mm = zxz_rates_matrix(angles);
                let rates = [v[3], v[4], v[5]];
                let w: [f64; 3] =
                    std::array::from_fn(|i| (0..3).map(|k| mm[i][k] * rates[k]).sum());
                [v[0], v[1], v[2], w[0], w[1], w[2]]
            };
            let expected = contact_law(name == "bowl", (m, j, r), u, omega(&v));
            let got = omega(&after);
            for i in 0..6 {
                assert!(
                    (got[i] - expected[i]).abs() < 1e-12 * (1.0 + expected[i].abs()),
                    "{name}, case {case}: {got:?} vs {expected:?}"
                );
            }
        }
    }
}

// --- Rolling inside a bowl ----------------------------------------------------

/// The unit vector from the bowl's centre to the ball's in
/// `tests/bodies/rolling_in_bowl.toml`: (sin a, cos a sin b, −cos a cos b).
fn bowl_normal(a: f64, b: f64) -> [f64; 3] {
    [a.sin(), a.cos() * b.sin(), -a.cos() * b.cos()]
}

/// A homogeneous ball (m = 1, r = 1/5, J = 2/25) rolling inside a sphere of
/// radius 1, against two classical answers. In the plane b = 0 the centre
/// moves as a pendulum of length ρ(1 + J/(m r²)), ρ = R − r (T = ½(m +
/// J/r²)ρ²ȧ², V = −m g ρ cos a): released at rest from a = 1/2 it first
/// reaches the bottom after √(l/g) K(sin ¼). In three dimensions the spin
/// about the normal, ω·n, is constant, as is the energy: d(ω·n)/dt =
/// ω̇·n + ω·ṅ, where J ω̇ = r n × F (the contact force F acts at r n from
/// the centre) has no part along n, and ṅ = (r/ρ) n × ω (rolling) is
/// orthogonal to ω. Those two hold for a ball on the outside of a sphere
/// too, so the contact point itself, at R n from the bowl's centre, is
/// checked to be at rest along the run.
#[test]
fn a_ball_rolls_in_a_bowl_as_theory_says() {
    let d = derived("tests/bodies", "rolling_in_bowl");
    let m = Interpreted::<5>::new(&d).unwrap();
    let (mass, r, j, rho, g) = (1.0, 0.2, 0.08, 0.8, 9.81);
    let settings = common::dormand_prince(1e-13);

    let a0 = 0.5;
    let q = [a0, 0.0, 0.0, std::f64::consts::FRAC_PI_2, 0.0];
    let start = State {
        t: 0.0,
        q,
        v: [0.0; 5],
    };
    let mut sim = Simulator::new(&m, start, settings).unwrap();
    let mut bracket = None;
    sim.run(2.0, |step| {
        let below = step.state.q[0] <= 0.0;
        if below {
            bracket = Some((step.t0, step.state.t));
        }
        !below
    })
    .unwrap();
    let (mut lo, mut hi) = bracket.expect("the ball reaches the bottom");
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if sim.state_at(mid).unwrap().q[0] > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let expected = common::pendulum_time(rho * (1.0 + j / (mass * r * r)), g, a0, 0.0);
    assert!(
        (lo - expected).abs() < 1e-10 * expected,
        "the bottom at t = {lo}, the pendulum's {expected}"
    );

    // Off the plane, with a spin: the velocities the start leaves out follow.
    let q = [0.4, 0.0, 0.0, 1.2, 0.0];
    let v = [0.0, 0.8, 2.0, 0.0, 0.0];
    let given = [false, true, true, false, false];
    let (v, _) = dalembert::runtime::simulate::starting_velocity(&m, &q, &v, &given).unwrap();
    let spin = |q: &[f64; 5], v: &[f64; 5]| {
        let w = apply(&zxz_rates_matrix([q[2], q[3], q[4]]), [v[2], v[3], v[4]]);
        let n = bowl_normal(q[0], q[1]);
        (0..3).map(|i| w[i] * n[i]).sum::<f64>()
    };
    // The material point touching the bowl, at R n from its centre: at rest.
    let slip = |q: &[f64; 5], v: &[f64; 5]| {
        let (a, b, da, db) = (q[0], q[1], v[0], v[1]);
        let centre = [
            rho * a.cos() * da,
            rho * (-a.sin() * b.sin() * da + a.cos() * b.cos() * db),
            rho * (a.sin() * b.cos() * da + a.cos() * b.sin() * db),
        ];
        let w = apply(&zxz_rates_matrix([q[2], q[3], q[4]]), [v[2], v[3], v[4]]);
        let n = bowl_normal(a, b).map(|x| r * x);
        let turn = [
            w[1] * n[2] - w[2] * n[1],
            w[2] * n[0] - w[0] * n[2],
            w[0] * n[1] - w[1] * n[0],
        ];
        (0..3)
            .map(|i| (centre[i] + turn[i]).abs())
            .fold(0.0, f64::max)
    };
    let energy = |q: &[f64; 5], v: &[f64; 5]| m.kinetic_energy(q, v) + m.potential(q);
    let (s0, e0) = (spin(&q, &v), energy(&q, &v));
    assert!(s0.abs() > 0.5, "{s0}");
    let mut sim = Simulator::new(&m, State { t: 0.0, q, v }, settings).unwrap();
    let (mut worst_s, mut worst_e, mut widest) = (0.0f64, 0.0f64, 0.0f64);
    let mut worst_slip = slip(&q, &v);
    sim.run(10.0, |step| {
        let (q, v) = (&step.state.q, &step.state.v);
        worst_slip = worst_slip.max(slip(q, v));
        worst_s = worst_s.max((spin(q, v) - s0).abs());
        worst_e = worst_e.max((energy(q, v) - e0).abs());
        widest = widest.max(q[1].abs());
        true
    })
    .unwrap();
    assert_eq!(sim.state().t, 10.0);
    assert!(widest > 0.1, "the centre leaves the plane b = 0: {widest}");
    assert!(
        worst_slip < 1e-12,
        "the contact point moves at {worst_slip:e}"
    );
    assert!(worst_s < 1e-10 * s0.abs(), "ω·n: {s0}, off by {worst_s:e}");
    assert!(
        worst_e < 1e-10 * e0.abs(),
        "energy: {e0}, off by {worst_e:e}"
    );
}
