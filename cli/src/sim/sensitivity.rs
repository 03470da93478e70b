//! `simulate --sensitivity` and `--phi`: Φ = ∂x(t)/∂x(0) followed through
//! the run (`simulate::Variational`), why it could not follow a step, the
//! growth the summary reports, and the entries written to the CSV.

use dalembert::runtime::prelude::*;
use dalembert::runtime::saltation::StateMatrix;
use dalembert::runtime::simulate::{State, Variational, VariationalError, tangent_direction};

/// Why Φ could not follow the run, naming walls as the model file does.
pub(crate) fn failure<M: Surfaces<N>, const N: usize>(
    model: &M,
    e: VariationalError<M::Wall>,
) -> String {
    let e = match e {
        VariationalError::Saltation { wall, error } => {
            format!("at the collision with `{}`: {error}", model.wall_name(wall))
        }
        VariationalError::NoDerivative => {
            "the model has no derivative of q̈ (no closed form or elimination written out)"
                .to_string()
        }
        other => format!("{other:?}"),
    };
    format!("Φ could not follow the run: {e}")
}

/// The growth of the perturbation of every coordinate and velocity by the
/// same amount, moved onto the admissible directions at the start.
pub(super) fn report<M: Surfaces<N>, const N: usize>(
    model: &M,
    start: &State<N>,
    t: f64,
    phi: &Variational<N>,
) -> Result<(), String> {
    let (dq, dv) = tangent_direction(model, &start.q, &start.v, &[1.0; N], &[1.0; N])
        .map_err(|e| format!("no admissible perturbation at the start: {e:?}"))?;
    let size = |q: &[f64; N], v: &[f64; N]| q.iter().chain(v).map(|x| x * x).sum::<f64>().sqrt();
    let (pq, pv) = phi.matrix().apply(&dq, &dv);
    let growth = size(&pq, &pv) / size(&dq, &dv);
    println!(
        "  sensitivity: |Φ δx₀|/|δx₀| = {growth:.6e} at t = {t} (δx₀: every coordinate and velocity +1, made admissible); rate ln(·)/t = {:.6e}",
        growth.ln() / t
    );
    Ok(())
}

/// Entries of Φ written as CSV columns (`--phi`): each the derivative of a
/// coordinate or velocity at t by one at the start.
pub(super) struct Columns {
    /// (row, column) of Φ over x = (q, q̇).
    entries: Vec<(usize, usize)>,
    /// Their CSV headers, `dA/dB(0)`.
    pub(super) names: Vec<String>,
}

impl Columns {
    /// The entries `spec` names: `A/B` pairs separated by commas, A and B
    /// coordinate or velocity names of `model`, or `all` for every entry
    /// (row by row).
    pub(super) fn parse<M: Surfaces<N>, const N: usize>(
        model: &M,
        spec: &str,
    ) -> Result<Self, String> {
        let names: Vec<&str> = (model.coordinate_names().iter())
            .chain(model.velocity_names())
            .copied()
            .collect();
        let index = |name: &str| {
            names.iter().position(|n| *n == name.trim()).ok_or_else(|| {
                format!(
                    "--phi: `{}` is not a coordinate or velocity of {} ({})",
                    name.trim(),
                    model.name(),
                    names.join(", ")
                )
            })
        };
        let entries = if spec.trim() == "all" {
            (0..2 * N)
                .flat_map(|i| (0..2 * N).map(move |j| (i, j)))
                .collect()
        } else {
            spec.split(',')
                .map(|entry| {
                    let (a, b) = entry.split_once('/').ok_or_else(|| {
                        format!(
                            "--phi `{entry}`: write the entry as A/B, the derivative of A at t by B at the start (e.g. {0}/{0})",
                            names[0]
                        )
                    })?;
                    Ok((index(a)?, index(b)?))
                })
                .collect::<Result<Vec<_>, String>>()?
        };
        let names = entries
            .iter()
            .map(|&(i, j)| format!("d{}/d{}(0)", names[i], names[j]))
            .collect();
        Ok(Self { entries, names })
    }

    /// The entries' values in `phi`.
    pub(super) fn values<const N: usize>(&self, phi: &StateMatrix<N>) -> Vec<f64> {
        self.entries
            .iter()
            .map(|&(i, j)| {
                let block = match (i < N, j < N) {
                    (true, true) => &phi.qq,
                    (true, false) => &phi.qv,
                    (false, true) => &phi.vq,
                    (false, false) => &phi.vv,
                };
                block[i % N][j % N]
            })
            .collect()
    }
}
