//! What holds where a body touches: a ball rolling on a plane, a knife
//! edge, and walls by shape (plane, sphere or cylinder from inside) and law
//! (smooth, or rough: the contact point's no-slip rows).

use std::collections::HashMap;
use std::ops::Range;

use toml::Spanned;

use super::super::Function;
use super::super::file::{KnifeEdgeDecl, PlaneDecl, RollingDecl, RoundDecl, WallDecl};
use super::frames::{self, Vec3, cross, dot, minus, plus, scale};
use super::sym::{Sym, add, call, div, int, mul, square, sub};
use super::{Body, Layer, structure};

/// A surface by shape: a plane (unit normal, offset, the normal's largest
/// axis), or a sphere or cylinder (centre, a cylinder's axis, radius).
enum Shape {
    Plane(Vec3, Sym, usize),
    Round(Vec3, Option<Vec3>, Sym),
}

impl Layer<'_> {
    /// The body a constraint or wall names.
    pub(super) fn find(&mut self, body: &Spanned<String>) -> Option<Body> {
        if !self.bodies.contains_key(body.get_ref()) {
            // A body declared but not read has had its errors reported.
            if self.declared_bodies.contains(body.get_ref()) {
                return None;
            }
            self.cx.error(
                structure(format!("no [[body]] is named `{}`", body.get_ref())),
                Some(body.span()),
            );
            return None;
        }
        self.bodies.get(body.get_ref()).cloned()
    }

    /// The name of the model's only body, for a declaration at `at` that
    /// names none; an error there when there are several.
    pub(super) fn only_body(&mut self, at: Range<usize>) -> Option<Spanned<String>> {
        let mut names: Vec<&String> = self.declared_bodies.iter().collect();
        if let [only] = names[..] {
            return Some(Spanned::new(at, only.clone()));
        }
        names.sort();
        let list: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
        self.cx.error(
            structure(format!(
                "the model has {} bodies ({}): name the `body` this is for",
                names.len(),
                list.join(", ")
            )),
            Some(at),
        );
        None
    }

    /// A plane's unit normal, offset and the axis of its largest component.
    fn plane(&mut self, p: &Spanned<PlaneDecl>) -> Option<(Vec3, Sym, usize)> {
        let n = self.vector(&p.get_ref().normal)?;
        let offset = match &p.get_ref().offset {
            Some(o) => self.sym(o)?,
            None => int(0),
        };
        let at = p.get_ref().normal.span();
        let k = self.unit_vector(&n, at)?;
        Some((n, offset, k))
    }

    /// Checks that `n` is a constant unit vector at the file's values and
    /// gives the axis of its largest component.
    pub(super) fn unit_vector(&mut self, n: &Vec3, at: Range<usize>) -> Option<usize> {
        let values: Option<Vec<f64>> = n.iter().map(|c| self.value(c)).collect();
        let Some(values) = values else {
            self.cx.error(
                structure("a direction is constant: numbers or expressions of the parameters"),
                Some(at),
            );
            return None;
        };
        let length = values.iter().map(|x| x * x).sum::<f64>().sqrt();
        if (length - 1.0).abs() > 1e-12 {
            self.cx.error(
                structure(format!(
                    "a normal or axis is a unit vector; this one has length {length} at the file's parameter values"
                )),
                Some(at),
            );
            return None;
        }
        let mut k = 0;
        for i in 1..3 {
            if values[i].abs() > values[k].abs() {
                k = i;
            }
        }
        Some(k)
    }

    /// A sphere's or a cylinder's centre, axis (a cylinder's) and radius,
    /// from whichever of the two is given.
    fn round(
        &mut self,
        sphere: &Option<Spanned<RoundDecl>>,
        cylinder: &Option<Spanned<RoundDecl>>,
    ) -> Option<(Vec3, Option<Vec3>, Sym)> {
        let (decl, is_cylinder) = match (sphere, cylinder) {
            (Some(s), _) => (s, false),
            (_, Some(c)) => (c, true),
            _ => return None,
        };
        let RoundDecl {
            centre,
            axis,
            radius,
        } = decl.get_ref();
        let c = self.vector(centre)?;
        let big = self.sym(radius)?;
        let axis = match (axis, is_cylinder) {
            (Some(a), true) => {
                let a = self.vector(a)?;
                self.unit_vector(&a, decl.span())?;
                Some(a)
            }
            (None, false) => None,
            _ => {
                self.cx.error(
                    structure("a cylinder has `axis`, a unit vector; a sphere has none"),
                    Some(decl.span()),
                );
                return None;
            }
        };
        Some((c, axis, big))
    }

    /// The surface a body rolls on or meets, by the one shape given (the
    /// caller checks there is one).
    fn shape(
        &mut self,
        plane: &Option<Spanned<PlaneDecl>>,
        sphere: &Option<Spanned<RoundDecl>>,
        cylinder: &Option<Spanned<RoundDecl>>,
    ) -> Option<Shape> {
        if let Some(p) = plane {
            let (n, offset, k) = self.plane(p)?;
            return Some(Shape::Plane(n, offset, k));
        }
        let (c, axis, big) = self.round(sphere, cylinder)?;
        Some(Shape::Round(c, axis, big))
    }

    /// Rows saying that the point at `offset` from the centre of `body` is
    /// at rest, except its component along `normal`: the components across
    /// the normal's largest axis `k` (with the normal's row, they span all
    /// three); identically zero rows left out.
    fn no_slip(body: &Body, offset: &Vec3, k: Option<usize>) -> Vec<Sym> {
        Self::no_slip_scaled(body, &int(1), offset, k)
    }

    /// [`Layer::no_slip`] for the rows `factor` times the contact point's
    /// velocity, which is then `factor` Ṡ + ω × `offset` (the offset
    /// scaled by `factor` too).
    fn no_slip_scaled(body: &Body, factor: &Sym, offset: &Vec3, k: Option<usize>) -> Vec<Sym> {
        let point = plus(&scale(factor, &body.velocity), &cross(&body.omega, offset));
        (0..3)
            .filter(|&i| Some(i) != k)
            .map(|i| point[i].clone())
            .filter(|r| !r.is_zero())
            .collect()
    }

    pub(super) fn rolling(&mut self, decl: &Spanned<RollingDecl>) {
        let r = decl.get_ref();
        let shapes = usize::from(r.plane.is_some())
            + usize::from(r.sphere.is_some())
            + usize::from(r.cylinder.is_some());
        if shapes != 1 {
            self.cx.error(
                structure("a ball rolls on a `plane` or inside a `sphere` or a `cylinder`: give exactly one"),
                Some(decl.span()),
            );
            return;
        }
        let Some(shape) = self.shape(&r.plane, &r.sphere, &r.cylinder) else {
            return;
        };
        let Some(name) = r.body.clone().or_else(|| self.only_body(decl.span())) else {
            return;
        };
        let Some(body) = self.find(&name) else {
            return;
        };
        if let Some((radius, axis)) = &body.disk {
            let Shape::Plane(n, offset, k) = &shape else {
                self.cx.error(
                    structure("a disk rolls on a `plane` (not inside a sphere or cylinder yet)"),
                    Some(decl.span()),
                );
                return;
            };
            if let Some(rows) = self.disk_on_plane(decl, &body, radius, axis, n, offset, *k) {
                for row in rows {
                    self.out
                        .constraints
                        .push(Spanned::new(decl.span(), row.to_string()));
                }
            }
            return;
        }
        let Some(radius) = body.radius.clone() else {
            let id = name.get_ref().clone();
            self.cx.error(
                structure(format!(
                    "body `{id}` rolls, so it needs a contact shape: `radius` (a sphere) or `disk`"
                )),
                Some(name.span()),
            );
            return;
        };
        let rows = match &shape {
            Shape::Plane(n, offset, k) => self.on_plane(decl, &body, &radius, n, offset, *k),
            Shape::Round(c, axis, big) => self.inside(decl, &body, &radius, c, axis.as_ref(), big),
        };
        let Some(rows) = rows else {
            return;
        };
        for row in rows {
            self.out
                .constraints
                .push(Spanned::new(decl.span(), row.to_string()));
        }
    }

    /// A ball on a plane: the contact point's velocity across the normal's
    /// largest axis; its height above the plane becomes a holonomic
    /// constraint where it varies.
    fn on_plane(
        &mut self,
        decl: &Spanned<RollingDecl>,
        body: &Body,
        radius: &Sym,
        n: &Vec3,
        offset: &Sym,
        k: usize,
    ) -> Option<Vec<Sym>> {
        let rows = Self::no_slip(body, &scale(&mul([int(-1), radius.clone()]), n), Some(k));
        let height = sub(sub(dot(n, &body.position), offset.clone()), radius.clone());
        let coordinates = &self.coordinates;
        if height.depends(&|x| coordinates.iter().any(|c| c == x)) {
            self.out
                .holonomic
                .push(Spanned::new(decl.span(), height.to_string()));
        } else if let Some(h) = self.value(&height)
            && h.abs() > 1e-12
        {
            self.cx.error(
                structure(format!(
                    "the ball does not touch the plane it rolls on: its height above it is {h} at the file's parameter values"
                )),
                Some(decl.span()),
            );
            return None;
        }
        Some(rows)
    }

    /// A disk (radius R, axis e) on a plane (unit normal n): it touches at
    /// the rim's point nearest the plane, C = S − R u with u = w/|w|,
    /// w = n − (n·e)e, and its centre's height h = n·S − offset is R|w|.
    /// The position must say so by its coordinates (as z = R sin θ does
    /// for z-x-z angles), which is checked at sample coordinates (h² =
    /// R²|w|²); then u = R w/h, with no square root, and C − S = −R² w/h.
    /// The rows are C's velocity across the normal's largest axis.
    #[allow(clippy::too_many_arguments)]
    fn disk_on_plane(
        &mut self,
        decl: &Spanned<RollingDecl>,
        body: &Body,
        radius: &Sym,
        e: &Vec3,
        n: &Vec3,
        offset: &Sym,
        k: usize,
    ) -> Option<Vec<Sym>> {
        let (w, size2) = toward(n, e);
        let h = sub(dot(n, &body.position), offset.clone());
        let gap = sub(square(h.clone()), mul([square(radius.clone()), size2]));
        let held = "a disk of radius R touching a plane keeps its centre at the height R·sqrt(1 − (n·e)²) above it (e its axis): write its position by coordinates that keep it there (the height R sin θ for z-x-z angles with the axis along the body's z)";
        if !self.kept_by_coordinates(&gap, &square(radius.clone()), held, decl.span()) {
            return None;
        }
        let offset = scale(&div(mul([int(-1), square(radius.clone())]), h), &w);
        Some(Self::no_slip(body, &offset, Some(k)))
    }

    /// A ball inside a sphere or a cylinder of radius R: its centre keeps
    /// the distance R − r from the centre (the axis), which the position
    /// must say by its coordinates (two angles, say); the contact point is
    /// at r d/(R − r) from the centre. The no-slip rows are the contact
    /// point's velocity along two tangent directions, t = ∂C/∂qⱼ for the
    /// first coordinate that moves the centre and d × t; with the normal
    /// (along which that velocity is zero on the surface) they span all
    /// three wherever t ≠ 0.
    fn inside(
        &mut self,
        decl: &Spanned<RollingDecl>,
        body: &Body,
        radius: &Sym,
        c: &Vec3,
        axis: Option<&Vec3>,
        big: &Sym,
    ) -> Option<Vec<Sym>> {
        let d = across(&body.position, c, axis);
        let reach = sub(big.clone(), radius.clone());
        let gap = sub(square(reach.clone()), dot(&d, &d));
        let held = "a ball rolling inside a sphere or cylinder of radius R keeps its centre at R − r from the centre (axis): write its position by coordinates that keep it there (two angles, say)";
        if !self.kept_by_coordinates(&gap, &square(reach.clone()), held, decl.span()) {
            return None;
        }
        let Some(t) = self
            .coordinates
            .iter()
            .map(|q| body.position.clone().map(|x| x.derivative(q)))
            .find(|t| t.iter().any(|x| !x.is_zero()))
        else {
            self.cx.error(
                structure("the ball's centre does not move: nothing rolls"),
                Some(decl.span()),
            );
            return None;
        };
        let other = cross(&d, &t);
        let offset = scale(&div(radius.clone(), reach), &d);
        let slip = plus(&body.velocity, &cross(&body.omega, &offset));
        Some(vec![dot(&slip, &t), dot(&slip, &other)])
    }

    /// Whether the coordinates keep `gap` (a difference of squares, of the
    /// size of `size`) at zero, by [`Layer::largest_over_coordinates`];
    /// otherwise an error at `span` saying `held` and by how much.
    fn kept_by_coordinates(
        &mut self,
        gap: &Sym,
        size: &Sym,
        held: &str,
        span: Range<usize>,
    ) -> bool {
        let scale_of = self.value(size).unwrap_or(1.0);
        let why = match self.largest_over_coordinates(gap) {
            Some(worst) if worst <= 1e-9 * (1.0 + scale_of) => return true,
            Some(worst) => {
                format!(
                    "here the squares of the two differ by up to {worst:.3} at sample coordinates"
                )
            }
            None => "it has no value at enough sample coordinates to check".to_string(),
        };
        self.cx
            .error(structure(format!("{held}; {why}")), Some(span));
        false
    }

    /// The largest |e| at sample values of the coordinates (the parameters
    /// at the file's values), four in each of [−s, s] for s = 2, 1, 1/2, 1/4
    /// (so that a position defined only near zero, through a square root,
    /// is sampled too), over the samples where e has a finite value; `None`
    /// when fewer than 4 of the 16 have one.
    fn largest_over_coordinates(&self, e: &Sym) -> Option<f64> {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut worst = 0.0f64;
        let mut defined = 0;
        for k in 0..16 {
            let size = 2.0 / f64::from(1u32 << (k / 4));
            let sample: HashMap<&str, f64> = self
                .coordinates
                .iter()
                .map(|q| {
                    seed ^= seed << 13;
                    seed ^= seed >> 7;
                    seed ^= seed << 17;
                    (
                        q.as_str(),
                        size * (2.0 * (seed >> 11) as f64 / (1u64 << 53) as f64 - 1.0),
                    )
                })
                .collect();
            let v = e.value(&|n| {
                sample
                    .get(n)
                    .copied()
                    .or_else(|| self.values.get(n).copied())
            });
            if let Some(v) = v.filter(|v| v.is_finite()) {
                worst = worst.max(v.abs());
                defined += 1;
            }
        }
        (defined >= 4).then_some(worst)
    }

    pub(super) fn knife_edge(&mut self, decl: &Spanned<KnifeEdgeDecl>) {
        let d = decl.get_ref();
        let (Some(blade), Some(n)) = (self.vector(&d.blade), self.vector(&d.normal)) else {
            return;
        };
        if self.unit_vector(&n, d.normal.span()).is_none() {
            return;
        }
        let Some(name) = d.body.clone().or_else(|| self.only_body(decl.span())) else {
            return;
        };
        let Some(body) = self.find(&name) else {
            return;
        };
        let across = cross(&n, &frames::apply(&body.rotation, &blade));
        let row = dot(&across, &body.velocity);
        if row.is_zero() {
            self.cx.error(
                structure("the blade is along the plane's normal: it constrains nothing"),
                Some(d.blade.span()),
            );
            return;
        }
        self.out
            .constraints
            .push(Spanned::new(decl.span(), row.to_string()));
    }

    pub(super) fn wall(&mut self, w: &mut WallDecl, span: Range<usize>) {
        let shapes = usize::from(w.plane.is_some())
            + usize::from(w.sphere.is_some())
            + usize::from(w.cylinder.is_some());
        // A wall by shape is met by the body it names, or by the only one.
        if w.body.is_none() && (shapes > 0 || w.law.is_some()) {
            w.body = self.only_body(span.clone());
        }
        let Some(body_name) = w.body.clone() else {
            return;
        };
        if shapes != 1 || w.surface.is_some() || !w.contact.is_empty() {
            self.cx.error(
                structure("a wall met by a body has one shape, `plane`, `sphere` or `cylinder`, and no `surface` or `contact` (they are derived)"),
                Some(span),
            );
            return;
        }
        let rough = match w.law.as_ref().map(|l| l.get_ref().as_str()) {
            None | Some("smooth") => false,
            Some("rough") => true,
            Some(other) => {
                let at = w.law.as_ref().map(|l| l.span());
                self.cx.error(
                    structure(format!("the law is `smooth` or `rough`, not `{other}`")),
                    at,
                );
                return;
            }
        };
        // The geometry first (it needs `self` mutably), then the body.
        let Some(shape) = self.shape(&w.plane, &w.sphere, &w.cylinder) else {
            return;
        };
        let Some(body) = self.find(&body_name) else {
            return;
        };
        if rough && body.disk.is_some() && matches!(shape, Shape::Round(_, None, _)) {
            self.cx.error(
                structure("a disk meets a sphere wall with the `smooth` law only: the rough law's contact rows at the rim make the derivation's exact rank test of B too large"),
                w.law.as_ref().map(|l| l.span()),
            );
            return;
        }
        let r = body.radius.clone().unwrap_or(int(0));
        // The surface; the factor the contact point's velocity is scaled
        // by in the rough rows, and the point's offset from the centre
        // times that factor; the axis whose component the rows leave out.
        let (surface, offset, factor, k) = match (&shape, &body.disk) {
            // A disk (radius R, axis e) meets the plane at its rim's point
            // nearest it, R u from the centre, u = w/|w|, w = n − (n·e)e:
            // f = n·S − offset − R|w|. (Where e is along n the disk lies
            // flat against the wall and f has no derivative.) Its rough
            // rows are |w| times the point's velocity, |w| Ṡ − R ω × w:
            // the same rows, and the exact rank test sees them dependent
            // with a rolling disk's rows (divided by the root, it does not).
            (Shape::Plane(n, offset, k), Some((radius, e))) => {
                let (w, size2) = toward(n, e);
                let size = call(Function::Sqrt, size2);
                (
                    sub(
                        sub(dot(n, &body.position), offset.clone()),
                        mul([radius.clone(), size.clone()]),
                    ),
                    scale(&mul([int(-1), radius.clone()]), &w),
                    size,
                    Some(*k),
                )
            }
            // A disk (radius ρ, axis e) inside a sphere (centre c, radius R):
            // its rim's point farthest from c is ρ u from the centre, u = w/|w|,
            // w = d − (d·e)e (d = S − c), at |d|² + ρ² + 2ρ|w| squared from c;
            // f = (R² − that)/(2R) has the distance's zero set, side and
            // gradient on the wall.
            // (Where d is along e every rim point is as far: the disk lies
            // against the sphere all round.) Smooth only: the rough rows,
            // |w| times that point's velocity, take the exact rank test of
            // B past the derivation's bounds (checked above).
            (Shape::Round(c, None, big), Some((radius, e))) => {
                let d = minus(&body.position, c);
                let along = dot(&d, e);
                let w = minus(&d, &scale(&along, e));
                let size = call(Function::Sqrt, sub(dot(&d, &d), square(along)));
                let far = add([
                    dot(&d, &d),
                    square(radius.clone()),
                    mul([int(2), radius.clone(), size.clone()]),
                ]);
                (
                    div(sub(square(big.clone()), far), mul([int(2), big.clone()])),
                    scale(radius, &w),
                    size,
                    None,
                )
            }
            (Shape::Round(_, Some(_), _), Some(_)) => {
                self.cx.error(
                    structure("a disk meets a `plane` or a `sphere` wall (not a cylinder: its rim's point farthest from an axis has no closed form)"),
                    Some(span.clone()),
                );
                return;
            }
            (Shape::Plane(n, offset, k), None) => (
                sub(sub(dot(n, &body.position), offset.clone()), r.clone()),
                scale(&mul([int(-1), r.clone()]), n),
                int(1),
                Some(*k),
            ),
            (Shape::Round(c, axis, big), None) => {
                let d = across(&body.position, c, axis.as_ref());
                let reach = sub(big.clone(), r.clone());
                let f = div(
                    sub(square(reach.clone()), dot(&d, &d)),
                    mul([int(2), reach.clone()]),
                );
                // On the wall |d| = R − r: the contact point is r d/(R − r) away.
                (f, scale(&div(r.clone(), reach), &d), int(1), None)
            }
        };
        let rows = if rough {
            if body.radius.is_none() && body.disk.is_none() {
                self.cx.error(
                    structure(format!(
                        "a rough wall holds the point of the body's contact shape that touches it; body `{}` has none (give it a `radius` or a `disk`)",
                        body_name.get_ref()
                    )),
                    w.law.as_ref().map(|l| l.span()),
                );
                return;
            }
            Self::no_slip_scaled(&body, &factor, &offset, k)
        } else {
            Vec::new()
        };
        w.surface = Some(Spanned::new(span.clone(), surface.to_string()));
        w.contact = rows
            .into_iter()
            .map(|r| Spanned::new(span.clone(), r.to_string()))
            .collect();
    }
}

/// The direction in a disk's plane (axis e) toward the plane of normal n,
/// w = n − (n·e)e, and |w|² = 1 − (n·e)² (n and e unit vectors): the rim's
/// point nearest the plane is R w/|w| from the centre.
fn toward(n: &Vec3, e: &Vec3) -> (Vec3, Sym) {
    let along = dot(n, e);
    (minus(n, &scale(&along, e)), sub(int(1), square(along)))
}

/// The position `p` from a sphere's centre `c`, or from a cylinder's axis
/// through `c` (its component along `axis` removed).
fn across(p: &Vec3, c: &Vec3, axis: Option<&Vec3>) -> Vec3 {
    let d = minus(p, c);
    match axis {
        Some(a) => minus(&d, &scale(&dot(&d, a), a)),
        None => d,
    }
}
