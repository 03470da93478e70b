//! `simulate --sensitivity`, `--phi` and `--by`: Φ = ∂x(t)/∂x(0) and
//! ∂x(t)/∂p followed through the run (`simulate::Variational`,
//! `simulate::ParameterSensitivity`), why they could not follow a step,
//! what the summary reports, and the columns written to the CSV.

use dalembert::runtime::prelude::*;
use dalembert::runtime::saltation::StateMatrix;
use dalembert::runtime::simulate::{
    ParameterSensitivity, Simulator, State, Step, Variational, VariationalError, tangent_direction,
};

use crate::run::starting_state;

/// What a run follows besides its state, and the CSV columns that adds:
/// Φ (`--sensitivity`, `--phi`, whose entries are columns) and the
/// derivatives by the parameters `--by` names (2N columns each).
pub(super) struct Followed<'p, const N: usize> {
    pub(super) phi: Option<Variational<N>>,
    columns: Option<Columns>,
    /// The parameters' names, with their derivatives.
    by: Vec<(&'p str, ParameterSensitivity<'p, N>)>,
    /// The added columns' headers.
    pub(super) names: Vec<String>,
}

impl<'p, const N: usize> Followed<'p, N> {
    /// Φ when `phi` (its entries `columns` written), and one derivative
    /// for each of `by`: a parameter's name, its unit direction and the
    /// start's derivative along it; `rtol` as for [`Variational::new`].
    pub(super) fn new<M: Surfaces<N>>(
        model: &M,
        (phi, columns): (bool, Option<Columns>),
        by: &'p [ByParameter<N>],
        rtol: f64,
    ) -> Self {
        let mut names = columns.as_ref().map_or(Vec::new(), |c| c.names.clone());
        let state_names = state_names(model);
        for p in by {
            names.extend(state_names.iter().map(|a| format!("d{a}/d{}", p.name)));
            names.push(format!("dt_collision/d{}", p.name));
        }
        Self {
            phi: (phi || columns.is_some()).then(|| Variational::new(rtol)),
            columns,
            by: by
                .iter()
                .map(|p| {
                    let (dq, dv) = p.start;
                    let s = ParameterSensitivity::new(&p.direction, rtol).starting_at(dq, dv);
                    (p.name.as_str(), s)
                })
                .collect(),
            names,
        }
    }

    /// Whether the CSV has columns of ours (whose rows must be steps' ends).
    pub(super) fn writes_columns(&self) -> bool {
        !self.names.is_empty()
    }

    /// Follows `step`, the step `sim` has just made; why not, naming walls
    /// as the model file does.
    pub(super) fn follow<M: Surfaces<N>>(
        &mut self,
        model: &M,
        sim: &Simulator<'_, M, N>,
        step: &Step<M::Wall, N>,
    ) -> Result<(), String> {
        if let Some(phi) = &mut self.phi {
            phi.follow(sim, step).map_err(|e| failure(model, "Φ", e))?;
        }
        for (p, s) in &mut self.by {
            (s.follow(sim, step)).map_err(|e| failure(model, &format!("∂x/∂{p}"), e))?;
        }
        Ok(())
    }

    /// The columns' values now, or just before the last step's collision
    /// (`before`). A derivative of the collision instant by a parameter
    /// is on the row before its collision; on the other rows its cell is
    /// empty (`None`).
    pub(super) fn values(&self, before: bool) -> Vec<Option<f64>> {
        let mut out = Vec::with_capacity(self.names.len());
        if let (Some(columns), Some(phi)) = (&self.columns, &self.phi) {
            let (m, gradient) = if before {
                (phi.before_collision(), phi.collision_gradient())
            } else {
                (phi.matrix(), None)
            };
            out.extend(columns.values(m, gradient));
        }
        for (_, s) in &self.by {
            let (dq, dv) = if before {
                s.before_collision()
            } else {
                s.value()
            };
            out.extend(dq.iter().chain(&dv).copied().map(Some));
            out.push(s.collision_shift().filter(|_| before));
        }
        out
    }

    /// The summary's lines: Φ's growth, and each derivative by a
    /// parameter at the end.
    pub(super) fn report<M: Surfaces<N>>(
        &self,
        model: &M,
        start: &State<N>,
        t: f64,
    ) -> Result<(), String> {
        if let Some(phi) = &self.phi {
            report(model, start, t, phi)?;
        }
        let names = state_names(model);
        for (p, s) in &self.by {
            let (dq, dv) = s.value();
            let values: Vec<String> = (names.iter().zip(dq.iter().chain(&dv)))
                .map(|(a, d)| format!("{a} {d:.6e}"))
                .collect();
            println!("  ∂/∂{p} at t = {t}: {}", values.join(", "));
        }
        Ok(())
    }
}

/// The names of the state's components: the coordinates, then the
/// velocities.
fn state_names<M: Surfaces<N>, const N: usize>(model: &M) -> Vec<&str> {
    (model.coordinate_names().iter())
        .chain(model.velocity_names())
        .copied()
        .collect()
}

/// A parameter the run is differentiated by (`--by`).
pub(super) struct ByParameter<const N: usize> {
    name: String,
    /// Its unit direction among the model's parameters.
    direction: Vec<f64>,
    /// The start's derivative by it, (∂q₀/∂p, ∂q̇₀/∂p).
    start: ([f64; N], [f64; N]),
}

/// For each parameter `spec` names (`--by`, names separated by commas):
/// its name, its unit direction, and the derivative along it of the start
/// `set` gives ([`starting_state`], whose `[initial]` may depend on the
/// parameters; coordinates that leave h(q) = 0 as p moves are taken to
/// their nearest point on it, and a note says so), by
/// Richardson-extrapolated central differences with the parameter moved by
/// 10⁻³|p| (10⁻³ at p = 0) and half that; `model` is left as it came.
pub(super) fn by_parameters<M: Surfaces<N>, const N: usize>(
    model: &mut M,
    set: &[(String, f64)],
    derived: &[String],
    spec: &str,
) -> Result<Vec<ByParameter<N>>, String> {
    let all: Vec<String> = model
        .parameter_names()
        .iter()
        .map(|p| p.to_string())
        .collect();
    let mut out = Vec::new();
    for name in spec.split(',').map(str::trim) {
        let Some(k) = all.iter().position(|p| p == name) else {
            let model_name = model.name();
            let list = if all.is_empty() {
                "it has none".to_string()
            } else {
                all.join(", ")
            };
            return Err(if derived.iter().any(|d| d == name) {
                format!(
                    "--by: `{name}` is a derived parameter of {model_name} (computed from others): differentiate by those it is computed from (parameters: {list})"
                )
            } else {
                format!("--by: `{name}` is not a parameter of {model_name} (parameters: {list})")
            });
        };
        if out.iter().any(|p: &ByParameter<N>| p.name == name) {
            return Err(format!("--by: `{name}` is named twice"));
        }
        let p0 = model.parameter(k).expect("a parameter of the model's list");
        let mut moved = false;
        let mut at = |p: f64| -> Result<Vec<f64>, String> {
            model.set_parameter(k, p);
            let start = starting_state(set, &*model, true)
                .map_err(|e| format!("--by {name}: with {name} = {p}, {e}"))?;
            moved |= start.moved;
            let x = start.state;
            Ok(x.q.iter().chain(&x.v).copied().collect())
        };
        // Relative to p, so that a small positive parameter (a mass, a
        // length under a root) stays positive; absolute at p = 0.
        let h = if p0 == 0.0 { 1e-3 } else { 1e-3 * p0.abs() };
        let mut central = |h: f64| -> Result<Vec<f64>, String> {
            let (plus, minus) = (at(p0 + h)?, at(p0 - h)?);
            Ok((plus.iter().zip(&minus))
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect())
        };
        let derivative = central(h).and_then(|coarse| {
            let fine = central(h / 2.0)?;
            Ok((fine.iter().zip(&coarse))
                .map(|(f, c)| (4.0 * f - c) / 3.0)
                .collect::<Vec<f64>>())
        });
        model.set_parameter(k, p0);
        let d = derivative?;
        if d.iter().any(|x| !x.is_finite()) {
            return Err(format!(
                "--by {name}: the start is not differentiable by {name} at {name} = {p0} (its differences are not finite)"
            ));
        }
        if moved {
            eprintln!(
                "note: --by {name}: the start's coordinates leave the holonomic constraints h(q) = 0 as {name} moves; the start's derivative is that of their nearest point on them (in the metric of G)"
            );
        }
        out.push(ByParameter {
            name: name.to_string(),
            direction: (0..all.len())
                .map(|i| f64::from(u8::from(i == k)))
                .collect(),
            start: (
                core::array::from_fn(|i| d[i]),
                core::array::from_fn(|i| d[N + i]),
            ),
        });
    }
    Ok(out)
}

/// Why `what` (Φ, or a derivative by a parameter) could not follow the
/// run, naming walls as the model file does.
pub(crate) fn failure<M: Surfaces<N>, const N: usize>(
    model: &M,
    what: &str,
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
    format!("{what} could not follow the run: {e}")
}

/// The growth of the perturbation of every coordinate and velocity by the
/// same amount, moved onto the admissible directions at the start.
fn report<M: Surfaces<N>, const N: usize>(
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
    /// The start's components the entries are by (each once, in their
    /// order): the collision instant's derivative by each is a column too.
    starts: Vec<usize>,
    /// Their CSV headers, `dA/dB(0)`, then `dt_collision/dB(0)`.
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
        let names = state_names(model);
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
        let mut starts: Vec<usize> = Vec::new();
        for &(_, j) in &entries {
            if !starts.contains(&j) {
                starts.push(j);
            }
        }
        let names = (entries.iter())
            .map(|&(i, j)| format!("d{}/d{}(0)", names[i], names[j]))
            .chain(
                starts
                    .iter()
                    .map(|&j| format!("dt_collision/d{}(0)", names[j])),
            )
            .collect();
        Ok(Self {
            entries,
            starts,
            names,
        })
    }

    /// The entries' values in `phi` (Φ, or Φ⁻ on the row before a
    /// collision), then the collision instant's derivative by each start
    /// component, `gradient` (∂t*/∂q₀, ∂t*/∂q̇₀): on the row before a
    /// collision only, empty (`None`) on the others.
    pub(super) fn values<const N: usize>(
        &self,
        phi: &StateMatrix<N>,
        gradient: Option<([f64; N], [f64; N])>,
    ) -> Vec<Option<f64>> {
        let entries = self.entries.iter().map(|&(i, j)| {
            let block = match (i < N, j < N) {
                (true, true) => &phi.qq,
                (true, false) => &phi.qv,
                (false, true) => &phi.vq,
                (false, false) => &phi.vv,
            };
            Some(block[i % N][j % N])
        });
        let instants = self
            .starts
            .iter()
            .map(|&j| gradient.map(|(by_q, by_v)| if j < N { by_q[j] } else { by_v[j - N] }));
        entries.chain(instants).collect()
    }
}
