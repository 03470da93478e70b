//! Springs: a linear spring of stiffness k and rest length L between two
//! points, each a point of a body (its centre, or a point fixed in the body)
//! or a point fixed in space, adds V = ½ k (|P₁ − P₂| − L)² (½ k |P₁ − P₂|²
//! for L = 0, with no root).

use toml::Spanned;

use super::super::file::{EndDecl, Number, SpringDecl};
use super::super::{Function, Rational};
use super::frames::{self, Vec3, dot, minus, plus};
use super::sym::{Sym, call, int, mul, square, sub};
use super::{Layer, structure};

impl Layer<'_> {
    pub(super) fn spring(&mut self, decl: &Spanned<SpringDecl>) {
        let d = decl.get_ref();
        let Some(k) = self.sym(&d.stiffness) else {
            return;
        };
        self.positive(&k, "the stiffness", d.stiffness.span());
        let length = match &d.length {
            Some(l) => {
                let Some(length) = self.sym(l) else {
                    return;
                };
                if let Some(v) = self.value(&length)
                    && v.partial_cmp(&0.0).is_none_or(|o| o.is_lt())
                {
                    self.cx.error(
                        structure(format!(
                            "the rest length must be zero or positive; it is {v} at the file's parameter values"
                        )),
                        Some(l.span()),
                    );
                }
                length
            }
            None => int(0),
        };
        let ends = d.ends.get_ref();
        if ends.len() != 2 {
            self.cx.error(
                structure(format!(
                    "a spring has two ends; this one has {}",
                    ends.len()
                )),
                Some(d.ends.span()),
            );
            return;
        }
        let (Some((p1, on_body_1)), Some((p2, on_body_2))) =
            (self.end(&ends[0]), self.end(&ends[1]))
        else {
            return;
        };
        if !on_body_1 && !on_body_2 {
            self.cx.error(
                structure("a spring between two fixed points does nothing: one end is on a body"),
                Some(d.ends.span()),
            );
            return;
        }
        let d2 = {
            let between = minus(&p1, &p2);
            dot(&between, &between)
        };
        let stretch = if length.is_zero() {
            d2
        } else {
            let distance = call(Function::Sqrt, d2);
            square(sub(distance, length))
        };
        let v = mul([Sym::Num(Rational { num: 1, den: 2 }), k, stretch]);
        if !v.is_zero() {
            self.out
                .potential
                .push(Spanned::new(decl.span(), v.to_string()));
        }
    }

    /// A spring's end as a point in the fixed frame, and whether it is on
    /// a body.
    fn end(&mut self, end: &Spanned<EndDecl>) -> Option<(Vec3, bool)> {
        let EndDecl { body, at, point } = end.get_ref();
        match (body, at, point) {
            (Some(body), at, None) => {
                let b = self.find(body)?;
                let Some(at) = at else {
                    return Some((b.position, true));
                };
                let offset = self.fixed(at)?;
                Some((
                    plus(&b.position, &frames::apply(&b.rotation, &offset)),
                    true,
                ))
            }
            (None, None, Some(point)) => Some((self.fixed(point)?, false)),
            _ => {
                self.cx.error(
                    structure(
                        "a spring's end is `{ body = … }` (its centre), `{ body = …, at = [x, y, z] }` (a point fixed in the body, in its frame) or `{ point = [x, y, z] }` (fixed in space)",
                    ),
                    Some(end.span()),
                );
                None
            }
        }
    }

    /// A vector that depends on neither coordinates nor velocities.
    fn fixed(&mut self, v: &Spanned<Vec<Spanned<Number>>>) -> Option<Vec3> {
        let p = self.vector(v)?;
        if p.iter().any(|c| self.moves(c)) {
            self.cx.error(
                structure("this point is fixed: numbers or expressions of the parameters"),
                Some(v.span()),
            );
            return None;
        }
        Some(p)
    }

    fn moves(&self, s: &Sym) -> bool {
        s.depends(&|n| self.is_coordinate(n) || self.rates.iter().any(|r| r == n))
    }
}
