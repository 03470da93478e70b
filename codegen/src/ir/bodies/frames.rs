//! A body's attitude: its rotation matrix R (body frame → fixed frame) and
//! its angular velocity in both frames, for a planar angle, a sequence of
//! three rotations about body axes (Euler or Tait–Bryan angles), or a unit
//! quaternion. Vectors are three expressions; `rate` is the time derivative
//! of an expression of the coordinates.

use super::super::Rational;
use super::super::expr::Function;
use super::sym::{Sym, add, call, int, mul, neg, sub};

/// A vector of three expressions.
pub(super) type Vec3 = [Sym; 3];

/// A 3×3 matrix of expressions, by rows.
pub(super) type Mat3 = [Vec3; 3];

/// How a body's attitude is given.
#[derive(Debug, Clone)]
pub(super) enum Attitude {
    /// Does not turn.
    Fixed,
    /// Turns by an angle about a fixed axis (0, 1, 2 for x, y, z).
    Angle { axis: usize, angle: Sym },
    /// R = R_{a₁}(α₁) R_{a₂}(α₂) R_{a₃}(α₃): rotations about the body's
    /// axes a₁, then the new a₂, then the newer a₃ (z-x-z: Euler's angles
    /// φ, θ, ψ; z-y-x: yaw, pitch, roll).
    Sequence { axes: [usize; 3], angles: [Sym; 3] },
    /// A unit quaternion (e₀, e₁, e₂, e₃), of coordinates.
    Quaternion([Sym; 4]),
}

/// The unit vector along axis `k`.
pub(super) fn unit(k: usize) -> Vec3 {
    std::array::from_fn(|i| int(i128::from(i == k)))
}

/// a · b.
pub(super) fn dot(a: &Vec3, b: &Vec3) -> Sym {
    add((0..3).map(|i| mul([a[i].clone(), b[i].clone()])))
}

/// a × b.
pub(super) fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    std::array::from_fn(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        sub(
            mul([a[j].clone(), b[k].clone()]),
            mul([a[k].clone(), b[j].clone()]),
        )
    })
}

/// a + b.
pub(super) fn plus(a: &Vec3, b: &Vec3) -> Vec3 {
    std::array::from_fn(|i| add([a[i].clone(), b[i].clone()]))
}

/// a − b.
pub(super) fn minus(a: &Vec3, b: &Vec3) -> Vec3 {
    std::array::from_fn(|i| sub(a[i].clone(), b[i].clone()))
}

/// s a.
pub(super) fn scale(s: &Sym, a: &Vec3) -> Vec3 {
    std::array::from_fn(|i| mul([s.clone(), a[i].clone()]))
}

/// M v.
pub(super) fn apply(m: &Mat3, v: &Vec3) -> Vec3 {
    std::array::from_fn(|i| dot(&m[i], v))
}

/// Mᵀ v.
pub(super) fn apply_transposed(m: &Mat3, v: &Vec3) -> Vec3 {
    std::array::from_fn(|i| add((0..3).map(|k| mul([m[k][i].clone(), v[k].clone()]))))
}

/// A B.
fn product(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| add((0..3).map(|k| mul([a[i][k].clone(), b[k][j].clone()]))))
    })
}

/// The rotation by `angle` about axis `k`.
fn rotation(k: usize, angle: &Sym) -> Mat3 {
    let (c, s) = (
        call(Function::Cos, angle.clone()),
        call(Function::Sin, angle.clone()),
    );
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let mut m: Mat3 = std::array::from_fn(unit);
    m[i][i] = c.clone();
    m[j][j] = c;
    m[i][j] = neg(s.clone());
    m[j][i] = s;
    m
}

impl Attitude {
    /// R, body frame → fixed frame.
    pub(super) fn rotation(&self) -> Mat3 {
        match self {
            Attitude::Fixed => std::array::from_fn(unit),
            Attitude::Angle { axis, angle } => rotation(*axis, angle),
            Attitude::Sequence { axes, angles } => product(
                &product(
                    &rotation(axes[0], &angles[0]),
                    &rotation(axes[1], &angles[1]),
                ),
                &rotation(axes[2], &angles[2]),
            ),
            Attitude::Quaternion([e0, e1, e2, e3]) => {
                // R = (e₀² − |e|²) I + 2 e eᵀ + 2 e₀ [e]×, for |(e₀, e)| = 1.
                let v = [e1.clone(), e2.clone(), e3.clone()];
                let two = || int(2);
                let diagonal = sub(
                    mul([e0.clone(), e0.clone()]),
                    add(v.iter().map(|x| mul([x.clone(), x.clone()]))),
                );
                std::array::from_fn(|i| {
                    std::array::from_fn(|j| {
                        let outer = mul([two(), v[i].clone(), v[j].clone()]);
                        let skew = match (j + 3 - i) % 3 {
                            // [e]×: entry (i, i+1) is −e_{i+2}, (i, i+2) is e_{i+1}.
                            1 => neg(mul([two(), e0.clone(), v[(i + 2) % 3].clone()])),
                            2 => mul([two(), e0.clone(), v[(i + 1) % 3].clone()]),
                            _ => diagonal.clone(),
                        };
                        add([outer, skew])
                    })
                })
            }
        }
    }

    /// For a sequence of angles: the axis of the last rotation, and the
    /// angular velocity in the frame the first two rotations make,
    /// α̇₃ a₃ + α̇₂ a₂ + α̇₁ R₂ᵀ a₁. It is the body frame's turned back by
    /// the last angle about a₃, and free of that angle: where the moments
    /// about the other two axes are equal (a coin, a wheel, a top spinning
    /// about a₃), ½ ΣIᵢΩᵢ² is the same in it without sin²+cos² to cancel.
    pub(super) fn before_last_rotation(&self, rate: &dyn Fn(&Sym) -> Sym) -> Option<(usize, Vec3)> {
        let Attitude::Sequence { axes, angles } = self else {
            return None;
        };
        let r2 = rotation(axes[1], &angles[1]);
        let parts = [
            scale(&rate(&angles[2]), &unit(axes[2])),
            scale(&rate(&angles[1]), &unit(axes[1])),
            scale(&rate(&angles[0]), &apply_transposed(&r2, &unit(axes[0]))),
        ];
        Some((axes[2], plus(&plus(&parts[0], &parts[1]), &parts[2])))
    }

    /// The angular velocity in the fixed frame and in the body frame, with
    /// `rate` the time derivative of an expression of the coordinates.
    pub(super) fn angular_velocity(&self, rate: &dyn Fn(&Sym) -> Sym) -> (Vec3, Vec3) {
        let zero = || std::array::from_fn(|_| int(0));
        match self {
            Attitude::Fixed => (zero(), zero()),
            Attitude::Angle { axis, angle } => {
                let w = scale(&rate(angle), &unit(*axis));
                (w.clone(), w)
            }
            Attitude::Sequence { axes, angles } => {
                let r1 = rotation(axes[0], &angles[0]);
                let r2 = rotation(axes[1], &angles[1]);
                let r3 = rotation(axes[2], &angles[2]);
                let rates: [Sym; 3] = std::array::from_fn(|i| rate(&angles[i]));
                // Fixed frame: α̇₁ a₁ + α̇₂ R₁ a₂ + α̇₃ R₁ R₂ a₃.
                let space = [
                    scale(&rates[0], &unit(axes[0])),
                    scale(&rates[1], &apply(&r1, &unit(axes[1]))),
                    scale(&rates[2], &apply(&product(&r1, &r2), &unit(axes[2]))),
                ];
                // Body frame: α̇₃ a₃ + α̇₂ R₃ᵀ a₂ + α̇₁ (R₂ R₃)ᵀ a₁.
                let body = [
                    scale(&rates[2], &unit(axes[2])),
                    scale(&rates[1], &apply_transposed(&r3, &unit(axes[1]))),
                    scale(
                        &rates[0],
                        &apply_transposed(&product(&r2, &r3), &unit(axes[0])),
                    ),
                ];
                let sum = |v: &[Vec3; 3]| plus(&plus(&v[0], &v[1]), &v[2]);
                (sum(&space), sum(&body))
            }
            Attitude::Quaternion([e0, e1, e2, e3]) => {
                // ω = 2 (e₀ ė − ė₀ e ± e × ė): + in the fixed frame, − in the body's.
                let v = [e1.clone(), e2.clone(), e3.clone()];
                let d0 = rate(e0);
                let dv: Vec3 = std::array::from_fn(|i| rate(&v[i]));
                let linear = minus(&scale(e0, &dv), &scale(&d0, &v));
                let turn = cross(&v, &dv);
                let two = Sym::Num(Rational { num: 2, den: 1 });
                (
                    scale(&two, &plus(&linear, &turn)),
                    scale(&two, &minus(&linear, &turn)),
                )
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::sym::name;
    use super::*;

    fn value(s: &Sym, at: &[(&str, f64)]) -> f64 {
        s.value(&|n| at.iter().find(|(m, _)| *m == n).map(|(_, v)| *v))
            .unwrap()
    }

    /// The angular velocity against the skew part of Ṙ Rᵀ (fixed frame) and
    /// Rᵀ Ṙ (body frame), Ṙ by central differences in time along a line
    /// q(t) = q₀ + t q̇.
    fn check(attitude: &Attitude, coords: &[&str], at: &[f64], rates: &[f64]) {
        let dot_names: Vec<String> = coords.iter().map(|c| format!("{c}_dot")).collect();
        let rate = |s: &Sym| {
            add(coords
                .iter()
                .zip(&dot_names)
                .map(|(c, d)| mul([s.derivative(c), name(d)])))
        };
        let (space, body) = attitude.angular_velocity(&rate);
        let r = attitude.rotation();
        let point = |t: f64| -> Vec<(&str, f64)> {
            coords
                .iter()
                .enumerate()
                .map(|(i, c)| (*c, at[i] + t * rates[i]))
                .chain(
                    dot_names
                        .iter()
                        .enumerate()
                        .map(|(i, d)| (d.as_str(), rates[i])),
                )
                .collect()
        };
        let matrix = |t: f64| -> [[f64; 3]; 3] {
            let p = point(t);
            std::array::from_fn(|i| std::array::from_fn(|j| value(&r[i][j], &p)))
        };
        let h = 1e-5;
        let (a, b, m) = (matrix(h), matrix(-h), matrix(0.0));
        let rdot: [[f64; 3]; 3] =
            std::array::from_fn(|i| std::array::from_fn(|j| (a[i][j] - b[i][j]) / (2.0 * h)));
        let mul = |x: &[[f64; 3]; 3], y: &[[f64; 3]; 3], tx: bool, ty: bool| -> [[f64; 3]; 3] {
            std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    (0..3)
                        .map(|k| {
                            let p = if tx { x[k][i] } else { x[i][k] };
                            let q = if ty { y[j][k] } else { y[k][j] };
                            p * q
                        })
                        .sum()
                })
            })
        };
        let p = point(0.0);
        for (w, skew) in [
            (&space, mul(&rdot, &m, false, true)),
            (&body, mul(&m, &rdot, true, false)),
        ] {
            let expected = [skew[2][1], skew[0][2], skew[1][0]];
            for i in 0..3 {
                let got = value(&w[i], &p);
                assert!(
                    (got - expected[i]).abs() < 1e-8,
                    "{attitude:?}: ω[{i}] = {got}, from R: {}",
                    expected[i]
                );
            }
        }
        // R is a rotation.
        let rtr = mul(&m, &m, true, false);
        for (i, row) in rtr.iter().enumerate() {
            for (j, x) in row.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((x - want).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn angular_velocity_is_that_of_the_rotation() {
        let c = ["a", "b", "c", "d"];
        check(
            &Attitude::Angle {
                axis: 1,
                angle: name("a"),
            },
            &c[..1],
            &[0.3],
            &[1.7],
        );
        for axes in [[2, 0, 2], [2, 1, 0], [0, 1, 2], [1, 2, 1]] {
            let attitude = Attitude::Sequence {
                axes,
                angles: [name("a"), name("b"), name("c")],
            };
            check(&attitude, &c[..3], &[0.3, 1.1, -0.4], &[0.5, -1.3, 2.1]);
        }
        // A unit quaternion moving along its sphere: rates orthogonal to it.
        let q = [0.5f64, 0.5, -0.5, 0.5];
        let rates = [0.3, -0.2, 0.3, 0.2]; // q · rates = 0
        let attitude = Attitude::Quaternion([name("a"), name("b"), name("c"), name("d")]);
        check(&attitude, &c, &q, &rates);
    }
}
