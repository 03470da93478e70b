//! `simulate --sensitivity`: Φ = ∂x(t)/∂x(0) followed through the run
//! (`simulate::Variational`), why it could not follow a step, and the
//! growth the summary reports.

use dalembert::runtime::prelude::*;
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
