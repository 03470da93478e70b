//! The Taylor-mode functions of a model whose q̈ is in closed form: the
//! series of the motion (`motion_series`) and, per wall, of f along it
//! (`{wall}_surface_series`), each the Taylor transform
//! ([`crate::program::Transform`]) of a program the table already holds,
//! written out as one loop over the orders. Order 0 is the program on the
//! values; at each order k ≥ 1 one inner loop over j = 1..k−1 sums every
//! convolution's history side by side, then each operation is finished in
//! program order (`dalembert_runtime::__private::taylor`'s `*_finish`). f64 only (the
//! runtime's series are f64).

//!
//! - this file: the functions and their signatures;
//! - [`room`]: `SeriesScratch`, the room the caller keeps for the
//!   intermediate series, and each function's prelude;
//! - [`orders`]: the statements of one order (order 0's values, the
//!   history loops and each operation's finish);
//! - [`pairs`]: which histories are summed two at a time, and the lanes
//!   that keep their operands side by side.

mod orders;
mod pairs;
mod room;

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::Ctx;
use crate::program::{Slot, Solve, Term, Transform};
use orders::{At, coefficient, ops};
use pairs::Plan;
use room::prelude;
pub(super) use room::scratch_struct;

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
    let Some((motion, walls)) = d.series() else {
        return TokenStream::new();
    };
    let n = Literal::usize_unsuffixed(d.model.velocities.len());
    let plan = pairs::plan(motion);
    let motion_prelude = prelude(d, motion, &plan);
    let tangent_fn = d.plan.variational.as_ref().map(|t| tangent_series(d, t));
    if let Some(solve) = motion.solve.as_ref().filter(|s| s.momentum) {
        let walls = wall_functions(d, walls, &n);
        let motion_fn = momentum_series(d, motion, solve, &plan, motion_prelude, &n);
        return quote! { #motion_fn #walls #tangent_fn };
    }
    let motion_ops = ops(d, motion, &plan.groups[0]);
    let feedback = (0..d.model.velocities.len()).map(|i| feedback(d, motion, i, i));
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
                let ik = ::dalembert_runtime::__private::taylor::RECIPROCALS[k + 1];
                #(#feedback)*
            }
            s.order = order;
        }
    };
    let wall_fns = wall_functions(d, walls, &n);
    quote! { #motion_fn #wall_fns #tangent_fn }
}

/// `tangent_series`: the series of columns of the variational flow along
/// the motion's series, by the transform of the variational system over
/// (q, δq) ([`crate::program::Program::variational`]). The function copies
/// the motion's coefficients into the first half of one series of
/// dimension 2N (`s`, which the ops read as `motion_series` reads its
/// own), runs the ops shared by every column to the last order
/// ([`Transform::shared`]), then for each column puts its start into the
/// second half and runs the other ops order by order; the feedback fills
/// the second half alone, the first being the motion's already.
fn tangent_series(d: &Ctx, t: &Transform) -> TokenStream {
    let n = d.model.velocities.len();
    let (nl, n2) = (
        Literal::usize_unsuffixed(n),
        Literal::usize_unsuffixed(2 * n),
    );
    let plan = pairs::plan(t);
    let prelude = prelude(d, t, &plan);
    let (shared, ops) = match &plan.groups[..] {
        [shared, rest] => (ops(d, t, shared), ops(d, t, rest)),
        _ => unreachable!("a variational system's ops are shared or not"),
    };
    let feedback = (0..n).map(|i| feedback(d, t, i, n + i));
    let lints = lints();
    let scratch = room::needs_room(t).then(|| {
        quote! { let scratch = &mut VariationalScratch::default(); }
    });
    quote! {
        /// Columns of the variational flow along the motion's series `motion`
        /// (`motion_series`'s): each of `columns` holds (δq, δq̇) at order 0,
        /// and gets its coefficients of orders 1 to `motion.order`, the
        /// series of δq(t), δq̇(t) under δq̈ = ∂q̈/∂q δq + ∂q̈/∂q̇ δq̇ (the
        /// Taylor transform of `accelerations_tangent`): each column's
        /// polynomial is the derivative of the motion's along its start.
        #lints
        pub fn tangent_series(
            &self,
            motion: &::dalembert_runtime::taylor::Series<#nl>,
            columns: &mut [::dalembert_runtime::taylor::Series<#nl>],
        ) {
            let order = motion.order.min(::dalembert_runtime::taylor::MAX_ORDER);
            #scratch
            #prelude
            let mut both = ::dalembert_runtime::taylor::Series::<#n2>::at(&[0.0; #n2], &[0.0; #n2]);
            both.q[..#nl].copy_from_slice(&motion.q);
            both.v[..#nl].copy_from_slice(&motion.v);
            let s = &mut both;
            for k in 0..order {
                #shared
            }
            for column in columns.iter_mut() {
                let s = &mut both;
                for i in 0..#nl {
                    s.q[#nl + i][0] = column.q[i][0];
                    s.v[#nl + i][0] = column.v[i][0];
                }
                for k in 0..order {
                    #ops
                    let ik = ::dalembert_runtime::__private::taylor::RECIPROCALS[k + 1];
                    #(#feedback)*
                }
                column.q.copy_from_slice(&s.q[#nl..]);
                column.v.copy_from_slice(&s.v[#nl..]);
                column.order = order;
            }
        }
    }
}

/// Every `{wall}_surface_series`.
fn wall_functions(d: &Ctx, walls: &[Transform], n: &Literal) -> TokenStream {
    let wall_fns = d.derivation.walls.iter().zip(walls).map(|(w, t)| {
        let name = format_ident!("{}_surface_series", w.name);
        let doc = format!(
            " Wall `{}`: the Taylor coefficients of f(q(t)) along `s`, orders 0 to `s.order`, in `scratch`'s room.",
            w.name
        );
        let plan = pairs::plan(t);
        let prelude = prelude(d, t, &plan);
        let ops = ops(d, t, &plan.groups[0]);
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
                // An exclusive range: `0..=n` compiles to a loop with an
                // extra exit test and no unrolling.
                for k in 0..s.order.min(::dalembert_runtime::taylor::MAX_ORDER) + 1 {
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
    plan: &Plan,
    prelude: TokenStream,
    n: &Literal,
) -> TokenStream {
    let before = ops(d, t, &plan.groups[0]);
    let after = ops(d, t, &plan.groups[1]);
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
                let ik = ::dalembert_runtime::__private::taylor::RECIPROCALS[k + 1];
                #(#feedback)*
            }
            s.order = order;
        }
    }
}

/// Coefficient k + 1 of coordinate and velocity `i` of `s` from
/// coefficient k of the velocity and of output `o` (its acceleration).
fn feedback(d: &Ctx, t: &Transform, o: usize, i: usize) -> TokenStream {
    let i = Literal::usize_unsuffixed(i);
    // A zero acceleration (a free coordinate) is zero at every order.
    let out = if zero_output(t, o) {
        quote! { 0.0 }
    } else {
        let out = output(d, t, o);
        quote! { #out * ik }
    };
    quote! {
        s.q[#i][k + 1] = s.v[#i][k] * ik;
        s.v[#i][k + 1] = #out;
    }
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
