//! Safe calls into the peers' generated collision maps (peers/generate.py
//! says how each is derived). Every function takes the model's parameters
//! and state as plain values and recomputes everything from them, as the
//! tools' users would call them; each is a call through the C ABI (no
//! inlining across the languages).

use std::hint::black_box;
use std::os::raw::c_int;

use dalembert::runtime::prelude::*;

mod ffi {
    use std::os::raw::c_int;

    /// CasADi's generated entry point: input and output arrays, integer and
    /// real work arrays (empty for these functions), memory slot.
    pub type Casadi = unsafe extern "C" fn(
        arg: *const *const f64,
        res: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        mem: c_int,
    ) -> c_int;

    /// The wrapper of a SymForce chain map: q, v, m, l, out.
    pub type SymforceChain =
        unsafe extern "C" fn(*const f64, *const f64, *const f64, *const f64, *mut f64);

    unsafe extern "C" {
        pub fn sf_ball_wall(m: f64, r: f64, j: f64, v: *const f64, out: *mut f64);
        pub fn sf_ball_floor(m: f64, r: f64, j: f64, v: *const f64, out: *mut f64);
        pub fn ca_ball_wall(
            a: *const *const f64,
            r: *const *mut f64,
            iw: *mut i64,
            w: *mut f64,
            mem: c_int,
        ) -> c_int;
        pub fn ca_ball_floor(
            a: *const *const f64,
            r: *const *mut f64,
            iw: *mut i64,
            w: *mut f64,
            mem: c_int,
        ) -> c_int;
    }

    /// The chains' entry points, and each tool's by number of links.
    macro_rules! chains {
        ($($n:literal: $sf:ident, $ca:ident;)*) => {
            unsafe extern "C" {
                $(
                    pub fn $sf(q: *const f64, v: *const f64, m: *const f64, l: *const f64, o: *mut f64);
                    pub fn $ca(a: *const *const f64, r: *const *mut f64, iw: *mut i64, w: *mut f64, mem: c_int) -> c_int;
                )*
            }
            pub fn symforce_chain(n: usize) -> Option<SymforceChain> {
                match n {
                    $($n => Some($sf as SymforceChain),)*
                    _ => None,
                }
            }
            pub fn casadi_chain(n: usize) -> Option<Casadi> {
                match n {
                    $($n => Some($ca as Casadi),)*
                    _ => None,
                }
            }
        };
    }

    chains! {
        1: sf_chain_1, ca_chain_1;
        2: sf_chain_2, ca_chain_2;
        3: sf_chain_3, ca_chain_3;
        4: sf_chain_4, ca_chain_4;
        5: sf_chain_5, ca_chain_5;
        6: sf_chain_6, ca_chain_6;
        7: sf_chain_7, ca_chain_7;
        8: sf_chain_8, ca_chain_8;
    }
}

/// Runs a CasADi function whose inputs are `args` (each an array of the
/// length the function expects) and whose one output has N entries.
fn casadi<const N: usize>(f: ffi::Casadi, args: &[*const f64]) -> [f64; N] {
    let mut out = [0.0; N];
    let res = [out.as_mut_ptr()];
    // SAFETY: the generated function reads one array per input, of the
    // sizes the callers below pass, writes N values to its output, and
    // needs no work arrays (its `_work` reports sizes 0).
    let rc: c_int = unsafe {
        f(
            args.as_ptr(),
            res.as_ptr(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            0,
        )
    };
    assert_eq!(rc, 0, "CasADi function failed");
    out
}

/// SymForce's §3.1 map (P simplified, then (I − 2P)v).
pub fn symforce_ball_wall(m: f64, r: f64, j: f64, v: &[f64; 5]) -> [f64; 5] {
    let mut out = [0.0; 5];
    // SAFETY: reads 5 values of v, writes 5 to out.
    unsafe { ffi::sf_ball_wall(m, r, j, v.as_ptr(), out.as_mut_ptr()) };
    out
}

/// SymForce's §3.2 map.
pub fn symforce_ball_floor(m: f64, r: f64, j: f64, v: &[f64; 6]) -> [f64; 6] {
    let mut out = [0.0; 6];
    // SAFETY: reads 6 values of v, writes 6 to out.
    unsafe { ffi::sf_ball_floor(m, r, j, v.as_ptr(), out.as_mut_ptr()) };
    out
}

/// CasADi's §3.1 map, from the same simplified matrix.
pub fn casadi_ball_wall(m: f64, r: f64, j: f64, v: &[f64; 5]) -> [f64; 5] {
    casadi(ffi::ca_ball_wall, &[&m, &r, &j, v.as_ptr()])
}

/// CasADi's §3.2 map.
pub fn casadi_ball_floor(m: f64, r: f64, j: f64, v: &[f64; 6]) -> [f64; 6] {
    casadi(ffi::ca_ball_floor, &[&m, &r, &j, v.as_ptr()])
}

/// The n-link chain's v⁺ at (q, v) for masses m and lengths l, in
/// SymForce's code (N = 1..=8; the lookup by N folds away).
#[inline]
pub fn symforce_chain<const N: usize>(
    q: &[f64; N],
    v: &[f64; N],
    m: &[f64; N],
    l: &[f64; N],
) -> [f64; N] {
    let f = ffi::symforce_chain(N).expect("chains of 1 to 8 links are generated");
    let mut out = [0.0; N];
    // SAFETY: the N-link wrapper reads N values of each input and writes N.
    unsafe {
        f(
            q.as_ptr(),
            v.as_ptr(),
            m.as_ptr(),
            l.as_ptr(),
            out.as_mut_ptr(),
        )
    };
    out
}

/// The same in CasADi's code.
#[inline]
pub fn casadi_chain<const N: usize>(
    q: &[f64; N],
    v: &[f64; N],
    m: &[f64; N],
    l: &[f64; N],
) -> [f64; N] {
    let f = ffi::casadi_chain(N).expect("chains of 1 to 8 links are generated");
    casadi(f, &[q.as_ptr(), v.as_ptr(), m.as_ptr(), l.as_ptr()])
}

/// The n-link chain as the peers benches take it: the model with the model
/// file's parameters at its initial configuration, its masses and lengths
/// as the peers' functions take them, and its wall; each way of computing
/// the collision map at that configuration.
pub struct Chain<M: Surfaces<N>, const N: usize> {
    pub model: M,
    pub q: [f64; N],
    m: [f64; N],
    l: [f64; N],
    wall: M::Wall,
}

impl<M: Surfaces<N> + Default, const N: usize> Chain<M, N> {
    pub fn new() -> Self {
        let model = M::default();
        let q = model.initial_coordinates();
        let value = |name: String| {
            let i = model
                .parameter_names()
                .iter()
                .position(|p| *p == name)
                .unwrap_or_else(|| panic!("{} has no parameter {name}", model.name()));
            model.parameter(i).expect("in range")
        };
        let m = std::array::from_fn(|k| value(format!("m{}", k + 1)));
        let l = std::array::from_fn(|k| value(format!("l{}", k + 1)));
        let wall = model.walls()[0];
        Self {
            model,
            q,
            m,
            l,
            wall,
        }
    }

    /// A velocity around the chain bench's (`benches/collision.rs`,
    /// 0.3 − 0.1 i) from uniform numbers u in [−2, 2): 0.3 − 0.1 i + u/2.
    pub fn velocity(u: [f64; N]) -> [f64; N] {
        std::array::from_fn(|i| 0.3 - 0.1 * i as f64 + 0.5 * u[i])
    }

    /// v⁺ by the generated map (through `Walls::collide`).
    #[inline]
    pub fn generated(&self, v: &[f64; N]) -> [f64; N] {
        black_box(&self.model).collide(self.wall, black_box(&self.q), v)
    }

    /// v⁺ by SymForce's code.
    #[inline]
    pub fn symforce(&self, v: &[f64; N]) -> [f64; N] {
        symforce_chain(
            black_box(&self.q),
            v,
            black_box(&self.m),
            black_box(&self.l),
        )
    }

    /// v⁺ by CasADi's code.
    #[inline]
    pub fn casadi(&self, v: &[f64; N]) -> [f64; N] {
        casadi_chain(
            black_box(&self.q),
            v,
            black_box(&self.m),
            black_box(&self.l),
        )
    }
}

impl<M: Surfaces<N> + Default, const N: usize> Default for Chain<M, N> {
    fn default() -> Self {
        Self::new()
    }
}
