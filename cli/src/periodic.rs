//! `dalembert periodic`: a periodic orbit through collisions by Newton's
//! method on a wall's return map, its Floquet multipliers and their
//! verdict (crate `dalembert-periodic`).

use clap::Args;
use dalembert::runtime::prelude::*;
use dalembert::runtime::saltation::SaltationError;
use dalembert::runtime::simulate::{ReturnError, Section, VariationalError};
use dalembert_periodic::{self as periodic, Angles, Orbit, PeriodicError, Search, Stability};

use crate::run::{RunArgs, WithModel, checked_run, positive, settings, start, with_model};

#[derive(Args, Debug)]
pub struct PeriodicArgs {
    #[command(flatten)]
    pub run: RunArgs,
    /// The wall whose collisions make the section (default: the model's
    /// first wall).
    #[arg(long)]
    pub wall: Option<String>,
    /// The orbit returns to the section after this many collisions with
    /// the wall (collisions with other walls in between are part of the
    /// orbit).
    #[arg(long, default_value_t = 1)]
    pub collisions: usize,
    /// Newton's method stops at |Π(x₀) − x₀|∞ ≤ this · max(1, |x₀|∞).
    #[arg(long, allow_hyphen_values = true, default_value_t = 1e-9)]
    pub residual: f64,
    /// Most Newton steps.
    #[arg(long, default_value_t = 20)]
    pub iterations: usize,
    /// The longest one return map may run, in model time.
    #[arg(long, allow_hyphen_values = true, default_value_t = 100.0)]
    pub t_max: f64,
    /// Coordinates that are angles: they return modulo 2π, so an orbit
    /// along which one makes whole turns is periodic (comma-separated
    /// names).
    #[arg(long, value_name = "NAME,…", value_delimiter = ',')]
    pub angles: Vec<String>,
    /// Write the orbit as JSON: {"period", "state", "multipliers": [[re,
    /// im], …], "residual", "iterations", …}.
    #[arg(long)]
    pub json: bool,
}

/// Runs `dalembert periodic`: `Ok(true)` with an orbit found.
pub fn periodic(args: &PeriodicArgs) -> Result<bool, String> {
    positive("--t-max", args.t_max)?;
    positive("--residual", args.residual)?;
    if args.collisions == 0 {
        return Err("--collisions must be at least 1".to_string());
    }
    checked_run(&args.run, "--t-max", args.t_max)?;
    with_model(
        &args.run.model,
        "motion and no periodic orbits",
        Periodic(args),
    )
}

struct Periodic<'a>(&'a PeriodicArgs);

impl WithModel for Periodic<'_> {
    type Output = bool;

    fn with<M: TaylorSeries<N>, const N: usize>(
        self,
        model: M,
        derived: &[String],
    ) -> Result<bool, String> {
        let args = self.0;
        let (model, start, _) = start(&args.run.set, model, derived)?;
        let wall = match &args.wall {
            None => *model
                .walls()
                .first()
                .ok_or_else(|| format!("{} has no wall: no section to return to", model.name()))?,
            Some(name) => *model
                .walls()
                .iter()
                .find(|w| model.wall_name(**w) == name)
                .ok_or_else(|| {
                    let names: Vec<&str> =
                        model.walls().iter().map(|w| model.wall_name(*w)).collect();
                    format!(
                        "`{name}` is not a wall of {} ({})",
                        model.name(),
                        names.join(", ")
                    )
                })?,
        };
        let section = Section {
            wall,
            returns: args.collisions,
            t_max: args.t_max,
        };
        let search = Search {
            settings: settings(&args.run),
            rtol: args.run.rtol,
            tolerance: args.residual,
            max_iterations: args.iterations,
            angles: angles(&model, &args.angles)?,
            ..Search::default()
        };
        let orbit = match periodic::find(&model, start, &section, &search) {
            Ok(orbit) => orbit,
            Err(e) => {
                // Searched and not found: exit 1, as a run stopped early.
                eprintln!("{}", failure(&model, &section, search.tolerance, e));
                return Ok(false);
            }
        };
        if args.json {
            println!("{}", json(&model, &section, &search, &orbit));
        } else {
            report(&model, &section, &search, &orbit);
        }
        Ok(true)
    }
}

/// The coordinates `names` as a set of angles.
fn angles<M: Surfaces<N>, const N: usize>(model: &M, names: &[String]) -> Result<Angles, String> {
    let coordinates = model.coordinate_names();
    let indices = names
        .iter()
        .map(|name| {
            coordinates
                .iter()
                .position(|c| *c == name.as_str())
                .ok_or_else(|| {
                    format!(
                        "--angles: `{name}` is not a coordinate of {} ({})",
                        model.name(),
                        coordinates.join(", ")
                    )
                })
        })
        .collect::<Result<Vec<usize>, String>>()?;
    Angles::of(&indices)
        .ok_or_else(|| "--angles: only the first 64 coordinates can be angles".to_string())
}

/// Why no orbit was found, naming walls as the model file does.
fn failure<M: Surfaces<N>, const N: usize>(
    model: &M,
    section: &Section<M::Wall>,
    tolerance: f64,
    e: PeriodicError<M::Wall>,
) -> String {
    let wall = model.wall_name(section.wall);
    let why = match e {
        PeriodicError::Return(ReturnError::Simulation(e)) => {
            format!(
                "a run of the return map failed: {}",
                e.map_wall(|w| model.wall_name(w))
            )
        }
        PeriodicError::Return(ReturnError::NoReturn { met, t_max }) => format!(
            "the motion met `{wall}` {met} times in t = {t_max} (--t-max), fewer than {} (--collisions): no return to the section",
            section.returns
        ),
        PeriodicError::Return(ReturnError::Variational(VariationalError::Saltation {
            wall: w,
            error: SaltationError::Grazing { normal_velocity },
        })) => format!(
            "the motion grazes `{}` (normal velocity {normal_velocity:e}): the return map has no derivative there",
            model.wall_name(w)
        ),
        PeriodicError::Return(ReturnError::Variational(e)) => format!(
            "the return map has no derivative: {}",
            crate::sim::sensitivity::failure(model, "Φ", e)
        ),
        PeriodicError::Return(ReturnError::Dynamics(e)) => {
            format!("q̈ at a return could not be computed: {e:?}")
        }
        PeriodicError::NoConvergence {
            iterations,
            residual,
        } => format!(
            "no orbit within {iterations} Newton steps (--iterations): the residual reached {residual:.3e}, above {tolerance:.1e} (--residual)"
        ),
        PeriodicError::Stalled {
            iterations,
            residual,
        } => format!(
            "Newton's method stalled after {iterations} steps at residual {residual:.3e}: no step along its direction, however short, lowers it (no orbit nearby, or the return map is not smooth here: the walls met change)"
        ),
        PeriodicError::TowardsGrazing {
            iterations,
            residual,
            normal_velocity,
        } => format!(
            "after {iterations} Newton steps (residual {residual:.3e}) the search heads for motions that slide along `{wall}` or rest against it instead of leaving it: the normal velocity at the last state is {normal_velocity:.3e}; no orbit through collisions nearby (more --iterations will not help; try another start with --set)"
        ),
        PeriodicError::SingularJacobian { iterations } => format!(
            "the return map's Jacobian minus I vanishes on the section after {iterations} steps: Newton's method has no direction"
        ),
        PeriodicError::Projection(e) => {
            format!("a state could not be put back on the constraints and the section: {e:?}")
        }
        PeriodicError::NoSection => format!(
            "`{wall}` is tangent to the constraint manifold at the start: the section has no admissible perturbations"
        ),
        PeriodicError::Decomposition => {
            "an eigenvalue or singular value decomposition did not converge".to_string()
        }
    };
    format!(
        "no periodic orbit of {} through `{wall}`: {why}",
        model.name()
    )
}

/// The verdict in words.
fn verdict(stability: Stability, unit: f64) -> String {
    match stability {
        Stability::Unstable { largest } => {
            format!("unstable: a multiplier of modulus {largest:.9} lies outside the unit circle")
        }
        Stability::Neutral => format!(
            "neutral: every multiplier is on the unit circle (within {unit:.0e}); the linearisation alone cannot decide stability"
        ),
        Stability::Stable { largest_inside } => format!(
            "linearly stable: no multiplier outside the unit circle, the largest inside of modulus {largest_inside:.9}"
        ),
    }
}

fn at_one<const N: usize>(orbit: &Orbit<N>, unit: f64) -> usize {
    orbit
        .multipliers
        .iter()
        .filter(|m| (m[0] - 1.0).hypot(m[1]) <= unit)
        .count()
}

fn report<M: Surfaces<N>, const N: usize>(
    model: &M,
    section: &Section<M::Wall>,
    search: &Search,
    orbit: &Orbit<N>,
) {
    println!(
        "{}: periodic orbit through {} return(s) to `{}` ({} collisions), period {:.15}",
        model.name(),
        section.returns,
        model.wall_name(section.wall),
        orbit.collisions,
        orbit.period
    );
    println!(
        "  found in {} Newton steps, residual |Π(x₀) − x₀|∞/max(1, |x₀|∞) = {:.3e}",
        orbit.iterations, orbit.residual
    );
    for (name, turns) in model.coordinate_names().iter().zip(&orbit.turns) {
        if *turns != 0 {
            println!("  {name} makes {turns} whole turn(s) per period (an angle, modulo 2π)");
        }
    }
    println!("  state on the section (just after the collision):");
    for (name, x) in model.coordinate_names().iter().zip(&orbit.state.q) {
        println!("    {name} = {x:.15}");
    }
    for (name, x) in model.velocity_names().iter().zip(&orbit.state.v) {
        println!("    {name} = {x:.15}");
    }
    println!(
        "  Floquet multipliers ({}: the monodromy on the section and the constraint manifold):",
        orbit.multipliers.len()
    );
    for m in &orbit.multipliers {
        println!(
            "    {:+.9} {:+.9}i   |λ| = {:.9}",
            m[0],
            m[1],
            m[0].hypot(m[1])
        );
    }
    let ones = at_one(orbit, search.unit);
    if ones > 0 {
        println!(
            "  {ones} multiplier(s) at 1 (within {:.0e}): families of orbits or symmetries",
            search.unit
        );
    }
    println!(
        "  stability: {}",
        verdict(
            periodic::stability(&orbit.multipliers, search.unit),
            search.unit
        )
    );
}

fn json<M: Surfaces<N>, const N: usize>(
    model: &M,
    section: &Section<M::Wall>,
    search: &Search,
    orbit: &Orbit<N>,
) -> String {
    let number = |x: f64| ryu::Buffer::new().format(x).to_string();
    let names = model
        .coordinate_names()
        .iter()
        .chain(model.velocity_names());
    let values = orbit.state.q.iter().chain(&orbit.state.v);
    let state: Vec<String> = names
        .zip(values)
        .map(|(n, x)| format!("\"{n}\": {}", number(*x)))
        .collect();
    let multipliers: Vec<String> = orbit
        .multipliers
        .iter()
        .map(|m| format!("[{}, {}]", number(m[0]), number(m[1])))
        .collect();
    let turns: Vec<String> = (model.coordinate_names().iter())
        .zip(&orbit.turns)
        .filter(|(_, k)| **k != 0)
        .map(|(n, k)| format!("\"{n}\": {k}"))
        .collect();
    let stability = match periodic::stability(&orbit.multipliers, search.unit) {
        Stability::Unstable { .. } => "unstable",
        Stability::Neutral => "neutral",
        Stability::Stable { .. } => "stable",
    };
    format!(
        "{{\"model\": \"{}\", \"wall\": \"{}\", \"returns\": {}, \"collisions\": {}, \"period\": {}, \"state\": {{{}}}, \"turns\": {{{}}}, \"multipliers\": [{}], \"at_one\": {}, \"stability\": \"{stability}\", \"residual\": {}, \"iterations\": {}}}",
        model.name(),
        model.wall_name(section.wall),
        section.returns,
        orbit.collisions,
        number(orbit.period),
        state.join(", "),
        turns.join(", "),
        multipliers.join(", "),
        at_one(orbit, search.unit),
        number(orbit.residual),
        orbit.iterations
    )
}
