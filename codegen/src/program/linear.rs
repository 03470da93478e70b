//! A linear map y = M v as a program, from a program computing the entries
//! of M that are not known at generation time. Used for collision maps
//! whose matrix I − 2P does not depend on the configuration: the entries
//! are then parameter-only work (done once), and each call is the
//! multiplications by the entries that are not zero.

use super::{Instr, Program, Slot};

/// An entry of M as known when the code is generated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Entry {
    /// Exactly 0: no term.
    Zero,
    /// Exactly 1: the component itself.
    One,
    /// Exactly −1: its negation.
    MinusOne,
    /// Anything else: the next output of the entries' program.
    General,
}

impl Program {
    /// y = M v for the n×n matrix M whose entries, row by row, are
    /// `entries`: this program's outputs are the `General` ones in that
    /// order, and v is inputs `v..v + n`.
    pub fn times_vector(&self, entries: &[Entry], n: usize, v: usize) -> Program {
        assert_eq!(entries.len(), n * n, "one entry per element of M");
        // The entries become temporaries after this program's own.
        let (mut instrs, base) = self.outputs_as_temps();
        let entry = |k: usize| Slot::Temp(base + k);
        let mut consts = self.consts.clone();
        let (minus_one, zero) = (
            super::constant(&mut consts, -1.0),
            super::constant(&mut consts, 0.0),
        );
        let mut next = base + self.outputs;
        let mut general = 0;
        for i in 0..n {
            let mut terms = Vec::new();
            for j in 0..n {
                let x = Slot::Input(v + j);
                let factor = match entries[i * n + j] {
                    Entry::Zero => continue,
                    Entry::One => {
                        terms.push(x);
                        continue;
                    }
                    Entry::MinusOne => minus_one,
                    Entry::General => {
                        general += 1;
                        entry(general - 1)
                    }
                };
                let t = Slot::Temp(next);
                next += 1;
                instrs.push(Instr::Mul(t, vec![factor, x]));
                terms.push(t);
            }
            let out = Slot::Out(i);
            instrs.push(match terms.as_slice() {
                [] => Instr::Assign(out, zero),
                [one] => Instr::Assign(out, *one),
                _ => Instr::Add(out, terms),
            });
        }
        assert_eq!(general, self.outputs, "one output per general entry");
        Program {
            inputs: self.inputs,
            consts,
            instrs,
            outputs: n,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// M = [[a, 0], [−1, 2a]] with a the first input, v the next two:
    /// y = (a v₀, −v₀ + 2a v₁).
    #[test]
    fn times_vector_is_the_matrix_product() {
        let a = Slot::Input(0);
        let entries = Program {
            inputs: 3,
            consts: vec![2.0],
            instrs: vec![
                Instr::Assign(Slot::Out(0), a),
                Instr::Mul(Slot::Temp(0), vec![Slot::Const(0), a]),
                Instr::Assign(Slot::Out(1), Slot::Temp(0)),
            ],
            outputs: 2,
        };
        use Entry::*;
        let p = entries.times_vector(&[General, Zero, MinusOne, General], 2, 1);
        assert_eq!(p.outputs, 2);
        let y = p.eval(&[1.5, 3.0, -4.0]);
        assert_eq!(y, vec![4.5, -3.0 + 3.0 * -4.0]);
        // Zero and one entries cost nothing: 1 multiplication in row 0,
        // a negation, 1 multiplication and 1 addition in row 1 (and the
        // entries' own 1 multiplication).
        let ops = p.op_count();
        assert_eq!((ops.add, ops.mul), (1, 4));
        let identity = Program {
            inputs: 2,
            consts: vec![],
            instrs: vec![],
            outputs: 0,
        }
        .times_vector(&[One, Zero, Zero, Zero], 2, 0);
        assert_eq!(identity.eval(&[7.0, 8.0]), vec![7.0, 0.0]);
    }
}
