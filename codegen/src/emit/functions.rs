//! The model's inherent functions: one per row of the quantity table that
//! the derivation filled in, plus the projector (and, where no program for
//! it was derived, the collision map) solved at run time from G and B.

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::body::{self, Place, lit, real};
use super::{Ctx, Scalar, doc_attr, ident};
use crate::derive::{Function, WallDerivation};
use crate::ir::camel;
use crate::plan::Step;
use crate::program::Program;
use crate::quantity::{Inputs, Quantity, Shape};

/// `impl Model { consts, new, every function }`.
pub(super) fn inherent_impl(d: &Ctx) -> TokenStream {
    let ty = format_ident!("{}", d.model.type_name());
    let (q, n) = dims(d);
    let model_fns = d
        .derivation
        .functions
        .iter()
        .map(|f| emit_function(d, f, None));
    let walls = d.derivation.walls.iter().map(|w| wall_fns(d, w));
    let qn = Literal::usize_unsuffixed(q);
    let nn = Literal::usize_unsuffixed(n);
    let init_q = d.model.initial[..q].iter().map(|x| lit(d, *x));
    let init_v = d.model.initial[q..].iter().map(|x| lit(d, *x));
    let given = d.model.velocities_given();
    let real = real(d);
    let name = &d.model.name;
    let coords = &d.model.coordinates;
    let vels = &d.model.velocities;
    let pnames = d.model.params.iter().map(|p| &p.name);
    let variants = d
        .derivation
        .walls
        .iter()
        .map(|w| format_ident!("{}", camel(&w.name)));
    // Only where `[initial]` gives rates that are not velocities.
    let rates: Vec<&String> = d.model.start_rates.iter().map(|r| &r.name).collect();
    let start_rates = (!rates.is_empty()).then(|| {
        quote! {
            /// The rates the model file's `[initial]` gives that are not velocities
            /// (definitions linear in them): `start_rows` and `start_values`, in order.
            pub const START_RATES: &'static [&'static str] = &[#(#rates),*];
        }
    });
    let precompute = precompute(d);
    let series = super::taylor::functions(d);
    quote! {
        impl #ty {
            /// The model's name, as in its file.
            pub const NAME: &'static str = #name;
            /// Names of the coordinates, in order.
            pub const COORDINATES: &'static [&'static str] = &[#(#coords),*];
            /// Names of the velocity components, in order.
            pub const VELOCITIES: &'static [&'static str] = &[#(#vels),*];
            /// Names of the parameters, in order (the fields of `Params`).
            pub const PARAMETERS: &'static [&'static str] = &[#(#pnames),*];
            /// Every wall, in file order.
            pub const WALLS: &'static [Wall] = &[#(Wall::#variants),*];
            /// Number of coordinates.
            pub const Q: usize = #qn;
            /// Number of velocity components.
            pub const N: usize = #nn;
            /// The model file's initial coordinates (`[initial]`, zero where silent) at the
            /// file's parameter values; `initial_state` follows the parameters in use.
            #[allow(clippy::approx_constant)]
            pub const INITIAL_COORDINATES: [#real; #qn] = [#(#init_q),*];
            /// The velocities the model file's `[initial]` gives (zero where silent, see
            /// `VELOCITIES_GIVEN`) at the file's parameter values; `initial_state` follows the
            /// parameters in use.
            #[allow(clippy::approx_constant)]
            pub const INITIAL_VELOCITIES: [#real; #nn] = [#(#init_v),*];
            /// Which initial velocities the model file gives; the others follow from the
            /// constraints at the start (`dalembert_runtime::simulate::starting_velocity`).
            pub const VELOCITIES_GIVEN: [bool; #nn] = [#(#given),*];
            #start_rates
            /// The model with the given parameters.
            pub fn new(params: Params) -> Self {
                Self { params, pre: Self::precompute(&params) }
            }
            /// The parameters in use.
            pub fn params(&self) -> &Params {
                &self.params
            }
            /// Sets every parameter (and recomputes the parameter-only values).
            pub fn set_params(&mut self, params: Params) {
                *self = Self::new(params);
            }
            #precompute
            #( #model_fns )*
            #( #walls )*
            #series
        }
    }
}

/// The once-per-parameter-set block: each function's parameter-only work,
/// storing the values its per-call code reads.
fn precompute(d: &Ctx) -> TokenStream {
    let blocks = d.plan.functions.iter().filter_map(|f| {
        let inputs = f.function.quantity.spec().inputs;
        let stmts = body::statements(d, &f.function.program, &f.once, inputs, Place::Once);
        (f.split.stored > 0).then(|| quote! { { #stmts } })
    });
    let real = real(d);
    let k = Literal::usize_unsuffixed(d.plan.stored);
    quote! {
        /// The parameter-only values the functions read, from `params`.
        #[allow(unused_variables, unused_mut, clippy::approx_constant)]
        fn precompute(params: &Params) -> [#real; #k] {
            let mut pre: [#real; #k] = [0.0; #k];
            #( #blocks )*
            pre
        }
    }
}

fn wall_fns(d: &Ctx, w: &WallDerivation) -> TokenStream {
    let fns = w
        .functions
        .iter()
        .map(|f| emit_function(d, f, Some(&w.name)));
    let structured = w.structured().then(|| structured_fns(d, w));
    let bounds = bounds_fns(d, w);
    quote! { #( #fns )* #structured #bounds }
}

/// The wall's f and normal df over a box of coordinates: the programs of
/// `{wall}_surface` and `{wall}_normal` formatted over the runtime's
/// intervals, with the same parameter-only values (f64 models with
/// coordinates; the simulator proves stretches of a step free of the wall
/// with them).
fn bounds_fns(d: &Ctx, w: &WallDerivation) -> TokenStream {
    if d.scalar != Scalar::F64 || d.model.coordinates.is_empty() {
        return TokenStream::new();
    }
    let b = &Ctx { bounds: true, ..*d };
    let interval = real(b);
    let nl = Literal::usize_unsuffixed(dims(d).1);
    let fns = [Quantity::Surface, Quantity::Normal].map(|quantity| {
        let Some(f) = w.functions.iter().find(|f| f.quantity == quantity) else {
            return TokenStream::new();
        };
        let spec = quantity.spec();
        let name = format!("{}_{}_bounds", w.name, spec.name);
        let doc = format!(
            "Wall `{}`: bounds on `{}_{}` over a box of coordinates (each value it takes there lies in them).",
            w.name, w.name, spec.name
        );
        let (ret, result) = match spec.shape {
            Shape::Vector => {
                let zero = quote! { Interval::point(0.0) };
                let outs = padded_outputs(&f.program, dims(d).1, zero);
                (quote! { [#interval; #nl] }, quote! { [#(#outs),*] })
            }
            _ => (interval.clone(), quote! { o0 }),
        };
        let steps = &d.plan.function(&format!("{}_{}", w.name, spec.name)).call;
        function(b, &name, &doc, &f.program, steps, spec.inputs, ret, result)
    });
    quote! { #( #fns )* }
}

/// One function, as its row of the quantity table says (a wall's is named
/// `{wall}_{name}`).
fn emit_function(d: &Ctx, f: &Function, wall: Option<&str>) -> TokenStream {
    let spec = f.quantity.spec();
    let (name, doc) = match wall {
        Some(w) => (format!("{w}_{}", spec.name), spec.doc.replace("{wall}", w)),
        None => (spec.name.to_string(), spec.doc.to_string()),
    };
    let (p, inputs) = (&f.program, spec.inputs);
    let (q, n) = dims(d);
    let nl = Literal::usize_unsuffixed(n);
    let real = real(d);
    let (ret, result) = match spec.shape {
        Shape::Scalar => (real, quote! { o0 }),
        Shape::Vector => {
            let outs = padded_outputs(p, n, quote! { 0.0 });
            (quote! { [#real; #nl] }, quote! { [#(#outs),*] })
        }
        Shape::Matrix => {
            let rows = (0..n).map(|i| {
                let cols = (0..n).map(move |j| format_ident!("o{}", i * n + j));
                quote! { [#(#cols),*] }
            });
            (quote! { [[#real; #nl]; #nl] }, quote! { [#(#rows),*] })
        }
        Shape::Rows => {
            let rows = (0..n).map(|i| {
                if i < f.rows {
                    let cols = (0..n).map(move |j| format_ident!("o{}", i * n + j));
                    quote! { [#(#cols),*] }
                } else {
                    quote! { [0.0; #n] }
                }
            });
            let array = quote! { [#(#rows),*] };
            counted(d, "Rows", quote! { [[f32; #nl]; #nl] }, array, f.rows)
        }
        Shape::Values => {
            let outs = padded_outputs(p, n, quote! { 0.0 });
            let array = quote! { [#(#outs),*] };
            counted(d, "Values", quote! { [f32; #nl] }, array, f.rows)
        }
        Shape::Tangent => {
            let m = p.outputs / 2;
            let part = |from: usize| {
                (0..n).map(move |i| {
                    if i < m {
                        let o = format_ident!("o{}", from + i);
                        quote! { #o }
                    } else {
                        quote! { 0.0 }
                    }
                })
            };
            let (values, derivatives) = (part(0), part(m));
            (
                quote! { ([#real; #nl], [#real; #nl]) },
                quote! { ([#(#values),*], [#(#derivatives),*]) },
            )
        }
        Shape::ScalarTangent => (quote! { (#real, #real) }, quote! { (o0, o1) }),
        Shape::State => {
            let ql = Literal::usize_unsuffixed(q);
            let q_outs = (0..q).map(|i| format_ident!("o{i}"));
            let v_outs = (q..q + n).map(|i| format_ident!("o{i}"));
            (
                quote! { ([#real; #ql], [#real; #nl]) },
                quote! { ([#(#q_outs),*], [#(#v_outs),*]) },
            )
        }
    };
    let steps = &d.plan.function(&name).call;
    function(d, &name, &doc, p, steps, inputs, ret, result)
}

/// P of a wall evaluated at run time from the generated G and B by the
/// runtime's fixed-size factorisations (NaN where B loses rank, as a closed
/// form would divide by zero there), and the collision map the same way
/// where the derivation has no program for it.
fn structured_fns(d: &Ctx, w: &WallDerivation) -> TokenStream {
    let (q, n) = dims(d);
    let (ql, nl) = (Literal::usize_unsuffixed(q), Literal::usize_unsuffixed(n));
    let name = &w.name;
    let projector = format_ident!("{name}_projector");
    let collide = format_ident!("{name}_collide");
    let rows = format_ident!("{name}_b_rows");
    let p_doc = doc_attr(&format!(
        "Wall `{name}`: the projector P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B, solved at run time from G and B (structured evaluation)."
    ));
    let c_doc = doc_attr(&format!(
        "Wall `{name}`: the collision map v⁺ = v⁻ − 2G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹Bv⁻, solved at run time from G and B (structured evaluation)."
    ));
    let collide_fn = w.collision.is_none().then(|| {
        quote! {
            #c_doc
            #[inline]
            pub fn #collide(&self, q: &[f64; #ql], v: &[f64; #nl]) -> [f64; #nl] {
                let b = self.#rows(q);
                let r = b.apply(v);
                match ::dalembert_runtime::__private::correction(&self.mass_matrix(q), b.as_slice(), r.as_slice()) {
                    Ok(d) => ::core::array::from_fn(|i| v[i] - 2.0 * d[i]),
                    Err(_) => [f64::NAN; #nl],
                }
            }
        }
    });
    quote! {
        #p_doc
        #[inline]
        pub fn #projector(&self, q: &[f64; #ql]) -> [[f64; #nl]; #nl] {
            let b = self.#rows(q);
            ::dalembert_runtime::__private::projector(&self.mass_matrix(q), b.as_slice())
                .unwrap_or([[f64::NAN; #nl]; #nl])
        }
        #collide_fn
    }
}

pub(super) fn dims(d: &Ctx) -> (usize, usize) {
    (d.model.coordinates.len(), d.model.velocities.len())
}

/// The arguments `inputs` lists (`Inputs::arrays`), each `name: &[T; len]`,
/// after `&self`.
fn args(d: &Ctx, inputs: Inputs) -> TokenStream {
    let (q, n) = dims(d);
    let real = real(d);
    let args = inputs.arrays().iter().map(|a| {
        let name = format_ident!("{}", a.name());
        let len = Literal::usize_unsuffixed(a.len(d.model.params.len(), q, n));
        quote! { , #name: &[#real; #len] }
    });
    quote! { #( #args )* }
}

/// An emitted method: doc, `#[inline]`, the arguments, the program's
/// per-call statements (`steps`, the plan's for it), then `result` of type
/// `ret`.
#[allow(clippy::too_many_arguments)]
fn function(
    d: &Ctx,
    name: &str,
    doc: &str,
    p: &Program,
    steps: &[Step],
    inputs: Inputs,
    ret: TokenStream,
    result: TokenStream,
) -> TokenStream {
    let f = ident(name);
    let args = args(d, inputs);
    let body = body::statements(d, p, steps, inputs, Place::Call);
    let doc = doc_attr(doc);
    // Over intervals the `let`s have no type, and clippy then calls the
    // last one before its return needless.
    let (interval, allow) = if d.bounds {
        (
            quote! { #[allow(unused_imports)] use ::dalembert_runtime::interval::Interval; },
            quote! { #[allow(unused_variables, clippy::approx_constant, clippy::let_and_return)] },
        )
    } else {
        (
            TokenStream::new(),
            quote! { #[allow(unused_variables, clippy::approx_constant)] },
        )
    };
    quote! {
        #doc
        #[inline]
        #allow
        pub fn #f(&self #args) -> #ret { #interval #body #result }
    }
}

/// `o0, o1, …` for the program's outputs, then `zero` up to n entries.
fn padded_outputs(
    p: &Program,
    n: usize,
    zero: TokenStream,
) -> impl Iterator<Item = TokenStream> + '_ {
    (0..n).map(move |i| {
        if i < p.outputs {
            let o = format_ident!("o{i}");
            quote! { #o }
        } else {
            zero.clone()
        }
    })
}

/// Return type and value of `k` rows or values in use out of `array`: the
/// runtime's `Rows`/`Values` (`runtime`) in f64, `(array, k)` in f32.
fn counted(
    d: &Ctx,
    runtime: &str,
    f32_type: TokenStream,
    array: TokenStream,
    k: usize,
) -> (TokenStream, TokenStream) {
    let n = Literal::usize_unsuffixed(d.model.velocities.len());
    let k = Literal::usize_unsuffixed(k);
    let runtime = format_ident!("{runtime}");
    match d.scalar {
        Scalar::F64 => (
            quote! { ::dalembert_runtime::#runtime<#n> },
            quote! { ::dalembert_runtime::#runtime::new(#array, #k) },
        ),
        Scalar::F32 => (quote! { (#f32_type, usize) }, quote! { (#array, #k) }),
    }
}
