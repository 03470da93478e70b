//! `dalembert simulate`: runs the hybrid simulator on a built-in model
//! (compiled) or on a model file (derived now and interpreted,
//! [`dalembert_codegen::interpret`]) and writes the trajectory as CSV and an
//! SVG plot.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use dalembert::for_each_model;
use dalembert::models::*;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    DormandPrince, Integrator, Residual, Rk4, Settings, SimError, Simulator, State, Taylor,
    Variational, admissible, residual,
};
use dalembert::runtime::taylor::MAX_ORDER;
use dalembert_codegen::Derivation;
use dalembert_codegen::interpret::Interpreted;
use indicatif::{ProgressBar, ProgressStyle};

use crate::plot::plot;

mod output;
pub(crate) mod sensitivity;
pub use output::Row;
use output::{MAX_ROWS, Output};

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

#[derive(Args, Debug)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub run: RunArgs,
    /// Simulate from t = 0 to this time.
    #[arg(long, allow_hyphen_values = true, default_value_t = 5.0)]
    pub t_end: f64,
    /// Time between output rows (default: t_end / 2000). Collisions are
    /// always written, before and after. With Taylor's method the rows come
    /// off the steps' polynomials; the other methods stop a step at each row.
    #[arg(long, allow_hyphen_values = true)]
    pub every: Option<f64>,
    /// Two coordinates to draw as the path, e.g. `x,z` (default: the first two).
    #[arg(long)]
    pub path: Option<String>,
    /// Directory for `<model>.csv` and `<model>.svg`.
    #[arg(long, default_value = "target/simulate")]
    pub out: PathBuf,
    /// Also follow Φ = ∂x(t)/∂x(0), x = (q, q̇), through the collisions
    /// (at `--rtol`) and report how the perturbation of every coordinate
    /// and velocity by the same amount, moved onto the directions the
    /// constraints allow, has grown at the end: |Φ δx₀|/|δx₀| and its rate
    /// ln(|Φ δx₀|/|δx₀|)/t (a finite-time Lyapunov estimate). Slower: Φ's
    /// 2N columns are integrated along every step.
    #[arg(long)]
    pub sensitivity: bool,
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
    fn with<M: Surfaces<N>, const N: usize>(
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

/// Runs `dalembert simulate`.
pub fn simulate(args: &SimulateArgs) -> Result<bool, String> {
    // Before a model file's derivation, which takes seconds.
    checked_spacing(args)?;
    struct Simulate<'a>(&'a SimulateArgs);
    impl WithModel for Simulate<'_> {
        type Output = bool;
        fn with<M: Surfaces<N>, const N: usize>(
            self,
            model: M,
            derived: &[String],
        ) -> Result<bool, String> {
            run(self.0, model, derived)
        }
    }
    with_model(&args.run.model, "motion to simulate", Simulate(args))
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

/// The run's settings checked before anything runs: finite, positive and
/// within bounds that keep time and output reasonable.
fn checked_spacing(args: &SimulateArgs) -> Result<f64, String> {
    positive("--t-end", args.t_end)?;
    let every = args.every.unwrap_or(args.t_end / 2000.0);
    positive("--every", every)?;
    if args.t_end / every > MAX_ROWS as f64 {
        return Err(format!(
            "--t-end {:?} with --every {every:?} would write {:.1e} rows; the limit is {MAX_ROWS:.0e}: raise --every",
            args.t_end,
            args.t_end / every
        ));
    }
    checked_run(&args.run, "--t-end", args.t_end)?;
    Ok(every)
}

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

/// Simulates `model` (whose derived parameters are `derived`) as `args` say.
fn run<M: Surfaces<N>, const N: usize>(
    args: &SimulateArgs,
    model: M,
    derived: &[String],
) -> Result<bool, String> {
    let every = checked_spacing(args)?;
    let path = path_axes(&model, args.path.as_deref())?;
    let (model, start, start_residual) = start(&args.run.set, model, derived)?;
    let e0 = model.energy(&start.q, &start.v);
    if !e0.is_finite() {
        return Err(format!(
            "the initial energy is {e0}: the initial state is out of range for f64"
        ));
    }
    let named = |e: SimError<M::Wall>| e.map_wall(|w| model.wall_name(w)).to_string();
    let mut sim = Simulator::new(&model, start, settings(&args.run)).map_err(named)?;
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("cannot create {}: {e}", args.out.display()))?;
    let csv = args.out.join(format!("{}.csv", model.name()));
    let svg = args.out.join(format!("{}.svg", model.name()));
    let mut out = Output::<N>::create(&model, &csv, e0)?;
    out.push(Row {
        t: 0.0,
        q: start.q,
        v: start.v,
        energy: e0,
        residual: [start_residual.velocity, start_residual.position],
        event: None,
    })?;
    // The output's bound, before a run that may be long.
    println!(
        "{}: writing {}: a row every {every} to t = {} ({} rows) and two per collision, at most {MAX_ROWS} rows",
        model.name(),
        csv.display(),
        args.t_end,
        // Rows at t = 0 and k·every up to t_end (a quotient a rounding
        // above a whole number is that number).
        (args.t_end / every * (1.0 - 1e-12)).ceil() as u64 + 1
    );
    let clock = Instant::now();
    let dense = matches!(args.run.integrator, Method::Taylor);
    let mut phi = args.sensitivity.then(|| Variational::new(args.run.rtol));
    let failure = integrate(
        &mut sim,
        &model,
        (args.t_end, every, dense),
        &mut out,
        phi.as_mut(),
    )?;
    let elapsed = clock.elapsed();
    out.finish()?;
    plot(&svg, &model, &out.kept, path, e0)?;
    summary(&sim, &model, args, &out, e0, elapsed.as_secs_f64());
    if let Some(phi) = &phi {
        sensitivity::report(&model, &start, sim.state().t, phi)?;
    }
    println!("  trajectory: {} ({} rows)", csv.display(), out.written);
    println!("  plot:       {}", svg.display());
    match failure {
        Some(e) => {
            println!("  stopped early: {e}");
            Ok(false)
        }
        None => Ok(true),
    }
}

/// The model with `--set` applied and the starting state: the file's
/// `[initial]` at the parameters in use (parameters are set first, so that
/// an initial value such as `z = "r"` follows `--set r=1`), then the
/// coordinates and velocities `--set` names; q on h(q) = 0, q̇ projected
/// onto ker A.
pub fn start<M: Surfaces<N>, const N: usize>(
    set: &[(String, f64)],
    mut model: M,
    derived: &[String],
) -> Result<(M, State<N>, Residual), String> {
    let is_state = |m: &M, name: &str| {
        m.coordinate_names().contains(&name) || m.velocity_names().contains(&name)
    };
    for (name, value) in set {
        if is_state(&model, name) {
            continue;
        }
        if derived.contains(name) {
            return Err(format!(
                "`{name}` is a derived parameter of {} (its value is computed from other parameters): set those instead",
                model.name()
            ));
        } else if !model.set_parameter_named(name, *value) {
            return Err(format!(
                "`{name}` is not a parameter ({}), coordinate ({}) or velocity ({}) of {}",
                model.parameter_names().join(", "),
                model.coordinate_names().join(", "),
                model.velocity_names().join(", "),
                model.name()
            ));
        }
    }
    let mut q = model.initial_coordinates();
    let mut v = model.initial_velocities();
    for (name, value) in set {
        if let Some(i) = model.coordinate_names().iter().position(|c| c == name) {
            q[i] = *value;
        } else if let Some(i) = model.velocity_names().iter().position(|c| c == name) {
            v[i] = *value;
        }
    }
    let position = residual(&model, &q, &v).position;
    if position > 1e-8 {
        return Err(format!(
            "the initial coordinates violate the holonomic constraints (|h(q)| = {position:e}): set them on the constraint manifold"
        ));
    }
    let projected = admissible(&model, &q, &v).map_err(|e| {
        format!("the initial velocity cannot be projected onto the constraints (A q̇ = 0): {e}")
    })?;
    if projected.iter().zip(&v).any(|(a, b)| (a - b).abs() > 1e-12) {
        eprintln!(
            "note: the initial velocity {v:?} is not admissible (A q̇ ≠ 0); using its G-orthogonal projection onto ker A, {projected:?}"
        );
    }
    // The residuals of the state the run starts from (its first row), not
    // of the velocity given before the projection.
    let start_residual = residual(&model, &q, &projected);
    let start = State {
        t: 0.0,
        q,
        v: projected,
    };
    Ok((model, start, start_residual))
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

/// Runs to `t_end`, a row every `every` and at each collision, with a
/// progress bar; the error that stopped it early, if any. With `dense` the
/// steps run on and the rows inside each are read off its dense output
/// ([`Simulator::state_at`]), so they cost no steps: for Taylor's method,
/// whose dense output is the step's own polynomial. Otherwise each step
/// stops at the next row: the Runge–Kutta interpolants are an order below
/// their steps (Dormand–Prince's rows on `chain_3` at the default
/// tolerances: 5e-8 energy error against 5e-10 at step ends).
fn integrate<'m, M: Surfaces<N>, const N: usize>(
    sim: &mut Simulator<'_, M, N>,
    model: &'m M,
    (t_end, every, dense): (f64, f64, bool),
    out: &mut Output<'m, N>,
    mut phi: Option<&mut Variational<N>>,
) -> Result<Option<String>, String> {
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template(
            "{msg} [{bar:40}] {percent}% ({elapsed} elapsed, ~{eta} left)",
        )
        .map_err(|e| e.to_string())?
        .progress_chars("=> "),
    );
    bar.set_message(format!("simulating {}", model.name()));
    // The next row on the grid is at k·every (t_end for the last).
    let mut k = 1.0;
    let grid = |k: f64| (k * every).min(t_end);
    let mut failure = None;
    while sim.state().t < t_end {
        let step = match sim.step(if dense { t_end } else { grid(k) }) {
            Ok(step) => step,
            Err(e) => {
                failure = Some(e.map_wall(|w| model.wall_name(w)).to_string());
                break;
            }
        };
        if let Some(phi) = phi.as_deref_mut()
            && let Err(e) = phi.follow(sim, &step)
        {
            failure = Some(sensitivity::failure(model, e));
            break;
        }
        // Rows strictly inside the step (before its collision, if any);
        // none where the step stopped at the next row.
        let stop = step.collision.as_ref().map_or(step.state.t, |c| c.t);
        while grid(k) < stop {
            let Some(s) = sim.state_at(grid(k)) else {
                break;
            };
            out.push(Row::of(model, s.t, s.q, s.v))?;
            k += 1.0;
        }
        if let Some(c) = &step.collision {
            // The state just before the collision, from its record.
            out.push(Row {
                event: Some(model.wall_name(c.wall)),
                ..Row::of(model, c.t, c.q, c.v_minus)
            })?;
        }
        let s = &step.state;
        let energy = step.energy(model);
        if !energy.is_finite() {
            failure = Some(format!("the energy became {energy} at t = {}", s.t));
        }
        let on_grid = s.t >= grid(k);
        if on_grid || step.collision.is_some() || failure.is_some() {
            out.push(Row::of(model, s.t, s.q, s.v))?;
        }
        if failure.is_some() {
            break;
        }
        if on_grid {
            k += 1.0;
        }
        bar.set_position((1000.0 * s.t / t_end) as u64);
    }
    bar.finish_and_clear();
    Ok(failure)
}

/// Steps, collisions, evaluations, time, energy drift and residuals.
fn summary<M: Surfaces<N>, const N: usize>(
    sim: &Simulator<'_, M, N>,
    model: &M,
    args: &SimulateArgs,
    out: &Output<'_, N>,
    e0: f64,
    secs: f64,
) {
    let stats = sim.stats();
    // Taylor's full order, and what the steps used: most flights end on a
    // lower-order trial's series, so the full order alone would overstate
    // the work (`Stats::series_orders` over the series computed, which are
    // the evaluations less the q̈ at the start).
    let order = sim.taylor_order().map_or(String::new(), |p| {
        let series = stats.evaluations.saturating_sub(1).max(1);
        format!(
            " at order {p} (series of mean order {:.1}; {} of {} steps on a lower-order trial)",
            stats.series_orders as f64 / series as f64,
            stats.low_order_steps,
            stats.steps
        )
    });
    println!(
        "{}: t = 0 → {} with {:?}{order}",
        model.name(),
        sim.state().t,
        args.run.integrator
    );
    println!(
        "  {} steps ({} rejected), {} collisions, {} evaluations of the equations of motion, in {:.3} s ({:.0} steps/s, {:.0} collisions/s, output included)",
        stats.steps,
        stats.rejected,
        stats.collisions,
        stats.evaluations,
        secs,
        stats.steps as f64 / secs,
        stats.collisions as f64 / secs
    );
    // A relative figure means nothing where E₀ = 0 (a system at rest at
    // zero potential, or one whose T and V cancel).
    let relative = if e0 == 0.0 {
        String::new()
    } else {
        format!(" (relative {:.2e})", out.drift / e0.abs())
    };
    println!(
        "  energy {e0:.12} at the start; largest |E − E₀| over the rows = {:.2e}{relative}",
        out.drift
    );
    println!(
        "  largest constraint residuals over the rows: |A q̇| = {:.2e}, |h(q)| = {:.2e}",
        out.worst[0], out.worst[1]
    );
}

/// Indices of the two coordinates drawn as the path.
fn path_axes<M: Surfaces<N>, const N: usize>(
    model: &M,
    spec: Option<&str>,
) -> Result<(usize, usize), String> {
    let names = model.coordinate_names();
    let find = |name: &str| {
        names.iter().position(|c| *c == name.trim()).ok_or_else(|| {
            format!(
                "--path: `{name}` is not a coordinate of {} ({})",
                model.name(),
                names.join(", ")
            )
        })
    };
    match spec {
        None => Ok((0, if N > 1 { 1 } else { 0 })),
        Some(s) => {
            let (a, b) = s
                .split_once(',')
                .ok_or_else(|| format!("--path `{s}`: write two coordinates, e.g. x,y"))?;
            Ok((find(a)?, find(b)?))
        }
    }
}
