//! The `dalembert` command line.
//!
//! `paper` derives the paper's models and compares them with what the paper
//! prints; `derive` shows what the generator derives for any model file;
//! `generate` writes its Rust code (to vendor it without symbolica);
//! `check` compares a derivation with a reference file; `simulate` runs a
//! built-in model through collisions and writes its trajectory and a plot.

mod periodic;
mod plot;
mod run;
mod sim;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use dalembert::models::BallFloor;
use dalembert::runtime::Walls;
use dalembert_codegen::derive::Projection;
use dalembert_codegen::derive::inspect as symbolic;
use dalembert_codegen::quantity::Quantity;
use dalembert_codegen::reference::{Comparison, Difference, Reference};
use dalembert_codegen::{Derivation, ModelErrors};

const MODELS_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");

#[derive(Parser)]
#[command(
    name = "dalembert",
    version,
    about = "Collisions in nonholonomic systems: derive, generate and check collision maps"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Derive P and the collision law for the paper's models (§3.1, §3.2) and
    /// compare them with what the paper prints.
    Paper {
        /// Directory with the model files and `reference/`.
        #[arg(long, default_value = MODELS_DIR)]
        models: PathBuf,
    },
    /// Print G, A, and for every wall B, P and the collision law.
    Derive {
        /// The model file.
        file: PathBuf,
        /// Print LaTeX (pmatrix environments) instead of plain text.
        #[arg(long)]
        latex: bool,
    },
    /// Write the generated Rust code for a model file.
    Generate {
        /// The model file.
        file: PathBuf,
        /// Where to write it (default: standard output; symbolica's licence
        /// notice goes to standard error).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Emit f32 arithmetic (for microcontrollers without double-precision
        /// hardware): the model's inherent functions, without the f64 `Model`
        /// trait; needs closed-form P (accuracy: docs/performance.md).
        #[arg(long)]
        f32: bool,
    },
    /// Compare a model's derived P (and collision law) with a reference file.
    Check {
        /// The model file.
        file: PathBuf,
        /// The reference file.
        reference: PathBuf,
    },
    /// Simulate a built-in model through its collisions; write the
    /// trajectory (CSV) and a plot (SVG).
    Simulate(sim::SimulateArgs),
    /// Find a periodic orbit that returns to a wall after K collisions with
    /// it (Newton's method on the return map), its period and Floquet
    /// multipliers, and say whether it is stable.
    Periodic(periodic::PeriodicArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Paper { models } => paper(&models),
        Command::Derive { file, latex: false } => derive_timed(&file),
        Command::Derive { file, latex: true } => derive(&file).and_then(|d| print_latex(&d)),
        Command::Generate { file, output, f32 } => generate(&file, output.as_deref(), f32),
        Command::Check { file, reference } => check(&file, &reference),
        Command::Simulate(args) => sim::simulate(&args),
        Command::Periodic(args) => periodic::periodic(&args),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(message) => {
            eprintln!("{message}");
            ExitCode::from(2)
        }
    }
}

fn derive(file: &Path) -> Result<Derivation, String> {
    notices_to_stderr(|| dalembert_codegen::derive(file)).map_err(|e: ModelErrors| e.render())
}

/// Runs `f`, which may be the generator's first use of symbolica, with
/// standard output sent to standard error. symbolica shows its licence
/// notice on standard output when first used; there it would become the
/// first lines of the Rust code, derivation or CSV summary a user
/// redirects to a file. On standard error it is still shown.
fn notices_to_stderr<T>(f: impl FnOnce() -> T) -> T {
    use std::io::Write as _;
    let _ = std::io::stdout().flush();
    #[cfg(unix)]
    // SAFETY: plain file-descriptor calls on this process's own standard
    // streams; a failed `dup` leaves standard output as it was.
    unsafe {
        let saved = libc::dup(1);
        if saved < 0 || libc::dup2(2, 1) < 0 {
            if saved >= 0 {
                libc::close(saved);
            }
            return f();
        }
        let out = f();
        let _ = std::io::stdout().flush();
        libc::dup2(saved, 1);
        libc::close(saved);
        out
    }
    #[cfg(not(unix))]
    f()
}

/// `derive`: the derivation, then how long derivation and emission took.
fn derive_timed(file: &Path) -> Result<bool, String> {
    // Waiting for another process's use of the engine is not derivation
    // time. Taking the lock makes the generator's first symbols, which can
    // show symbolica's notice.
    notices_to_stderr(dalembert_codegen::lock::acquire)?;
    let start = std::time::Instant::now();
    let d = derive(file)?;
    let derived = start.elapsed();
    let code = dalembert_codegen::emit::file(&d, dalembert_codegen::Options::default());
    let total = start.elapsed();
    print_derivation(&d);
    println!(
        "generator time: derivation {:.1} ms, emission {:.1} ms ({} lines of Rust)",
        derived.as_secs_f64() * 1e3,
        (total - derived).as_secs_f64() * 1e3,
        code.lines().count()
    );
    Ok(true)
}

fn generate(file: &Path, output: Option<&Path>, f32: bool) -> Result<bool, String> {
    let code = notices_to_stderr(|| {
        if f32 {
            dalembert_codegen::generate_f32(file)
        } else {
            dalembert_codegen::generate(file)
        }
    })
    .map_err(|e| e.render())?;
    match output {
        Some(path) => std::fs::write(path, code).map_err(|e| format!("{}: {e}", path.display()))?,
        None => print!("{code}"),
    }
    Ok(true)
}

fn check(file: &Path, reference: &Path) -> Result<bool, String> {
    let d = derive(file)?;
    let r = Reference::load(reference)?;
    let c = r.compare(&d)?;
    Ok(report(&d, &r, &c, "the reference"))
}

fn paper(models: &Path) -> Result<bool, String> {
    let mut all_ok = true;
    for (name, section) in [("ball_wall", "§3.1"), ("ball_floor", "§3.2")] {
        let d = derive(&models.join(format!("{name}.toml")))?;
        println!("==================== {section}: {name} ====================");
        print_derivation(&d);
        let r = Reference::load(&models.join("reference").join(format!("{name}.toml")))?;
        let c = r.compare(&d)?;
        all_ok &= report(&d, &r, &c, "the paper");
        println!();
    }
    section_3_2_1_collision_map();
    println!();
    Ok(all_ok && section_3_2_1_simulated()?)
}

/// §3.2.1 simulated: the ball in flight (`models/ball_bounce.toml`) from the
/// model file's initial state (just after a bounce, u = 2, v = 1) through
/// 20 bounces, written to target/simulate/.
fn section_3_2_1_simulated() -> Result<bool, String> {
    println!(
        "==================== §3.2.1 simulated: 20 bounces of ball_bounce ===================="
    );
    let flight = 2.0 * 2.0 / dalembert::models::BallBounce::default().params().g;
    let t_end = format!("{}", 20.5 * flight);
    let cli = Cli::try_parse_from([
        "dalembert",
        "simulate",
        "ball_bounce",
        "--t-end",
        &t_end,
        "--path",
        "x,z",
    ])
    .map_err(|e| e.to_string())?;
    match cli.command {
        Command::Simulate(args) => sim::simulate(&args),
        _ => unreachable!("parsed as `simulate`"),
    }
}

/// §3.2.1 with the generated code itself: the paper's initial data must
/// come back reversed.
fn section_3_2_1_collision_map() {
    let ball = BallFloor::default();
    let p = *ball.params();
    let (v, u) = (1.5, 2.0);
    let v_minus = [-v, 0.0, -u, 0.0, p.r * p.m * v / p.J, 0.0];
    let v_plus = ball.collide(BallFloor::WALLS[0], &[], &v_minus);
    println!(
        "==================== §3.2.1: nonholonomic pendulum (generated code) ===================="
    );
    println!("m = {}, r = {}, J = {}; v = {v}, u = {u}", p.m, p.r, p.J);
    println!("v⁻ = {v_minus:?}");
    println!("v⁺ = {v_plus:?}");
    let reversed = v_plus
        .iter()
        .zip(&v_minus)
        .all(|(a, b)| (a + b).abs() <= 1e-12 * (1.0 + b.abs()));
    println!(
        "v⁺ = −v⁻ (the ball returns along its parabola): {}",
        if reversed { "yes" } else { "NO" }
    );
}

/// A matrix as a LaTeX `pmatrix`.
fn latex_matrix(m: &[Vec<String>]) -> Result<String, String> {
    let mut rows = Vec::new();
    for row in m {
        let cells: Result<Vec<String>, String> = row.iter().map(|e| symbolic::latex(e)).collect();
        rows.push(cells?.join(" & "));
    }
    Ok(format!(
        "\\begin{{pmatrix}}\n  {}\n\\end{{pmatrix}}",
        rows.join(" \\\\\n  ")
    ))
}

/// `derive --latex`: G, A, q̈ where solved in closed form and, per wall, B,
/// P and the collision law.
fn print_latex(d: &Derivation) -> Result<bool, String> {
    let m = &d.model;
    println!(
        "% model `{}`: velocities ({})",
        m.name,
        m.velocities.join(", ")
    );
    println!("G = {}", latex_matrix(&d.mass_matrix)?);
    if !d.constraint_rows.is_empty() {
        println!("A = {}", latex_matrix(&d.constraint_rows)?);
    }
    if let Some(qdd) = &d.accelerations {
        println!("% equations of motion between collisions, in closed form");
        println!("\\begin{{aligned}}");
        for (name, e) in m.coordinates.iter().zip(qdd) {
            println!(
                "  \\ddot{{{}}} &= {} \\\\",
                symbolic::latex(name)?,
                symbolic::latex(e)?
            );
        }
        println!("\\end{{aligned}}");
    }
    for w in &d.walls {
        println!("% wall `{}`", w.name);
        println!("B = {}", latex_matrix(&w.b_rows)?);
        let Projection::ClosedForm {
            projector,
            collision,
        } = &w.projection
        else {
            println!("% P: structured evaluation (solved at run time from G and B)");
            continue;
        };
        println!("P = {}", latex_matrix(projector)?);
        println!("\\begin{{aligned}}");
        for (name, c) in m.velocities.iter().zip(collision) {
            println!(
                "  {}^+ &= {} \\\\",
                symbolic::latex(name)?,
                symbolic::latex(c)?
            );
        }
        println!("\\end{{aligned}}");
    }
    Ok(true)
}

fn print_matrix(title: &str, m: &[Vec<String>]) {
    println!("{title}");
    for row in m {
        println!("  [ {} ]", row.join(", "));
    }
}

fn print_derivation(d: &Derivation) -> bool {
    let m = &d.model;
    println!(
        "model `{}` ({}): velocities ({})",
        m.name,
        m.file.display(),
        m.velocities.join(", ")
    );
    if !m.coordinates.is_empty() {
        println!("coordinates ({})", m.coordinates.join(", "));
    }
    if !m.from_bodies.is_empty() {
        println!("derived from the bodies (line of the declaration):");
        for x in &m.from_bodies {
            let (line, _) = dalembert_codegen::diag::line_col(&m.source, x.span.start);
            println!("  {} = {}   (line {line})", x.what, x.text);
        }
    }
    print_matrix("G =", &d.mass_matrix);
    if d.constraint_rows.is_empty() {
        println!("A: no constraints");
    } else {
        print_matrix("A =", &d.constraint_rows);
    }
    if let Some(qdd) = &d.accelerations {
        println!("equations of motion between collisions (G q̈ + h = Aᵀλ, A q̈ + Ȧq̇ = 0), solved:");
        for (name, e) in m.coordinates.iter().zip(qdd) {
            println!("  {name}'' = {e}");
        }
    }
    for w in &d.walls {
        println!("--- wall `{}` ---", w.name);
        print_matrix(&format!("B = (rows: {})", w.b_origin.join("; ")), &w.b_rows);
        if !w.dropped.is_empty() {
            println!("  dependent rows removed: {}", w.dropped.join("; "));
        }
        let Projection::ClosedForm {
            projector,
            collision,
        } = &w.projection
        else {
            println!(
                "P and the collision map: structured evaluation (solved at run time from G and B; set `projector = \"symbolic\"` under [model] for closed forms)"
            );
            continue;
        };
        print_matrix("P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B =", projector);
        println!("collision law v⁺ = (I − 2P)v⁻:");
        for (name, c) in m.velocities.iter().zip(collision) {
            println!("  {name}⁺ = {c}");
        }
        let count = |q| {
            w.function(q)
                .map(|f| f.program.op_count().to_string())
                .unwrap_or_default()
        };
        println!(
            "operation counts: projector {}; collision map {}",
            count(Quantity::Projector),
            count(Quantity::Collide)
        );
    }
    true
}

/// Prints the verdict; true when the derivation agrees with the reference
/// except for diagonal entries printed as "1" inside a prefactor that
/// scales (the paper's misprint of an entry that is exactly 1).
fn report(d: &Derivation, r: &Reference, c: &Comparison, who: &str) -> bool {
    let n = d.model.velocities.len();
    println!("--- compared with: {} ---", r.source);
    // The paper's pattern exactly: a "1" on the diagonal inside a
    // prefactor that is neither 0 nor 1 (so that the printed entry is
    // not 1), where the derived entry is exactly 1, in a matrix where the
    // prefactor is borne out by another entry (one printed non-zero that
    // agrees). A prefactor of 0 or 1 explains no difference, and one that
    // no entry confirms does not make every "1" a misprint.
    let borne_out = (0..n).any(|i| {
        (0..n).any(|j| {
            r.projector[i][j].trim() != "0"
                && r.projector[i][j].trim() != "1"
                && !c.projector.iter().any(|x| x.row == i && x.col == j)
        })
    });
    let scales = borne_out
        && r.prefactor.as_deref().is_some_and(|f| {
            symbolic::same(f, "0") == Ok(false) && symbolic::same(f, "1") == Ok(false)
        });
    let misprint = |i: usize, j: usize| {
        scales
            && i == j
            && r.projector[i][j].trim() == "1"
            && symbolic::same(
                &c.projector
                    .iter()
                    .find(|x| x.row == i && x.col == j)
                    .map(|x| x.derived.clone())
                    .unwrap_or_default(),
                "1",
            )
            .unwrap_or(false)
    };
    // Differences not proven but equal at random points, with their place.
    let numeric: Vec<_> = c
        .projector
        .iter()
        .map(|x| (format!("entry ({},{})", x.row + 1, x.col + 1), x))
        .chain(
            c.collision
                .iter()
                .map(|x| (format!("collision component {}", x.row + 1), x)),
        )
        .filter(|(_, x)| x.numerically_equal.is_some())
        .collect();
    let collision_ok = c.collision.iter().all(|x| x.numerically_equal.is_some());
    let (known, other): (Vec<_>, Vec<_>) = c
        .projector
        .iter()
        .filter(|x| x.numerically_equal.is_none())
        .partition(|x| misprint(x.row, x.col));
    println!(
        "P: {} of {} entries agree exactly",
        n * n - c.projector.len(),
        n * n
    );
    for (place, x) in &numeric {
        println!(
            "  {place}: equal at {} random points, not proven: reference {}, derived {}",
            x.numerically_equal.unwrap_or(0),
            x.reference,
            x.derived
        );
    }
    for x in &known {
        println!(
            "  entry ({},{}): {who} prints 1 inside the prefactor {}, i.e. {}; the derived entry is {}: a misprint (P² = P forces this entry to be 1)",
            x.row + 1,
            x.col + 1,
            r.prefactor.as_deref().unwrap_or(""),
            x.reference,
            x.derived
        );
    }
    // Where a differing entry is written, for the reader to go and look.
    let at = |x: &Difference| x.at.as_ref().map(|a| format!(" ({a})")).unwrap_or_default();
    for x in &other {
        println!(
            "  entry ({},{}) DIFFERS{}: reference {}, derived {}",
            x.row + 1,
            x.col + 1,
            at(x),
            x.reference,
            x.derived
        );
    }
    if c.has_collision {
        if collision_ok {
            println!("collision law: agrees with {who} in every component");
        }
        for x in c.collision.iter().filter(|x| x.numerically_equal.is_none()) {
            println!(
                "  collision component {} DIFFERS{}: reference {}, derived {}",
                x.row + 1,
                at(x),
                x.reference,
                x.derived
            );
        }
    }
    let ok = other.is_empty() && collision_ok;
    let unproven = if numeric.is_empty() {
        String::new()
    } else {
        format!(
            " ({} entr{} equal only at random points, not proven)",
            numeric.len(),
            if numeric.len() == 1 { "y" } else { "ies" }
        )
    };
    println!(
        "verdict: {}{unproven}",
        if ok && known.is_empty() {
            format!("agrees with {who}")
        } else if ok {
            format!(
                "agrees with {who} except {} misprinted diagonal entr{} of the printed P",
                known.len(),
                if known.len() == 1 { "y" } else { "ies" }
            )
        } else {
            format!("DISAGREES with {who}")
        }
    );
    ok
}
