//! The Taylor-mode functions of a model whose q̈ is in closed form: the
//! series of the motion (`motion_series`) and, per wall, of f along it
//! (`{wall}_surface_series`), each the Taylor transform
//! ([`crate::program::Transform`]) of a program the table already holds,
//! written out as one loop over the orders. Order 0 is the program on the
//! values; at each order k ≥ 1 one inner loop over j = 1..k−1 sums every
//! convolution's history side by side, then each operation is finished in
//! program order (`dalembert_runtime::taylor`'s `*_finish`). f64 only (the
//! runtime's series are f64).

use std::ops::Range;

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::Ctx;
use super::body::{self, Place};
use crate::program::{Emit, Op, Program, Series, Slot, Solve, Term, Transform};

/// The model's transforms: q̈'s, then each wall's f's (`None` for f32 or
/// where q̈ is not written out: then the model has no series at all).
pub(super) fn transforms<'a>(d: &'a Ctx) -> Option<(&'a Transform, &'a [Transform])> {
    d.series.as_ref().map(|(m, w)| (m, w.as_slice()))
}

/// Histories summed side by side in one loop over j: x86-64 has 16
/// vector registers, and each sum holds one while two operands are loaded.
const HISTORIES_PER_LOOP: usize = 12;

/// The lints the series functions' shape sets off: unused bindings of
/// the time-constant values, literal constants near π, loops over orders
/// that index several arrays, copies of coefficients, and `&x` of an
/// intermediate series held in `scratch` (already a reference).
fn lints() -> TokenStream {
    quote! {
        #[allow(
            unused_variables,
            clippy::approx_constant,
            clippy::needless_range_loop,
            clippy::manual_memcpy,
            clippy::needless_borrow
        )]
    }
}

/// `motion_series`'s lints and signature, whichever transform it writes.
fn motion_signature(n: &Literal) -> TokenStream {
    let lints = lints();
    quote! {
        #lints
        pub fn motion_series(
            &self,
            s: &mut ::dalembert_runtime::taylor::Series<#n>,
            scratch: &mut SeriesScratch,
            order: usize,
        )
    }
}

/// `motion_series` and every `{wall}_surface_series`.
pub(super) fn functions(d: &Ctx) -> TokenStream {
    let Some((motion, walls)) = transforms(d) else {
        return TokenStream::new();
    };
    let n = Literal::usize_unsuffixed(d.model.velocities.len());
    let motion_prelude = prelude(d, motion);
    if let Some(solve) = motion.solve.as_ref().filter(|s| s.momentum) {
        let walls = wall_functions(d, walls, &n);
        let motion_fn = momentum_series(d, motion, solve, motion_prelude, &n);
        return quote! { #motion_fn #walls };
    }
    let motion_ops = ops(d, motion);
    let feedback = (0..d.model.velocities.len()).map(|i| {
        let i_lit = Literal::usize_unsuffixed(i);
        // A zero acceleration (a free coordinate) is zero at every order.
        let out = if zero_output(motion, i) {
            quote! { 0.0 }
        } else {
            let out = output(d, motion, i);
            quote! { #out * ik }
        };
        quote! {
            s.q[#i_lit][k + 1] = s.v[#i_lit][k] * ik;
            s.v[#i_lit][k + 1] = #out;
        }
    });
    let how: &[&str] = if motion.solve.is_some() {
        &[
            " `taylor::MAX_ORDER`) by the Taylor transform of G and h",
            " (`mass_matrix`, `forcing`) with G q̈ = −h solved at each order,",
        ]
    } else {
        &[" `taylor::MAX_ORDER`) by the Taylor transform of `accelerations`,"]
    };
    let signature = motion_signature(&n);
    let motion_fn = quote! {
        /// The Taylor series of the motion through the state at order 0 of
        /// `s` (q(t₀), q̇(t₀)): fills its orders 1 to `order` (at most
        #(#[doc = #how])*
        /// one order at a time, in `scratch`'s room.
        #signature {
            let order = order.min(::dalembert_runtime::taylor::MAX_ORDER);
            #motion_prelude
            for k in 0..order {
                #motion_ops
                let ik = ::dalembert_runtime::taylor::RECIPROCALS[k + 1];
                #(#feedback)*
            }
            s.order = order;
        }
    };
    let wall_fns = wall_functions(d, walls, &n);
    quote! { #motion_fn #wall_fns }
}

/// Every `{wall}_surface_series`.
fn wall_functions(d: &Ctx, walls: &[Transform], n: &Literal) -> TokenStream {
    let wall_fns = d.walls.iter().zip(walls).map(|(w, t)| {
        let name = format_ident!("{}_surface_series", w.name);
        let doc = format!(
            " Wall `{}`: the Taylor coefficients of f(q(t)) along `s`, orders 0 to `s.order`, in `scratch`'s room.",
            w.name
        );
        let prelude = prelude(d, t);
        let ops = ops(d, t);
        let (out, lints) = (output(d, t, 0), lints());
        quote! {
            #[doc = #doc]
            #lints
            pub fn #name(
                &self,
                s: &::dalembert_runtime::taylor::Series<#n>,
                scratch: &mut SeriesScratch,
                out: &mut ::dalembert_runtime::taylor::Coefficients,
            ) {
                #prelude
                for k in 0..=s.order.min(::dalembert_runtime::taylor::MAX_ORDER) {
                    #ops
                    out[k] = #out;
                }
            }
        }
    });
    quote! { #(#wall_fns)* }
}

/// `motion_series` where the series of the momentum p = G q̇ is followed
/// (ṗ = ∂L/∂q, the solve's right-hand side): at each order k the ops
/// that read coordinates only (G's among them), then G₀ q̇ₖ = pₖ −
/// Σⱼ₌₁..ₖ Gⱼ q̇ₖ₋ⱼ (k ≥ 1; G₀ factored at k = 0), then the ops that read
/// velocities, then qₖ₊₁ = q̇ₖ/(k + 1) and pₖ₊₁ = (∂L/∂q)ₖ/(k + 1); one
/// more order of the first ops and the solve gives q̇ at the last order.
fn momentum_series(
    d: &Ctx,
    t: &Transform,
    solve: &Solve,
    prelude: TokenStream,
    n: &Literal,
) -> TokenStream {
    let before = ops_in(d, t, 0..solve.split, true);
    let after = ops_in(d, t, solve.split..t.ops.len(), false);
    let feedback = solve.rhs.iter().enumerate().map(|(i, f)| {
        let i = Literal::usize_unsuffixed(i);
        let f = coefficient(d, t, f, At::Any);
        quote! {
            s.q[#i][k + 1] = s.v[#i][k] * ik;
            p[#i] = #f * ik;
        }
    });
    let signature = motion_signature(n);
    quote! {
        /// The Taylor series of the motion through the state at order 0 of
        /// `s` (q(t₀), q̇(t₀)): fills its orders 1 to `order` (at most
        /// `taylor::MAX_ORDER`) by the Taylor transform of G and ∂L/∂q
        /// (`mass_matrix`, the gradient of T − V), following the momentum
        /// p = G q̇ (ṗ = ∂L/∂q) with G q̇ = p solved at each order, one
        /// order at a time, in `scratch`'s room.
        #signature {
            let order = order.min(::dalembert_runtime::taylor::MAX_ORDER);
            #prelude
            let mut p = [0.0f64; #n];
            for k in 0..=order {
                #before
                if k == order {
                    break;
                }
                #after
                let ik = ::dalembert_runtime::taylor::RECIPROCALS[k + 1];
                #(#feedback)*
            }
            s.order = order;
        }
    }
}

/// `SeriesScratch`: room for the intermediate series of every function
/// above, one pool they share (they never run at once), as long as the
/// longest list of [`arrays`].
pub(super) fn scratch_struct(d: &Ctx) -> TokenStream {
    let Some((motion, walls)) = transforms(d) else {
        return TokenStream::new();
    };
    let len = std::iter::once(motion)
        .chain(walls)
        .map(|t| arrays(t).len())
        .max()
        .unwrap_or(0);
    let doc = quote! {
        /// Room for the intermediate series of `motion_series` and the
        /// walls' `surface_series` (`Dynamics::SeriesScratch`), kept by
        /// the caller from one call to the next: a call writes each
        /// coefficient before it reads it, so nothing needs clearing
        /// between calls.
    };
    if len == 0 {
        return quote! {
            #doc
            /// (This model's series keep every intermediate on the stack.)
            #[derive(Clone, Copy, Debug, Default)]
            pub struct SeriesScratch;
        };
    }
    let len = Literal::usize_unsuffixed(len);
    quote! {
        #doc
        #[derive(Clone, Debug)]
        pub struct SeriesScratch {
            arrays: [::dalembert_runtime::taylor::Coefficients; #len],
        }
        impl Default for SeriesScratch {
            fn default() -> Self {
                Self { arrays: [[0.0; ::dalembert_runtime::taylor::CAPACITY]; #len] }
            }
        }
    }
}

/// The intermediate series of `t` kept as whole arrays, in the order they
/// take their places in `SeriesScratch`: the temporaries read at lower
/// orders (`x{j}`, the rest keep their current coefficient alone), then the
/// weighted operands' series (`w{op}`).
fn arrays(t: &Transform) -> Vec<proc_macro2::Ident> {
    let temps = t
        .current_only()
        .into_iter()
        .enumerate()
        .filter(|(_, current)| !current)
        .map(|(j, _)| format_ident!("x{j}"));
    let weights = t
        .ops
        .iter()
        .enumerate()
        .filter(|(_, op)| weighted(op))
        .map(|(index, _)| format_ident!("w{index}"));
    temps.chain(weights).collect()
}

/// The time-constant values, the intermediate series (single coefficients
/// on the stack, whole arrays in `scratch`).
fn prelude(d: &Ctx, t: &Transform) -> TokenStream {
    let plan = vec![Emit::Compute; t.numbers.instrs.len()];
    let numbers = body::statements(d, &t.numbers, &plan, Place::Call);
    // Series operations read parameters directly too (a product with m);
    // those the numbers read are bound by their statements.
    let read: Vec<Slot> = t
        .numbers
        .instrs
        .iter()
        .flat_map(|ins| ins.sources().to_vec())
        .collect();
    let params = d
        .model
        .params
        .iter()
        .enumerate()
        .filter(move |(i, _)| !read.contains(&Slot::Input(*i)))
        .map(|(i, p)| {
            let (name, field) = (format_ident!("i{i}"), super::ident(&p.name));
            quote! { let #name: f64 = self.params.#field; }
        });
    // Temporaries read only at the current order keep that coefficient
    // alone (`taylor::Current`, indexed like the arrays).
    let temps = t
        .current_only()
        .into_iter()
        .enumerate()
        .filter(|(_, current)| *current)
        .map(|(j, _)| {
            let x = format_ident!("x{j}");
            quote! { let mut #x = ::dalembert_runtime::taylor::Current::default(); }
        });
    let arrays = arrays(t);
    let arrays =
        (!arrays.is_empty()).then(|| quote! { let [#(#arrays,)* ..] = &mut scratch.arrays; });
    let factor = t.solve.as_ref().map(|solve| {
        let n = solve.x.len();
        let len = Literal::usize_unsuffixed(n * (n + 1) / 2);
        quote! { let mut factor = [0.0f64; #len]; }
    });
    quote! { #(#params)* #numbers #(#temps)* #arrays #factor }
}

/// Whether an op's history is weighted by j (it keeps the series j·xⱼ of
/// the weighted operand, `w{op}`).
fn weighted(op: &Op) -> bool {
    matches!(op, Op::Exp { .. } | Op::Log { .. } | Op::SinCos { .. })
}

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

/// Whether output `o` is the constant 0.
fn zero_output(t: &Transform, o: usize) -> bool {
    matches!(t.outputs[o], Term::Number(Slot::Const(i)) if t.numbers.consts[i] == 0.0)
}

/// Coefficient k of output `o`.
fn output(d: &Ctx, t: &Transform, o: usize) -> TokenStream {
    if zero_output(t, o) {
        return quote! { 0.0 };
    }
    coefficient(d, t, &Some(t.outputs[o]), At::Any)
}

/// Order k of every op: at k = 0 the values, beyond it the fused history
/// loops and each op's finish.
fn ops(d: &Ctx, t: &Transform) -> TokenStream {
    ops_in(d, t, 0..t.ops.len(), t.solve.is_some())
}

/// [`ops`] for the ops in `range` only, followed by the transform's solve
/// if `solve`.
fn ops_in(d: &Ctx, t: &Transform, range: Range<usize>, solve: bool) -> TokenStream {
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
enum At {
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
fn coefficient(d: &Ctx, t: &Transform, term: &Option<Term>, at: At) -> TokenStream {
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
