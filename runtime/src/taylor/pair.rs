//! Two histories summed side by side in one vector register.
//!
//! A generated series sums each convolution's history, Σⱼ₌₁..ₖ₋₁ aⱼ bₖ₋ⱼ,
//! in one loop over j for all of a program's convolutions. Two histories
//! whose operands are kept side by side (`Pair`s: aⱼ beside cⱼ, bᵣ beside
//! dᵣ) take one load of each pair, one vector multiplication and one vector
//! addition per j instead of two of each; the generator keeps those pairs
//! in the caller's `SeriesScratch`, written once per order.
//!
//! Each lane is multiplied and then added, rounded twice, as the scalar
//! recurrences are (never fused): a paired sum has the same bits as the
//! same sum taken alone. Where SSE2 is enabled (every x86-64 target) a
//! pair is one SSE register, through `safe_arch`'s safe wrappers; elsewhere
//! it is two `f64`s, which the compiler may vectorise on its own.

use super::CAPACITY;

#[cfg(target_feature = "sse2")]
pub use sse2::Pair;

#[cfg(not(target_feature = "sse2"))]
pub use portable::Pair;

/// One pair of series' coefficients, orders 0 to [`super::MAX_ORDER`].
pub type Pairs = [Pair; CAPACITY];

#[cfg(target_feature = "sse2")]
mod sse2 {
    use safe_arch::{add_m128d, m128d, mul_m128d, set_m128d};

    /// Coefficient j of two series side by side, or two histories'
    /// running sums: one SSE register.
    #[derive(Clone, Copy, Debug, Default)]
    pub struct Pair(m128d);

    impl Pair {
        /// `a` in the first lane, `b` in the second.
        ///
        /// Built in a register and written with one 16-byte store: two
        /// 8-byte stores read back by one 16-byte load (the next order's
        /// history loop) cannot be forwarded from the store buffer, and
        /// stall it.
        #[inline(always)]
        pub fn new(a: f64, b: f64) -> Pair {
            Pair(set_m128d(b, a))
        }

        /// `self + a·b` lane by lane: the product rounded, then the sum
        /// (no fused multiply-add, so each lane is the scalar `h + a * b`).
        #[inline(always)]
        pub fn add_product(self, a: Pair, b: Pair) -> Pair {
            Pair(add_m128d(self.0, mul_m128d(a.0, b.0)))
        }

        /// The two lanes.
        #[inline(always)]
        pub fn lanes(self) -> (f64, f64) {
            let [a, b] = self.0.to_array();
            (a, b)
        }
    }
}

/// The same without SSE2 (and in the tests, to check it against SSE2).
#[cfg(any(not(target_feature = "sse2"), test))]
mod portable {
    /// Coefficient j of two series side by side, or two histories'
    /// running sums: two `f64`s.
    #[derive(Clone, Copy, Debug, Default)]
    #[repr(align(16))]
    pub struct Pair([f64; 2]);

    impl Pair {
        /// `a` in the first lane, `b` in the second.
        #[inline(always)]
        pub fn new(a: f64, b: f64) -> Pair {
            Pair([a, b])
        }

        /// `self + a·b` lane by lane: the product rounded, then the sum.
        #[inline(always)]
        pub fn add_product(self, a: Pair, b: Pair) -> Pair {
            Pair([self.0[0] + a.0[0] * b.0[0], self.0[1] + a.0[1] * b.0[1]])
        }

        /// The two lanes.
        #[inline(always)]
        pub fn lanes(self) -> (f64, f64) {
            (self.0[0], self.0[1])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CASES: [(f64, f64, f64); 5] = [
        (1.0 + f64::EPSILON, 1.0 - f64::EPSILON, -1.0),
        (0.1, 0.7, 0.3),
        (1e16, 1.0 + 1e-16, -1e16),
        (3.0, 1.0 / 3.0, -1.0),
        (-0.0, 2.0, 0.0),
    ];

    /// A paired sum has each lane's scalar bits, at values where a fused
    /// multiply-add would round differently, with or without SSE2.
    #[test]
    fn lanes_round_as_scalars() {
        for &(a, b, h) in &CASES {
            for &(c, d, g) in &CASES {
                let sum = Pair::new(h, g).add_product(Pair::new(a, c), Pair::new(b, d));
                let plain = portable::Pair::new(h, g)
                    .add_product(portable::Pair::new(a, c), portable::Pair::new(b, d));
                let (first, second) = sum.lanes();
                assert_eq!(first.to_bits(), (h + a * b).to_bits());
                assert_eq!(second.to_bits(), (g + c * d).to_bits());
                let (p, q) = plain.lanes();
                assert_eq!(
                    (p.to_bits(), q.to_bits()),
                    (first.to_bits(), second.to_bits())
                );
            }
        }
        // A sum starts from +0, as a scalar history does.
        for (first, second) in [Pair::default().lanes(), portable::Pair::default().lanes()] {
            assert_eq!((first.to_bits(), second.to_bits()), (0, 0));
        }
        // The first case would differ if fused: a·b = 1 − ε², rounded to 1.
        let (a, b) = (1.0 + f64::EPSILON, 1.0 - f64::EPSILON);
        assert_ne!((-1.0 + a * b).to_bits(), libm::fma(a, b, -1.0).to_bits());
    }
}
