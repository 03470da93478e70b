//! A straight-line program as Rust statements: inputs bound to `i{k}`,
//! temporaries `t{k}`, outputs `o{k}`; sin and cos of one value computed by
//! one `sincos` call; parameter-only values stored once (`pre[k]`) and read
//! per call (`self.pre[k]`).
//!
//! The same statements format a program over the runtime's `Interval`
//! (`Ctx::bounds`): each instruction is then the interval operation of
//! its machine form (xⁿ as `powi`, a tight power, where floats multiply),
//! and numbers, parameters and kept values enter as points.

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::{Ctx, Scalar, ident};
use crate::plan::Step;
use crate::program::machine::{Machine, Operand};
use crate::program::{Program, Slot};
use crate::quantity::Inputs;

/// `f64` or `f32` (or the runtime's `Interval`, formatting bounds).
pub(super) fn real(d: &Ctx) -> TokenStream {
    if d.bounds {
        return quote! { ::dalembert_runtime::interval::Interval };
    }
    match d.scalar {
        Scalar::F64 => quote! { f64 },
        Scalar::F32 => quote! { f32 },
    }
}

/// A float literal of the emitted type.
pub(super) fn lit(d: &Ctx, x: f64) -> Literal {
    match d.scalar {
        Scalar::F64 => Literal::f64_suffixed(x),
        Scalar::F32 => Literal::f32_suffixed(x as f32),
    }
}

/// libm's function `name` for the emitted type (`sin` or `sinf`).
pub(super) fn libm_fn(d: &Ctx, name: &str) -> TokenStream {
    let f = match d.scalar {
        Scalar::F64 => format_ident!("{name}"),
        Scalar::F32 => format_ident!("{name}f"),
    };
    quote! { ::dalembert_runtime::libm::#f }
}

/// The type annotation of a `let`: `: f64` (`: f32`), or none over
/// intervals (inferred: the bodies stay readable).
fn annotation(d: &Ctx) -> TokenStream {
    if d.bounds {
        TokenStream::new()
    } else {
        let real = real(d);
        quote! { : #real }
    }
}

/// A number (a literal, a parameter, a kept value) as a value of the
/// formatted type: itself, or the interval of that one point.
fn number(d: &Ctx, x: TokenStream) -> TokenStream {
    if d.bounds {
        quote! { Interval::point(#x) }
    } else {
        x
    }
}

/// Where statements go: the per-call function, or the block run once per
/// parameter set.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Place {
    Call,
    Once,
}

/// Statements computing `o0, o1, …` from the program, each instruction as
/// its [`Step`] in `place` says: computed, stored as `pre[k]`, read from
/// `self.pre[k]`, a kept value computed, or left out.
pub(super) fn statements(
    d: &Ctx,
    p: &Program,
    steps: &[Step],
    inputs: Inputs,
    place: Place,
) -> TokenStream {
    let mut used = vec![false; p.inputs];
    for m in steps.iter().filter_map(Step::machine) {
        for s in m.slots() {
            if let Slot::Input(k) = s {
                used[k] = true;
            }
        }
    }
    let real = annotation(d);
    let params = match place {
        Place::Call => quote! { self.params },
        Place::Once => quote! { params },
    };
    let inputs = used.iter().enumerate().filter(|(_, u)| **u).map(|(i, _)| {
        let name = format_ident!("i{i}");
        let value = input_value(d, i, inputs, &params);
        let value = if i < d.model.params.len() {
            number(d, value)
        } else {
            value
        };
        quote! { let #name #real = #value; }
    });
    let stmts = p.instrs.iter().zip(steps).map(|(ins, step)| {
        let dst = ins.dst();
        match step {
            Step::Skip => TokenStream::new(),
            Step::Compute(m) => statement(d, p, dst, m),
            Step::Store(m, k) => {
                let computation = statement(d, p, dst, m);
                let (dst, k) = (slot(d, p, dst), Literal::usize_unsuffixed(*k));
                quote! { #computation pre[#k] = #dst; }
            }
            Step::Load(k) => {
                let (dst, k) = (slot(d, p, dst), Literal::usize_unsuffixed(*k));
                let value = number(d, quote! { self.pre[#k] });
                quote! { let #dst #real = #value; }
            }
            Step::Keep(m, k) => {
                let value = expression(d, p, m);
                let k = Literal::usize_unsuffixed(*k);
                quote! { pre[#k] = #value; }
            }
        }
    });
    quote! { #(#inputs)* #(#stmts)* }
}

/// `let dst = …;` for an instruction in machine form; the first of a
/// sin/cos pair computes both into `sc{k}_sin` and `sc{k}_cos`, and each
/// half takes its own.
fn statement(d: &Ctx, p: &Program, dst: Slot, m: &Machine) -> TokenStream {
    let both = if d.bounds {
        TokenStream::new()
    } else {
        let real = real(d);
        quote! { : (#real, #real) }
    };
    let real = annotation(d);
    let dst = slot(d, p, dst);
    let half = |pair: usize, sin: bool| {
        let (s, c) = (format_ident!("sc{pair}_sin"), format_ident!("sc{pair}_cos"));
        (if sin { s.clone() } else { c.clone() }, s, c)
    };
    match *m {
        Machine::SinCos { x, pair, sin } => {
            let (mine, s, c) = half(pair, sin);
            let x = slot(d, p, x);
            let call = if d.bounds {
                quote! { #x.sincos() }
            } else {
                let f = libm_fn(d, "sincos");
                quote! { #f(#x) }
            };
            quote! {
                let (#s, #c) #both = #call;
                let #dst #real = #mine;
            }
        }
        Machine::Half { pair, sin } => {
            let mine = half(pair, sin).0;
            quote! { let #dst #real = #mine; }
        }
        _ => {
            let value = expression(d, p, m);
            quote! { let #dst #real = #value; }
        }
    }
}

/// The value of an instruction in machine form as a Rust expression.
fn expression(d: &Ctx, p: &Program, m: &Machine) -> TokenStream {
    let operand = |o: &Operand| match *o {
        Operand::Slot(s) => slot(d, p, s),
        Operand::Kept(k) => {
            let k = Literal::usize_unsuffixed(k);
            number(d, quote! { self.pre[#k] })
        }
    };
    let over = |reciprocal: bool, x: TokenStream| match (reciprocal, d.bounds) {
        (false, _) => x,
        (true, false) => quote! { 1.0 / #x },
        (true, true) => quote! { (#x).recip() },
    };
    // A function of x: libm's, or the interval's method of that name.
    let call = |name: &str, x: TokenStream, arg: Option<Literal>| {
        if d.bounds {
            let f = format_ident!("{name}");
            quote! { #x.#f(#arg) }
        } else {
            let f = libm_fn(d, name);
            let arg = arg.map(|a| quote! { , #a });
            quote! { #f(#x #arg) }
        }
    };
    match m {
        Machine::Sum(terms) => join(terms.iter().map(operand), quote! { + }),
        Machine::Difference(a, b) => {
            let (a, b) = (slot(d, p, *a), slot(d, p, *b));
            quote! { #a - #b }
        }
        Machine::Product { factors, negate } => {
            let product = join(factors.iter().map(operand), quote! { * });
            if *negate {
                quote! { -(#product) }
            } else {
                product
            }
        }
        Machine::Number(x) => {
            let a = Literal::f64_unsuffixed(x.abs());
            let value = if x.is_sign_negative() {
                quote! { -#a }
            } else {
                quote! { #a }
            };
            number(d, value)
        }
        Machine::Power { x, n, reciprocal } => {
            let x = slot(d, p, *x);
            let power = if d.bounds {
                let n = Literal::u32_unsuffixed(*n);
                quote! { #x.powi(#n) }
            } else {
                let product = join(std::iter::repeat_n(x, *n as usize), quote! { * });
                quote! { (#product) }
            };
            over(*reciprocal, power)
        }
        Machine::Pow { x, e, reciprocal } => {
            let (x, e) = (slot(d, p, *x), lit(d, *e));
            over(*reciprocal, call("pow", x, Some(e)))
        }
        Machine::Sqrt { x, reciprocal } => {
            let x = slot(d, p, *x);
            over(*reciprocal, call("sqrt", x, None))
        }
        Machine::Call(f, x) => call(f.name(), slot(d, p, *x), None),
        Machine::Copy(x) => slot(d, p, *x),
        Machine::SinCos { .. } | Machine::Half { .. } => {
            unreachable!("a sin/cos pair is a statement of its own")
        }
    }
}

/// Where input i of every program comes from: parameters, then coordinates,
/// then velocities.
fn input_value(d: &Ctx, i: usize, inputs: Inputs, params: &TokenStream) -> TokenStream {
    let (np, nq, nv) = (
        d.model.params.len(),
        d.model.coordinates.len(),
        d.model.velocities.len(),
    );
    match inputs.array_of(i, np, nq, nv) {
        None => {
            let p = ident(&d.model.params[i].name);
            quote! { #params.#p }
        }
        Some((array, k)) => {
            let (array, k) = (
                format_ident!("{}", array.name()),
                Literal::usize_unsuffixed(k),
            );
            quote! { #array[#k] }
        }
    }
}

pub(super) fn slot(d: &Ctx, p: &Program, s: Slot) -> TokenStream {
    let name = match s {
        Slot::Input(i) => format_ident!("i{i}"),
        Slot::Temp(i) => format_ident!("t{i}"),
        Slot::Out(i) => format_ident!("o{i}"),
        Slot::Const(i) => {
            let lit = lit(d, p.consts[i]);
            return number(d, quote! { #lit });
        }
    };
    quote! { #name }
}

/// Operands joined by an operator: `a + b + c`.
fn join(operands: impl Iterator<Item = TokenStream>, op: TokenStream) -> TokenStream {
    let mut out = TokenStream::new();
    for (k, x) in operands.enumerate() {
        if k > 0 {
            out.extend(op.clone());
        }
        out.extend(x);
    }
    out
}
