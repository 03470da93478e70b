//! Where a run's rows go: the CSV file as they come, a thinned copy for the
//! plot, and the largest energy drift and residuals over every row.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::residual;

/// One output row.
pub struct Row<const N: usize> {
    pub t: f64,
    pub q: [f64; N],
    pub v: [f64; N],
    pub energy: f64,
    pub residual: [f64; 2],
    pub event: Option<String>,
}

impl<const N: usize> Row<N> {
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

/// Rows kept in memory for the plot; the CSV has them all.
const PLOT_ROWS: usize = 4000;

/// Where the rows go: the CSV file as they come, a thinned copy for the
/// plot, and the largest energy drift and residuals over every row.
pub(super) struct Output<const N: usize> {
    file: std::io::BufWriter<std::fs::File>,
    path: PathBuf,
    /// Rows for the plot: every `stride`-th row and every collision.
    pub(super) kept: Vec<Row<N>>,
    stride: usize,
    pub(super) written: usize,
    pub(super) e0: f64,
    pub(super) drift: f64,
    pub(super) worst: [f64; 2],
}

impl<const N: usize> Output<N> {
    pub(super) fn create<M: Surfaces<N>>(model: &M, path: &Path, e0: f64) -> Result<Self, String> {
        let file = std::fs::File::create(path)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        let mut out = Self {
            file: std::io::BufWriter::new(file),
            path: path.to_path_buf(),
            kept: Vec::new(),
            stride: 1,
            written: 0,
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
        header.push_str(",energy,residual_velocity,residual_position,collision\n");
        out.write(&header)?;
        Ok(out)
    }

    fn write(&mut self, text: &str) -> Result<(), String> {
        use std::io::Write as _;
        self.file
            .write_all(text.as_bytes())
            .map_err(|e| format!("cannot write {}: {e}", self.path.display()))
    }

    pub(super) fn push(&mut self, r: Row<N>) -> Result<(), String> {
        let mut line = String::new();
        let _ = write!(line, "{:e}", r.t);
        for x in r.q.iter().chain(&r.v) {
            let _ = write!(line, ",{x:e}");
        }
        let _ = writeln!(
            line,
            ",{:e},{:e},{:e},{}",
            r.energy,
            r.residual[0],
            r.residual[1],
            r.event.as_deref().unwrap_or("")
        );
        self.write(&line)?;
        self.drift = self.drift.max((r.energy - self.e0).abs());
        self.worst = [
            self.worst[0].max(r.residual[0]),
            self.worst[1].max(r.residual[1]),
        ];
        if self.written.is_multiple_of(self.stride) || r.event.is_some() {
            self.kept.push(r);
        }
        self.written += 1;
        if self.kept.len() > 2 * PLOT_ROWS {
            // Thin to every other row, keeping collisions.
            let mut k = 0;
            self.kept.retain(|r| {
                k += 1;
                k % 2 == 1 || r.event.is_some()
            });
            self.stride *= 2;
        }
        Ok(())
    }

    pub(super) fn finish(&mut self) -> Result<(), String> {
        use std::io::Write as _;
        self.file
            .flush()
            .map_err(|e| format!("cannot write {}: {e}", self.path.display()))
    }
}
