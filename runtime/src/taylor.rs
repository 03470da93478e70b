//! Taylor series of the motion: the coefficients a model's series fill
//! ([`Series`], [`Coefficients`]), what they cost ([`Work`],
//! [`SeriesWork`]), and their evaluation ([`eval`]). Taylor's method
//! ([`crate::simulate::Taylor`]) reads them.
//!
//! The recurrences generated code computes them with (one per operation,
//! instruction by instruction over a model's programs) are the generator's
//! and not part of the API: `crate::__private::taylor`.

pub(crate) mod pair;
pub(crate) mod recurrences;
pub(crate) mod solve;

/// Coefficients kept per series: orders 0 to [`MAX_ORDER`].
pub const CAPACITY: usize = 32;

/// The highest order a series holds.
pub const MAX_ORDER: usize = CAPACITY - 1;

/// The coefficients of one function of time.
pub type Coefficients = [f64; CAPACITY];

/// The work of one series program per order, as the generator counts it:
/// a convolution sums k − 1 products at order k, and every operation is
/// finished once per order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Work {
    /// Series operations per order.
    pub operations: usize,
    /// Of them, convolutions (a product, a quotient, a function's
    /// recurrence: a sum over the coefficients so far).
    pub convolutions: usize,
}

impl Work {
    /// Multiply-adds to compute `orders` orders (0 to `orders` − 1):
    /// c·(n − 1)(n − 2)/2 + o·n.
    pub fn multiply_adds(&self, orders: usize) -> f64 {
        let n = orders as f64;
        self.convolutions as f64 * (n - 1.0).max(0.0) * (n - 2.0).max(0.0) / 2.0
            + self.operations as f64 * n
    }
}

impl core::ops::Add for Work {
    type Output = Work;
    fn add(self, other: Work) -> Work {
        Work {
            operations: self.operations + other.operations,
            convolutions: self.convolutions + other.convolutions,
        }
    }
}

impl core::iter::Sum for Work {
    fn sum<I: Iterator<Item = Work>>(works: I) -> Work {
        works.fold(Work::default(), |a, b| a + b)
    }
}

/// What a model's series cost: the motion's (q̈'s program, whose orders 0
/// to p − 1 give the series of order p) and every wall's f along it, summed
/// ([`crate::TaylorSeries::series_work`]). Taylor's method picks its order from
/// it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SeriesWork {
    /// `motion_series`.
    pub motion: Work,
    /// The walls' `surface_series`, summed over the walls.
    pub walls: Work,
}

/// The Taylor series of a state (q(t₀ + τ), q̇(t₀ + τ)) in τ: `q[i][k]` is
/// the k-th normalised coefficient of coordinate i, `v[i][k]` that of
/// velocity i.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Series<const N: usize> {
    /// Coefficients of the coordinates.
    pub q: [Coefficients; N],
    /// Coefficients of the velocities.
    pub v: [Coefficients; N],
    /// The highest order filled in.
    pub order: usize,
}

impl<const N: usize> Series<N> {
    /// The series of order 0 at the state (q, v): only the values.
    pub fn at(q: &[f64; N], v: &[f64; N]) -> Self {
        let mut s = Self {
            q: [[0.0; CAPACITY]; N],
            v: [[0.0; CAPACITY]; N],
            order: 0,
        };
        s.restart(q, v);
        s
    }

    /// Makes this the series of order 0 at (q, v), as [`Series::at`] does,
    /// without clearing the coefficients above order 0: every reader of a
    /// series stops at its `order`, so a buffer reused step after step
    /// need not be zeroed again.
    pub fn restart(&mut self, q: &[f64; N], v: &[f64; N]) {
        for i in 0..N {
            self.q[i][0] = q[i];
            self.v[i][0] = v[i];
        }
        self.order = 0;
    }

    /// The state at τ on the series (Horner's scheme, every component in
    /// step so that the 2N chains run side by side; each is [`eval`]'s).
    pub fn state(&self, tau: f64) -> ([f64; N], [f64; N]) {
        let (mut q, mut v) = ([0.0; N], [0.0; N]);
        for k in (0..=self.order.min(MAX_ORDER)).rev() {
            for i in 0..N {
                q[i] = q[i] * tau + self.q[i][k];
                v[i] = v[i] * tau + self.v[i][k];
            }
        }
        (q, v)
    }
}

/// Σₖ₌₀..order cₖ τᵏ (Horner's scheme).
pub fn eval(c: &Coefficients, order: usize, tau: f64) -> f64 {
    let mut acc = 0.0;
    for x in c[..=order.min(MAX_ORDER)].iter().rev() {
        acc = acc * tau + x;
    }
    acc
}

/// The value and the first derivative in τ of Σₖ₌₀..order cₖ τᵏ.
pub fn eval_with_derivative(c: &Coefficients, order: usize, tau: f64) -> (f64, f64) {
    let (mut p, mut dp) = (0.0, 0.0);
    for x in c[..=order.min(MAX_ORDER)].iter().rev() {
        dp = dp * tau + p;
        p = p * tau + x;
    }
    (p, dp)
}

/// The degree of the polynomial of `order` with coefficients `c`: the
/// highest k ≤ order with cₖ ≠ 0 (0 for the zero polynomial).
pub fn degree(c: &Coefficients, order: usize) -> usize {
    let order = order.min(MAX_ORDER);
    c[..=order].iter().rposition(|x| *x != 0.0).unwrap_or(0)
}
