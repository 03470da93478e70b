//! Stage 3: the middle end. A [`Derivation`] planned once for both back
//! ends, which only format what this stage decides:
//!
//! - **hoisting**: each function's parameter-only work is split off into
//!   the once-per-parameter-set block ([`Program::split`]), and the values
//!   its per-call code reads are numbered across all functions;
//! - **machine form**: every instruction in the place it runs, as a
//!   [`Machine`] (negations, powers, roots, sin/cos pairs decided there);
//! - **Taylor transforms**: the series of q̈ (the cheapest of the closed
//!   form and each elimination's), of each wall's f, and of the
//!   variational equation along the motion (q̈'s tangent).
//!
//! [`crate::emit`] writes a plan as Rust. [`crate::interpret`] runs each
//! program whole per call (the same values: hoisting only moves work) and
//! takes the plan's transforms.

use crate::derive::{Derivation, Function};
use crate::program::machine::{Machine, lower, split};
use crate::program::{Emit, OpCount, Program, Split, Transform};
use crate::quantity::Quantity;

/// What the back ends need beyond the derivation.
#[derive(Debug)]
pub struct Plan<'a> {
    /// What was derived.
    pub derivation: &'a Derivation,
    /// Every function, in [`Derivation::named_functions`] order.
    pub functions: Vec<Planned<'a>>,
    /// Parameter-only values kept in all (`pre[0..stored]`).
    pub stored: usize,
    /// The Taylor transforms of q̈ and of each wall's f, where q̈ is written
    /// out and series were asked for.
    pub series: Option<(Transform, Vec<Transform>)>,
    /// Where there are series and a tangent of q̈: the Taylor transform of
    /// the variational equation, a second-order system over (q, δq)
    /// ([`Program::variational`]) whose outputs are δq̈.
    pub variational: Option<Transform>,
}

/// One function, placed.
#[derive(Debug)]
pub struct Planned<'a> {
    /// Its name in generated code (`{wall}_{quantity}` for a wall's).
    pub name: String,
    /// The derived function.
    pub function: &'a Function,
    /// Its split into per-call and once-per-parameter-set work.
    pub split: Split,
    /// Each instruction per call.
    pub call: Vec<Step>,
    /// Each instruction in the once-per-parameter-set block.
    pub once: Vec<Step>,
}

/// What one instruction does in one place; `dst` is the instruction's own.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// Nothing.
    Skip,
    /// dst = the value.
    Compute(Machine),
    /// dst = the value, and kept value k = dst.
    Store(Machine, usize),
    /// dst = kept value k.
    Load(usize),
    /// Kept value k = the value (the leading operands of a sum or product
    /// whose others vary per call; dst is not assigned).
    Keep(Machine, usize),
}

impl Step {
    /// The machine form computed here, if any.
    pub fn machine(&self) -> Option<&Machine> {
        match self {
            Self::Compute(m) | Self::Store(m, _) | Self::Keep(m, _) => Some(m),
            Self::Skip | Self::Load(_) => None,
        }
    }
}

/// Whether a plan carries Taylor series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Taylor {
    /// With the transforms (f64 code, the interpreter).
    Include,
    /// Without (f32 code).
    Omit,
}

impl<'a> Plan<'a> {
    /// Plans `d`.
    pub fn new(d: &'a Derivation, taylor: Taylor) -> Self {
        let params = d.model.params.len();
        let mut stored = 0;
        let functions = d
            .named_functions()
            .into_iter()
            .map(|(name, function)| {
                let p = &function.program;
                let split = p.split(params, stored);
                stored += split.stored;
                Planned {
                    name,
                    function,
                    call: steps(p, &split.call, Place::Call),
                    once: steps(p, &split.once, Place::Once),
                    split,
                }
            })
            .collect();
        let series = (taylor == Taylor::Include).then(|| transforms(d)).flatten();
        let variational = (series.as_ref()).and_then(|(motion, _)| variational(d, motion));
        Self {
            derivation: d,
            functions,
            stored,
            series,
            variational,
        }
    }

    /// The function named `name` in generated code.
    pub fn function(&self, name: &str) -> &Planned<'a> {
        (self.functions.iter().find(|f| f.name == name))
            .unwrap_or_else(|| panic!("no function {name} in the plan"))
    }

    /// Operations per call and once per parameter set, by function.
    pub fn op_counts(&self) -> Vec<(String, OpCount, OpCount)> {
        (self.functions.iter())
            .map(|f| {
                let (call, once) = f.split.op_counts(&f.function.program);
                (f.name.clone(), call, once)
            })
            .collect()
    }
}

/// Every instruction of `p` computed per call (a Taylor transform's
/// time-constant numbers, which the series reads per call).
pub fn computed(p: &Program) -> Vec<Step> {
    steps(p, &vec![Emit::Compute; p.instrs.len()], Place::Call)
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Place {
    Call,
    Once,
}

/// Each instruction of `p` where `emit` places it, in machine form.
fn steps(p: &Program, emit: &[Emit], place: Place) -> Vec<Step> {
    let computed = |i: usize| matches!(emit[i], Emit::Compute | Emit::Store(_));
    let machine = lower(p, computed);
    (p.instrs.iter().zip(machine).zip(emit))
        .map(|((ins, m), e)| match (*e, place) {
            (Emit::Skip, _) => Step::Skip,
            (Emit::Compute, _) => Step::Compute(m.expect("computed")),
            (Emit::Store(k), _) => Step::Store(m.expect("computed"), k),
            (Emit::Load(k), _) => Step::Load(k),
            (Emit::Leading(k, n), Place::Once) => {
                Step::Keep(split(p, ins, None, &ins.sources()[..n]), k)
            }
            (Emit::Leading(k, n), Place::Call) => {
                Step::Compute(split(p, ins, Some(k), &ins.sources()[n..]))
            }
        })
        .collect()
}

/// The Taylor transforms of q̈ and of each wall's f (`None` where q̈ is not
/// written out). Without constraint rows, the series of q̈ can also be that
/// of G and h, or of G and ∂L/∂q, with the solve per order
/// ([`Program::taylor_solve`]): the transform of q̈'s own program (closed
/// form or elimination) or of one of these systems, whichever costs least
/// at the default tolerance's order (q̈'s own on a tie).
fn transforms(d: &Derivation) -> Option<(Transform, Vec<Transform>)> {
    let (np, nq) = (d.model.params.len(), d.model.coordinates.len());
    let plain = d.function(Quantity::Accelerations)?.program.taylor(np, nq);
    let order = dalembert_runtime::simulate::Taylor::default().order();
    let solved = d.motion_systems.iter().filter_map(|s| {
        s.program
            .taylor_solve(np, nq, &s.layout, &s.rhs, s.momentum)
    });
    let motion = std::iter::once(plain)
        .chain(solved)
        .min_by_key(|t| t.cost(order))
        .expect("the elimination's transform at least");
    let walls = (d.walls.iter())
        .map(|w| {
            w.function(Quantity::Surface)
                .map(|f| f.program.taylor(np, nq))
        })
        .collect::<Option<Vec<_>>>()?;
    Some((motion, walls))
}

/// How many times the motion's series the variational system's may cost
/// (in multiply-adds at the default tolerance's order, all of its ops
/// counted). A tangent costs about three times its program: 2.5 to 3.2
/// times the motion's series for the built-in models and the test files
/// whose series is q̈'s own, 4.1 with every arc and hyperbolic function in
/// q̈ (`tests/walls/disk_functions.toml`). Where the motion's series is
/// solved per order from G (the chains), the tangent of the written-out q̈
/// costs 6.4 to 21 times it, and Φ is left to its integration along the
/// step instead.
const VARIATIONAL_COST: usize = 5;

/// The Taylor transform of the variational system along the motion
/// ([`Program::variational`] of q̈'s tangent), where q̈ has a tangent and
/// its series costs at most [`VARIATIONAL_COST`] times `motion`'s.
fn variational(d: &Derivation, motion: &Transform) -> Option<Transform> {
    let (np, n) = (d.model.params.len(), d.model.velocities.len());
    let tangent = d.function(Quantity::AccelerationsTangent)?;
    let t = tangent
        .program
        .variational(np, n)
        .taylor(np, 2 * n)
        .shared(n);
    let order = dalembert_runtime::simulate::Taylor::default().order();
    (t.cost(order) <= VARIATIONAL_COST * motion.cost(order)).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::machine::Operand;
    use crate::program::{Function, Instr, Slot};

    /// Inputs (m, x) with m a parameter: −m·x has its leading −1·m kept
    /// once (the −1 as the kept value's negation) and read per call;
    /// sin and cos of x are one pair per call; 1/m is stored once and
    /// loaded per call.
    #[test]
    fn steps_place_each_instruction_in_machine_form() {
        let (m, x) = (Slot::Input(0), Slot::Input(1));
        let p = Program {
            inputs: 2,
            consts: vec![-1.0],
            instrs: vec![
                Instr::Mul(Slot::Out(0), vec![m, Slot::Const(0), x]),
                Instr::Fun(Slot::Temp(0), Function::Sin, x),
                Instr::Fun(Slot::Temp(1), Function::Cos, x),
                Instr::Pow(Slot::Temp(2), m, -1),
                Instr::Add(
                    Slot::Out(1),
                    vec![Slot::Temp(0), Slot::Temp(1), Slot::Temp(2)],
                ),
            ],
            outputs: 2,
        };
        let split = p.split(1, 3);
        let (call, once) = (
            steps(&p, &split.call, Place::Call),
            steps(&p, &split.once, Place::Once),
        );
        let slot = Operand::Slot;
        assert_eq!(
            once,
            vec![
                Step::Keep(
                    Machine::Product {
                        factors: vec![slot(m)],
                        negate: true
                    },
                    3
                ),
                Step::Skip,
                Step::Skip,
                Step::Store(
                    Machine::Power {
                        x: m,
                        n: 1,
                        reciprocal: true
                    },
                    4
                ),
                Step::Skip,
            ]
        );
        assert_eq!(
            call,
            vec![
                Step::Compute(Machine::Product {
                    factors: vec![Operand::Kept(3), slot(x)],
                    negate: false
                }),
                Step::Compute(Machine::SinCos {
                    x,
                    pair: 0,
                    sin: true
                }),
                Step::Compute(Machine::Half {
                    pair: 0,
                    sin: false
                }),
                Step::Load(4),
                Step::Compute(Machine::Sum(vec![
                    slot(Slot::Temp(0)),
                    slot(Slot::Temp(1)),
                    slot(Slot::Temp(2))
                ])),
            ]
        );
        // Computed whole: every instruction per call.
        assert_eq!(computed(&p).len(), p.instrs.len());
        assert!(computed(&p).iter().all(|s| matches!(s, Step::Compute(_))));
    }
}
