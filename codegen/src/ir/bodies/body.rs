//! A body: its mass, inertia, attitude and centre, read from `[[body]]`;
//! its velocities as definitions, its T and V.

use std::ops::Range;

use toml::Spanned;

use super::super::Rational;
use super::super::file::{BodyDecl, Inertia, Number, OrientationDecl};
use super::frames::{self, Attitude, Vec3, dot};
use super::sym::{Sym, add, int, mul, name, square, sub};
use super::{Body, Layer, structure};
use crate::diag::ErrorKind;

impl Layer<'_> {
    pub(super) fn body(&mut self, decl: &Spanned<BodyDecl>, gravity: Option<&Vec3>) {
        let b = decl.get_ref();
        let id = b.name.get_ref();
        let snake = !id.is_empty()
            && id.starts_with(|c: char| c.is_ascii_lowercase())
            && id
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if !snake {
            self.cx.error(
                ErrorKind::BadName {
                    name: id.clone(),
                    why: "a body's name is snake_case (lower case, digits and `_`)".into(),
                },
                Some(b.name.span()),
            );
            return;
        }
        if self.bodies.contains_key(id) {
            self.cx.error(
                ErrorKind::Duplicate {
                    name: id.clone(),
                    first: "body",
                },
                Some(b.name.span()),
            );
            return;
        }
        // Each part is read, so that the mistakes of all are reported.
        let mass = self.sym(&b.mass);
        if let Some(m) = &mass {
            self.positive(m, "the mass", b.mass.span());
        }
        let position = self.vector(&b.position).filter(|p| {
            p.iter()
                .all(|x| self.positional(x, "the position", b.position.span()))
        });
        let inertia = b.inertia.as_ref().map(|i| self.inertia(i));
        let attitude = self.attitude(b);
        let (Some(mass), Some(position), Some(attitude)) = (mass, position, attitude) else {
            return;
        };
        let inertia = match inertia {
            Some(None) => return,
            Some(i) => i,
            None => None,
        };
        if inertia.is_none() && !matches!(attitude, Attitude::Fixed) {
            self.cx.error(
                structure(format!(
                    "body `{id}` turns (it has an orientation), so it needs `inertia`"
                )),
                Some(decl.span()),
            );
            return;
        }
        let radius = match &b.radius {
            Some(r) => {
                let Some(r) = self.sym(r) else { return };
                self.positive(
                    &r,
                    "the radius",
                    b.radius.as_ref().map_or(0..0, |s| s.span()),
                );
                Some(r)
            }
            None => None,
        };
        let attitude_rotation = attitude.rotation();
        let disk = match &b.disk {
            Some(d) => {
                if b.radius.is_some() {
                    self.cx.error(
                        structure(
                            "a body's contact shape is a sphere (`radius`) or a `disk`, not both",
                        ),
                        Some(d.span()),
                    );
                    return;
                }
                let (Some(r), Some(axis)) = (
                    self.sym(&d.get_ref().radius),
                    self.vector(&d.get_ref().axis),
                ) else {
                    return;
                };
                self.positive(&r, "the disk's radius", d.get_ref().radius.span());
                if self.unit_vector(&axis, d.get_ref().axis.span()).is_none() {
                    return;
                }
                Some((r, frames::apply(&attitude_rotation, &axis)))
            }
            None => None,
        };

        // Kinematics, with compound components as definitions.
        let velocity_raw: Vec3 = std::array::from_fn(|i| self.rate(&position[i]));
        let axes = ["x", "y", "z"];
        let velocity: Vec3 = std::array::from_fn(|i| {
            self.named(
                velocity_raw[i].clone(),
                &b.name,
                &format!("v{}", axes[i]),
                "its centre's velocity",
            )
        });
        let (space, frame) = attitude.angular_velocity(&|s| self.rate(s));
        let omega: Vec3 = std::array::from_fn(|i| {
            self.named(
                space[i].clone(),
                &b.name,
                &format!("w{}", axes[i]),
                "its angular velocity",
            )
        });

        // T.
        let half = Sym::Num(Rational { num: 1, den: 2 });
        let translation = mul([
            half.clone(),
            mass.clone(),
            add(velocity.iter().map(|v| square(v.clone()))),
        ]);
        let mut kinetic = vec![translation];
        match (&inertia, &attitude) {
            (None, _) => {}
            // A ball's ½ J |ω|² is 2 J (|e|² |ė|² − (e · ė)²); with the
            // added 2 J (e · ė)² below and |e|² = 1, 2 J |ė|².
            (Some(Moments::Ball(j)), Attitude::Quaternion(e)) => kinetic.push(mul([
                int(2),
                j.clone(),
                add(e.iter().map(|x| square(self.rate(x)))),
            ])),
            (Some(Moments::Ball(j)), _) => kinetic.push(mul([
                half.clone(),
                j.clone(),
                add(omega.iter().map(|w| square(w.clone()))),
            ])),
            // Equal moments about the two axes other than the last angle's:
            // the same T in the frame before the last rotation.
            (Some(Moments::Principal(m)), _)
                if let Some((k, turned)) = attitude.before_last_rotation(&|s| self.rate(s))
                    && m[(k + 1) % 3].to_string() == m[(k + 2) % 3].to_string() =>
            {
                let quadratic = Moments::Principal(m.clone()).quadratic(&turned);
                kinetic.push(mul([half.clone(), quadratic]));
            }
            (Some(moments), _) => {
                let body_frame: Vec3 = std::array::from_fn(|i| {
                    self.named(
                        frame[i].clone(),
                        &b.name,
                        &format!("w{}", i + 1),
                        "its angular velocity in the body frame",
                    )
                });
                kinetic.push(mul([half.clone(), moments.quadratic(&body_frame)]));
            }
        }
        if let Attitude::Quaternion(e) = &attitude {
            if let Some(moments @ (Moments::Principal(_) | Moments::Tensor(_))) = &inertia {
                let along = add(e.iter().map(|x| mul([x.clone(), self.rate(x)])));
                kinetic.push(mul([
                    Sym::Num(Rational { num: 2, den: 3 }),
                    moments.trace(),
                    square(along),
                ]));
            }
            let norm = sub(add(e.iter().map(|x| square(x.clone()))), int(1));
            self.out
                .holonomic
                .push(Spanned::new(decl.span(), norm.to_string()));
        }
        for t in kinetic {
            if !t.is_zero() {
                self.out
                    .kinetic
                    .push(Spanned::new(decl.span(), t.to_string()));
            }
        }

        // V.
        if let Some(g) = gravity {
            let down: Vec3 = std::array::from_fn(|i| mul([int(-1), g[i].clone()]));
            let v = mul([mass.clone(), dot(&down, &position)]);
            if !v.is_zero() {
                self.out
                    .potential
                    .push(Spanned::new(decl.span(), v.to_string()));
            }
        }
        self.bodies.insert(
            id.clone(),
            Body {
                position,
                velocity,
                omega,
                rotation: attitude_rotation,
                radius,
                disk,
            },
        );
    }

    /// Records an error when a quantity that must be positive is not, at the
    /// file's parameter values (and goes on).
    pub(super) fn positive(&mut self, s: &Sym, what: &str, span: Range<usize>) {
        if let Some(v) = self.value(s)
            && v.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        {
            self.cx.error(
                structure(format!(
                    "{what} must be positive; it is {v} at the file's parameter values"
                )),
                Some(span),
            );
        }
    }

    fn attitude(&mut self, b: &BodyDecl) -> Option<Attitude> {
        let Some(o) = &b.orientation else {
            return Some(Attitude::Fixed);
        };
        let span = o.span();
        let OrientationDecl {
            angle,
            axis,
            euler,
            angles,
            quaternion,
        } = o.get_ref();
        let given = usize::from(angle.is_some())
            + usize::from(euler.is_some())
            + usize::from(quaternion.is_some());
        if given != 1 {
            self.cx.error(
                structure(
                    "an orientation is one of: `angle` (with `axis`), `euler` (with `angles`), `quaternion`",
                ),
                Some(span),
            );
            return None;
        }
        let axis_of = |c: char| "xyz".find(c);
        if let Some(angle) = angle {
            let k = match axis {
                None => 2,
                Some(a) => match a.get_ref().as_str() {
                    "x" => 0,
                    "y" => 1,
                    "z" => 2,
                    other => {
                        self.cx.error(
                            structure(format!("the axis is `x`, `y` or `z`, not `{other}`")),
                            Some(a.span()),
                        );
                        return None;
                    }
                },
            };
            let angle_sym = self.sym_text(angle.get_ref(), angle.span())?;
            if !self.positional(&angle_sym, "the angle", angle.span()) {
                return None;
            }
            return Some(Attitude::Angle {
                axis: k,
                angle: angle_sym,
            });
        }
        if let Some(sequence) = euler {
            let seq = sequence.get_ref();
            let axes: Vec<usize> = seq.chars().filter_map(axis_of).collect();
            let valid =
                seq.len() == 3 && axes.len() == 3 && axes[0] != axes[1] && axes[1] != axes[2];
            if !valid {
                self.cx.error(
                    structure(format!(
                        "`{seq}` is not a rotation sequence: three of x, y, z, no axis twice in a row (zxz, zyx, …)"
                    )),
                    Some(sequence.span()),
                );
                return None;
            }
            let Some(angles) = angles else {
                self.cx.error(
                    structure("`euler` needs `angles`, its three angles in the sequence's order"),
                    Some(span),
                );
                return None;
            };
            if angles.get_ref().len() != 3 {
                self.cx.error(
                    structure(format!(
                        "`angles` has three angles; this one has {}",
                        angles.get_ref().len()
                    )),
                    Some(angles.span()),
                );
                return None;
            }
            let mut out = Vec::new();
            for a in angles.get_ref() {
                let s = self.sym_text(a.get_ref(), a.span())?;
                if !self.positional(&s, "the angle", a.span()) {
                    return None;
                }
                out.push(s);
            }
            return Some(Attitude::Sequence {
                axes: [axes[0], axes[1], axes[2]],
                angles: [out[0].clone(), out[1].clone(), out[2].clone()],
            });
        }
        let q = quaternion.as_ref()?;
        let parts = q.get_ref();
        let all_coordinates = parts.iter().all(|p| self.is_coordinate(p.get_ref()));
        if parts.len() != 4 || !all_coordinates {
            self.cx.error(
                structure(
                    "a quaternion is four coordinates (e0, e1, e2, e3), e0 the scalar part; its norm 1 becomes a holonomic constraint",
                ),
                Some(q.span()),
            );
            return None;
        }
        Some(Attitude::Quaternion(std::array::from_fn(|i| {
            name(parts[i].get_ref())
        })))
    }

    fn inertia(&mut self, i: &Spanned<Inertia>) -> Option<Moments> {
        let span = i.span();
        let spanned = |n: &Number| Spanned::new(span.clone(), n.clone());
        match i.get_ref() {
            Inertia::Ball(j) => {
                let j = self.sym(&spanned(j))?;
                self.positive(&j, "the moment of inertia", span);
                Some(Moments::Ball(j))
            }
            Inertia::Principal(m) if m.len() == 3 => {
                let m: Vec<Sym> = m
                    .iter()
                    .map(|x| self.sym(&spanned(x)))
                    .collect::<Option<_>>()?;
                for x in &m {
                    self.positive(x, "a principal moment of inertia", span.clone());
                }
                Some(Moments::Principal(std::array::from_fn(|k| m[k].clone())))
            }
            Inertia::Tensor(rows) if rows.len() == 3 && rows.iter().all(|r| r.len() == 3) => {
                let mut t: Vec<Vec<Sym>> = Vec::new();
                for r in rows {
                    t.push(
                        r.iter()
                            .map(|x| self.sym(&spanned(x)))
                            .collect::<Option<_>>()?,
                    );
                }
                let tensor: frames::Mat3 =
                    std::array::from_fn(|i| std::array::from_fn(|j| t[i][j].clone()));
                let symmetric = (0..3).all(|i| (0..3).all(|j| tensor[i][j] == tensor[j][i]));
                if !symmetric {
                    self.cx.error(
                        structure(
                            "an inertia tensor is symmetric: write entry (j, i) as entry (i, j)",
                        ),
                        Some(span.clone()),
                    );
                    return None;
                }
                // Positive definite at the file's values (leading minors).
                let v: Option<Vec<Vec<f64>>> = tensor
                    .iter()
                    .map(|r| r.iter().map(|x| self.value(x)).collect())
                    .collect();
                if let Some(v) = v {
                    let m1 = v[0][0];
                    let m2 = v[0][0] * v[1][1] - v[0][1] * v[1][0];
                    let m3 = v[0][0] * (v[1][1] * v[2][2] - v[1][2] * v[2][1])
                        - v[0][1] * (v[1][0] * v[2][2] - v[1][2] * v[2][0])
                        + v[0][2] * (v[1][0] * v[2][1] - v[1][1] * v[2][0]);
                    if !(m1 > 0.0 && m2 > 0.0 && m3 > 0.0) {
                        self.cx.error(
                            structure("the inertia tensor must be positive definite; at the file's parameter values it is not"),
                            Some(span),
                        );
                        return None;
                    }
                }
                Some(Moments::Tensor(Box::new(tensor)))
            }
            _ => {
                self.cx.error(
                    structure("`inertia` is a number (a ball's moment), three principal moments, or a 3×3 tensor"),
                    Some(span),
                );
                None
            }
        }
    }
}

/// A body's inertia about its centre.
enum Moments {
    /// J I.
    Ball(Sym),
    /// diag(I₁, I₂, I₃) in the body frame.
    Principal([Sym; 3]),
    /// A symmetric tensor in the body frame.
    Tensor(Box<frames::Mat3>),
}

impl Moments {
    /// Ωᵀ I Ω.
    fn quadratic(&self, w: &Vec3) -> Sym {
        match self {
            Moments::Ball(j) => mul([j.clone(), add(w.iter().map(|x| square(x.clone())))]),
            Moments::Principal(m) => add((0..3).map(|i| mul([m[i].clone(), square(w[i].clone())]))),
            Moments::Tensor(t) => add((0..3).flat_map(|i| {
                (0..3).map(move |j| {
                    if i == j {
                        mul([t[i][i].clone(), square(w[i].clone())])
                    } else if i < j {
                        mul([int(2), t[i][j].clone(), w[i].clone(), w[j].clone()])
                    } else {
                        int(0)
                    }
                })
            })),
        }
    }

    /// tr I.
    fn trace(&self) -> Sym {
        match self {
            Moments::Ball(j) => mul([int(3), j.clone()]),
            Moments::Principal(m) => add(m.iter().cloned()),
            Moments::Tensor(t) => add((0..3).map(|i| t[i][i].clone())),
        }
    }
}
