//! The paper's Theorems 3.1 and 3.2 written by hand, the anchors the
//! generated collision maps are measured against (`benches/collision.rs`,
//! `peers/benches/peers.rs`): once recomputing the parameter combinations on
//! every call, once with them computed when the parameters are set.

/// Theorem 3.1 for admissible v = (v1, v2, w1, w2, w3), with w1, w2 of v⁺ from
/// the rolling constraints (3.1), recomputing the parameter combinations.
pub fn hand_3_1(m: f64, r: f64, j: f64, v: &[f64; 5]) -> [f64; 5] {
    Hand31::new(m, r, j).collide(v)
}

/// Theorem 3.1 with the parameter combinations computed once.
pub struct Hand31 {
    a: f64,
    b: f64,
    c: f64,
    r: f64,
}

impl Hand31 {
    pub fn new(m: f64, r: f64, j: f64) -> Self {
        let jt = j + 0.5 * r * r * m; // J~
        let jp = j + r * r * m; // J'
        let inv = 1.0 / jt;
        Self {
            a: 0.5 * r * r * m * inv,
            b: r * j * inv,
            c: jp * inv / r,
            r,
        }
    }

    #[inline]
    pub fn collide(&self, v: &[f64; 5]) -> [f64; 5] {
        let v1 = -v[0];
        let v2 = self.a * v[1] + self.b * v[4];
        let w3 = self.c * v[1] - self.a * v[4];
        [v1, v2, -v2 / self.r, v1 / self.r, w3]
    }
}

/// Theorem 3.2, recomputing the parameter combinations.
pub fn hand_3_2(m: f64, r: f64, j: f64, v: &[f64; 6]) -> [f64; 6] {
    Hand32::new(m, r, j).collide(v)
}

/// Theorem 3.2 with the parameter combinations computed once.
pub struct Hand32 {
    a: f64,
    b: f64,
    c: f64,
}

impl Hand32 {
    pub fn new(m: f64, r: f64, j: f64) -> Self {
        let inv = 1.0 / (j + r * r * m); // 1/J'
        Self {
            a: (m * r * r - j) * inv,
            b: 2.0 * j * r * inv,
            c: 2.0 * r * m * inv,
        }
    }

    #[inline]
    pub fn collide(&self, v: &[f64; 6]) -> [f64; 6] {
        let (a, b, c) = (self.a, self.b, self.c);
        [
            a * v[0] + b * v[4],
            a * v[1] - b * v[3],
            -v[2],
            -c * v[1] - a * v[3],
            c * v[0] - a * v[4],
            v[5],
        ]
    }
}
