//! The runtime's capability traits for the model: `Model` and `Walls`
//! always, `Dynamics` and `Surfaces` for a model with coordinates; the
//! names and parameters, and one forwarding method per row of the quantity
//! table that has one (per-wall rows dispatch on the wall).

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::functions::dims;
use super::{Ctx, ident};
use crate::ir::{Kind, camel};
use crate::program::Transform;
use crate::quantity::{Array, Capability, Forward, Shape, Spec, TABLE};
use dalembert_runtime::taylor::Work;

pub(super) fn trait_impl(d: &Ctx) -> TokenStream {
    let ty = format_ident!("{}", d.model.type_name());
    let (q, n) = dims(d);
    let ql = Literal::usize_unsuffixed(q);
    let nl = Literal::usize_unsuffixed(n);
    let variants: Vec<Ident> = d
        .derivation
        .walls
        .iter()
        .map(|w| format_ident!("{}", camel(&w.name)))
        .collect();
    let wall_names: Vec<&String> = d.derivation.walls.iter().map(|w| &w.name).collect();
    let pidents: Vec<Ident> = d.model.params.iter().map(|p| ident(&p.name)).collect();
    let pidx: Vec<Literal> = (0..pidents.len()).map(Literal::usize_unsuffixed).collect();
    let methods = |c: Capability| {
        TABLE
            .iter()
            .filter(move |spec| spec.capability == c)
            .filter_map(|spec| forward(d, spec, &variants))
            .collect::<Vec<_>>()
    };
    let (model, walls) = (methods(Capability::Model), methods(Capability::Walls));
    // A model without walls has an empty `Wall`: every per-wall method is
    // `match wall {}`, which never reads its other arguments.
    let no_walls = variants
        .is_empty()
        .then(|| quote! { #[allow(unused_variables, unreachable_code)] });
    let model_impl = quote! {
        impl ::dalembert_runtime::Model<#ql, #nl> for #ty {
            fn name(&self) -> &str { Self::NAME }
            fn coordinate_names(&self) -> &[&str] { Self::COORDINATES }
            fn velocity_names(&self) -> &[&str] { Self::VELOCITIES }
            fn parameter_names(&self) -> &[&str] { Self::PARAMETERS }
            fn parameter(&self, index: usize) -> Option<f64> {
                match index { #(#pidx => Some(self.params.#pidents),)* _ => None }
            }
            fn set_parameter(&mut self, index: usize, value: f64) -> bool {
                match index {
                    #(#pidx => { self.params.#pidents = value; self.pre = Self::precompute(&self.params); true })*
                    _ => false
                }
            }
            #( #model )*
        }
        impl ::dalembert_runtime::FromParams for #ty {
            type Params = Params;
            fn with_params(params: Params) -> Self { Self::new(params) }
            fn params(&self) -> &Params { &self.params }
        }
        #no_walls
        impl ::dalembert_runtime::Walls<#ql, #nl> for #ty {
            type Wall = Wall;
            fn walls(&self) -> &[Wall] { Self::WALLS }
            fn wall_name(&self, wall: Wall) -> &str {
                match wall { #(Wall::#variants => #wall_names,)* }
            }
            #( #walls )*
        }
    };
    if d.model.kind == Kind::Instantaneous {
        return model_impl;
    }
    let (dynamics, surfaces) = (methods(Capability::Dynamics), methods(Capability::Surfaces));
    let (motion_series, surface_series) = match d.series() {
        Some((motion, walls)) => {
            let work = |w: Work| {
                let (o, c) = (
                    Literal::usize_unsuffixed(w.operations),
                    Literal::usize_unsuffixed(w.convolutions),
                );
                quote! { ::dalembert_runtime::taylor::Work { operations: #o, convolutions: #c } }
            };
            let motion_work = work(motion.work());
            let walls_work = work(walls.iter().map(Transform::work).sum());
            let variational = d.plan.variational.as_ref().map(|_| {
                quote! {
                    #[inline]
                    fn variational_series(
                        &self,
                        series: &::dalembert_runtime::taylor::Series<#nl>,
                        columns: &mut [::dalembert_runtime::taylor::Series<#nl>],
                    ) -> bool {
                        self.tangent_series(series, columns);
                        true
                    }
                }
            });
            let arms = d.derivation.walls.iter().zip(&variants).map(|(w, v)| {
                let f = format_ident!("{}_surface_series", w.name);
                quote! { Wall::#v => self.#f(series, scratch, out) }
            });
            (
                quote! {
                    type SeriesScratch = SeriesScratch;
                    #[inline]
                    fn taylor_series(
                        &self,
                        series: &mut ::dalembert_runtime::taylor::Series<#nl>,
                        scratch: &mut SeriesScratch,
                        order: usize,
                    ) -> bool {
                        self.motion_series(series, scratch, order);
                        true
                    }
                },
                quote! {
                    #[inline]
                    fn surface_series(
                        &self,
                        wall: Wall,
                        series: &::dalembert_runtime::taylor::Series<#nl>,
                        scratch: &mut SeriesScratch,
                        out: &mut ::dalembert_runtime::taylor::Coefficients,
                    ) -> bool {
                        match wall { #(#arms,)* }
                        true
                    }
                    #variational
                    #[inline]
                    fn series_work(&self) -> Option<::dalembert_runtime::taylor::SeriesWork> {
                        Some(::dalembert_runtime::taylor::SeriesWork {
                            motion: #motion_work,
                            walls: #walls_work,
                        })
                    }
                },
            )
        }
        None => (quote! { type SeriesScratch = (); }, TokenStream::new()),
    };
    let series_impl = quote! {
        #no_walls
        impl ::dalembert_runtime::TaylorSeries<#nl> for #ty {
            #motion_series
            #surface_series
        }
    };
    let bound = |what: &str| {
        let arms = d.derivation.walls.iter().zip(&variants).map(|(w, v)| {
            let f = format_ident!("{}_{what}_bounds", w.name);
            quote! { Wall::#v => Some(self.#f(q)) }
        });
        quote! { match wall { #(#arms,)* } }
    };
    let (surface_bounds, normal_bounds) = (bound("surface"), bound("normal"));
    let interval = quote! { ::dalembert_runtime::interval::Interval };
    let start_rate_names = (!d.model.start_rates.is_empty())
        .then(|| quote! { fn start_rate_names(&self) -> &[&str] { Self::START_RATES } });
    quote! {
        #model_impl
        impl ::dalembert_runtime::Dynamics<#nl> for #ty {
            fn initial_coordinates(&self) -> [f64; #ql] { self.initial_state().0 }
            fn initial_velocities(&self) -> [f64; #nl] { self.initial_state().1 }
            fn initial_velocities_given(&self) -> [bool; #nl] { Self::VELOCITIES_GIVEN }
            #start_rate_names
            #( #dynamics )*
        }
        #no_walls
        impl ::dalembert_runtime::Surfaces<#nl> for #ty {
            #( #surfaces )*
            #[inline]
            fn surface_bounds(&self, wall: Wall, q: &[#interval; #nl]) -> Option<#interval> {
                #surface_bounds
            }
            #[inline]
            fn normal_bounds(&self, wall: Wall, q: &[#interval; #nl]) -> Option<[#interval; #nl]> {
                #normal_bounds
            }
        }
        #series_impl
    }
}

/// The trait method of one table row, forwarding to the inherent function
/// (`None` when the row has no method, or the model lacks the function).
fn forward(d: &Ctx, spec: &Spec, variants: &[Ident]) -> Option<TokenStream> {
    let (method, wrap) = spec.method?;
    let (q, n) = dims(d);
    let (ql, nl) = (Literal::usize_unsuffixed(q), Literal::usize_unsuffixed(n));
    let method = format_ident!("{method}");
    // The trait takes a direction of the parameters as a slice (its
    // length is the model's); a slice of another length has no derivative.
    let np = d.model.params.len();
    let arrays = spec.inputs.arrays();
    let names = arrays.iter().map(|a| format_ident!("{}", a.name()));
    let args = quote! { #( #names ),* };
    let params = arrays.iter().map(|a| {
        let name = format_ident!("{}", a.name());
        match a {
            Array::Dp => quote! { #name: &[f64] },
            _ => {
                let len = Literal::usize_unsuffixed(a.len(np, q, n));
                quote! { #name: &[f64; #len] }
            }
        }
    });
    let params = quote! { #( #params ),* };
    let convert = arrays.contains(&Array::Dp).then(|| {
        let npl = Literal::usize_unsuffixed(np);
        quote! {
            let Ok(dp) = <&[f64; #npl]>::try_from(dp) else {
                return None;
            };
        }
    });
    let wrapped = |call: TokenStream| match wrap {
        Forward::Plain => call,
        Forward::Some => quote! { Some(#call) },
    };
    let ty = match spec.shape {
        Shape::Scalar => quote! { f64 },
        Shape::Vector => quote! { [f64; #nl] },
        Shape::Matrix => quote! { [[f64; #nl]; #nl] },
        Shape::Rows => quote! { ::dalembert_runtime::Rows<#nl> },
        Shape::Values => quote! { ::dalembert_runtime::Values<#nl> },
        Shape::State => quote! { ([f64; #ql], [f64; #nl]) },
        Shape::Tangent => quote! { ([f64; #nl], [f64; #nl]) },
        Shape::ScalarTangent => quote! { (f64, f64) },
    };
    let ret = match wrap {
        Forward::Plain => ty,
        Forward::Some => quote! { Option<#ty> },
    };
    let (params, value) = if !spec.capability.per_wall() {
        d.derivation.function(spec.quantity)?;
        let f = format_ident!("{}", spec.name);
        (params, wrapped(quote! { self.#f(#args) }))
    } else {
        // A wall without the function (a collision map solved at run
        // time has no tangent program) answers `None`; where no wall has
        // it, the trait's default does.
        let none = d
            .derivation
            .walls
            .iter()
            .all(|w| w.function(spec.quantity).is_none());
        if none && matches!(wrap, Forward::Some) {
            return None;
        }
        let arms = d.derivation.walls.iter().zip(variants).map(|(w, v)| {
            let f = format_ident!("{}_{}", w.name, spec.name);
            let value = match (w.function(spec.quantity), wrap) {
                (None, Forward::Some) => quote! { None },
                _ => wrapped(quote! { self.#f(#args) }),
            };
            quote! { Wall::#v => #value }
        });
        (
            quote! { wall: Wall, #params },
            quote! { match wall { #(#arms,)* } },
        )
    };
    Some(quote! {
        #[inline]
        fn #method(&self, #params) -> #ret { #convert #value }
    })
}
