//! Safe calls into the peers' generated collision maps (peers/generate.py
//! says how each is derived). Every function takes the model's parameters
//! and state as plain values and recomputes everything from them, as the
//! tools' users would call them; each is a call through the C ABI (no
//! inlining across the languages).

use std::os::raw::c_int;

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

/// A chain model's masses m1.. and lengths l1.., read by name from its
/// parameters (the peers' functions take them as arrays).
pub fn masses_and_lengths<M: dalembert::runtime::Model<N, N>, const N: usize>(
    m: &M,
) -> ([f64; N], [f64; N]) {
    let value = |name: String| {
        let i = m
            .parameter_names()
            .iter()
            .position(|p| *p == name)
            .unwrap_or_else(|| panic!("{} has no parameter {name}", m.name()));
        m.parameter(i).expect("in range")
    };
    (
        std::array::from_fn(|k| value(format!("m{}", k + 1))),
        std::array::from_fn(|k| value(format!("l{}", k + 1))),
    )
}
