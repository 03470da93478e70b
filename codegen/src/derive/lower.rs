//! Pass 3: function applications lowered to symbols, so that every entry of
//! G, A and B is a rational function of symbols and exact linear algebra
//! applies; sin² + cos² = 1 and cosh² − sinh² = 1 reduced; the functions
//! raised back before evaluation. Before lowering, sin, cos, sinh and cosh
//! of a whole multiple n·u (or of −u) are written in those of u
//! ([`in_base_arguments`]), so that the identities reach multiple angles.
//!
//! A [`Lowering`] is made only from the whole [`Raw`] derivation, so no
//! expression that is later turned into a rational function can miss it.

use std::collections::HashMap;
use std::sync::Arc;

use symbolica::prelude::*;

use super::atoms::{children, size};
use super::budget::{self, Over};
use super::build::{Differentiate, constant_symbol, own_constants, own_functions, own_symbol};
use super::mechanics::Raw;
use super::symbols::Symbols;
use super::{Rat, is_zero};
use crate::ir::{Constant, Function};

/// How many times larger than an evaluated quantity as written its
/// reduction may be and still be compiled to see which is cheaper.
const REDUCED_GROWTH: usize = 10;

/// A function application replaced by a symbol while matrices are computed.
struct Lowered {
    symbol: Symbol,
    function: Atom,
}

/// The symbols of sin and cos (`sign` −1: c² = 1 − s²), or of sinh and
/// cosh (`sign` +1: c² = 1 + s²), of one argument.
#[derive(Clone, Copy)]
struct Pair {
    s: Symbol,
    c: Symbol,
    sign: i64,
}

/// The lowered function applications of one model and the variables of its
/// rational functions.
pub struct Lowering {
    lowered: Vec<Lowered>,
    /// Pairs of one argument whose squares are tied ([`Pair`]).
    pairs: Vec<Pair>,
    vars: Arc<Vec<PolyVariable>>,
}

impl Lowering {
    /// Finds every application of a model function in `raw` and gives it a
    /// symbol; sin and cos, and sinh and cosh, of the same argument are
    /// paired for the reduction.
    pub fn new(sym: &Symbols, raw: &Raw) -> Self {
        let atoms: Vec<Atom> = raw.expressions().into_iter().map(prepared).collect();
        let mut base: Vec<Symbol> = sym
            .params
            .iter()
            .chain(&sym.coords)
            .chain(&sym.vels)
            .copied()
            .collect();
        base.extend([Constant::Pi, Constant::E].map(constant_symbol));
        Self::of(&atoms, base)
    }

    /// The lowering of `atoms`, whose rational functions have the variables
    /// `base` and the lowered applications.
    fn of(atoms: &[Atom], base: Vec<Symbol>) -> Self {
        let mut lowered: Vec<Lowered> = Vec::new();
        let mut seen: HashMap<String, usize> = HashMap::new();
        // The pairs' symbols by argument: sin, cos, sinh, cosh.
        let mut args_by_fn: HashMap<String, [Option<Symbol>; 4]> = HashMap::new();
        let [sinh, cosh] = [Function::Sinh, Function::Cosh].map(|f| own_symbol(f.name()));
        let functions = [Symbol::SIN, Symbol::COS, Symbol::EXP, Symbol::LOG]
            .into_iter()
            .chain(own_functions());
        for f in functions {
            for a in atoms {
                let mut found = Vec::new();
                applications(a.as_view(), f, &mut found);
                for arg in found {
                    let app = function!(f, arg.clone());
                    let key = app.to_string();
                    if seen.contains_key(&key) {
                        continue;
                    }
                    let s = own_symbol(&format!("fn__{}", lowered.len()));
                    seen.insert(key, lowered.len());
                    lowered.push(Lowered {
                        symbol: s,
                        function: app,
                    });
                    let place = [Symbol::SIN, Symbol::COS, sinh, cosh]
                        .iter()
                        .position(|g| *g == f);
                    if let Some(k) = place {
                        args_by_fn.entry(arg.to_string()).or_default()[k] = Some(s);
                    }
                }
            }
        }
        let mut pairs: Vec<Pair> = Vec::new();
        for [sin, cos, sinh, cosh] in args_by_fn.into_values() {
            if let (Some(s), Some(c)) = (sin, cos) {
                pairs.push(Pair { s, c, sign: -1 });
            }
            if let (Some(s), Some(c)) = (sinh, cosh) {
                pairs.push(Pair { s, c, sign: 1 });
            }
        }
        pairs.sort_by_key(|p| p.s.to_string());
        let mut vars: Vec<PolyVariable> = base.into_iter().map(PolyVariable::Symbol).collect();
        for l in &lowered {
            vars.push(PolyVariable::Symbol(l.symbol));
        }
        Self {
            lowered,
            pairs,
            vars: Arc::new(vars),
        }
    }

    fn lower(&self, a: &Atom) -> Atom {
        let mut a = prepared(a);
        for l in &self.lowered {
            a = a.replace(l.function.clone()).with(Atom::from(l.symbol));
        }
        a
    }

    /// Lowered symbols back to the functions they stand for.
    pub fn raise(&self, a: &Atom) -> Atom {
        let mut a = a.clone();
        for l in &self.lowered {
            a = a.replace(Atom::from(l.symbol)).with(l.function.clone());
        }
        a
    }

    pub(super) fn rat(&self, a: &Atom) -> Rat {
        a.to_rational_polynomial(&Q, &Z, Some(self.vars.clone()))
    }

    /// `a` as a rational function of the model's symbols and the lowered
    /// function applications, its numerator and denominator reduced by
    /// sin² + cos² = 1 and cosh² − sinh² = 1 ([`Over`] where the bound on
    /// its terms, [`budget::rational_terms`], or that reduction is past the
    /// budget).
    ///
    /// The exact linear algebra works with rational functions of sin and
    /// cos as independent symbols. Reduced, an entry that vanishes by the
    /// identities is zero (left as cos² + sin² − 1 it would be a pivot,
    /// and what is computed from it would divide by zero), and rows equal
    /// by them are equal. Combinations that vanish only by the identities
    /// after elimination are not seen (the note in `docs/model-format.md`).
    pub fn to_rat(&self, a: &Atom) -> Result<Rat, Over> {
        let lowered = self.lower(a);
        budget::check(budget::rational_terms(&lowered))?;
        self.reduce_rat(self.rat(&lowered))
    }
    /// A rational function of the lowered symbols with its numerator and
    /// denominator reduced by the identities, as [`Lowering::to_rat`]
    /// gives one.
    pub(super) fn reduce_rat(&self, r: Rat) -> Result<Rat, Over> {
        if self.pairs.is_empty() {
            return Ok(r);
        }
        let num = self.reduce_trig(&r.numerator.to_expression())?;
        let den = self.reduce_trig(&r.denominator.to_expression())?;
        if is_zero(&den) {
            // Undefined everywhere, by the identities: left as it is.
            return Ok(r);
        }
        Ok(self.rat(&(num / den)))
    }

    /// Reduces a polynomial modulo c² + s² − 1 for every sin/cos pair and
    /// c² − s² − 1 for every sinh/cosh pair: each cⁿ (n ≥ 2) becomes
    /// c^(n mod 2)·(1 ∓ s²)^⌊n/2⌋ at once, then the polynomial is expanded
    /// again. (Taking two powers of c per round of
    /// rewriting and expanding, cos(x)¹⁰⁰·cos(y)¹⁰⁰·cos(z)¹⁰⁰ in T took 49
    /// expansions of a growing polynomial per entry and ran past 120 s.)
    ///
    /// The reduction can multiply terms out (c¹⁰⁰ is 51 terms in s), so each
    /// rewrite is bounded by [`budget::MAX_EXPANDED_TERMS`] before it is
    /// expanded: [`Over`] past it.
    fn reduce_trig(&self, a: &Atom) -> Result<Atom, Over> {
        let mut a = a.expand();
        for p in &self.pairs {
            let folded = fold_cos(a.as_view(), p);
            budget::check(budget::expansion_terms(&folded))?;
            a = folded.expand();
        }
        Ok(a)
    }

    /// A rational function in lowest terms, sin² + cos² = 1 and
    /// cosh² − sinh² = 1 reduced,
    /// functions raised; [`Over`] where the reduction is past the budget or
    /// the denominator vanishes by the identities.
    pub fn simplify(&self, r: &Rat) -> Result<Atom, Over> {
        let num = self.reduce_trig(&r.numerator.to_expression())?;
        let den = self.reduce_trig(&r.denominator.to_expression())?;
        if is_zero(&den) {
            return Err(Over::VanishingDenominator);
        }
        let reduced = self.rat(&(num / den));
        let raised = self.raise(&reduced.to_expression());
        // As a rational function an exponential of a sum is split, the
        // terms of opposite signs apart (exp(−(1 + x² + y²)/w²) times a
        // sum of terms in exp((2x cos a + 2y sin a)/w²) for a narrow
        // Gaussian post), and the factors overflow to 0 · ∞ = NaN where
        // the whole is a number. Expanded, each term's exponentials are
        // one again (the symbolic engine multiplies them into one).
        Ok(if holds_exp(raised.as_view()) {
            raised.expand()
        } else {
            raised
        })
    }

    /// [`Lowering::simplify`] of an expression.
    pub fn reduce(&self, a: &Atom) -> Result<Atom, Over> {
        self.simplify(&self.to_rat(a)?)
    }

    /// The forms an evaluated quantity is compiled from, the cheaper kept:
    /// `written`, then its reduction ([`Lowering::reduce_or_keep`]) where
    /// [`worth_compiling`]. Without sin/cos or sinh/cosh pairs the
    /// reduction is finished only where its terms in lowest terms, a lower
    /// bound on its size, leave it within [`REDUCED_GROWTH`] of the written
    /// form's (raising the functions again and writing it out cost the
    /// most). With pairs it is always finished, since it may find a
    /// denominator vanishing by the identities, an error; with an
    /// exponential too, whose terms can merge when expanded.
    pub fn evaluated_forms(&self, written: Vec<Atom>) -> Result<Vec<Vec<Atom>>, Over> {
        let rats = (written.iter())
            .map(|a| match self.to_rat(a) {
                Ok(r) => Ok(Some(r)),
                Err(Over::Terms(_)) => Ok(None),
                Err(o) => Err(o),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let least: usize = (written.iter().zip(&rats))
            .map(|(w, r)| match r {
                Some(r) if r.denominator.is_constant() => r.numerator.nterms(),
                Some(r) => r.numerator.nterms() + r.denominator.nterms(),
                None => size(w.as_view()),
            })
            .sum();
        let sizes: usize = written.iter().map(|w| size(w.as_view())).sum();
        let finished = !self.pairs.is_empty() || written.iter().any(|w| holds_exp(w.as_view()));
        if least > REDUCED_GROWTH * sizes && !finished {
            return Ok(vec![written]);
        }
        let reduced = (written.iter().zip(rats))
            .map(|(w, r)| match r.map(|r| self.simplify(&r)) {
                Some(Err(Over::Terms(_))) | None => Ok(w.clone()),
                Some(reduced) => reduced,
            })
            .collect::<Result<Vec<_>, _>>()?;
        let keep = worth_compiling(&written, &reduced);
        Ok(std::iter::once(written)
            .chain(Some(reduced).filter(|_| keep))
            .collect())
    }

    /// [`Lowering::reduce`] of an expression that is only evaluated, or
    /// the expression as written where its reduction is past the budget:
    /// evaluation needs no normal form, and a compact expression can have
    /// an exponential one (a wall's Hessian form through nested atan).
    pub fn reduce_or_keep(&self, a: &Atom) -> Result<Atom, Over> {
        match self.reduce(a) {
            Err(Over::Terms(_)) => Ok(a.clone()),
            reduced => reduced,
        }
    }

    /// v⁺ component printed as a combination of the velocities.
    pub fn collect_velocities(&self, sym: &Symbols, c: &Atom) -> Result<String, Over> {
        let mut terms = Vec::new();
        for (k, v) in sym.vels.iter().enumerate() {
            let coeff = self.reduce(&c.d(*v))?;
            if is_zero(&coeff) {
                continue;
            }
            let name = &sym.model.velocities[k];
            if is_zero(&(coeff.clone() - Atom::num(1))) {
                terms.push(name.clone());
            } else if is_zero(&(coeff.clone() + Atom::num(1))) {
                terms.push(format!("-{name}"));
            } else {
                terms.push(format!("({coeff})*{name}"));
            }
        }
        Ok(if terms.is_empty() {
            "0".into()
        } else {
            terms.join(" + ")
        })
    }
}

/// Whether `reduced`, the same quantity as `written` entry by entry, is
/// worth compiling beside it: it differs, and is at most
/// [`REDUCED_GROWTH`] times its size (compiling costs in proportion).
pub fn worth_compiling<'a>(
    written: impl IntoIterator<Item = &'a Atom>,
    reduced: impl IntoIterator<Item = &'a Atom>,
) -> bool {
    let (mut differs, mut sizes) = (false, (0, 0));
    for (w, r) in written.into_iter().zip(reduced) {
        differs |= w != r;
        sizes.0 += size(w.as_view());
        sizes.1 += size(r.as_view());
    }
    differs && sizes.1 <= REDUCED_GROWTH * sizes.0
}

/// What a reduction past the budget names in its error: `what` (a
/// quantity) in the form the exact algebra works with.
pub fn reduced(what: &str) -> String {
    format!("{what}, as an exact rational function with sin² + cos² = 1 applied,")
}

/// Whether `a` is zero as a rational function of its symbols and function
/// applications, sin² + cos² = 1 and cosh² − sinh² = 1 reduced; [`Over`]
/// where the reduction is past the budget.
pub fn vanishes(a: &Atom) -> Result<bool, Over> {
    let a = prepared(a);
    let low = Lowering::of(std::slice::from_ref(&a), Vec::new());
    let r: Rat = low.lower(&a).to_rational_polynomial(&Q, &Z, None);
    let numerator = low.reduce_trig(&r.numerator.to_expression())?;
    Ok(is_zero(&numerator))
}

/// Whether `a` holds an exponential: exp(u), or e^u as the symbolic
/// engine writes it.
fn holds_exp(a: AtomView) -> bool {
    is_exp(a) || children(a).into_iter().any(holds_exp)
}

/// Whether `a` is exp(u) or e^u.
fn is_exp(a: AtomView) -> bool {
    match a {
        AtomView::Fun(f) => f.get_symbol() == Symbol::EXP,
        AtomView::Pow(p) => {
            let e = [Symbol::E, constant_symbol(Constant::E)];
            matches!(p.get_base_exp().0, AtomView::Var(v) if e.contains(&v.get_symbol()))
        }
        _ => false,
    }
}

/// What is lowered: `a` with our names for e and π, in base arguments.
fn prepared(a: &Atom) -> Atom {
    in_base_arguments(own_constants(a).as_view())
}

/// The largest multiple n in sin(n·u) (and cos, sinh, cosh) written in the
/// functions of u; a larger one is left as it is.
const MAX_MULTIPLE: i64 = 12;

/// `a` with sin, cos, sinh and cosh of n·u (n a whole number, 2 ≤ |n| ≤
/// [`MAX_MULTIPLE`]) or of −u written as polynomials in those of u, from
/// (c + i s)ⁿ for sin and cos and (c + s)ⁿ for sinh and cosh: cos(2u) =
/// c² − s², sin(−u) = −s. Equal to `a` as a function; the identities of
/// the pairs then see sin(2x) − 2 sin x cos x as zero. tanh is left alone:
/// written sinh/cosh it would overflow where tanh itself does not.
fn in_base_arguments(a: AtomView) -> Atom {
    match a {
        AtomView::Fun(f) => {
            let args: Vec<Atom> = f.iter().map(in_base_arguments).collect();
            if let [u] = &args[..]
                && let Some(x) = multiple_of(f.get_symbol(), u)
            {
                return x;
            }
            FunctionBuilder::new(f.get_symbol())
                .add_args(&args)
                .finish()
        }
        AtomView::Pow(p) => {
            let (b, e) = p.get_base_exp();
            in_base_arguments(b).pow(in_base_arguments(e))
        }
        AtomView::Mul(m) => m.iter().fold(Atom::num(1), |p, x| p * in_base_arguments(x)),
        AtomView::Add(t) => sum(t.iter().map(in_base_arguments).collect()),
        AtomView::Var(_) | AtomView::Num(_) => a.to_owned(),
    }
}

/// f(u) in the functions of the base argument when f is sin, cos, sinh or
/// cosh and u = n·v with a whole n ≠ 0, 1 ([`in_base_arguments`]).
fn multiple_of(f: Symbol, u: &Atom) -> Option<Atom> {
    let [sinh, cosh] = [Function::Sinh, Function::Cosh].map(|g| own_symbol(g.name()));
    let (s, c, circular) = if f == Symbol::SIN || f == Symbol::COS {
        (Symbol::SIN, Symbol::COS, true)
    } else if f == sinh || f == cosh {
        (sinh, cosh, false)
    } else {
        return None;
    };
    let AtomView::Mul(m) = u.as_view() else {
        return None;
    };
    let mut n = None;
    let mut base = Atom::num(1);
    for x in m.iter() {
        match x {
            AtomView::Num(_) if n.is_none() => n = Some(x.to_string().parse::<i64>().ok()?),
            _ => base *= x.to_owned(),
        }
    }
    let n = n?;
    if n == 0 || n == 1 || n.abs() > MAX_MULTIPLE {
        return None;
    }
    let (sv, cv) = (function!(s, base.clone()), function!(c, base));
    let odd = f == s;
    let m = n.unsigned_abs();
    // Σ over k of the parity of f: binom(m, k) c^(m−k) s^k, with the sign
    // of i^k for sin and cos.
    let mut terms = Vec::new();
    let mut binomial: i64 = 1;
    for k in 0..=m {
        if (k % 2 == 1) == odd {
            let sign = if circular && (k / 2) % 2 == 1 { -1 } else { 1 };
            let power = |x: &Atom, e: u64| x.pow(Atom::num(i64::try_from(e).unwrap_or(0)));
            terms.push(Atom::num(sign * binomial) * power(&cv, m - k) * power(&sv, k));
        }
        binomial = binomial * i64::try_from(m - k).unwrap_or(0) / i64::try_from(k + 1).unwrap_or(1);
    }
    let value = sum(terms);
    // sin and sinh are odd, cos and cosh even.
    Some(if odd && n < 0 { -value } else { value })
}

/// The arguments of the applications of `f` (one argument each) in `a`,
/// each application before those inside it.
fn applications(a: AtomView, f: Symbol, out: &mut Vec<Atom>) {
    let parts = children(a);
    if let AtomView::Fun(g) = a
        && g.get_symbol() == f
        && let [arg] = parts[..]
    {
        out.push(arg.to_owned());
    }
    parts.into_iter().for_each(|x| applications(x, f, out));
}

/// `a` with every power cⁿ (n ≥ 2, an integer) of the pair's symbol `c`
/// written as c^(n mod 2)·(1 ± s²)^⌊n/2⌋, the rest as it is.
fn fold_cos(a: AtomView, pair: &Pair) -> Atom {
    let Pair { s, c, sign } = *pair;
    match a {
        AtomView::Pow(p) => {
            let (b, e) = p.get_base_exp();
            if let AtomView::Var(v) = b
                && v.get_symbol() == c
                && let Ok(n) = e.to_string().parse::<u32>()
                && n >= 2
            {
                let rest = Atom::num(1) + Atom::num(sign) * Atom::from(s).pow(Atom::num(2));
                return Atom::from(c).pow(Atom::num(i64::from(n % 2)))
                    * rest.pow(Atom::num(i64::from(n / 2)));
            }
            fold_cos(b, pair).pow(fold_cos(e, pair))
        }
        AtomView::Mul(m) => m.iter().fold(Atom::num(1), |p, x| p * fold_cos(x, pair)),
        AtomView::Add(t) => sum(t.iter().map(|x| fold_cos(x, pair)).collect()),
        AtomView::Fun(_) | AtomView::Var(_) | AtomView::Num(_) => a.to_owned(),
    }
}

/// The sum of `terms`, added in halves (adding one term at a time to a
/// growing sum copies it each time).
fn sum(mut terms: Vec<Atom>) -> Atom {
    match terms.len() {
        0 => Atom::num(0),
        1 => terms.pop().unwrap_or_else(|| Atom::num(0)),
        n => {
            let right = terms.split_off(n / 2);
            sum(terms) + sum(right)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::echelon::Echelon;
    use super::super::inspect::same;
    use super::*;
    use crate::derive::build::Namespace;

    /// A narrow post's f = 1/2 − exp(−((x − cos a)² + (y − sin a)²)/w²),
    /// differentiated and reduced (sin² a + cos² a = 1): as a rational
    /// function its exponential is split into exp(−(1 + x² + y²)/w²) and
    /// exp((2x cos a + 2y sin a)/w²), which overflow apart to 0 · ∞ where
    /// the whole is a number. Reduced, each term holds one exponential.
    #[test]
    fn reduced_exponentials_stay_whole() {
        crate::lock::acquire().unwrap();
        let _ns = Namespace::enter("lower test");
        let names = ["x", "y", "a", "w"].map(own_symbol);
        let [x, y, a, w] = names.map(Atom::from);
        let two = Atom::num(2);
        let distance = (&x - function!(Symbol::COS, a.clone())).pow(two.clone())
            + (&y - function!(Symbol::SIN, a.clone())).pow(two.clone());
        let f = Atom::num(1) / &two - function!(Symbol::EXP, -(distance / w.pow(two)));
        let d = f.d(names[0]);
        let low = Lowering::of(std::slice::from_ref(&prepared(&d)), names.to_vec());
        let reduced = low.simplify(&low.to_rat(&d).unwrap()).unwrap();
        fn exps(a: AtomView) -> usize {
            usize::from(is_exp(a)) + children(a).into_iter().map(exps).sum::<usize>()
        }
        let terms: Vec<usize> = match reduced.as_view() {
            AtomView::Add(t) => t.iter().map(exps).collect(),
            v => vec![exps(v)],
        };
        assert!(terms.iter().all(|&k| k == 1), "{reduced}");
    }

    /// (cos x, sin x) and cos x times it, whose first entry reduces to
    /// 1 − sin² x: dependent only through sin² + cos² = 1 once elimination
    /// has combined them (the plain rank over the rational functions of
    /// sin and cos as independent symbols is 2). Rows that are independent
    /// stay so.
    #[test]
    fn rows_dependent_through_the_identities_after_elimination() {
        crate::lock::acquire().unwrap();
        let _ns = Namespace::enter("lower test");
        let x = own_symbol("x");
        let s = function!(Symbol::SIN, Atom::from(x));
        let c = function!(Symbol::COS, Atom::from(x));
        let rank = |rows: Vec<Vec<Atom>>| {
            let all: Vec<Atom> = rows.iter().flatten().map(prepared).collect();
            let low = Lowering::of(&all, vec![x]);
            let rats: Vec<Vec<Rat>> = (rows.iter())
                .map(|r| r.iter().map(|a| low.to_rat(a).unwrap()).collect())
                .collect();
            let field = super::super::Field::from_poly(&rats[0][0].numerator);
            let plain = super::super::rows_matrix(&rats, 2, &field).unwrap().rank();
            let mut echelon = Echelon::new(&low);
            let kept = (rats.iter()).filter(|r| echelon.insert(r).unwrap()).count();
            (kept, plain)
        };
        let dependent = vec![vec![c.clone(), s.clone()], vec![&c * &c, &s * &c]];
        assert_eq!(rank(dependent), (1, 2));
        let independent = vec![vec![c.clone(), s.clone()], vec![s.clone(), c.clone()]];
        assert_eq!(rank(independent).0, 2);
    }

    /// Zero only by sin² + cos² = 1 or cosh² − sinh² = 1, powers
    /// included; and near misses that are not zero.
    #[test]
    fn squares_of_pairs_reduce() {
        for (a, b) in [
            ("sin(x)^2 + cos(x)^2", "1"),
            ("cosh(x)^2 - sinh(x)^2", "1"),
            ("cosh(x)^4 - sinh(x)^4", "cosh(x)^2 + sinh(x)^2"),
            ("y*cosh(2*x)^3", "y*cosh(2*x)*(1 + sinh(2*x)^2)"),
            ("y*cos(2*x)^3", "y*cos(2*x)*(1 - sin(2*x)^2)"),
            ("y*cosh(x)^3", "y*cosh(x)*(1 + sinh(x)^2)"),
            ("cosh(2*x)^2", "1 + sinh(2*x)^2"),
            ("(cosh(x)^2 - sinh(x)^2)*sin(y)^2", "1 - cos(y)^2"),
        ] {
            assert_eq!(same(a, b), Ok(true), "{a} = {b}");
        }
        for (a, b) in [
            ("cosh(x)^2 + sinh(x)^2", "1"),
            // Not multiples of one argument.
            ("sin(x/2)", "2*sin(x/4)*cos(x/4)"),
            ("sin(2*x)", "2*sin(x)*cos(y)"),
            ("cos(13*x)^2 + sin(x)^2", "1"),
            ("cosh(x)^2 - sinh(y)^2", "1"),
            ("cosh(x)^2 - sin(x)^2", "1"),
            ("cos(x)^2 - sinh(x)^2", "1"),
        ] {
            assert_eq!(same(a, b), Ok(false), "{a} ≠ {b}");
        }
    }

    /// Whole multiples of an argument, and its negative, in the functions of
    /// the argument: sympy's double angles, the triple-angle formulas, mixed
    /// multiples of one angle and the hyperbolic ones.
    #[test]
    fn multiples_of_an_argument_reduce() {
        for (a, b) in [
            ("sin(2*x)", "2*sin(x)*cos(x)"),
            ("cos(2*x)", "1 - 2*sin(x)^2"),
            ("(1 + cos(2*a))/2", "cos(a)^2"),
            ("cos(3*x)", "4*cos(x)^3 - 3*cos(x)"),
            ("sin(3*x)", "3*sin(x) - 4*sin(x)^3"),
            ("sin(-x) + sin(x)", "0"),
            ("cos(-2*x)", "cos(2*x)"),
            ("sin(4*x*y)", "2*sin(2*x*y)*cos(2*x*y)"),
            ("sin(6*x)", "2*sin(3*x)*cos(3*x)"),
            ("cos(12*x)", "2*cos(6*x)^2 - 1"),
            ("sinh(2*x)", "2*sinh(x)*cosh(x)"),
            ("cosh(2*x)", "1 + 2*sinh(x)^2"),
            ("sinh(-3*x)", "-3*sinh(x) - 4*sinh(x)^3"),
            ("y*sin(2*(x + z))", "2*y*sin(x + z)*cos(x + z)"),
        ] {
            assert_eq!(same(a, b), Ok(true), "{a} = {b}");
        }
    }
}
