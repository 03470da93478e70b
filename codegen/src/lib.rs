//! dalembert's generator: a model file to specialised, allocation-free Rust.
//!
//! The pipeline has visible stages:
//!
//! 1. [`ir`]: the model file (TOML) to a validated [`ir::Model`], every error
//!    collected with file:line:col;
//! 2. [`mod@derive`]: G, A, each wall's B, P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B and the
//!    collision map (I − 2P)v, derived exactly in named passes, the paper's
//!    hypotheses checked, and each emitted function optimised into a
//!    straight-line [`program::Program`]; the result is plain data;
//! 3. [`plan`]: the middle end, done once for both back ends: each function
//!    split into per-call and once-per-parameter-set work, every
//!    instruction in machine form ([`program::machine`]), the Taylor
//!    transforms chosen;
//! 4. [`emit`]: the plan as Rust tokens, formatted with prettyplease, for the
//!    [`emit::Options`] asked for (f64 or f32); or [`interpret`]: the plan
//!    run by a register machine behind the runtime's traits.
//!
//! Between the stages: [`quantity`], the table of emitted functions that
//! stages 2 to 4 share, [`program`] and [`diag`]; below them all,
//! [`function`], the language's functions, one file each, with every rule
//! each stage needs of them. No stage imports a later one.
//!
//! Front ends: [`compile_dir`] for build scripts (see the workspace's
//! `build.rs`), [`generate`] and [`fn@derive`] for the CLI and for tests.
//!
//! The symbolic engine (symbolica) is used only inside [`mod@derive`], only at
//! build time, and only by one thread of one process at a time ([`lock`]).

pub mod derive;
pub mod diag;
pub mod emit;
pub mod function;
pub mod interpret;
pub mod ir;
pub mod lock;
pub mod plan;
pub mod program;
pub mod quantity;
pub mod reference;

use std::path::{Path, PathBuf};

pub use derive::Derivation;
pub use diag::{Diagnostic, ErrorKind, ModelErrors};
pub use emit::{Options, Scalar};

/// Validates and derives the model in `path`.
pub fn derive(path: &Path) -> Result<Derivation, ModelErrors> {
    let model = ir::load(path)?;
    derive::derive(&model)
}

/// The formatted Rust source for the model in `path` (f64).
pub fn generate(path: &Path) -> Result<String, ModelErrors> {
    generate_with(path, Options::default())
}

/// The formatted Rust source for the model in `path`, emitted as `options`
/// say. f32 needs a closed-form P for every wall (structured evaluation
/// uses the runtime's f64 numerics).
pub fn generate_with(path: &Path, options: Options) -> Result<String, ModelErrors> {
    let d = derive(path)?;
    emittable(&d, options)?;
    Ok(emit::file(&d, options))
}

/// Most instructions the generated functions of one model may have
/// together. rustc's time grows about as the square of the code's size: a
/// model whose G has every entry non-zero (T = ½m|q̇|² + ½k(Σ cos qᵢ q̇ᵢ)²)
/// writes 7 300 instructions for 20 coordinates, which a debug build
/// compiles in 2.6 s; 36 900 for 40 coordinates, 25 s and 0.7 GB; 104 900
/// (7.1 MB of Rust) for 60 coordinates, 214 s and 1.7 GB (`rustc -C
/// opt-level=0`; with `-C opt-level=3`, 271 s and 3.4 GB; 2026-12-05).
/// This bound, about 48 such coordinates, keeps a debug build near a minute.
pub const MAX_GENERATED_INSTRUCTIONS: usize = 60_000;

/// That `d` can be emitted as `options` say, or the located reason why not:
/// f32 needs a closed-form P and constants within its range, and the code
/// must stay within [`MAX_GENERATED_INSTRUCTIONS`].
fn emittable(d: &Derivation, options: Options) -> Result<(), ModelErrors> {
    let refuse = |kind: ErrorKind, span: Option<std::ops::Range<usize>>| {
        let mut cx = diag::Collector::new(&d.model.file, &d.model.source);
        let e = cx.error(kind, span);
        cx.conclude::<()>(Err(e))
    };
    let functions = || {
        let model = d
            .functions
            .iter()
            .map(|f| (f, &d.model.kinetic_energy.span));
        let walls = (d.walls.iter().zip(&d.model.walls))
            .flat_map(|(w, declared)| w.functions.iter().map(|f| (f, &declared.span)));
        model.chain(walls)
    };
    let total: usize = functions().map(|(f, _)| f.program.instrs.len()).sum();
    if total > MAX_GENERATED_INSTRUCTIONS {
        let (largest, span) = functions()
            .max_by_key(|(f, _)| f.program.instrs.len())
            .expect("code that large has functions");
        return refuse(
            ErrorKind::Limit(format!(
                "the generated code would have {total} instructions, more than the {MAX_GENERATED_INSTRUCTIONS} a model's generated Rust may have (rustc's time grows about as the square of the code's size: a minute for a debug build at the bound); the largest function, `{}`, has {}. Fewer coordinates, or a G with fewer non-zero entries, make less code",
                largest.quantity.spec().name,
                largest.program.instrs.len()
            )),
            Some(span.clone()),
        );
    }
    if options.scalar == Scalar::F32 {
        if let Some(w) = d.walls.iter().find(|w| w.structured()) {
            return refuse(
                ErrorKind::Structure(format!(
                    "f32 generation needs a closed-form P, and wall `{}` is structured: set `projector = \"symbolic\"` under [model]",
                    w.name
                )),
                None,
            );
        }
        let too_large =
            functions().find(|(f, _)| f.program.consts.iter().any(|c| c.abs() > f32::MAX as f64));
        if let Some((f, span)) = too_large {
            return refuse(
                ErrorKind::Limit(format!(
                    "a constant of `{}` exceeds f32's range (about 3.4e38): generate f64 code",
                    f.quantity.spec().name
                )),
                Some(span.clone()),
            );
        }
    }
    Ok(())
}

/// The formatted Rust source for the model in `path` with `f32` arithmetic
/// (for microcontrollers without double-precision hardware): the model's
/// inherent functions, without the f64 `Model` trait.
pub fn generate_f32(path: &Path) -> Result<String, ModelErrors> {
    generate_with(
        path,
        Options {
            scalar: Scalar::F32,
        },
    )
}

/// One model's generated file and what it took to make it.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The model file.
    pub model_file: PathBuf,
    /// The written Rust file.
    pub rust_file: PathBuf,
    /// The model's type name.
    pub type_name: String,
    /// Number of coordinates.
    pub q: usize,
    /// Number of velocity components.
    pub n: usize,
}

/// A model's code not generated: `why`, reported at the model file.
fn generation_error(model_file: &Path, why: String) -> ModelErrors {
    let mut cx = diag::Collector::new(model_file, "");
    cx.error(ErrorKind::Generation(why), None);
    cx.into_errors()
}

/// Generates every `*.toml` model in `models_dir` into `out_dir` (one file per
/// model plus `models.rs`, which includes them all), in this process, in
/// name order. Errors of every model are collected before returning.
///
/// Each model's file is the one [`generate`] writes for it alone: a
/// model's programs do not depend on what the process derived before
/// (`derive/evaluate.rs` says how; `tests/reproducible.rs` derives the
/// built-in models in several orders in one process).
pub fn compile_dir(models_dir: &Path, out_dir: &Path) -> Result<Vec<Generated>, Vec<ModelErrors>> {
    let mut files: Vec<PathBuf> = match std::fs::read_dir(models_dir) {
        Ok(rd) => rd
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect(),
        Err(e) => {
            let mut cx = diag::Collector::new(models_dir, "");
            cx.error(ErrorKind::Io(e.to_string()), None);
            return Err(vec![cx.into_errors()]);
        }
    };
    files.sort();
    let mut done = Vec::new();
    let mut errors = Vec::new();
    for file in files {
        let model = match ir::load(&file) {
            Ok(m) => m,
            Err(e) => {
                errors.push(e);
                continue;
            }
        };
        let generated = Generated {
            rust_file: out_dir.join(format!("{}.rs", model.name)),
            model_file: file,
            type_name: model.type_name(),
            q: model.coordinates.len(),
            n: model.velocities.len(),
        };
        let written = derive::derive(&model)
            .and_then(|d| emittable(&d, Options::default()).map(|()| d))
            .and_then(|d| {
                let code = emit::file(&d, Options::default());
                std::fs::write(&generated.rust_file, code).map_err(|e| {
                    let file = generated.rust_file.display();
                    generation_error(&generated.model_file, format!("{file}: {e}"))
                })
            });
        match written {
            Ok(()) => done.push(generated),
            Err(e) => errors.push(e),
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    done.sort_by(|a, b| a.model_file.cmp(&b.model_file));
    let index = emit::index(&done);
    let index_file = out_dir.join("models.rs");
    if let Err(e) = std::fs::write(&index_file, index) {
        let why = format!("{}: {e}", index_file.display());
        return Err(vec![generation_error(models_dir, why)]);
    }
    Ok(done)
}
