//! `dalembert simulate`: runs the hybrid simulator on a built-in model and
//! writes the trajectory as CSV and an SVG plot.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use dalembert::for_each_model;
use dalembert::models::*;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    DormandPrince, Integrator, Rk4, Settings, Simulator, State, Step, admissible, residual,
};
use indicatif::{ProgressBar, ProgressStyle};
use plotters::prelude::*;

/// The integration method.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Method {
    /// Adaptive Dormand–Prince 5(4) (`--rtol`, `--atol`).
    DormandPrince,
    /// Classical Runge–Kutta with a fixed step (`--step`).
    Rk4,
}

#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// A built-in model with coordinates: ball_bounce, ball_wall_euler,
    /// pendulum_wall, masses_on_line, puck.
    pub model: String,
    /// Simulate from t = 0 to this time.
    #[arg(long, default_value_t = 5.0)]
    pub t_end: f64,
    /// Integration method.
    #[arg(long, value_enum, default_value_t = Method::DormandPrince)]
    pub integrator: Method,
    /// Step of the fixed-step method.
    #[arg(long, default_value_t = 1e-3)]
    pub step: f64,
    /// Relative tolerance of the adaptive method.
    #[arg(long, default_value_t = 1e-10)]
    pub rtol: f64,
    /// Absolute tolerance of the adaptive method.
    #[arg(long, default_value_t = 1e-12)]
    pub atol: f64,
    /// NAME=VALUE for a parameter, a coordinate or a velocity (repeatable);
    /// the rest come from the model file (`[parameters]`, `[initial]`).
    #[arg(long = "set", value_name = "NAME=VALUE", value_parser = assignment)]
    pub set: Vec<(String, f64)>,
    /// Time between output rows (default: t_end / 2000). Collisions are
    /// always written, before and after.
    #[arg(long)]
    pub every: Option<f64>,
    /// Two coordinates to draw as the path, e.g. `x,z` (default: the first two).
    #[arg(long)]
    pub path: Option<String>,
    /// Directory for `<model>.csv` and `<model>.svg`.
    #[arg(long, default_value = "target/simulate")]
    pub out: PathBuf,
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

/// Runs `dalembert simulate`.
pub fn simulate(args: &SimulateArgs) -> Result<bool, String> {
    let mut known = Vec::new();
    macro_rules! dispatch {
        ($module:ident, $ty:ident, 0, $n:literal) => {
            if args.model == stringify!($module) {
                return Err(format!(
                    "`{}` is an instantaneous model (velocities at the collision instant only): \
                     it has no motion to simulate; its counterparts in coordinates are \
                     ball_wall_euler (§3.1) and ball_bounce (§3.2)",
                    args.model
                ));
            }
        };
        ($module:ident, $ty:ident, $q:literal, $n:literal) => {
            if args.model == stringify!($module) {
                return run::<$ty, $q>(args);
            }
            known.push(stringify!($module));
        };
    }
    for_each_model!(dispatch);
    Err(format!(
        "no built-in model `{}`; models with coordinates: {}",
        args.model,
        known.join(", ")
    ))
}

/// One output row.
struct Row<const N: usize> {
    t: f64,
    q: [f64; N],
    v: [f64; N],
    energy: f64,
    residual: [f64; 2],
    event: Option<&'static str>,
}

fn run<M: Surfaces<N>, const N: usize>(args: &SimulateArgs) -> Result<bool, String> {
    let mut model = M::with_params(Default::default());
    let mut q = M::INITIAL_COORDINATES;
    let mut v = M::INITIAL_VELOCITIES;
    for (name, value) in &args.set {
        if let Some(i) = M::PARAMETERS.iter().position(|p| p == name) {
            model.set_parameter(i, *value);
        } else if let Some(i) = M::COORDINATES.iter().position(|c| c == name) {
            q[i] = *value;
        } else if let Some(i) = M::VELOCITIES.iter().position(|c| c == name) {
            v[i] = *value;
        } else {
            return Err(format!(
                "`{name}` is not a parameter ({}), coordinate ({}) or velocity ({}) of {}",
                M::PARAMETERS.join(", "),
                M::COORDINATES.join(", "),
                M::VELOCITIES.join(", "),
                M::NAME
            ));
        }
    }
    let start_residual = residual(&model, &q, &v);
    if start_residual.position > 1e-8 {
        return Err(format!(
            "the initial coordinates violate the holonomic constraints (|h(q)| = {:e}): set them on the constraint manifold",
            start_residual.position
        ));
    }
    let projected = admissible(&model, &q, &v).map_err(|e| format!("initial velocity: {e:?}"))?;
    if projected.iter().zip(&v).any(|(a, b)| (a - b).abs() > 1e-12) {
        eprintln!(
            "note: the initial velocity {v:?} is not admissible (A q̇ ≠ 0); using its G-orthogonal projection onto ker A, {projected:?}"
        );
    }
    let v = projected;
    let integrator = match args.integrator {
        Method::Rk4 => Integrator::Rk4(Rk4 { step: args.step }),
        Method::DormandPrince => Integrator::DormandPrince(DormandPrince {
            rtol: args.rtol,
            atol: args.atol,
            max_step: f64::INFINITY,
        }),
    };
    let settings = Settings {
        integrator,
        ..Settings::default()
    };
    let start = State { t: 0.0, q, v };
    let mut sim = Simulator::new(&model, start, settings).map_err(|e| e.to_string())?;
    let every = args.every.unwrap_or(args.t_end / 2000.0);
    if !(every > 0.0 && args.t_end > 0.0) {
        return Err("--t-end and --every must be positive".into());
    }

    let e0 = model.energy(&q, &v);
    let mut rows = vec![Row {
        t: 0.0,
        q,
        v,
        energy: e0,
        residual: [start_residual.velocity, start_residual.position],
        event: None,
    }];
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template(
            "{msg} [{bar:40}] {percent}% ({elapsed} elapsed, ~{eta} left)",
        )
        .map_err(|e| e.to_string())?
        .progress_chars("=> "),
    );
    bar.set_message(format!("simulating {}", M::NAME));
    let clock = Instant::now();
    let mut next = every;
    let mut failure = None;
    while sim.state().t < args.t_end {
        let target = next.min(args.t_end);
        match sim.step(target) {
            Ok(step) => record::<M, N>(&mut rows, &step),
            Err(e) => {
                failure = Some(e.to_string());
                break;
            }
        }
        if sim.state().t >= target {
            next += every;
            bar.set_position((1000.0 * sim.state().t / args.t_end) as u64);
        }
    }
    let elapsed = clock.elapsed();
    bar.finish_and_clear();

    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("cannot create {}: {e}", args.out.display()))?;
    let csv = args.out.join(format!("{}.csv", M::NAME));
    let svg = args.out.join(format!("{}.svg", M::NAME));
    write_csv::<M, N>(&csv, &rows)?;
    let path = path_axes::<M, N>(args.path.as_deref())?;
    plot::<M, N>(&svg, &rows, path, e0)?;

    let stats = sim.stats();
    let drift = rows
        .iter()
        .fold(0.0f64, |m, r| m.max((r.energy - e0).abs()));
    let worst = rows.iter().fold([0.0f64; 2], |m, r| {
        [m[0].max(r.residual[0]), m[1].max(r.residual[1])]
    });
    let secs = elapsed.as_secs_f64();
    println!(
        "{}: t = 0 → {} with {:?}",
        M::NAME,
        sim.state().t,
        args.integrator
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
    println!(
        "  energy {e0:.12} at the start; largest |E − E₀| = {drift:.2e} (relative {:.2e})",
        drift / e0.abs().max(f64::MIN_POSITIVE)
    );
    println!(
        "  largest constraint residuals: |A q̇| = {:.2e}, |h(q)| = {:.2e}",
        worst[0], worst[1]
    );
    println!("  trajectory: {}", csv.display());
    println!("  plot:       {}", svg.display());
    match failure {
        Some(e) => {
            println!("  stopped early: {e}");
            Ok(false)
        }
        None => Ok(true),
    }
}

fn record<M: Surfaces<N>, const N: usize>(rows: &mut Vec<Row<N>>, step: &Step<M::Wall, N>) {
    if let Some(c) = &step.collision {
        // The state just before the collision, from its record.
        let last = rows.last().map_or(step.energy, |r| r.energy);
        rows.push(Row {
            t: c.t,
            q: c.q,
            v: c.v_minus,
            energy: last,
            residual: [step.residual.velocity, step.residual.position],
            event: Some(M::wall_name(c.wall)),
        });
    }
    let s = &step.state;
    rows.push(Row {
        t: s.t,
        q: s.q,
        v: s.v,
        energy: step.energy,
        residual: [step.residual.velocity, step.residual.position],
        event: None,
    });
}

fn write_csv<M: Surfaces<N>, const N: usize>(file: &Path, rows: &[Row<N>]) -> Result<(), String> {
    let mut out = String::from("t");
    for name in M::COORDINATES.iter().chain(M::VELOCITIES) {
        out.push(',');
        out.push_str(name);
    }
    out.push_str(",energy,residual_velocity,residual_position,collision\n");
    for r in rows {
        let _ = write!(out, "{:e}", r.t);
        for x in r.q.iter().chain(&r.v) {
            let _ = write!(out, ",{x:e}");
        }
        let _ = writeln!(
            out,
            ",{:e},{:e},{:e},{}",
            r.energy,
            r.residual[0],
            r.residual[1],
            r.event.unwrap_or("")
        );
    }
    std::fs::write(file, out).map_err(|e| format!("cannot write {}: {e}", file.display()))
}

/// Indices of the two coordinates drawn as the path.
fn path_axes<M: Surfaces<N>, const N: usize>(spec: Option<&str>) -> Result<(usize, usize), String> {
    let find = |name: &str| {
        M::COORDINATES
            .iter()
            .position(|c| *c == name.trim())
            .ok_or_else(|| {
                format!(
                    "--path: `{name}` is not a coordinate of {} ({})",
                    M::NAME,
                    M::COORDINATES.join(", ")
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

fn range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
        (l.min(x), h.max(x))
    });
    if !lo.is_finite() || !hi.is_finite() {
        return 0.0..1.0;
    }
    let pad = ((hi - lo) * 0.05).max(1e-12 * (1.0 + lo.abs().max(hi.abs())));
    lo - pad..hi + pad
}

/// Three panels: the coordinates over time, the path, and the energy drift.
fn plot<M: Surfaces<N>, const N: usize>(
    file: &Path,
    rows: &[Row<N>],
    (a, b): (usize, usize),
    e0: f64,
) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| format!("plotting {}: {e}", file.display());
    let root = SVGBackend::new(file, (1000, 1200)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let panels = root.split_evenly((3, 1));
    let t_range = 0.0..rows.last().map_or(1.0, |r| r.t.max(1e-12));

    let mut chart = ChartBuilder::on(&panels[0])
        .caption(format!("{}: coordinates", M::NAME), ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(60)
        .build_cartesian_2d(t_range.clone(), range(rows.iter().flat_map(|r| r.q)))
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc("t")
        .draw()
        .map_err(|e| err(&e))?;
    for i in 0..N {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(rows.iter().map(|r| (r.t, r.q[i])), color))
            .map_err(|e| err(&e))?
            .label(M::COORDINATES[i])
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;

    let mut path = ChartBuilder::on(&panels[1])
        .caption(
            format!("path: {} against {}", M::COORDINATES[b], M::COORDINATES[a]),
            ("sans-serif", 22),
        )
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(60)
        .build_cartesian_2d(
            range(rows.iter().map(|r| r.q[a])),
            range(rows.iter().map(|r| r.q[b])),
        )
        .map_err(|e| err(&e))?;
    path.configure_mesh()
        .x_desc(M::COORDINATES[a])
        .y_desc(M::COORDINATES[b])
        .draw()
        .map_err(|e| err(&e))?;
    path.draw_series(LineSeries::new(rows.iter().map(|r| (r.q[a], r.q[b])), BLUE))
        .map_err(|e| err(&e))?;
    path.draw_series(
        rows.iter()
            .filter(|r| r.event.is_some())
            .map(|r| Circle::new((r.q[a], r.q[b]), 3, RED.filled())),
    )
    .map_err(|e| err(&e))?;

    let mut energy = ChartBuilder::on(&panels[2])
        .caption(
            format!("energy drift E − E₀ (E₀ = {e0:.6})"),
            ("sans-serif", 22),
        )
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(80)
        .build_cartesian_2d(t_range, range(rows.iter().map(|r| r.energy - e0)))
        .map_err(|e| err(&e))?;
    energy
        .configure_mesh()
        .x_desc("t")
        .y_label_formatter(&|y| format!("{y:.1e}"))
        .draw()
        .map_err(|e| err(&e))?;
    energy
        .draw_series(LineSeries::new(
            rows.iter().map(|r| (r.t, r.energy - e0)),
            RED,
        ))
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
