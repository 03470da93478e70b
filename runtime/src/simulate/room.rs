//! The Taylor engine's buffers: the series of the current step and the
//! model's scratch room for its intermediate series. A simulator holds them
//! only when built for Taylor's method ([`Simulator::with_series`]), by
//! reference, so that a Runge–Kutta simulator of a large model carries none
//! of them (`chain_8`'s are about 87 KiB).
//!
//! [`Simulator::with_series`]: super::Simulator::with_series

use crate::TaylorSeries;
use crate::taylor::{Coefficients, Series, SeriesWork};

/// Room for Taylor's method on `M`: the model, the series of a step, and
/// the model's scratch ([`TaylorSeries::SeriesScratch`]). Build one where
/// it may live as long as the simulator (on the stack, or in a `static`
/// on a microcontroller) and pass it to
/// [`Simulator::with_series`](super::Simulator::with_series).
pub struct SeriesRoom<'m, M: TaylorSeries<N>, const N: usize> {
    model: &'m M,
    series: Series<N>,
    scratch: M::SeriesScratch,
}

impl<'m, M: TaylorSeries<N>, const N: usize> SeriesRoom<'m, M, N> {
    /// Empty room for `model`'s series.
    pub fn new(model: &'m M) -> Self {
        Self {
            model,
            series: Series::at(&[0.0; N], &[0.0; N]),
            scratch: M::SeriesScratch::default(),
        }
    }

    /// The model the room is for.
    pub fn model(&self) -> &'m M {
        self.model
    }
}

/// What the simulator asks of the room, with walls by their index in the
/// model's `walls()`: object safe, so that the simulator's type does not
/// name the model's scratch.
pub(super) trait Room<const N: usize> {
    /// The series last computed.
    fn series(&self) -> &Series<N>;
    /// The series of the motion through (q, v) to `order`; `false` where
    /// the model has none.
    fn expand(&mut self, q: &[f64; N], v: &[f64; N], order: usize) -> bool;
    /// Wall `k`'s f along the series, into `out`; `false` where the model
    /// has none.
    fn surface(&mut self, k: usize, out: &mut Coefficients) -> bool;
    /// [`TaylorSeries::series_work`].
    fn work(&self) -> Option<SeriesWork>;
    /// [`TaylorSeries::variational_series`] along the series, extended to
    /// `order` first where that is higher than its own.
    fn variational(&self, columns: &mut [Series<N>], order: usize) -> bool;
}

impl<M: TaylorSeries<N>, const N: usize> Room<N> for SeriesRoom<'_, M, N> {
    fn series(&self) -> &Series<N> {
        &self.series
    }

    fn expand(&mut self, q: &[f64; N], v: &[f64; N], order: usize) -> bool {
        self.series.restart(q, v);
        self.model
            .taylor_series(&mut self.series, &mut self.scratch, order)
    }

    fn surface(&mut self, k: usize, out: &mut Coefficients) -> bool {
        let m = self.model;
        m.walls()
            .get(k)
            .is_some_and(|&wall| m.surface_series(wall, &self.series, &mut self.scratch, out))
    }

    fn work(&self) -> Option<SeriesWork> {
        self.model.series_work()
    }

    fn variational(&self, columns: &mut [Series<N>], order: usize) -> bool {
        if order <= self.series.order {
            return self.model.variational_series(&self.series, columns);
        }
        // The same series to a higher order (the motion's series is
        // filled from order 0): its coefficients up to its own order are
        // the same (each order's recurrence reads lower ones only),
        // computed in room of its own (the scratch is the simulator's, and
        // this reads the room).
        let mut longer = self.series;
        let scratch = &mut M::SeriesScratch::default();
        self.model.taylor_series(&mut longer, scratch, order)
            && self.model.variational_series(&longer, columns)
    }
}
