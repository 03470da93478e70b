//! What the commands that run a model share: the model named on the
//! command line (built-in and compiled, or a model file derived now and
//! interpreted), the integrator's options and their checks, and the
//! starting state with `--set` applied.

use std::path::Path;

use clap::{Args, ValueEnum};
use dalembert::for_each_model;
use dalembert::models::*;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    DormandPrince, Integrator, Residual, Rk4, Settings, StartRule, State, Taylor, onto_holonomic,
    residual, starting_velocity_with,
};
use dalembert::runtime::taylor::MAX_ORDER;
use dalembert_codegen::Derivation;
use dalembert_codegen::interpret::Interpreted;

/// The integration method.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Method {
    /// Adaptive Dormand–Prince 5(4) (`--rtol`, `--atol`).
    DormandPrince,
    /// Classical Runge–Kutta with a fixed step (`--step`).
    Rk4,
    /// Taylor's method on the model's generated series, collisions found on
    /// the step's polynomial (`--tolerance`).
    Taylor,
}

/// A model and how to run it: what `simulate` and `periodic` share.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// A model file (`path/to/model.toml`) or a built-in model with
    /// coordinates (listed below).
    #[arg(long_help = models_help())]
    pub model: String,
    /// Integration method.
    #[arg(long, value_enum, default_value_t = Method::DormandPrince)]
    pub integrator: Method,
    /// Step of the fixed-step method.
    #[arg(long, allow_hyphen_values = true, default_value_t = 1e-3)]
    pub step: f64,
    /// Relative tolerance of the adaptive method.
    #[arg(long, allow_hyphen_values = true, default_value_t = 1e-10)]
    pub rtol: f64,
    /// Absolute tolerance of the adaptive method.
    #[arg(long, allow_hyphen_values = true, default_value_t = 1e-12)]
    pub atol: f64,
    /// Tolerance of Taylor's method, from 1e-26 to below 1: absolute where
    /// the state's largest component is below 1 in size, relative above
    /// (default: the unit roundoff of f64, 2^-53).
    #[arg(long, allow_hyphen_values = true)]
    pub tolerance: Option<f64>,
    /// A fixed order for Taylor's method (2 to 31; default: the one that
    /// costs least per unit of time by the model's series work, at least
    /// the tolerance's, 20 at 2^-53). Above the tolerance's order the steps
    /// are longer, where the radius of convergence bounds them.
    #[arg(long, allow_hyphen_values = true)]
    pub order: Option<usize>,
    /// NAME=VALUE for a parameter, a coordinate or a velocity (repeatable);
    /// the rest come from the model file (`[parameters]`, `[initial]`).
    #[arg(long = "set", value_name = "NAME=VALUE", value_parser = assignment)]
    pub set: Vec<(String, f64)>,
}

/// The built-in models with coordinates, for `--help`.
fn models_help() -> String {
    let mut names: Vec<&str> = Vec::new();
    macro_rules! with_coordinates {
        ($module:ident, $ty:ident, 0, $n:literal) => {};
        ($module:ident, $ty:ident, $q:literal, $n:literal) => {
            names.push(stringify!($module));
        };
    }
    for_each_model!(with_coordinates);
    format!(
        "A model file (a path ending in `.toml`: derived and interpreted at once, no Rust \
         to write), or a built-in model with coordinates (compiled): {}",
        names.join(", ")
    )
}

fn assignment(s: &str) -> Result<(String, f64), String> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}`: write NAME=VALUE"))?;
    let value: f64 = value
        .trim()
        .parse()
        .map_err(|_| format!("`{value}` is not a number"))?;
    if !value.is_finite() {
        return Err(format!("`{value}` is not finite"));
    }
    Ok((name.trim().to_string(), value))
}

/// What a command does with the model it names, once its size is known.
pub trait WithModel {
    /// The command's result.
    type Output;
    /// Runs on `model`, whose derived parameters are `derived`.
    fn with<M: TaylorSeries<N>, const N: usize>(
        self,
        model: M,
        derived: &[String],
    ) -> Result<Self::Output, String>;
}

/// Hands the model `name` names to `command`: a built-in model with
/// coordinates (compiled), or a model file (derived now, its programs
/// interpreted, [`dalembert_codegen::interpret`]). `what` says what an
/// instantaneous model has none of, for the error.
pub fn with_model<C: WithModel>(name: &str, what: &str, command: C) -> Result<C::Output, String> {
    if is_model_file(name) {
        return with_model_file(name, what, command);
    }
    let mut known = Vec::new();
    macro_rules! dispatch {
        ($module:ident, $ty:ident, 0, $n:literal) => {
            if name == stringify!($module) {
                return Err(format!(
                    "`{name}` is an instantaneous model (velocities at the collision instant only): \
                     it has no {what}; its counterparts in coordinates are \
                     ball_wall_euler (§3.1) and ball_bounce (§3.2)"
                ));
            }
        };
        ($module:ident, $ty:ident, $q:literal, $n:literal) => {
            if name == stringify!($module) {
                return command.with::<$ty, $q>(<$ty>::with_params(Default::default()), &[]);
            }
            known.push(stringify!($module));
        };
    }
    for_each_model!(dispatch);
    Err(format!(
        "no built-in model `{name}` (and no model file of that name); models with coordinates: {}",
        known.join(", ")
    ))
}

/// Whether the MODEL argument names a file rather than a built-in model:
/// a path ending in `.toml`, or an existing file.
fn is_model_file(model: &str) -> bool {
    model.ends_with(".toml") || Path::new(model).is_file()
}

/// Most velocity components of a model file the CLI interprets: its
/// simulator is compiled once for each size up to this.
pub const MAX_INTERPRETED: usize = 16;

/// A model file derived now and its programs interpreted by the same
/// simulator as the built-in models.
fn with_model_file<C: WithModel>(name: &str, what: &str, command: C) -> Result<C::Output, String> {
    let path = Path::new(name);
    if !path.is_file() {
        return Err(format!("no model file {}", path.display()));
    }
    let d: Derivation = crate::derive(path)?;
    let n = d.model.velocities.len();
    macro_rules! sizes {
        ($($n:literal)*) => {
            match n {
                $($n => {
                    let model = Interpreted::<$n>::new(&d).map_err(|e| e.to_string())?;
                    command.with::<Interpreted<$n>, $n>(model, &d.model.derived)
                })*
                _ => Err(format!(
                    "`{}` has {n} velocities; the CLI interprets models of 1 to {MAX_INTERPRETED}: generate its Rust code (`dalembert generate`) and use it from a crate",
                    d.model.name
                )),
            }
        };
    }
    if d.model.coordinates.is_empty() {
        return Err(format!(
            "`{}` is an instantaneous model (velocities at the collision instant only): it has no {what}",
            d.model.name
        ));
    }
    sizes!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16)
}

/// Most fixed steps a run may take (about 100 s of RK4 on a small model).
const MAX_STEPS: f64 = 1e9;

/// `Ok` where `x` is positive and finite, else an error naming `name`.
pub fn positive(name: &str, x: f64) -> Result<(), String> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(format!(
            "{name} must be a positive finite number (got {x:?})"
        ))
    }
}

/// The integrator's settings checked, for a run of at most `span` in
/// time (given as `flag`).
pub fn checked_run(args: &RunArgs, flag: &str, span: f64) -> Result<(), String> {
    if !matches!(args.integrator, Method::Taylor) {
        for (flag, given) in [
            ("--tolerance", args.tolerance.is_some()),
            ("--order", args.order.is_some()),
        ] {
            if given {
                return Err(format!("{flag} applies to --integrator taylor only"));
            }
        }
    }
    match args.integrator {
        Method::Rk4 => {
            positive("--step", args.step)?;
            if span / args.step >= MAX_STEPS {
                return Err(format!(
                    "{flag} {span:?} with --step {:?} would take {:.1e} steps; the limit is {MAX_STEPS:.0e}",
                    args.step,
                    span / args.step
                ));
            }
        }
        Method::DormandPrince => {
            positive("--rtol", args.rtol)?;
            positive("--atol", args.atol)?;
        }
        Method::Taylor => {
            if let Some(tol) = args.tolerance
                && !(Taylor::MIN_TOLERANCE..1.0).contains(&tol)
            {
                return Err(format!(
                    "--tolerance must be from {:e} (the order it asks for is then {MAX_ORDER}) to below 1, not {tol:?}",
                    Taylor::MIN_TOLERANCE
                ));
            }
            if let Some(p) = args.order
                && !(2..=MAX_ORDER).contains(&p)
            {
                return Err(format!("--order must be from 2 to {MAX_ORDER}, not {p}"));
            }
            // Below the tolerance's own order the steps shrink fast (the
            // last two terms must fall below the tolerance): allowed, but
            // said, since a looser tolerance is what lowers the order well.
            if let (Some(p), Integrator::Taylor(t)) = (args.order, settings(args).integrator) {
                let own = Taylor {
                    fixed_order: None,
                    ..t
                }
                .order();
                if p < own {
                    eprintln!(
                        "note: --order {p} is below the order the tolerance asks for ({own}): the steps will be far shorter than at {own} (at order 2, about the tolerance over the speed); a looser --tolerance gives a lower order"
                    );
                }
            }
        }
    }
    Ok(())
}

/// The model with `--set` applied and the starting state: the file's
/// `[initial]` at the parameters in use (parameters are set first, so that
/// an initial value such as `z = "r"` follows `--set r=1`), then the
/// coordinates and velocities `--set` names; q on h(q) = 0, and the
/// velocities neither gives following from A q̇ = 0
/// ([`starting_velocity`]). Notes on how the velocities were completed go
/// to stderr.
pub fn start<M: Surfaces<N>, const N: usize>(
    set: &[(String, f64)],
    mut model: M,
    derived: &[String],
) -> Result<(M, State<N>, Residual), String> {
    set_parameters(set, &mut model, derived)?;
    let start = starting_state(set, &model, false)?;
    if let Some(note) = start.note {
        eprintln!("note: {note}");
    }
    Ok((model, start.state, start.residual))
}

/// Sets the parameters `set` names on `model`; an error for a name that is
/// a derived parameter or nothing of the model's.
fn set_parameters<M: Surfaces<N>, const N: usize>(
    set: &[(String, f64)],
    model: &mut M,
    derived: &[String],
) -> Result<(), String> {
    let is_state = |m: &M, name: &str| {
        m.coordinate_names().contains(&name)
            || m.velocity_names().contains(&name)
            || m.start_rate_names().contains(&name)
    };
    for (name, value) in set {
        if is_state(model, name) {
            continue;
        }
        if derived.contains(name) {
            return Err(format!(
                "`{name}` is a derived parameter of {} (its value is computed from other parameters): set those instead",
                model.name()
            ));
        } else if !model.set_parameter_named(name, *value) {
            let rates = model.start_rate_names();
            let rates = if rates.is_empty() {
                String::new()
            } else {
                format!(", or rate given at the start ({})", rates.join(", "))
            };
            return Err(format!(
                "`{name}` is not a parameter ({}), coordinate ({}) or velocity ({}){rates} of {}",
                model.parameter_names().join(", "),
                model.coordinate_names().join(", "),
                model.velocity_names().join(", "),
                model.name()
            ));
        }
    }
    Ok(())
}

/// A starting state and what was done to reach it.
pub struct Start<const N: usize> {
    pub state: State<N>,
    /// Its residuals.
    pub residual: Residual,
    /// How the velocities were completed or projected, where they were.
    pub note: Option<String>,
    /// Whether the coordinates were moved onto h(q) = 0.
    pub moved: bool,
}

/// The starting state at `model`'s parameters with the coordinates and
/// velocities `set` names (see [`start`]). Coordinates off h(q) = 0 are an
/// error, or with `nearest` moved to the nearest point on it
/// ([`onto_holonomic`]).
pub fn starting_state<M: Surfaces<N>, const N: usize>(
    set: &[(String, f64)],
    model: &M,
    nearest: bool,
) -> Result<Start<N>, String> {
    let mut q = model.initial_coordinates();
    let mut v = model.initial_velocities();
    let mut given = model.initial_velocities_given();
    let rate_names = model.start_rate_names();
    let mut rates = model.start_values().as_slice().to_vec();
    for (name, value) in set {
        if let Some(i) = model.coordinate_names().iter().position(|c| c == name) {
            q[i] = *value;
        } else if let Some(i) = model.velocity_names().iter().position(|c| c == name) {
            v[i] = *value;
            given[i] = true;
        } else if let Some(r) =
            (rate_names.iter().position(|c| c == name)).and_then(|i| rates.get_mut(i))
        {
            *r = *value;
        }
    }
    let rates = &rates[..];
    let mut moved = false;
    let position = residual(model, &q, &v).position;
    if position > 1e-8 && nearest {
        q = onto_holonomic(model, &q).map_err(|e| {
            format!("the initial coordinates cannot be moved onto the holonomic constraints: {e:?}")
        })?;
        moved = true;
    } else if position > 1e-8 {
        return Err(format!(
            "the initial coordinates violate the holonomic constraints (|h(q)| = {position:e}): set them on the constraint manifold"
        ));
    }
    let (projected, rule) = starting_velocity_with(model, &q, &v, &given, rates).map_err(|e| {
        format!("the initial velocity cannot be put on the constraints (A q̇ = 0): {e}")
    })?;
    let names = model.velocity_names();
    // "the constraints and ball_wz = 5", where rates are given.
    let stated_rates: Vec<String> = (rate_names.iter().zip(rates))
        .map(|(n, c)| format!("{n} = {c:e}"))
        .collect();
    let and_rates = if stated_rates.is_empty() {
        String::new()
    } else {
        format!(" and {}", stated_rates.join(", "))
    };
    let note = match rule {
        StartRule::Completed => {
            let followed: Vec<String> = (0..N)
                .filter(|i| !given[*i] && projected[*i] != 0.0)
                .map(|i| format!("{} = {:e}", names[i], projected[i]))
                .collect();
            (!followed.is_empty()).then(|| {
                format!(
                    "the velocities the start does not give follow from the constraints{and_rates}: {}",
                    followed.join(", ")
                )
            })
        }
        StartRule::Projected => {
            let stated: Vec<f64> = (0..N).map(|i| if given[i] { v[i] } else { 0.0 }).collect();
            Some(format!(
                "the initial velocity {stated:?} is not admissible (A q̇ ≠ 0){and_rates}, and no choice of the velocities it does not give makes it so; using its G-orthogonal projection onto ker A{}, {projected:?}",
                if stated_rates.is_empty() {
                    ""
                } else {
                    " and those rates"
                }
            ))
        }
    };
    // The residuals of the state the run starts from (its first row), not
    // of the velocity given before the projection.
    Ok(Start {
        state: State {
            t: 0.0,
            q,
            v: projected,
        },
        residual: residual(model, &q, &projected),
        note,
        moved,
    })
}

/// The simulator's settings from the command line.
pub fn settings(args: &RunArgs) -> Settings {
    let integrator = match args.integrator {
        Method::Rk4 => Integrator::Rk4(Rk4 { step: args.step }),
        Method::DormandPrince => Integrator::DormandPrince(DormandPrince {
            rtol: args.rtol,
            atol: args.atol,
            max_step: f64::INFINITY,
        }),
        Method::Taylor => Integrator::Taylor(Taylor {
            tolerance: args.tolerance.unwrap_or(Taylor::default().tolerance),
            fixed_order: args.order,
            ..Taylor::default()
        }),
    };
    Settings {
        integrator,
        ..Settings::default()
    }
}
