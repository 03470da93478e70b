//! The statements of one order of a series function: order 0's values,
//! and at each order k ≥ 1 the history loops (every convolution's sum over
//! j = 1..k−1 side by side) and each operation's finish in program order.

use std::ops::Range;

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::super::Ctx;
use super::super::body;
use super::pairs::{GroupPlan, History, Operand};
use crate::program::{Op, Program, Series, Slot, Solve, Term, Transform};

/// Running sums (a pair of histories or a single one) side by side in one
/// loop over j: x86-64 has 16 vector registers, and each sum holds one
/// while its two operands are loaded.
const SUMS_PER_LOOP: usize = 12;

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

/// A history's operand as an expression (`w{op}` for a weighted one).
fn operand(o: Operand) -> TokenStream {
    match o {
        Operand::Series(s) => series(s),
        Operand::Weight(index) => {
            let w = format_ident!("w{index}");
            quote! { #w }
        }
    }
}

fn number(d: &Ctx, p: &Program, s: Slot) -> TokenStream {
    body::slot(d, p, s)
}
/// Order k of one group of ops (`plan`'s), followed by the transform's
/// solve if the group has it: at k = 0 the values, beyond it the fused
/// history loops and each op's finish.
pub(super) fn ops(d: &Ctx, t: &Transform, plan: &GroupPlan) -> TokenStream {
    let group = &plan.group;
    let range = group.ops.clone();
    let ops = &t.ops[range.clone()];
    if !group.solve
        && ops
            .iter()
            .all(|op| linear(d, &t.numbers, op, At::Any).is_some())
    {
        // Sums and scalings only: one statement per op at every order.
        let stmts = ops.iter().flat_map(|op| linear(d, &t.numbers, op, At::Any));
        return quote! { #(#stmts)* };
    }
    let solve = group.solve(t);
    let zero = order_zero(d, t, range, solve);
    let (histories, finishes) = order_k(d, t, plan);
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

/// The name of op `index`'s factor known from order 0 on (see
/// [`order_factor`]).
pub(super) fn factor_name(index: usize) -> proc_macro2::Ident {
    format_ident!("inv{index}")
}

/// Whether an op's finish multiplies by a factor that order 0 fixes (1/b₀
/// of a quotient, 1/(2c₀) of a square root, 1/a₀ of a logarithm): the
/// series works it out once, at order 0, into `inv{op}`, rather than
/// dividing at every order (the same value, so the same bits).
pub(super) fn order_factor(op: &Op) -> bool {
    matches!(
        op,
        Op::Div { .. } | Op::Sqrt { .. } | Op::Log { .. } | Op::Arc { .. }
    )
}

/// Order 0: each function's value (the runtime's recurrences at order 0).
fn order_zero(d: &Ctx, t: &Transform, range: Range<usize>, solve: Option<&Solve>) -> TokenStream {
    let tay = quote! { ::dalembert_runtime::__private::taylor };
    let first = range.start;
    let stmts = t.ops[range].iter().enumerate().map(|(i, op)| {
        if let Some(l) = linear(d, &t.numbers, op, At::Zero) {
            return l;
        }
        let inv = factor_name(first + i);
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
                quote! {
                    #dst[0] = #tay::div(&#dst, &#a, &#b, 0);
                    #inv = 1.0 / #b[0];
                }
            }
            Op::Sqrt { dst, a } => {
                let value = unary(quote! { #tay::sqrt }, *dst, *a, None);
                let dst = series(*dst);
                quote! { #value #inv = 0.5 / #dst[0]; }
            }
            Op::Exp { dst, a } => unary(quote! { #tay::exp }, *dst, *a, None),
            Op::Log { dst, a } => {
                let value = unary(quote! { #tay::log }, *dst, *a, None);
                let a = series(*a);
                quote! { #value #inv = 1.0 / #a[0]; }
            }
            Op::Power { dst, a, alpha } => {
                let alpha = Literal::f64_suffixed(*alpha);
                unary(quote! { #tay::power }, *dst, *a, Some(quote! { #alpha, }))
            }
            Op::SinCos { sin, cos, a } => {
                let (s, c, a) = (series(*sin), series(*cos), series(*a));
                quote! { (#s[0], #c[0]) = #tay::sin_cos(&#s, &#c, &#a, 0); }
            }
            Op::Arc {
                dst,
                a,
                w,
                f,
                minus,
            } => {
                let (dst, a, w) = (series(*dst), series(*a), series(*w));
                let f = format_ident!("{}", f.name());
                let one = if *minus {
                    quote! { -1.0 }
                } else {
                    quote! { 1.0 }
                };
                quote! {
                    #dst[0] = ::dalembert_runtime::libm::#f(#a[0]);
                    #inv = #one / #w[0];
                }
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

/// Orders k ≥ 1: the history loops (pairs of histories and single ones,
/// at most [`SUMS_PER_LOOP`] running sums per loop), then each op's finish
/// in program order, then the group's lanes at order k.
fn order_k(d: &Ctx, t: &Transform, plan: &GroupPlan) -> (TokenStream, TokenStream) {
    let tay = quote! { ::dalembert_runtime::__private::taylor };
    let group = &plan.group;
    // h{i} is history i of the plan's; the finishes read them in that
    // order.
    let mut names = (0..plan.histories.len()).map(|i| format_ident!("h{i}"));
    let mut history = || names.next().expect("one name per history");
    let first = group.ops.start;
    let finishes: Vec<TokenStream> = t.ops[group.ops.clone()]
        .iter()
        .enumerate()
        .map(|(i, op)| {
            let index = first + i;
            if let Some(l) = linear(d, &t.numbers, op, At::Beyond) {
                return l;
            }
            let w = format_ident!("w{index}");
            let inv = factor_name(index);
            match op {
                Op::Mul { dst, a, b } => {
                    let (dst, a, b) = (series(*dst), series(*a), series(*b));
                    let h = history();
                    quote! { #dst[k] = #tay::mul_finish(&#a, &#b, #h, k); }
                }
                Op::Square { dst, a } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let h = history();
                    quote! { #dst[k] = #tay::square_finish(&#a, #h, k); }
                }
                Op::Recip { dst, a } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let h = history();
                    quote! { #dst[k] = #tay::recip_finish(&#dst, &#a, #h, k); }
                }
                Op::Div { dst, a, b } => {
                    let (dst, a, b) = (series(*dst), series(*a), series(*b));
                    let h = history();
                    quote! { #dst[k] = #tay::div_finish_by(&#dst, &#a, &#b, #h, k, #inv); }
                }
                Op::Sqrt { dst, a } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let h = history();
                    quote! { #dst[k] = #tay::sqrt_finish_by(&#a, #h, k, #inv); }
                }
                Op::Power { dst, a, alpha } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let alpha = Literal::f64_suffixed(*alpha);
                    let h = history();
                    quote! { #dst[k] = #tay::power_finish(&#dst, &#a, #alpha, #h, k); }
                }
                Op::Exp { dst, a } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let h = history();
                    quote! {
                        #w[k] = k as f64 * #a[k];
                        #dst[k] = #tay::exp_finish(&#dst, &#a, #h, k);
                    }
                }
                Op::Log { dst, a } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let h = history();
                    quote! {
                        #dst[k] = #tay::log_finish_by(&#a, #h, k, #inv);
                        #w[k] = k as f64 * #dst[k];
                    }
                }
                Op::Arc { dst, a, minus, .. } => {
                    let (dst, a) = (series(*dst), series(*a));
                    let h = history();
                    let h = if *minus {
                        quote! { -#h }
                    } else {
                        quote! { #h }
                    };
                    quote! {
                        #dst[k] = #tay::log_finish_by(&#a, #h, k, #inv);
                        #w[k] = k as f64 * #dst[k];
                    }
                }
                Op::SinCos { sin, cos, a } => {
                    let (s, c, a) = (series(*sin), series(*cos), series(*a));
                    let (hs, hc) = (history(), history());
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
    let solve = group.solve(t).map(|solve| {
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
            let h = history();
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
    // Coefficient k of each lane this group is the first to read, now that
    // its operands have it: after the finishes, off the chain from one op
    // to the next (a lane stored between two finishes makes the compiler,
    // which cannot tell a lane from an operand's array, read the next
    // operands back from memory, on that chain).
    let lanes = plan.stores.iter().map(|(id, (a, b))| {
        let (l, a, b) = (format_ident!("l{id}"), operand(*a), operand(*b));
        quote! { #l[k] = #tay::Pair::new(#a[k], #b[k]); }
    });
    (loops(plan), quote! { #(#finishes)* #solve #(#lanes)* })
}

/// The history loops: one running sum per pair (`hp{n}`, from its lanes)
/// and per single history (`h{i}`), in the order of their first history,
/// at most [`SUMS_PER_LOOP`] to a loop; after each loop the pairs' lanes
/// are bound to their histories' names.
fn loops(plan: &GroupPlan) -> TokenStream {
    let tay = quote! { ::dalembert_runtime::__private::taylor };
    // (first history, declaration, term at j, binding after the loop)
    let mut sums: Vec<(usize, TokenStream, TokenStream, TokenStream)> = plan
        .pairs
        .iter()
        .enumerate()
        .map(|(n, p)| {
            let hp = format_ident!("hp{n}");
            let (l, r) = (format_ident!("l{}", p.left), format_ident!("l{}", p.right));
            let (a, b) = (
                format_ident!("h{}", p.first),
                format_ident!("h{}", p.second),
            );
            (
                p.first.min(p.second),
                quote! { let mut #hp = #tay::Pair::default(); },
                quote! { #hp = #hp.add_product(#l[j], #r[r]); },
                quote! { let (#a, #b) = #hp.lanes(); },
            )
        })
        .collect();
    sums.extend(plan.single.iter().map(|&i| {
        let h = format_ident!("h{i}");
        let term = match plan.histories[i] {
            History::Product { left, right } => {
                let (a, b) = (operand(left), operand(right));
                quote! { #a[j] * #b[r] }
            }
            History::Power { alpha, a, dst } => {
                let (a, dst) = (series(a), series(dst));
                let alpha = Literal::f64_suffixed(alpha);
                quote! { #tay::power_weight(#alpha, r, j) * #a[r] * #dst[j] }
            }
        };
        (
            i,
            quote! { let mut #h = 0.0; },
            quote! { #h += #term; },
            TokenStream::new(),
        )
    }));
    sums.sort_by_key(|s| s.0);
    let fused = sums.chunks(SUMS_PER_LOOP).map(|chunk| {
        let decls = chunk.iter().map(|s| &s.1);
        let terms = chunk.iter().map(|s| &s.2);
        let binds = chunk.iter().map(|s| &s.3);
        quote! {
            #(#decls)*
            for j in 1..k {
                let r = k - j;
                #(#terms)*
            }
            #(#binds)*
        }
    });
    quote! { #(#fused)* }
}

/// dst[0] = f(&dst, &a, [extra,] 0): a recurrence on its own result, at
/// order 0.
fn unary(f: TokenStream, dst: Series, a: Series, extra: Option<TokenStream>) -> TokenStream {
    let (dst, a) = (series(dst), series(a));
    quote! { #dst[0] = #f(&#dst, &#a, #extra 0); }
}
