//! Classical fourth-order Runge–Kutta with a fixed step, cubic Hermite
//! dense output.

use super::super::phase::{Combine, Phase};
use super::{Dense, Method, Trial};

/// Classical fourth-order Runge–Kutta with a fixed step (the last step
/// before the horizon is shortened to end on it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rk4 {
    /// The step.
    pub step: f64,
}

const WEIGHTS: [f64; 4] = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];

impl Method for Rk4 {
    fn valid(&self) -> bool {
        self.step > 0.0 && self.step.is_finite()
    }

    fn adaptive(&self) -> bool {
        false
    }

    fn initial_step<const N: usize>(&self, _: &Phase<N>, _: &Phase<N>) -> f64 {
        self.step
    }

    fn max_step(&self) -> f64 {
        self.step
    }

    fn factor(&self, _: f64) -> f64 {
        1.0
    }

    fn advance<Y: Combine, E>(
        &self,
        rhs: &mut impl FnMut(f64, &Y) -> Result<Y, E>,
        y0: &Y,
        f0: &Y,
        t0: f64,
        h: f64,
    ) -> Result<(Y, Option<Y>), E> {
        let mut k = [*f0; 4];
        k[1] = rhs(t0 + h / 2.0, &y0.plus(h, &[(0.5, &k[0])]))?;
        k[2] = rhs(t0 + h / 2.0, &y0.plus(h, &[(0.5, &k[1])]))?;
        k[3] = rhs(t0 + h, &y0.plus(h, &[(1.0, &k[2])]))?;
        let terms: [(f64, &Y); 4] = core::array::from_fn(|j| (WEIGHTS[j], &k[j]));
        Ok((y0.plus(h, &terms), None))
    }

    fn estimate<Y: Combine, E>(
        &self,
        rhs: &mut impl FnMut(f64, &Y) -> Result<Y, E>,
        y0: &Y,
        f0: &Y,
        t0: f64,
        h: f64,
    ) -> Result<(Y, f64), E> {
        Ok((self.advance(rhs, y0, f0, t0, h)?.0, 0.0))
    }

    fn trial<const N: usize, E>(
        &self,
        rhs: &mut impl FnMut(f64, &Phase<N>) -> Result<Phase<N>, E>,
        y0: &Phase<N>,
        f0: &Phase<N>,
        t0: f64,
        h: f64,
    ) -> Result<Trial<N>, E> {
        let (y1, _) = self.advance(rhs, y0, f0, t0, h)?;
        let f1 = rhs(t0 + h, &y1)?;
        Ok(Trial {
            y1,
            f1,
            error: 0.0,
            dense: Dense::Hermite {
                y0: *y0,
                y1,
                f0: *f0,
                f1,
            },
        })
    }
}
