//! Criterion measured in CPU time rather than wall time: on a shared
//! machine, time spent descheduled is not counted against the code.
//! [`ThreadCpuTime`] counts the calling thread (`CLOCK_THREAD_CPUTIME_ID`);
//! [`ProcessCpuTime`] counts the process and its waited children
//! (`getrusage`), for a bench that runs a command.

use criterion::Throughput;
use criterion::measurement::{Measurement, ValueFormatter};

/// The thread's CPU time, in nanoseconds.
pub struct ThreadCpuTime;

/// The CPU time (user and system) of the process and of its children that
/// have been waited for, in nanoseconds.
#[allow(dead_code)] // only the benches that run a command use it
pub struct ProcessCpuTime;

/// The calling thread's CPU time so far, in nanoseconds.
pub fn now_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a
    // constant every Linux and macOS kernel supports.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID) failed");
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

/// The process's and its waited children's CPU time so far, in nanoseconds.
#[allow(dead_code)] // with `ProcessCpuTime`
fn process_ns() -> u64 {
    let used = |who| {
        // SAFETY: an all-zero rusage is valid, and getrusage only writes it.
        let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
        // SAFETY: `usage` is a valid, writable rusage; `who` is a constant
        // every Unix supports.
        assert_eq!(unsafe { libc::getrusage(who, &mut usage) }, 0);
        let ns = |t: libc::timeval| t.tv_sec as u64 * 1_000_000_000 + t.tv_usec as u64 * 1000;
        ns(usage.ru_utime) + ns(usage.ru_stime)
    };
    used(libc::RUSAGE_SELF) + used(libc::RUSAGE_CHILDREN)
}

/// Criterion's measurement for a clock in nanoseconds.
macro_rules! cpu_measurement {
    ($ty:ident, $now:path) => {
        impl Measurement for $ty {
            type Intermediate = u64;
            type Value = u64;

            fn start(&self) -> u64 {
                $now()
            }
            fn end(&self, start: u64) -> u64 {
                $now().saturating_sub(start)
            }
            fn add(&self, a: &u64, b: &u64) -> u64 {
                a + b
            }
            fn zero(&self) -> u64 {
                0
            }
            fn to_f64(&self, value: &u64) -> f64 {
                *value as f64
            }
            fn formatter(&self) -> &dyn ValueFormatter {
                &CpuFormatter
            }
        }
    };
}

cpu_measurement!(ThreadCpuTime, now_ns);
cpu_measurement!(ProcessCpuTime, process_ns);

/// Nanoseconds shown in ns, µs, ms or s.
struct CpuFormatter;

impl CpuFormatter {
    fn unit(typical: f64) -> (f64, &'static str) {
        if typical < 1e3 {
            (1.0, "ns (cpu)")
        } else if typical < 1e6 {
            (1e-3, "µs (cpu)")
        } else if typical < 1e9 {
            (1e-6, "ms (cpu)")
        } else {
            (1e-9, "s (cpu)")
        }
    }
}

impl ValueFormatter for CpuFormatter {
    fn scale_values(&self, typical: f64, values: &mut [f64]) -> &'static str {
        let (factor, unit) = Self::unit(typical);
        values.iter_mut().for_each(|v| *v *= factor);
        unit
    }

    fn scale_throughputs(
        &self,
        _typical: f64,
        throughput: &Throughput,
        values: &mut [f64],
    ) -> &'static str {
        let per = match *throughput {
            Throughput::Bytes(n) | Throughput::BytesDecimal(n) | Throughput::Elements(n) => {
                n as f64
            }
        };
        values.iter_mut().for_each(|v| *v = per * 1e9 / *v);
        "per cpu second"
    }

    fn scale_for_machines(&self, _values: &mut [f64]) -> &'static str {
        "ns"
    }
}
