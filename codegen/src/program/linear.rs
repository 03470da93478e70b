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
        self.times_vector_folded(entries, &vec![false; n], n, v)
    }

    /// As [`Program::times_vector`], but a row i with `over_outputs[i]`
    /// multiplies y instead of v: yᵢ = Σⱼ Mᵢⱼ yⱼ, computed after the other
    /// rows, which are the only ones it may read.
    pub fn times_vector_folded(
        &self,
        entries: &[Entry],
        over_outputs: &[bool],
        n: usize,
        v: usize,
    ) -> Program {
        assert_eq!(entries.len(), n * n, "one entry per element of M");
        assert_eq!(over_outputs.len(), n, "one flag per row");
        // The entries become temporaries after this program's own.
        let (mut instrs, base) = self.outputs_as_temps();
        let entry = |k: usize| Slot::Temp(base + k);
        let mut consts = self.consts.clone();
        let (minus_one, zero) = (
            super::constant(&mut consts, -1.0),
            super::constant(&mut consts, 0.0),
        );
        let mut next = base + self.outputs;
        // Where each row's general entries start among the outputs.
        let first: Vec<usize> = (0..n)
            .scan(0, |k, i| {
                let at = *k;
                *k += entries[i * n..(i + 1) * n]
                    .iter()
                    .filter(|e| **e == Entry::General)
                    .count();
                Some(at)
            })
            .collect();
        let read = |j: usize| (0..n).any(|i| over_outputs[i] && entries[i * n + j] != Entry::Zero);
        let mut value: Vec<Option<Slot>> = vec![None; n];
        let rows = (0..n)
            .filter(|&i| !over_outputs[i])
            .chain((0..n).filter(|&i| over_outputs[i]));
        for i in rows {
            let mut terms = Vec::new();
            let mut general = first[i];
            for j in 0..n {
                let x = if over_outputs[i] {
                    match entries[i * n + j] {
                        Entry::Zero => continue,
                        _ => value[j].expect("a folded row reads rows computed from v"),
                    }
                } else {
                    Slot::Input(v + j)
                };
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
            // A row other rows read is kept in a temporary first.
            let out = if read(i) {
                next += 1;
                Slot::Temp(next - 1)
            } else {
                Slot::Out(i)
            };
            instrs.push(match terms.as_slice() {
                [] => Instr::Assign(out, zero),
                [one] => Instr::Assign(out, *one),
                _ => Instr::Add(out, terms),
            });
            if out != Slot::Out(i) {
                instrs.push(Instr::Assign(Slot::Out(i), out));
            }
            value[i] = Some(out);
        }
        let general = entries.iter().filter(|e| **e == Entry::General).count();
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

    /// Row 1 over the outputs: y₀ = a v₀ + v₁, then y₁ = −y₀ (it reads
    /// row 0's value, computed first).
    #[test]
    fn a_row_over_the_outputs_reads_the_others() {
        let a = Slot::Input(0);
        let entries = Program {
            inputs: 3,
            consts: vec![],
            instrs: vec![Instr::Assign(Slot::Out(0), a)],
            outputs: 1,
        };
        use Entry::*;
        let p = entries.times_vector_folded(&[General, One, MinusOne, Zero], &[false, true], 2, 1);
        let y = p.eval(&[1.5, 3.0, -4.0]);
        assert_eq!(y, vec![0.5, -0.5]);
        let ops = p.op_count();
        assert_eq!((ops.add, ops.mul), (1, 2));
    }
}
