//! What the command line costs over the library for the same output
//! (issue 43 §5): §3.2.1's ball through 10⁴ bounces with Taylor's method,
//! a row every 10⁴ time units and two at each collision (20 002 rows), as
//! `dalembert simulate ball_bounce --integrator taylor --t-end 4077.6
//! --every 10000` writes it. One group, three rows:
//!
//! - `library`: the same run through `Simulator::run`, no output;
//! - `library_csv`: the same run through `Simulator::step` and
//!   `Simulator::state_at`, writing the same CSV as the command line (each
//!   row's energy and residuals computed, numbers by Ryū); before timing,
//!   its file is checked byte for byte against the command line's;
//! - `command_line`: the CLI as a process (start-up, the CSV, the SVG plot
//!   of up to 8000 rows, the summary).
//!
//! Measured in CPU time of this process and its waited children
//! (`getrusage`), so that the process row counts the child's work and not
//! the time it waits to be scheduled.
//!
//! Run: `cargo bench -p dalembert-cli --bench command_line`.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::Command;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use dalembert::models::BallBounce;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    Integrator, SeriesRoom, Settings, Simulator, State, Taylor, residual,
};

#[path = "../../benches/common/cpu_time.rs"]
#[allow(dead_code)] // the thread clock is not used here
mod cpu_time;
use cpu_time::ProcessCpuTime;

const BOUNCES: u64 = 10_000;
const T_END: f64 = 4077.6;
const EVERY: f64 = 10_000.0;

fn settings() -> Settings {
    Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    }
}

fn start<M: Dynamics<N>, const N: usize>(m: &M) -> State<N> {
    State {
        t: 0.0,
        q: m.initial_coordinates(),
        v: m.initial_velocities(),
    }
}

/// One row as the command line writes it: t, q, q̇, energy, |A q̇|, |h(q)|
/// and the wall's name on the row before a collision.
fn row<M: TaylorSeries<N>, const N: usize>(
    out: &mut impl Write,
    m: &M,
    t: f64,
    q: &[f64; N],
    v: &[f64; N],
    event: &str,
) {
    let r = residual(m, q, v);
    let mut number = ryu::Buffer::new();
    let mut line = Vec::with_capacity(32 * (2 * N + 4));
    line.extend_from_slice(number.format(t).as_bytes());
    for &x in q
        .iter()
        .chain(v)
        .chain(&[m.energy(q, v), r.velocity, r.position])
    {
        line.push(b',');
        line.extend_from_slice(number.format(x).as_bytes());
    }
    line.push(b',');
    line.extend_from_slice(event.as_bytes());
    line.push(b'\n');
    out.write_all(&line).unwrap();
}

/// The run written to `path` as a library user would: step to the end,
/// rows on the grid read off each step's polynomial, the state before and
/// after each collision. Returns the collisions.
fn library_csv(m: &BallBounce, path: &Path) -> u64 {
    let mut out = BufWriter::new(File::create(path).unwrap());
    let mut header = String::from("t");
    for name in m.coordinate_names().iter().chain(m.velocity_names()) {
        header.push(',');
        header.push_str(name);
    }
    header.push_str(",energy,residual_velocity,residual_position,collision\n");
    out.write_all(header.as_bytes()).unwrap();
    let s = start(m);
    row(&mut out, m, 0.0, &s.q, &s.v, "");
    let mut room = SeriesRoom::new(m);
    let mut sim = Simulator::with_series(&mut room, s, settings()).unwrap();
    let grid = |k: f64| (k * EVERY).min(T_END);
    let mut k = 1.0;
    while sim.state().t < T_END {
        let step = sim.step(T_END).unwrap();
        let stop = step.collision.as_ref().map_or(step.state.t, |c| c.t);
        while grid(k) < stop {
            let s = sim.state_at(grid(k)).unwrap();
            row(&mut out, m, s.t, &s.q, &s.v, "");
            k += 1.0;
        }
        if let Some(c) = &step.collision {
            row(&mut out, m, c.t, &c.q, &c.v_minus, m.wall_name(c.wall));
        }
        let on_grid = step.state.t >= grid(k);
        if on_grid || step.collision.is_some() {
            row(&mut out, m, step.state.t, &step.state.q, &step.state.v, "");
        }
        if on_grid {
            k += 1.0;
        }
    }
    out.flush().unwrap();
    sim.stats().collisions
}

/// The command line's run, its CSV in `dir`.
fn command_line(dir: &Path) {
    let status = Command::new(env!("CARGO_BIN_EXE_dalembert"))
        .args(["simulate", "ball_bounce", "--integrator", "taylor"])
        .args(["--t-end", &T_END.to_string(), "--every", &EVERY.to_string()])
        .arg("--out")
        .arg(dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
}

fn scratch() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bench-command-line");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn bench(c: &mut Criterion<ProcessCpuTime>) {
    let m = BallBounce::default();
    let dir = scratch();
    let csv = dir.join("library.csv");
    // The three paths do the same run: the same bounces, and the same file.
    command_line(&dir);
    assert_eq!(library_csv(&m, &csv), BOUNCES);
    let ours = std::fs::read(&csv).unwrap();
    assert!(
        ours == std::fs::read(dir.join("ball_bounce.csv")).unwrap(),
        "the library's CSV differs from the command line's"
    );
    let mut room = SeriesRoom::new(&m);
    let mut sim = Simulator::with_series(&mut room, start(&m), settings()).unwrap();
    assert_eq!(sim.run(T_END, |_| true).unwrap().collisions, BOUNCES);

    let mut group = c.benchmark_group("ball_bounce_10000_bounces_taylor");
    group.throughput(Throughput::Elements(BOUNCES));
    group.sample_size(20);
    group.bench_function("library", |b| {
        b.iter(|| {
            let mut room = SeriesRoom::new(&m);
            let mut sim = Simulator::with_series(&mut room, start(&m), settings()).unwrap();
            sim.run(T_END, |_| true).unwrap()
        })
    });
    group.bench_function("library_csv", |b| b.iter(|| library_csv(&m, &csv)));
    group.bench_function("command_line", |b| b.iter(|| command_line(&dir)));
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ProcessCpuTime);
    targets = bench
}
criterion_main!(benches);
