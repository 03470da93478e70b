//! Where a run's rows go: the CSV file as they come, a thinned copy for the
//! plot, and the largest energy drift and residuals over every row.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::residual;

/// One output row; `event` is the name of the wall met, on the row just
/// before a collision.
pub struct Row<'m, const N: usize> {
    pub t: f64,
    pub q: [f64; N],
    pub v: [f64; N],
    pub energy: f64,
    pub residual: [f64; 2],
    pub event: Option<&'m str>,
}

impl<const N: usize> Row<'_, N> {
    /// The row of the state (q, v) at t, its energy and residuals computed.
    pub fn of<M: Surfaces<N>>(model: &M, t: f64, q: [f64; N], v: [f64; N]) -> Self {
        let r = residual(model, &q, &v);
        Row {
            t,
            q,
            v,
            energy: model.energy(&q, &v),
            residual: [r.velocity, r.position],
            event: None,
        }
    }
}

/// Most rows a run may write, collisions' rows included (about 1.5 GB of
/// CSV for a model with 6 coordinates): a run that reaches it stops with
/// an error saying so, the rows so far written.
pub(super) const MAX_ROWS: usize = 10_000_000;

/// Rows kept in memory for the plot (up to twice this many); the CSV has
/// them all.
const PLOT_ROWS: usize = 4000;

/// Where the rows go: the CSV file as they come, a thinned copy for the
/// plot, and the largest energy drift and residuals over every row.
pub(super) struct Output<'m, const N: usize> {
    file: std::io::BufWriter<std::fs::File>,
    path: PathBuf,
    /// Rows for the plot: every `stride`-th row of a state, and every
    /// `collision_stride`-th collision (each one while they take at most a
    /// quarter of the budget; see [`Output::thin`]).
    pub(super) kept: Vec<Row<'m, N>>,
    stride: usize,
    collision_stride: usize,
    /// Rows written in all, and of them collisions.
    pub(super) written: usize,
    collisions: usize,
    pub(super) e0: f64,
    pub(super) drift: f64,
    pub(super) worst: [f64; 2],
}

impl<'m, const N: usize> Output<'m, N> {
    /// The CSV file at `path` with its header: t, the coordinates, the
    /// velocities, energy, residuals, collision, then `extra` (columns
    /// each row gives [`Output::push`] after its own).
    pub(super) fn create<M: Surfaces<N>>(
        model: &M,
        path: &Path,
        e0: f64,
        extra: &[String],
    ) -> Result<Self, String> {
        let file = std::fs::File::create(path)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        let mut out = Self {
            file: std::io::BufWriter::new(file),
            path: path.to_path_buf(),
            kept: Vec::new(),
            stride: 1,
            collision_stride: 1,
            written: 0,
            collisions: 0,
            e0,
            drift: 0.0,
            worst: [0.0; 2],
        };
        let mut header = String::from("t");
        for name in model
            .coordinate_names()
            .iter()
            .chain(model.velocity_names())
        {
            header.push(',');
            header.push_str(name);
        }
        header.push_str(",energy,residual_velocity,residual_position,collision");
        for name in extra {
            header.push(',');
            header.push_str(name);
        }
        header.push('\n');
        out.write(header.as_bytes())?;
        Ok(out)
    }

    fn write(&mut self, text: &[u8]) -> Result<(), String> {
        self.file
            .write_all(text)
            .map_err(|e| format!("cannot write {}: {e}", self.path.display()))
    }

    /// Writes the row `r` and its `extra` columns (as many as the header's;
    /// `None` leaves a cell empty).
    pub(super) fn push(&mut self, r: Row<'m, N>, extra: &[Option<f64>]) -> Result<(), String> {
        if self.written >= MAX_ROWS {
            return Err(format!(
                "stopped at t = {}: the run has written {MAX_ROWS} rows to {} (collisions count as rows), the most a run may write; raise --every or shorten --t-end",
                r.t,
                self.path.display()
            ));
        }
        // Each number in its shortest form that reads back exactly (Ryū:
        // std's `{:e}` took most of a bouncing ball's run).
        let mut number = ryu::Buffer::new();
        let mut line = Vec::with_capacity(32 * (2 * N + 4));
        line.extend_from_slice(number.format(r.t).as_bytes());
        let values = (r.q.iter().chain(&r.v)).chain([&r.energy, &r.residual[0], &r.residual[1]]);
        for &x in values {
            line.push(b',');
            line.extend_from_slice(number.format(x).as_bytes());
        }
        line.push(b',');
        line.extend_from_slice(r.event.unwrap_or("").as_bytes());
        for x in extra {
            line.push(b',');
            if let Some(x) = x {
                line.extend_from_slice(number.format(*x).as_bytes());
            }
        }
        line.push(b'\n');
        self.write(&line)?;
        self.drift = self.drift.max((r.energy - self.e0).abs());
        self.worst = [
            self.worst[0].max(r.residual[0]),
            self.worst[1].max(r.residual[1]),
        ];
        let keep = if r.event.is_some() {
            self.collisions.is_multiple_of(self.collision_stride)
        } else {
            (self.written - self.collisions).is_multiple_of(self.stride)
        };
        self.written += 1;
        self.collisions += usize::from(r.event.is_some());
        if keep {
            self.kept.push(r);
        }
        if self.kept.len() > 2 * PLOT_ROWS {
            self.thin();
        }
        Ok(())
    }

    /// Halves the rows kept for the plot: every other row of a state, and
    /// every other collision once collisions are more than a quarter of the
    /// budget (before that, every collision stays marked). Either way at
    /// most about 1.25 × [`PLOT_ROWS`] rows remain, so thinning happens
    /// once in thousands of rows, and the rows kept of each kind stay
    /// evenly spread over the run.
    fn thin(&mut self) {
        let marked = self.kept.iter().filter(|r| r.event.is_some()).count();
        let thin_collisions = marked > PLOT_ROWS / 2;
        let (mut states, mut events) = (0usize, 0usize);
        self.kept.retain(|r| {
            let seen = match (&r.event, thin_collisions) {
                (None, _) => &mut states,
                (Some(_), true) => &mut events,
                (Some(_), false) => return true,
            };
            *seen += 1;
            *seen % 2 == 1
        });
        self.stride = self.stride.saturating_mul(2);
        if thin_collisions {
            self.collision_stride = self.collision_stride.saturating_mul(2);
        }
    }

    pub(super) fn finish(&mut self) -> Result<(), String> {
        self.file
            .flush()
            .map_err(|e| format!("cannot write {}: {e}", self.path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dalembert::models::PendulumWall;

    /// `rows` rows at t = 0, 1, …, a collision wherever `collision(t)`.
    fn pushed(name: &str, rows: usize, collision: impl Fn(usize) -> bool) -> Output<'static, 2> {
        let path = std::env::temp_dir().join(format!("dalembert-output-{name}.csv"));
        let mut out = Output::create(&PendulumWall::default(), &path, 0.0, &[]).unwrap();
        for t in 0..rows {
            out.push(
                Row {
                    t: t as f64,
                    q: [0.0; 2],
                    v: [0.0; 2],
                    energy: 0.0,
                    residual: [0.0; 2],
                    event: collision(t).then_some("wall"),
                },
                &[],
            )
            .unwrap();
            assert!(
                out.kept.len() <= 2 * PLOT_ROWS,
                "{} rows kept at t = {t}",
                out.kept.len()
            );
        }
        out.finish().unwrap();
        let _ = std::fs::remove_file(&path);
        out
    }

    /// A run that is mostly collisions (each written before and after, as
    /// a bouncing ball's): the plot's rows stay within the budget, and both
    /// kinds stay spread over the whole run. Keeping every collision
    /// regardless let them fill the budget, and every later row then
    /// rescanned them all.
    #[test]
    fn collisions_are_thinned_when_they_fill_the_plot() {
        let rows = 40_000;
        let out = pushed("bounces", rows, |t| t % 2 == 0);
        assert_eq!((out.written, out.collisions), (rows, rows / 2));
        for marked in [true, false] {
            let times: Vec<f64> = (out.kept.iter())
                .filter(|r| r.event.is_some() == marked)
                .map(|r| r.t)
                .collect();
            assert!(times.len() >= PLOT_ROWS / 4, "{} rows", times.len());
            // Evenly spread: no gap longer than twice the mean one.
            let mean = rows as f64 / times.len() as f64;
            for pair in times.windows(2) {
                assert!(pair[1] - pair[0] <= 2.0 * mean, "{pair:?}, mean gap {mean}");
            }
            assert!(times[0] < mean && times[times.len() - 1] > rows as f64 - 2.0 * mean);
        }
    }

    /// A few collisions in a long run: every one stays marked.
    #[test]
    fn a_few_collisions_all_stay() {
        let out = pushed("rare", 50_000, |t| t % 5_000 == 4_999);
        let marked: Vec<f64> = out
            .kept
            .iter()
            .filter(|r| r.event.is_some())
            .map(|r| r.t)
            .collect();
        assert_eq!(
            marked,
            (1..=10).map(|k| (5_000 * k - 1) as f64).collect::<Vec<_>>()
        );
        assert!(out.kept.len() >= PLOT_ROWS);
    }
}
