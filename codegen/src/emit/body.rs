//! A straight-line program as Rust statements: inputs bound to `i{k}`,
//! temporaries `t{k}`, outputs `o{k}`; sin and cos of one value computed by
//! one `sincos` call; parameter-only values stored once (`pre[k]`) and read
//! per call (`self.pre[k]`).

use std::collections::HashMap;

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::{Ctx, Scalar, ident};
use crate::program::{Emit, Func, Instr, Program, Slot};

/// `f64` or `f32`.
pub(super) fn real(d: &Ctx) -> TokenStream {
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

/// Where statements go: the per-call function, or the block run once per
/// parameter set.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Place {
    Call,
    Once,
}

/// Statements computing `o0, o1, …` from the program, each instruction as
/// `plan` says for `place`: computed, stored as `pre[k]`, read from
/// `self.pre[k]`, split at its leading operands, or left out.
pub(super) fn statements(d: &Ctx, p: &Program, plan: &[Emit], place: Place) -> TokenStream {
    // The operands each instruction reads here.
    let reads = |i: usize| -> &[Slot] {
        let s = p.instrs[i].sources();
        match (plan[i], place) {
            (Emit::Compute | Emit::Store(_), _) => s,
            (Emit::Leading(_, n), Place::Once) => &s[..n],
            (Emit::Leading(_, n), Place::Call) => &s[n..],
            (Emit::Skip | Emit::Load(_), _) => &[],
        }
    };
    let mut used = vec![false; p.inputs];
    for i in 0..p.instrs.len() {
        for s in reads(i) {
            if let Slot::Input(k) = s {
                used[*k] = true;
            }
        }
    }
    let real = real(d);
    let params = match place {
        Place::Call => quote! { self.params },
        Place::Once => quote! { params },
    };
    let inputs = used.iter().enumerate().filter(|(_, u)| **u).map(|(i, _)| {
        let name = format_ident!("i{i}");
        let value = input_value(d, i, &params);
        quote! { let #name: #real = #value; }
    });
    // sin and cos of a value share one sincos where both are computed here.
    let computed = |i: usize| matches!(plan[i], Emit::Compute | Emit::Store(_));
    let pairs = p.sincos_pairs();
    let mut halves: HashMap<usize, usize> = HashMap::new();
    for (i, pair) in pairs.iter().enumerate() {
        if let Some((k, _)) = pair.filter(|_| computed(i)) {
            *halves.entry(k).or_default() += 1;
        }
    }
    let stmts = p
        .instrs
        .iter()
        .zip(&pairs)
        .enumerate()
        .map(|(i, (ins, pair))| {
            let computation = || match (ins, pair) {
                (Instr::Fun(dst, f, src), Some(pair)) if halves.get(&pair.0) == Some(&2) => {
                    sincos(d, p, *dst, *f, *src, *pair)
                }
                _ => instr(d, p, ins),
            };
            let dst = slot(d, p, ins.dst());
            match (plan[i], place) {
                (Emit::Skip, _) => TokenStream::new(),
                (Emit::Compute, _) => computation(),
                (Emit::Store(k), _) => {
                    let (computation, k) = (computation(), Literal::usize_unsuffixed(k));
                    quote! { #computation pre[#k] = #dst; }
                }
                (Emit::Load(k), _) => {
                    let k = Literal::usize_unsuffixed(k);
                    quote! { let #dst: #real = self.pre[#k]; }
                }
                (Emit::Leading(k, n), Place::Once) => {
                    let k = Literal::usize_unsuffixed(k);
                    let value = operation(d, p, ins, None, &ins.sources()[..n]);
                    quote! { pre[#k] = #value; }
                }
                (Emit::Leading(k, n), Place::Call) => {
                    let k = Literal::usize_unsuffixed(k);
                    let stored = quote! { self.pre[#k] };
                    let value = operation(d, p, ins, Some(stored), &ins.sources()[n..]);
                    quote! { let #dst: #real = #value; }
                }
            }
        });
    quote! { #(#inputs)* #(#stmts)* }
}

/// The sum or product `ins` computes, over `first` (a value already
/// computed, standing for leading operands) and then `operands`.
fn operation(
    d: &Ctx,
    p: &Program,
    ins: &Instr,
    first: Option<TokenStream>,
    operands: &[Slot],
) -> TokenStream {
    match ins {
        Instr::Add(..) => {
            let rest = operands.iter().map(|&x| slot(d, p, x));
            join(first.into_iter().chain(rest), quote! { + })
        }
        Instr::Mul(..) => product(d, p, first, operands),
        _ => unreachable!("only sums and products are split at leading operands"),
    }
}

/// One half of a sin/cos pair: the first computes both into `sc{k}_sin`
/// and `sc{k}_cos`, each takes its own.
fn sincos(
    d: &Ctx,
    p: &Program,
    dst: Slot,
    f: Func,
    src: Slot,
    (k, first): (usize, bool),
) -> TokenStream {
    let (s, c) = (format_ident!("sc{k}_sin"), format_ident!("sc{k}_cos"));
    let real = real(d);
    let both = first.then(|| {
        let call = libm_fn(d, "sincos");
        let src = slot(d, p, src);
        quote! { let (#s, #c): (#real, #real) = #call(#src); }
    });
    let mine = if f == Func::Sin { s } else { c };
    let dst = slot(d, p, dst);
    quote! { #both let #dst: #real = #mine; }
}

/// Where input i of every program comes from: parameters, then coordinates,
/// then velocities.
fn input_value(d: &Ctx, i: usize, params: &TokenStream) -> TokenStream {
    let np = d.model.params.len();
    let nq = d.model.coordinates.len();
    if i < np {
        let p = ident(&d.model.params[i].name);
        quote! { #params.#p }
    } else if i < np + nq {
        let k = Literal::usize_unsuffixed(i - np);
        quote! { q[#k] }
    } else {
        let k = Literal::usize_unsuffixed(i - np - nq);
        quote! { v[#k] }
    }
}

pub(super) fn slot(d: &Ctx, p: &Program, s: Slot) -> TokenStream {
    let name = match s {
        Slot::Input(i) => format_ident!("i{i}"),
        Slot::Temp(i) => format_ident!("t{i}"),
        Slot::Out(i) => format_ident!("o{i}"),
        Slot::Const(i) => {
            let lit = lit(d, p.consts[i]);
            return quote! { #lit };
        }
    };
    quote! { #name }
}

fn instr(d: &Ctx, p: &Program, ins: &Instr) -> TokenStream {
    let (dst, value) = match ins {
        Instr::Add(o, s) => (*o, join(s.iter().map(|&x| slot(d, p, x)), quote! { + })),
        Instr::Sub(o, s) => (*o, join(s.iter().map(|&x| slot(d, p, x)), quote! { - })),
        Instr::Mul(o, s) => (*o, product(d, p, None, s)),
        Instr::Pow(o, s, n) => (*o, pow(d, slot(d, p, *s), *n)),
        Instr::Powf(o, s, x) => (*o, powf(d, slot(d, p, *s), *x)),
        Instr::Fun(o, f, s) => {
            let f = libm_fn(d, f.name());
            let s = slot(d, p, *s);
            (*o, quote! { #f(#s) })
        }
        Instr::Assign(o, s) => (*o, slot(d, p, *s)),
    };
    let dst = slot(d, p, dst);
    let real = real(d);
    quote! { let #dst: #real = #value; }
}

/// A product of `first` (if any) and `factors`; a factor −1 becomes a
/// negation.
fn product(d: &Ctx, p: &Program, first: Option<TokenStream>, factors: &[Slot]) -> TokenStream {
    let minus_one = |s: &Slot| matches!(s, Slot::Const(i) if p.consts[*i] == -1.0);
    let rest: Vec<TokenStream> = factors
        .iter()
        .filter(|s| !minus_one(s))
        .map(|&x| slot(d, p, x))
        .collect();
    let negations = factors.iter().filter(|s| minus_one(s)).count();
    let operands: Vec<TokenStream> = first.into_iter().chain(rest).collect();
    if operands.is_empty() {
        return if negations % 2 == 1 {
            quote! { -1.0 }
        } else {
            quote! { 1.0 }
        };
    }
    let prod = join(operands.into_iter(), quote! { * });
    if negations % 2 == 1 {
        quote! { -(#prod) }
    } else {
        prod
    }
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

fn pow(d: &Ctx, x: TokenStream, n: i64) -> TokenStream {
    let m = n.unsigned_abs();
    let positive = if m == 0 {
        quote! { 1.0 }
    } else if m <= 8 {
        let product = join(std::iter::repeat_n(x.clone(), m as usize), quote! { * });
        quote! { (#product) }
    } else {
        let e = lit(d, m as f64);
        let f = libm_fn(d, "pow");
        quote! { #f(#x, #e) }
    };
    if n < 0 {
        quote! { 1.0 / #positive }
    } else {
        positive
    }
}

/// x^e for a fractional constant e: a square root for ±½ (as
/// [`crate::program::powf`] evaluates it), libm's pow otherwise.
fn powf(d: &Ctx, x: TokenStream, e: f64) -> TokenStream {
    let sqrt = libm_fn(d, "sqrt");
    if e == 0.5 {
        quote! { #sqrt(#x) }
    } else if e == -0.5 {
        quote! { 1.0 / #sqrt(#x) }
    } else {
        let f = libm_fn(d, "pow");
        let e = lit(d, e);
        quote! { #f(#x, #e) }
    }
}
