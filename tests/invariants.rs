//! The paper's invariants on every generated model, at random parameters,
//! configurations and velocities (property tests; no symbolic engine).
//!
//! P² = P, GP = PᵀG, AP = A, BP = B (Lemma 1); the collision map keeps the
//! kinetic energy (2.10), maps ker A into ker A, reverses the wall's normal
//! velocity and is an involution; the generated P equals the one computed
//! numerically from G and B by the runtime's generic path; the emitted
//! normal df and normal velocity agree with B's first row, and the emitted
//! vᵀ∇²f v with a central difference of df along v.

use dalembert::for_each_model;
use dalembert::models::*;
use dalembert::runtime::Rows;
use dalembert::runtime::linalg::{kinetic_energy, mat_mul, mat_vec, projector};
use dalembert::runtime::prelude::*;

mod common;
use common::{for_random_cases, onto_kernel};
use proptest::prelude::*;

/// Tolerance relative to the size of the quantities compared.
const TOL: f64 = 1e-9;

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= TOL * (1.0 + scale)
}

fn max_abs<const N: usize>(m: &[[f64; N]; N]) -> f64 {
    m.iter().flatten().fold(0.0_f64, |x, y| x.max(y.abs()))
}

/// What every per-wall check sees.
struct At<'a, M: Walls<Q, N>, const Q: usize, const N: usize> {
    model: &'a M,
    wall: M::Wall,
    name: &'a str,
    q: &'a [f64; Q],
    v: [f64; N],
    g: [[f64; N]; N],
    a: Rows<N>,
    p: [[f64; N]; N],
    scale: f64,
}

/// Checks every invariant for one model instance at (q, v).
fn check<M: Walls<Q, N>, const Q: usize, const N: usize>(
    model: &M,
    q: &[f64; Q],
    v: [f64; N],
) -> Result<(), TestCaseError> {
    let a = model.constraints(q);
    let v = onto_kernel(&a, v);
    for &wall in model.walls() {
        let p = model.projector(wall, q);
        let at = At {
            model,
            wall,
            name: model.wall_name(wall),
            q,
            v,
            g: model.mass_matrix(q),
            a,
            p,
            scale: max_abs(&p),
        };
        projector_is_g_orthogonal(&at)?;
        normal_is_b_first_row(&at)?;
        rows_are_kept(&at)?;
        collision_map(&at)?;
    }
    Ok(())
}

/// P² = P and GP = PᵀG (Lemma 1).
fn projector_is_g_orthogonal<M: Walls<Q, N>, const Q: usize, const N: usize>(
    at: &At<M, Q, N>,
) -> Result<(), TestCaseError> {
    let At {
        name, g, p, scale, ..
    } = *at;
    // P² = P
    let p2 = mat_mul(&p, &p);
    for i in 0..N {
        for j in 0..N {
            prop_assert!(
                close(p2[i][j], p[i][j], scale * scale),
                "{} {name}: P² ≠ P at ({i},{j})",
                at.model.name()
            );
        }
    }
    // GP = PᵀG
    let gp = mat_mul(&g, &p);
    let gs = max_abs(&g) * scale;
    for i in 0..N {
        for j in 0..N {
            let ptg: f64 = (0..N).map(|k| p[k][i] * g[k][j]).sum();
            prop_assert!(
                close(gp[i][j], ptg, gs),
                "{} {name}: GP ≠ PᵀG at ({i},{j})",
                at.model.name()
            );
        }
    }
    Ok(())
}

/// The emitted normal and normal velocity are B's first row and that row
/// times v.
fn normal_is_b_first_row<M: Walls<Q, N>, const Q: usize, const N: usize>(
    at: &At<M, Q, N>,
) -> Result<(), TestCaseError> {
    let At {
        model,
        wall,
        name,
        q,
        v,
        ..
    } = *at;
    // The emitted normal and normal velocity are B's first row and
    // that row times v.
    let b = model.wall_rows(wall, q);
    let row = b.as_slice()[0];
    let normal = model.normal(wall, q);
    let size = row.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    for j in 0..N {
        prop_assert!(
            close(normal[j], row[j], size),
            "{} {name}: normal ≠ B's first row at {j}",
            at.model.name()
        );
    }
    let nv: f64 = row.iter().zip(&v).map(|(x, y)| x * y).sum();
    let vs = size * v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    prop_assert!(
        close(model.normal_velocity(wall, q, &v), nv, vs),
        "{} {name}: normal velocity ≠ B's first row · v",
        at.model.name()
    );
    Ok(())
}

/// AP = A, BP = B, and the generic numeric path gives the same P.
fn rows_are_kept<M: Walls<Q, N>, const Q: usize, const N: usize>(
    at: &At<M, Q, N>,
) -> Result<(), TestCaseError> {
    let At {
        model,
        wall,
        name,
        q,
        g,
        a,
        p,
        scale,
        ..
    } = *at;
    let b = model.wall_rows(wall, q);
    // AP = A and BP = B
    for (what, rows) in [("A", &a), ("B", &b)] {
        for row in rows.as_slice() {
            for j in 0..N {
                let rp: f64 = (0..N).map(|k| row[k] * p[k][j]).sum();
                prop_assert!(
                    close(
                        rp,
                        row[j],
                        scale * row.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
                    ),
                    "{} {name}: {what}P ≠ {what} in column {j}",
                    at.model.name()
                );
            }
        }
    }
    // The generic numeric path gives the same P.
    let p_generic =
        projector(&g, b.as_slice()).map_err(|e| TestCaseError::fail(format!("{e:?}")))?;
    for i in 0..N {
        for j in 0..N {
            prop_assert!(
                (p_generic[i][j] - p[i][j]).abs() <= 1e-7 * (1.0 + scale),
                "{} {name}: generated P differs from the generic path at ({i},{j}): {} vs {}",
                at.model.name(),
                p[i][j],
                p_generic[i][j]
            );
        }
    }
    Ok(())
}

/// The collision map keeps T, maps ker A into ker A, reverses the normal
/// velocity, is an involution and equals (I − 2P)v.
fn collision_map<M: Walls<Q, N>, const Q: usize, const N: usize>(
    at: &At<M, Q, N>,
) -> Result<(), TestCaseError> {
    let At {
        model,
        wall,
        name,
        q,
        v,
        g,
        a,
        p,
        scale,
    } = *at;
    // The collision map.
    let vp = model.collide(wall, q, &v);
    let e0 = kinetic_energy(&g, &v);
    let e1 = kinetic_energy(&g, &vp);
    prop_assert!(
        close(e0, e1, e0.abs()),
        "{} {name}: energy not kept: {e0} → {e1}",
        at.model.name()
    );
    prop_assert!(
        close(model.kinetic_energy(q, &v), e0, e0.abs()),
        "{} {name}: T(q,v) ≠ ½vᵀGv",
        at.model.name()
    );
    let vmax = v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    prop_assert!(
        a.apply(&vp).max_abs() <= TOL * (1.0 + vmax * 10.0),
        "{} {name}: v⁺ ∉ ker A",
        at.model.name()
    );
    let n0 = model.normal_velocity(wall, q, &v);
    let n1 = model.normal_velocity(wall, q, &vp);
    prop_assert!(
        close(n1, -n0, vmax),
        "{} {name}: normal velocity {n0} → {n1}, not reversed",
        at.model.name()
    );
    let back = model.collide(wall, q, &vp);
    for i in 0..N {
        prop_assert!(
            close(back[i], v[i], vmax),
            "{} {name}: the collision map is not an involution",
            at.model.name()
        );
    }
    // Same as (I − 2P)v computed from P.
    let pv = mat_vec(&p, &v);
    for i in 0..N {
        prop_assert!(
            close(vp[i], v[i] - 2.0 * pv[i], vmax * (1.0 + scale)),
            "{} {name}: collide ≠ (I − 2P)v",
            at.model.name()
        );
    }
    Ok(())
}

/// The emitted vᵀ∇²f v of every wall is the rate of df along v, times v
/// (a central difference), in a model with coordinates.
fn check_hessian<M: Surfaces<N>, const N: usize>(
    model: &M,
    q: &[f64; N],
    v: [f64; N],
) -> Result<(), TestCaseError> {
    for &wall in model.walls() {
        let name = model.wall_name(wall);
        let row = model.normal(wall, q);
        let size = row.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let eps = 1e-5;
        let shifted = |sign: f64| {
            let qs: [f64; N] = core::array::from_fn(|i| q[i] + sign * eps * v[i]);
            model.normal(wall, &qs)
        };
        let (ahead, behind) = (shifted(1.0), shifted(-1.0));
        let difference: f64 =
            (0..N).map(|j| (ahead[j] - behind[j]) * v[j]).sum::<f64>() / (2.0 * eps);
        let hessian = model.surface_hessian(wall, q, &v);
        let vmax = v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        prop_assert!(
            hessian.is_some_and(|h| (h - difference).abs() <= 1e-5 * (1.0 + size * vmax * vmax)),
            "{} {name}: vᵀ∇²f v = {hessian:?}, a central difference gives {difference}",
            model.name()
        );
    }
    Ok(())
}

/// 512 random cases (see `common::for_random_cases`).
fn run<M: Walls<Q, N> + FromParams, const Q: usize, const N: usize>() {
    for_random_cases::<M, Q, N>(512, check);
}

macro_rules! invariant_test {
    ($module:ident, $ty:ident, 0, $n:literal) => {
        #[test]
        fn $module() {
            run::<$ty, 0, $n>();
        }
    };
    ($module:ident, $ty:ident, $q:literal, $n:literal) => {
        #[test]
        fn $module() {
            run::<$ty, $q, $n>();
            for_random_cases::<$ty, $n, $n>(512, check_hessian);
        }
    };
}

for_each_model!(invariant_test);

/// A model whose collision map reverses all of v: it keeps the energy and
/// is an involution, but is not the reflection (I − 2P)v. `check` must reject it.
struct Reversing(BallFloor);

impl Model<0, 6> for Reversing {
    fn name(&self) -> &str {
        "reversing"
    }
    fn coordinate_names(&self) -> &[&str] {
        &[]
    }
    fn velocity_names(&self) -> &[&str] {
        self.0.velocity_names()
    }
    fn parameter_names(&self) -> &[&str] {
        self.0.parameter_names()
    }
    fn parameter(&self, i: usize) -> Option<f64> {
        self.0.parameter(i)
    }
    fn set_parameter(&mut self, i: usize, x: f64) -> bool {
        self.0.set_parameter(i, x)
    }
    fn mass_matrix(&self, q: &[f64; 0]) -> [[f64; 6]; 6] {
        self.0.mass_matrix(q)
    }
    fn kinetic_energy(&self, q: &[f64; 0], v: &[f64; 6]) -> f64 {
        self.0.kinetic_energy(q, v)
    }
    fn constraints(&self, q: &[f64; 0]) -> Rows<6> {
        self.0.constraints(q)
    }
}

impl Walls<0, 6> for Reversing {
    type Wall = ball_floor::Wall;
    fn walls(&self) -> &[Self::Wall] {
        self.0.walls()
    }
    fn wall_name(&self, w: Self::Wall) -> &str {
        self.0.wall_name(w)
    }
    fn wall_rows(&self, w: Self::Wall, q: &[f64; 0]) -> Rows<6> {
        self.0.wall_rows(w, q)
    }
    fn projector(&self, w: Self::Wall, q: &[f64; 0]) -> [[f64; 6]; 6] {
        Walls::projector(&self.0, w, q)
    }
    fn collide(&self, _: Self::Wall, _: &[f64; 0], v: &[f64; 6]) -> [f64; 6] {
        v.map(|x| -x)
    }
}

#[test]
fn a_wrong_collision_map_is_caught() {
    let wrong = Reversing(BallFloor::default());
    let v = [0.3, -0.2, -1.0, 0.1, 0.4, 0.7];
    assert!(check(&wrong, &[], v).is_err());
    assert!(check(&BallFloor::default(), &[], v).is_ok());
}
