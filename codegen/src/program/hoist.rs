//! Parameter-only work, done once: which instructions of a program depend
//! on the model's parameters alone, so that they can run when the
//! parameters are set instead of on every call, and which of their values
//! the per-call instructions (or the outputs) read.
//!
//! A sum or product that mixes parameters with the coordinates or
//! velocities is evaluated left to right, and its parameter-only leading
//! operands form a value of their own: `m·r·v` is `(m·r)·v`. That leading
//! part is computed once as well, which leaves every value bit for bit
//! what the program computes (the symbolic engine orders the parameters
//! first, so this is where they usually stand).

use std::collections::HashMap;

use super::{Instr, OpCount, Program, Slot};

/// What one instruction's value depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Constants only: left where it is (the compiler folds it).
    Constant,
    /// A parameter copied as it is: left wherever it is read (reading it
    /// costs what reading a stored value would).
    Copy,
    /// Parameters and constants only: computed once per parameter set.
    Parameter {
        /// Read by the per-call code (or an output), so that it is stored.
        read: bool,
    },
    /// The coordinates or velocities: computed on every call.
    Varying {
        /// How many leading operands of a sum or product are
        /// parameter-only and computed once together (0, or at least 2
        /// with a parameter among them).
        leading: usize,
    },
}

impl Role {
    /// Whether the value depends on the coordinates or velocities.
    pub fn varies(self) -> bool {
        matches!(self, Role::Varying { .. })
    }

    /// The role of a value computed from values of roles `self` and `other`.
    fn join(self, other: Role) -> Role {
        match (self, other) {
            (Role::Varying { .. }, _) | (_, Role::Varying { .. }) => Role::Varying { leading: 0 },
            (Role::Constant, Role::Constant) => Role::Constant,
            _ => Role::Parameter { read: false },
        }
    }

    /// Whether it is computed wherever something reads it.
    fn in_place(self) -> bool {
        matches!(self, Role::Constant | Role::Copy)
    }
}

/// How an instruction appears in one of the two places emitted code
/// computes: the per-call function and the block run once per parameter
/// set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Emit {
    /// Not there.
    Skip,
    /// Computed.
    Compute,
    /// Computed, and its value stored as precomputed value k.
    Store(usize),
    /// Its value read from precomputed value k.
    Load(usize),
    /// Once: its first n operands combined and stored as precomputed value
    /// k. Per call: computed with precomputed value k in place of them.
    Leading(usize, usize),
}

/// A program split into the work done once per parameter set and the work
/// done per call.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Split {
    /// Each instruction in the per-call function.
    pub call: Vec<Emit>,
    /// Each instruction in the once-per-parameter-set block.
    pub once: Vec<Emit>,
    /// How many precomputed values it stores (numbered from the `first`
    /// given to [`Program::split`]).
    pub stored: usize,
}

impl Split {
    /// The operations of `p` per call and once per parameter set under
    /// this split (constant work that stays per call counts there only).
    pub fn op_counts(&self, p: &Program) -> (OpCount, OpCount) {
        let call = p.op_count_by(|i, ins| {
            let len = ins.sources().len();
            match self.call[i] {
                Emit::Compute => Some(len),
                // The stored value, then the operands after the leading ones.
                Emit::Leading(_, n) => Some(len - n + 1),
                Emit::Skip | Emit::Load(_) | Emit::Store(_) => None,
            }
        });
        let once = p.op_count_by(|i, ins| {
            let len = ins.sources().len();
            match (self.once[i], self.call[i]) {
                (Emit::Leading(_, n), _) => Some(n),
                (_, Emit::Compute) | (Emit::Skip, _) => None,
                (Emit::Compute | Emit::Store(_), _) => Some(len),
                (Emit::Load(_), _) => None,
            }
        });
        (call, once)
    }
}

impl Program {
    /// The split when the first `params` inputs are the parameters and the
    /// values it stores are numbered from `first`. Parameter work moves to
    /// the once block, storing what the per-call code reads; constants and
    /// copies stay wherever something reads them (or they are outputs).
    pub fn split(&self, params: usize, first: usize) -> Split {
        let (origins, finals) = (self.origins(), self.final_writers());
        let roles = self.roles_from(params, &origins, &finals);
        let n = self.instrs.len();
        let (mut call, mut once) = (vec![Emit::Skip; n], vec![Emit::Skip; n]);
        let (mut in_call, mut in_once) = (vec![false; n], vec![false; n]);
        let mut stored = 0;
        // A copy of a parameter value is that value: it shares its stored
        // slot rather than taking one of its own.
        let mut same: Vec<usize> = (0..n).collect();
        let mut slot: Vec<Option<usize>> = vec![None; n];
        for (i, role) in roles.iter().enumerate() {
            match *role {
                Role::Parameter { read } => {
                    in_once[i] = true;
                    if let (Instr::Assign(..), Some(Some(o))) =
                        (&self.instrs[i], origins[i].first())
                        && matches!(roles[*o], Role::Parameter { .. })
                    {
                        same[i] = same[*o];
                    }
                    if read {
                        let owner = same[i];
                        let k = *slot[owner].get_or_insert_with(|| {
                            stored += 1;
                            first + stored - 1
                        });
                        call[i] = Emit::Load(k);
                        once[owner] = Emit::Store(k);
                    }
                }
                Role::Varying { leading } => {
                    in_call[i] = true;
                    if leading > 0 {
                        call[i] = Emit::Leading(first + stored, leading);
                        once[i] = Emit::Leading(first + stored, leading);
                        stored += 1;
                    }
                }
                Role::Constant | Role::Copy => in_call[i] = finals.contains(&i),
            }
        }
        // What an included instruction reads, back to front so that what
        // those read is found too: in place values where they are read,
        // the leading operands of a split sum or product once.
        for i in (0..n).rev() {
            let leading = match roles[i] {
                Role::Varying { leading } => leading,
                _ => 0,
            };
            let per_call = in_call[i] && !matches!(call[i], Emit::Load(_));
            for (j, o) in origins[i].iter().enumerate() {
                // Parameter work is in the once block already, and stored
                // where read per call; varying work is per call already.
                let Some(o) = o.filter(|o| roles[*o].in_place()) else {
                    continue;
                };
                in_once[o] |= in_once[i] || j < leading;
                in_call[o] |= per_call && j >= leading;
            }
        }
        for i in 0..n {
            if in_call[i] && call[i] == Emit::Skip {
                call[i] = Emit::Compute;
            }
            if in_once[i] && once[i] == Emit::Skip {
                once[i] = Emit::Compute;
            }
        }
        Split { call, once, stored }
    }

    /// For each source of each instruction, the instruction whose value it
    /// reads (`None` for inputs and constants).
    fn origins(&self) -> Vec<Vec<Option<usize>>> {
        let mut writer: HashMap<Slot, usize> = HashMap::new();
        let mut out = Vec::with_capacity(self.instrs.len());
        for (i, ins) in self.instrs.iter().enumerate() {
            out.push(
                ins.sources()
                    .iter()
                    .map(|s| writer.get(s).copied())
                    .collect(),
            );
            writer.insert(ins.dst(), i);
        }
        out
    }

    /// The instruction that last writes each output.
    fn final_writers(&self) -> Vec<usize> {
        let mut writer: HashMap<Slot, usize> = HashMap::new();
        for (i, ins) in self.instrs.iter().enumerate() {
            writer.insert(ins.dst(), i);
        }
        (0..self.outputs)
            .filter_map(|o| writer.get(&Slot::Out(o)).copied())
            .collect()
    }

    /// The role of each instruction when the first `params` inputs are the
    /// model's parameters. Slots may be written more than once: a read
    /// refers to the latest write before it.
    pub fn roles(&self, params: usize) -> Vec<Role> {
        self.roles_from(params, &self.origins(), &self.final_writers())
    }

    /// [`Program::roles`] from the program's origins and final writers.
    fn roles_from(
        &self,
        params: usize,
        origins: &[Vec<Option<usize>>],
        finals: &[usize],
    ) -> Vec<Role> {
        let mut roles: Vec<Role> = Vec::with_capacity(self.instrs.len());
        for (ins, from) in self.instrs.iter().zip(origins) {
            let of = |s: &Slot, w: &Option<usize>, roles: &[Role]| match (*s, w) {
                (Slot::Const(_), _) => Role::Constant,
                (Slot::Input(k), _) if k < params => Role::Parameter { read: false },
                (_, Some(w)) => roles[*w],
                // Another input, or a slot read before any write (not a
                // value this analysis knows).
                (_, None) => Role::Varying { leading: 0 },
            };
            let sources: Vec<Role> = ins
                .sources()
                .iter()
                .zip(from)
                .map(|(s, w)| of(s, w, &roles))
                .collect();
            let mut role = sources.iter().fold(Role::Constant, |r, s| r.join(*s));
            if let Instr::Assign(_, Slot::Input(k)) = ins
                && *k < params
            {
                role = Role::Copy;
            }
            if role.varies() {
                let leading = match ins {
                    Instr::Add(..) | Instr::Mul(..) => {
                        let n = sources.iter().take_while(|r| !r.varies()).count();
                        let parametric = sources[..n].iter().any(|r| *r != Role::Constant);
                        if n >= 2 && parametric { n } else { 0 }
                    }
                    _ => 0,
                };
                role = Role::Varying { leading };
                // What the per-call part reads of parameter work is stored.
                for &w in from[leading..].iter().flatten() {
                    if let Role::Parameter { read } = &mut roles[w] {
                        *read = true;
                    }
                }
            }
            roles.push(role);
        }
        for &w in finals {
            if let Role::Parameter { read } = &mut roles[w] {
                *read = true;
            }
        }
        roles
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Function, Instr};
    use super::*;

    /// Inputs (m, J, x) with m and J parameters.
    fn example() -> Program {
        let (m, j, x) = (Slot::Input(0), Slot::Input(1), Slot::Input(2));
        let (t0, t1, t2) = (Slot::Temp(0), Slot::Temp(1), Slot::Temp(2));
        Program {
            inputs: 3,
            consts: vec![std::f64::consts::PI, 0.5],
            instrs: vec![
                // m·J and its reciprocal: parameter work, the reciprocal read
                // per call.
                Instr::Mul(t0, vec![m, j]),
                Instr::Pow(t0, t0, -1),
                // π/2: constant, read per call and by a leading part.
                Instr::Mul(t1, vec![Slot::Const(0), Slot::Const(1)]),
                Instr::Mul(Slot::Out(0), vec![t0, x, t1]),
                // t0 written again from x: varying.
                Instr::Fun(t0, Function::Sin, x),
                Instr::Add(Slot::Out(1), vec![t0, m]),
                // A parameter-only output.
                Instr::Fun(Slot::Out(2), Function::Exp, j),
                // (m·π/2)·x: the leading two operands computed once.
                Instr::Mul(Slot::Out(3), vec![m, t1, x]),
                // A copy of m, read per call.
                Instr::Assign(t2, m),
                Instr::Add(Slot::Out(4), vec![t2, x]),
            ],
            outputs: 5,
        }
    }

    #[test]
    fn roles_follow_values() {
        use Role::{Constant, Copy, Varying};
        let p = example();
        let (unread, read) = (
            Role::Parameter { read: false },
            Role::Parameter { read: true },
        );
        let varying = Varying { leading: 0 };
        assert_eq!(
            p.roles(2),
            vec![
                unread,
                read,
                Constant,
                varying,
                varying,
                varying,
                read,
                Varying { leading: 2 },
                Copy,
                varying
            ]
        );
        // With no parameters every instruction that reads an input varies,
        // and nothing is computed once.
        let none = p.roles(0);
        assert!(none.iter().all(|r| !matches!(r, Role::Parameter { .. })));
        assert_eq!(p.split(0, 0).stored, 0);
    }

    /// The once block computes the parameter work and stores what the
    /// per-call code reads; the per-call code loads it, and keeps the
    /// constant and the copy it reads.
    #[test]
    fn split_stores_what_calls_read() {
        use Emit::*;
        let split = example().split(2, 5);
        assert_eq!(
            split.call,
            vec![
                Skip,
                Load(5),
                Compute,
                Compute,
                Compute,
                Compute,
                Load(6),
                Leading(7, 2),
                Compute,
                Compute
            ]
        );
        assert_eq!(
            split.once,
            vec![
                Compute,
                Store(5),
                Compute,
                Skip,
                Skip,
                Skip,
                Store(6),
                Leading(7, 2),
                Skip,
                Skip
            ]
        );
        assert_eq!(split.stored, 3);
        let (call, once) = split.op_counts(&example());
        let ops = |add, mul, div, fun| OpCount { add, mul, div, fun };
        assert_eq!(call, ops(2, 4, 0, 1));
        assert_eq!(once, ops(0, 2, 1, 1));
    }

    /// Two outputs that copy one parameter value share its stored slot.
    #[test]
    fn copies_share_a_stored_value() {
        use Emit::*;
        let (m, x) = (Slot::Input(0), Slot::Input(1));
        let p = Program {
            inputs: 2,
            consts: vec![],
            instrs: vec![
                Instr::Pow(Slot::Temp(0), m, -1),
                Instr::Assign(Slot::Out(0), Slot::Temp(0)),
                Instr::Assign(Slot::Out(1), Slot::Temp(0)),
                Instr::Mul(Slot::Out(2), vec![Slot::Temp(0), x]),
            ],
            outputs: 3,
        };
        let split = p.split(1, 0);
        assert_eq!(split.call, vec![Load(0), Load(0), Load(0), Compute]);
        assert_eq!(split.once[0], Store(0));
        assert_eq!(split.stored, 1);
        let y = |m: f64, x: f64| p.eval(&[m, x]);
        assert_eq!(y(4.0, 2.0), vec![0.25, 0.25, 0.5]);
    }
}
