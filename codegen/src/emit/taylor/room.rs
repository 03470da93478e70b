//! `SeriesScratch`, the room the caller keeps for a model's intermediate
//! series from one call to the next, and each series function's prelude:
//! its time-constant values and where its intermediate series live.

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::super::Ctx;
use super::super::body::{self, Place};
use super::pairs::{self, Plan};
use crate::plan::computed;
use crate::program::{Op, Slot, Transform};
use crate::quantity::Inputs;

/// `SeriesScratch`: room for the intermediate series of every function
/// above, one pool they share (they never run at once), as long as the
/// longest list of [`arrays`], and one pool of lanes (pairs of series side
/// by side, [`pairs`]) as long as the most any of them uses; and
/// `VariationalScratch`, the same for the variational series, which that
/// function keeps on its stack for one call (so that a simulator without
/// Φ carries none of it).
pub(in crate::emit) fn scratch_struct(d: &Ctx) -> TokenStream {
    let Some((motion, walls)) = d.series() else {
        return TokenStream::new();
    };
    let series = room(
        format_ident!("SeriesScratch"),
        std::iter::once(motion).chain(walls),
        quote! {
            /// Room for the intermediate series of `motion_series` and the
            /// walls' `surface_series` (`TaylorSeries::SeriesScratch`), kept by
            /// the caller from one call to the next: a call writes each
            /// coefficient before it reads it, so nothing needs clearing
            /// between calls.
        },
    );
    let variational = d
        .plan
        .variational
        .as_ref()
        .filter(|t| needs_room(t))
        .map(|t| {
            room(
                format_ident!("VariationalScratch"),
                std::iter::once(t),
                quote! {
                    /// Room for the intermediate series of `tangent_series`, on its
                    /// stack for the call.
                },
            )
        });
    quote! { #series #variational }
}

/// Whether `t`'s function keeps intermediate series in a scratch room
/// (whole arrays, or lanes).
pub(super) fn needs_room(t: &Transform) -> bool {
    !arrays(t).is_empty() || pairs::plan(t).lanes > 0
}

/// A struct named `name` with room for the intermediate series of any one
/// of `transforms` at a time.
fn room<'t>(
    name: proc_macro2::Ident,
    transforms: impl Iterator<Item = &'t Transform> + Clone,
    doc: TokenStream,
) -> TokenStream {
    let most =
        |count: &dyn Fn(&Transform) -> usize| transforms.clone().map(count).max().unwrap_or(0);
    let len = most(&|t| arrays(t).len());
    let lanes = most(&|t| pairs::plan(t).lanes);
    if len == 0 && lanes == 0 {
        return quote! {
            #doc
            /// (This model's series keep every intermediate on the stack.)
            #[derive(Clone, Copy, Debug, Default)]
            pub struct #name;
        };
    }
    let tay = quote! { ::dalembert_runtime::__private::taylor };
    let (mut fields, mut values) = (Vec::new(), Vec::new());
    if len > 0 {
        let len = Literal::usize_unsuffixed(len);
        fields.push(quote! { arrays: [#tay::Coefficients; #len], });
        values.push(quote! { arrays: [[0.0; #tay::CAPACITY]; #len], });
    }
    if lanes > 0 {
        let lanes = Literal::usize_unsuffixed(lanes);
        fields.push(quote! { pairs: [#tay::Pairs; #lanes], });
        values.push(quote! { pairs: [[#tay::Pair::default(); #tay::CAPACITY]; #lanes], });
    }
    quote! {
        #doc
        #[derive(Clone, Debug)]
        pub struct #name { #(#fields)* }
        impl Default for #name {
            fn default() -> Self {
                Self { #(#values)* }
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
/// on the stack, whole arrays in `scratch`) and the lanes of `plan`.
pub(super) fn prelude(d: &Ctx, t: &Transform, plan: &Plan) -> TokenStream {
    let numbers = body::statements(
        d,
        &t.numbers,
        &computed(&t.numbers),
        Inputs::Phase,
        Place::Call,
    );
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
            let (name, field) = (format_ident!("i{i}"), super::super::ident(&p.name));
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
            quote! { let mut #x = ::dalembert_runtime::__private::taylor::Current::default(); }
        });
    let arrays = arrays(t);
    let arrays =
        (!arrays.is_empty()).then(|| quote! { let [#(#arrays,)* ..] = &mut scratch.arrays; });
    let lanes = (0..plan.lanes).map(|id| format_ident!("l{id}"));
    let lanes = (plan.lanes > 0).then(|| quote! { let [#(#lanes,)* ..] = &mut scratch.pairs; });
    let factor = t.solve.as_ref().map(|solve| {
        let n = solve.x.len();
        let len = Literal::usize_unsuffixed(n * (n + 1) / 2);
        quote! { let mut factor = [0.0f64; #len]; }
    });
    // Each factor that order 0 fixes (`orders::order_factor`).
    let inverses = t
        .ops
        .iter()
        .enumerate()
        .filter(|(_, op)| super::orders::order_factor(op))
        .map(|(index, _)| {
            let inv = super::orders::factor_name(index);
            quote! { let mut #inv = 0.0f64; }
        });
    quote! { #(#params)* #numbers #(#temps)* #arrays #lanes #factor #(#inverses)* }
}

/// Whether an op's history is weighted by j (it keeps the series j·xⱼ of
/// the weighted operand, `w{op}`).
fn weighted(op: &Op) -> bool {
    matches!(
        op,
        Op::Exp { .. } | Op::Log { .. } | Op::SinCos { .. } | Op::Arc { .. }
    )
}
