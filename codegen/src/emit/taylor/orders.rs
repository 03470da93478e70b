//! The statements of one order of a series function: order 0's values,
//! and at each order k ≥ 1 the history loops (every convolution's sum over
//! j = 1..k−1 side by side) and each operation's finish in program order.

use std::ops::Range;

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::super::Ctx;
use super::super::body;
use crate::program::{Op, Program, Series, Slot, Solve, Term, Transform};

/// Histories summed side by side in one loop over j: x86-64 has 16
/// vector registers, and each sum holds one while two operands are loaded.
const HISTORIES_PER_LOOP: usize = 12;

/// A series as an expression (`s.q[i]`, `s.v[i]`, `x{j}`).
fn series(s: Series) -> TokenStream {
    match s {
        Series::Q(i) => {
            let i = Literal::usize_unsuffixed(i);
            quote! { s.q[#i] }
        }
        Series::V(i) => {
            let i = Literal::usize_unsuffixed(i);
            quote! { s.v[#i] }
        }
        Series::Temp(j) => {
            let x = format_ident!("x{j}");
            quote! { #x }
        }
    }
}

fn number(d: &Ctx, p: &Program, s: Slot) -> TokenStream {
    body::slot(d, p, s)
}
/// Order k of every op: at k = 0 the values, beyond it the fused history
/// loops and each op's finish.
pub(super) fn ops(d: &Ctx, t: &Transform) -> TokenStream {
    ops_in(d, t, 0..t.ops.len(), t.solve.is_some())
}

/// [`ops`] for the ops in `range` only, followed by the transform's solve
/// if `solve`.
pub(super) fn ops_in(d: &Ctx, t: &Transform, range: Range<usize>, solve: bool) -> TokenStream {
    let group = &t.ops[range.clone()];
    if !solve
        && group
            .iter()
            .all(|op| linear(d, &t.numbers, op, At::Any).is_some())
    {
        // Sums and scalings only: one statement per op at every order.
        let stmts = group
            .iter()
            .flat_map(|op| linear(d, &t.numbers, op, At::Any));
        return quote! { #(#stmts)* };
    }
    let solve = if solve { t.solve.as_ref() } else { None };
    let zero = order_zero(d, t, range.clone(), solve);
    let (histories, finishes) = order_k(d, t, range, solve);
    quote! {
        if k == 0 {
            #zero
        } else {
            #histories
            #finishes
        }
    }
}

/// Which orders a statement is written for.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum At {
    /// Order 0 only.
    Zero,
    /// Orders k ≥ 1 only.
    Beyond,
    /// Every order (the order-0 part guarded by `k == 0`).
    Any,
}

/// Coefficient k of a sum or a scaling (the same at every order but for
/// the numbers of a sum, which count at order 0 only); `None` for the
/// other ops.
fn linear(d: &Ctx, p: &Program, op: &Op, at: At) -> Option<TokenStream> {
    match op {
        Op::Add {
            dst,
            series: terms,
            numbers,
        } => {
            let dst = series(*dst);
            // In order, each with its sign: `a[k] - b[k] + c[k]`.
            let terms = terms.iter().enumerate().map(|(i, t)| {
                let s = series(t.series);
                match (i, t.minus) {
                    (0, false) => quote! { #s[k] },
                    (0, true) => quote! { -#s[k] },
                    (_, false) => quote! { + #s[k] },
                    (_, true) => quote! { - #s[k] },
                }
            });
            let constant = (at != At::Beyond && !numbers.is_empty()).then(|| {
                let ns = numbers.iter().map(|s| number(d, p, *s));
                let add = quote! { #dst[0] += #(#ns)+*; };
                if at == At::Any {
                    quote! { if k == 0 { #add } }
                } else {
                    add
                }
            });
            Some(quote! { #dst[k] = #(#terms)*; #constant })
        }
        Op::Scale { dst, a, by } => {
            let (dst, a) = (series(*dst), series(*a));
            Some(if matches!(by, Slot::Const(i) if p.consts[*i] == -1.0) {
                quote! { #dst[k] = -#a[k]; }
            } else {
                let by = number(d, p, *by);
                quote! { #dst[k] = #a[k] * #by; }
            })
        }
        _ => None,
    }
}

/// Order 0: each function's value (the runtime's recurrences at order 0).
fn order_zero(d: &Ctx, t: &Transform, range: Range<usize>, solve: Option<&Solve>) -> TokenStream {
    let tay = quote! { ::dalembert_runtime::taylor };
    let stmts = t.ops[range].iter().map(|op| {
        if let Some(l) = linear(d, &t.numbers, op, At::Zero) {
            return l;
        }
        match op {
            Op::Mul { dst, a, b } => {
                let (dst, a, b) = (series(*dst), series(*a), series(*b));
                quote! { #dst[0] = #tay::mul(&#a, &#b, 0); }
            }
            Op::Square { dst, a } => {
                let (dst, a) = (series(*dst), series(*a));
                quote! { #dst[0] = #tay::square(&#a, 0); }
            }
            Op::Recip { dst, a } => unary(quote! { #tay::recip }, *dst, *a, None),
            Op::Div { dst, a, b } => {
                let (dst, a, b) = (series(*dst), series(*a), series(*b));
                quote! { #dst[0] = #tay::div(&#dst, &#a, &#b, 0); }
            }
            Op::Sqrt { dst, a } => unary(quote! { #tay::sqrt }, *dst, *a, None),
            Op::Exp { dst, a } => unary(quote! { #tay::exp }, *dst, *a, None),
            Op::Log { dst, a } => unary(quote! { #tay::log }, *dst, *a, None),
            Op::Power { dst, a, alpha } => {
                let alpha = Literal::f64_suffixed(*alpha);
                unary(quote! { #tay::power }, *dst, *a, Some(quote! { #alpha, }))
            }
            Op::SinCos { sin, cos, a } => {
                let (s, c, a) = (series(*sin), series(*cos), series(*a));
                quote! { (#s[0], #c[0]) = #tay::sin_cos(&#s, &#c, &#a, 0); }
            }
            Op::Add { .. } | Op::Scale { .. } => unreachable!("linear ops above"),
        }
    });
    let solve = solve.map(|solve| {
        let n = solve.x.len();
        let n_lit = Literal::usize_unsuffixed(n);
        let lower = (0..n).flat_map(|i| (0..=i).map(move |j| (i, j)));
        let entries = lower.map(|(i, j)| coefficient(d, t, &solve.g[i][j], At::Zero));
        let factor = quote! {
            factor = [#(#entries),*];
            #tay::ldl_factor(&mut factor, #n_lit);
        };
        if solve.momentum {
            // The velocities' order 0 is the state's.
            return factor;
        }
        let rhs = solve.rhs.iter().map(|h| coefficient(d, t, h, At::Zero));
        let store = store_x(solve);
        quote! {
            #factor
            let mut rhs = [#(#rhs),*];
            #tay::ldl_solve(&factor, &mut rhs);
            #store
        }
    });
    quote! { #(#stmts)* #solve }
}

/// Coefficient 0 (`At::Zero`), k ≥ 1 (`At::Beyond`) or k (`At::Any`) of a
/// term (`None`: zero): an output, or an entry of a solve.
pub(super) fn coefficient(d: &Ctx, t: &Transform, term: &Option<Term>, at: At) -> TokenStream {
    let k = if at == At::Zero {
        quote! { 0 }
    } else {
        quote! { k }
    };
    match *term {
        None => quote! { 0.0 },
        Some(Term::Number(s)) => {
            let x = number(d, &t.numbers, s);
            match at {
                At::Zero => x,
                At::Beyond => quote! { 0.0 },
                At::Any => quote! { (if k == 0 { #x } else { 0.0 }) },
            }
        }
        Some(Term::Series(s)) => {
            let s = series(s);
            quote! { #s[#k] }
        }
        Some(Term::Negated(s)) => {
            let s = series(s);
            quote! { (-#s[#k]) }
        }
    }
}

/// x's coefficient k from the solve's `rhs`.
fn store_x(solve: &Solve) -> TokenStream {
    let stores = solve.x.iter().enumerate().map(|(i, x)| {
        let (x, i) = (series(*x), Literal::usize_unsuffixed(i));
        quote! { #x[k] = rhs[#i]; }
    });
    quote! { #(#stores)* }
}

/// Orders k ≥ 1: the history loops (one accumulator per history, at most
/// [`HISTORIES_PER_LOOP`] per loop), then each op's finish in program
/// order.
fn order_k(
    d: &Ctx,
    t: &Transform,
    range: Range<usize>,
    solve: Option<&Solve>,
) -> (TokenStream, TokenStream) {
    let tay = quote! { ::dalembert_runtime::taylor };
    let mut accs = Vec::new();
    let mut terms = Vec::new();
    let mut history = |term: TokenStream| {
        let h = format_ident!("h{}", accs.len());
        terms.push(quote! { #h += #term; });
        accs.push(h.clone());
        h
    };
    let first = range.start;
    let finishes: Vec<TokenStream> = t.ops[range]
        .iter()
        .enumerate()
        .map(|(i, op)| {
            let index = first + i;
            if let Some(l) = linear(d, &t.numbers, op, At::Beyond) {
                return l;
            }
            let w = format_ident!("w{index}");
            match op {
                Op::Mul { dst, a, b } => {
                    let (dst, a, b) = (series(*dst), series(*a), series(*b));
                    let h = history(quote! { #a[j] * #b[r] });
                    quote! { #dst[k] = #tay::mul_finish(&#a, &#b, #h, k); }
                }
                Op::Square { dst, a } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let h = history(quote! { #a[j] * #a[r] });
                    quote! { #dst[k] = #tay::square_finish(&#a, #h, k); }
                }
                Op::Recip { dst, a } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let h = history(quote! { #a[j] * #dst[r] });
                    quote! { #dst[k] = #tay::recip_finish(&#dst, &#a, #h, k); }
                }
                Op::Div { dst, a, b } => {
                    let (dst, a, b) = (series(*dst), series(*a), series(*b));
                    let h = history(quote! { #b[j] * #dst[r] });
                    quote! { #dst[k] = #tay::div_finish(&#dst, &#a, &#b, #h, k); }
                }
                Op::Sqrt { dst, a } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let h = history(quote! { #dst[j] * #dst[r] });
                    quote! { #dst[k] = #tay::sqrt_finish(&#dst, &#a, #h, k); }
                }
                Op::Power { dst, a, alpha } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let alpha = Literal::f64_suffixed(*alpha);
                    let h = history(quote! { #tay::power_weight(#alpha, r, j) * #a[r] * #dst[j] });
                    quote! { #dst[k] = #tay::power_finish(&#dst, &#a, #alpha, #h, k); }
                }
                Op::Exp { dst, a } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let h = history(quote! { #w[j] * #dst[r] });
                    quote! {
                        #w[k] = k as f64 * #a[k];
                        #dst[k] = #tay::exp_finish(&#dst, &#a, #h, k);
                    }
                }
                Op::Log { dst, a } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let h = history(quote! { #w[j] * #a[r] });
                    quote! {
                        #dst[k] = #tay::log_finish(&#a, #h, k);
                        #w[k] = k as f64 * #dst[k];
                    }
                }
                Op::SinCos { sin, cos, a } => {
                    let (s, c, a) = (series(*sin), series(*cos), series(*a));
                    let hs = history(quote! { #w[j] * #c[r] });
                    let hc = history(quote! { #w[j] * #s[r] });
                    quote! {
                        #w[k] = k as f64 * #a[k];
                        (#s[k], #c[k]) = #tay::sin_cos_finish(&#s, &#c, &#a, #hs, #hc, k);
                    }
                }
                Op::Add { .. } | Op::Scale { .. } => unreachable!("linear ops above"),
            }
        })
        .collect();
    // The solve: hₖ (or pₖ) − (history + Gₖx₀) per entry of G that
    // varies, in row order (a negated entry added), then the triangular
    // solves.
    let solve = solve.map(|solve| {
        let mut rows: Vec<TokenStream> = if solve.momentum {
            (0..solve.x.len())
                .map(|i| {
                    let i = Literal::usize_unsuffixed(i);
                    quote! { p[#i] }
                })
                .collect()
        } else {
            solve
                .rhs
                .iter()
                .map(|h| coefficient(d, t, h, At::Beyond))
                .collect()
        };
        for (i, m, g, minus) in solve.varying() {
            let (g, x) = (series(g), series(solve.x[m]));
            let h = history(quote! { #g[j] * #x[r] });
            let term = quote! { (#h + #g[k] * #x[0]) };
            let row = &rows[i];
            rows[i] = if minus {
                quote! { #row + #term }
            } else {
                quote! { #row - #term }
            };
        }
        let store = store_x(solve);
        quote! {
            let mut rhs = [#(#rows),*];
            #tay::ldl_solve(&factor, &mut rhs);
            #store
        }
    });
    // One loop per group of histories: enough independent sums to keep the
    // floating-point units busy, few enough that they stay in registers.
    let fused = accs
        .chunks(HISTORIES_PER_LOOP)
        .zip(terms.chunks(HISTORIES_PER_LOOP))
        .map(|(accs, terms)| {
            quote! {
                #(let mut #accs = 0.0;)*
                for j in 1..k {
                    let r = k - j;
                    #(#terms)*
                }
            }
        });
    (quote! { #(#fused)* }, quote! { #(#finishes)* #solve })
}

/// dst[0] = f(&dst, &a, [extra,] 0): a recurrence on its own result, at
/// order 0.
fn unary(f: TokenStream, dst: Series, a: Series, extra: Option<TokenStream>) -> TokenStream {
    let (dst, a) = (series(dst), series(a));
    quote! { #dst[0] = #f(&#dst, &#a, #extra 0); }
}
