//! `dalembert simulate`: runs the hybrid simulator on a built-in model
//! (compiled) or on a model file (derived now and interpreted,
//! [`dalembert_codegen::interpret`]) and writes the trajectory as CSV and an
//! SVG plot.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{SeriesRoom, SimError, Simulator};
use indicatif::{ProgressBar, ProgressStyle};

use crate::plot::plot;
use crate::run::{Method, RunArgs, WithModel, checked_run, positive, settings, start, with_model};

mod output;
pub(crate) mod sensitivity;
pub use output::Row;
use output::{MAX_ROWS, Output};
use sensitivity::{Columns, Followed, by_parameters};

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
    /// Entries of Φ to add to the CSV as columns `dA/dB(0)`: `A/B` pairs
    /// separated by commas, the derivative of A at t by B at the start (A
    /// and B coordinate or velocity names, e.g. `x/x,x/x_dot`), or `all`.
    /// Follows Φ as `--sensitivity` does. Every row is then a step's end
    /// (Taylor's method too stops a step at each row); the row just before
    /// a collision has Φ just before it, the row after it Φ after it. For
    /// each B named, a column `dt_collision/dB(0)` has how the collision
    /// instant moves with B at the start (∂t*/∂B₀) on the row before each
    /// collision, empty on the others.
    #[arg(long)]
    pub phi: Option<String>,
    /// Parameters to differentiate the run by, separated by commas (e.g.
    /// `r,g`): for each parameter p, ∂A/∂p at t for every coordinate and
    /// velocity A is added to the CSV as a column `dA/dp`, and its values
    /// at the end to the summary. Followed through the collisions as Φ is
    /// (at `--rtol`), with the start's own derivative (its `[initial]`
    /// may depend on p) by differences. Every row is then a step's end;
    /// the row just before a collision has the derivative just before it.
    #[arg(long)]
    pub by: Option<String>,
}

/// Runs `dalembert simulate`.
pub fn simulate(args: &SimulateArgs) -> Result<bool, String> {
    // Before a model file's derivation, which takes seconds.
    checked_spacing(args)?;
    struct Simulate<'a>(&'a SimulateArgs);
    impl WithModel for Simulate<'_> {
        type Output = bool;
        fn with<M: TaylorSeries<N>, const N: usize>(
            self,
            model: M,
            derived: &[String],
        ) -> Result<bool, String> {
            run(self.0, model, derived)
        }
    }
    with_model(&args.run.model, "motion to simulate", Simulate(args))
}

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

/// Simulates `model` (whose derived parameters are `derived`) as `args` say.
fn run<M: TaylorSeries<N>, const N: usize>(
    args: &SimulateArgs,
    model: M,
    derived: &[String],
) -> Result<bool, String> {
    let every = checked_spacing(args)?;
    let path = path_axes(&model, args.path.as_deref())?;
    let (mut model, start, start_residual) = start(&args.run.set, model, derived)?;
    let by = (args.by.as_deref())
        .map(|spec| by_parameters(&mut model, &args.run.set, derived, spec))
        .transpose()?
        .unwrap_or_default();
    let e0 = model.energy(&start.q, &start.v);
    if !e0.is_finite() {
        return Err(format!(
            "the initial energy is {e0}: the initial state is out of range for f64"
        ));
    }
    let named = |e: SimError<M::Wall>| e.map_wall(|w| model.wall_name(w)).to_string();
    let mut room = SeriesRoom::new(&model);
    let mut sim = Simulator::with_series(&mut room, start, settings(&args.run)).map_err(named)?;
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("cannot create {}: {e}", args.out.display()))?;
    let csv = args.out.join(format!("{}.csv", model.name()));
    let svg = args.out.join(format!("{}.svg", model.name()));
    let columns = (args.phi.as_deref())
        .map(|spec| Columns::parse(&model, spec))
        .transpose()?;
    let mut followed = Followed::new(&model, (args.sensitivity, columns), &by, args.run.rtol);
    let mut out = Output::<N>::create(&model, &csv, e0, &followed.names)?;
    out.push(
        Row {
            t: 0.0,
            q: start.q,
            v: start.v,
            energy: e0,
            residual: [start_residual.velocity, start_residual.position],
            event: None,
        },
        &followed.values(false),
    )?;
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
    // Φ and the derivatives by parameters are known at the steps' ends
    // only.
    let dense = matches!(args.run.integrator, Method::Taylor) && !followed.writes_columns();
    let failure = integrate(
        &mut sim,
        &model,
        (args.t_end, every, dense),
        &mut out,
        &mut followed,
    )?;
    let elapsed = clock.elapsed();
    out.finish()?;
    plot(&svg, &model, &out.kept, path, e0)?;
    summary(&sim, &model, args, &out, e0, elapsed.as_secs_f64());
    followed.report(&model, &start, sim.state().t)?;
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
    followed: &mut Followed<'_, N>,
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
        if let Err(e) = followed.follow(model, sim, &step) {
            failure = Some(e);
            break;
        }
        // Rows strictly inside the step (before its collision, if any);
        // none where the step stopped at the next row.
        let stop = step.collision.as_ref().map_or(step.state.t, |c| c.t);
        while grid(k) < stop {
            let Some(s) = sim.state_at(grid(k)) else {
                break;
            };
            // (Only where no derivatives are written: rows inside steps
            // are dense.)
            out.push(Row::of(model, s.t, s.q, s.v), &[])?;
            k += 1.0;
        }
        if let Some(c) = &step.collision {
            // The state just before the collision, from its record.
            out.push(
                Row {
                    event: Some(model.wall_name(c.wall)),
                    ..Row::of(model, c.t, c.q, c.v_minus)
                },
                &followed.values(true),
            )?;
        }
        let s = &step.state;
        let energy = step.energy(model);
        if !energy.is_finite() {
            failure = Some(format!("the energy became {energy} at t = {}", s.t));
        }
        let on_grid = s.t >= grid(k);
        if on_grid || step.collision.is_some() || failure.is_some() {
            out.push(Row::of(model, s.t, s.q, s.v), &followed.values(false))?;
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
