//! The interpreter's Taylor series: the plan's transforms of q̈, of each
//! wall's f and of the variational system, each with its time-constant
//! values, run by [`Transform`]'s evaluation in one reused workspace, behind
//! [`TaylorSeries`] as the generated model's `motion_series`,
//! `{wall}_surface_series` and `tangent_series`.

use std::cell::RefCell;

use dalembert_runtime::TaylorSeries;
use dalembert_runtime::taylor::{Coefficients, MAX_ORDER, Series, SeriesWork};

use super::{Interpreted, WallIndex, run_program};
use crate::plan::Plan;
use crate::program::{Evaluation, Transform};

/// The Taylor transforms of q̈ and of each wall's f (the generated model's
/// `motion_series` and `{wall}_surface_series` do the same operations),
/// each with its time-constant values at the current parameters
/// ([`Transform::number_values`]).
#[derive(Clone, Debug)]
pub(super) struct SeriesPrograms {
    motion: (Transform, Vec<f64>),
    walls: Vec<(Transform, Vec<f64>)>,
    /// The variational system's (`tangent_series`), where q̈ has a tangent.
    variational: Option<(Transform, Vec<f64>)>,
    /// The coefficients of one evaluation, reused by every call (a step
    /// of Taylor's method allocates nothing once it has run).
    workspace: RefCell<Evaluation>,
}

impl SeriesPrograms {
    pub(super) fn new(plan: Plan, params: &[f64]) -> Option<Self> {
        let (motion, walls) = plan.series?;
        let with_numbers = |t: Transform| {
            let numbers = t.number_values(params, run_program);
            (t, numbers)
        };
        Some(Self {
            motion: with_numbers(motion),
            walls: walls.into_iter().map(with_numbers).collect(),
            variational: plan.variational.map(with_numbers),
            workspace: RefCell::default(),
        })
    }

    /// Recomputes the time-constant values (the parameters changed).
    pub(super) fn refresh(&mut self, params: &[f64]) {
        let all = std::iter::once(&mut self.motion)
            .chain(&mut self.walls)
            .chain(&mut self.variational);
        for (t, numbers) in all {
            *numbers = t.number_values(params, run_program);
        }
    }
}

impl<const N: usize> TaylorSeries<N> for Interpreted<N> {
    /// The interpreter keeps its room itself (`SeriesPrograms::workspace`,
    /// sized by the first call and reused by every simulator after it).
    type SeriesScratch = ();
    fn taylor_series(&self, series: &mut Series<N>, _: &mut (), order: usize) -> bool {
        let Some(sp) = &self.series else {
            return false;
        };
        let q: [f64; N] = std::array::from_fn(|i| series.q[i][0]);
        let v: [f64; N] = std::array::from_fn(|i| series.v[i][0]);
        let order = order.min(MAX_ORDER);
        let (motion, numbers) = &sp.motion;
        let e = &mut *sp.workspace.borrow_mut();
        motion.motion_into(e, numbers, &q, &v, order);
        for i in 0..N {
            series.q[i] = e.q[i];
            series.v[i] = e.v[i];
        }
        series.order = order;
        true
    }
    fn surface_series(
        &self,
        wall: WallIndex,
        series: &Series<N>,
        _: &mut (),
        out: &mut Coefficients,
    ) -> bool {
        let Some(sp) = &self.series else {
            return false;
        };
        let Some((t, numbers)) = sp.walls.get(wall.0) else {
            return false;
        };
        let e = &mut *sp.workspace.borrow_mut();
        e.q.clear();
        e.q.extend_from_slice(&series.q);
        e.v.clear();
        e.v.extend_from_slice(&series.v);
        *out = t.along(numbers, e, series.order);
        true
    }
    fn variational_series(&self, series: &Series<N>, columns: &mut [Series<N>]) -> bool {
        let Some(sp) = &self.series else {
            return false;
        };
        let Some((t, numbers)) = &sp.variational else {
            return false;
        };
        let order = series.order.min(MAX_ORDER);
        let e = &mut *sp.workspace.borrow_mut();
        for (e, x) in [(&mut e.q, &series.q), (&mut e.v, &series.v)] {
            e.clear();
            e.extend_from_slice(x);
            e.extend_from_slice(x);
        }
        t.shared_into(e, numbers, order);
        for c in columns {
            e.q[N..].copy_from_slice(&c.q);
            e.v[N..].copy_from_slice(&c.v);
            t.tangent_into(e, numbers, order);
            c.q.copy_from_slice(&e.q[N..]);
            c.v.copy_from_slice(&e.v[N..]);
            c.order = order;
        }
        true
    }
    fn series_work(&self) -> Option<SeriesWork> {
        let sp = self.series.as_ref()?;
        Some(SeriesWork {
            motion: sp.motion.0.work(),
            walls: sp.walls.iter().map(|(t, _)| t.work()).sum(),
        })
    }
}
