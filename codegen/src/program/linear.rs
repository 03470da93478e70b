//! A linear map y = M v as a program, from a program computing the entries
//! of M that are not known at generation time. Used for collision maps
//! whose matrix I − 2P does not depend on the configuration: the entries
//! are then parameter-only work (done once), and each call is the
//! multiplications by the entries that are not zero. An entry that is the
//! negation of another reads that one's value, and its term is subtracted:
//! one stored value, and no negation, where a row has a positive term.

use super::{Instr, Program, Slot};

/// An entry of M as known when the code is generated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Entry {
    /// Exactly 0: no term.
    Zero,
    /// Exactly 1: the component itself.
    One,
    /// Exactly −1: the component, subtracted.
    MinusOne,
    /// Output k of the entries' program, or its negation (the term
    /// subtracted).
    Value { k: usize, negated: bool },
}

impl Entry {
    /// Whether its term is subtracted.
    fn subtracted(self) -> bool {
        matches!(self, Entry::MinusOne | Entry::Value { negated: true, .. })
    }
}

/// Chooses how each of the `values` distinct values that `entries` (n×n,
/// row by row) read is stored, so that no row needs a negation (a row whose
/// terms are all subtracted): first the sign of each value, flipping one
/// while that lowers the number of such rows; then, in each such row left,
/// the first value read gets a stored copy of the opposite sign (one more
/// value read per call costs less than a negation). Rewrites the entries to
/// name the stored values and returns them: stored value k is value
/// `source` negated or not. A row of −1 entries alone keeps its negation.
pub fn stored_signs(entries: &mut [Entry], n: usize, values: usize) -> Vec<(usize, bool)> {
    let all_subtracted = |row: &[Entry]| {
        let mut terms = row.iter().filter(|e| **e != Entry::Zero).peekable();
        terms.peek().is_some() && terms.all(|e| e.subtracted())
    };
    let negations = |entries: &[Entry]| entries.chunks(n).filter(|r| all_subtracted(r)).count();
    let flip = |entries: &mut [Entry], value: usize| {
        for e in entries.iter_mut() {
            if let Entry::Value { k, negated } = e
                && *k == value
            {
                *negated = !*negated;
            }
        }
    };
    let mut stored: Vec<(usize, bool)> = (0..values).map(|k| (k, false)).collect();
    let mut count = negations(entries);
    let mut improved = true;
    while improved {
        improved = false;
        for (value, sign) in stored.iter_mut().enumerate() {
            flip(entries, value);
            let trial = negations(entries);
            if trial < count {
                (count, improved) = (trial, true);
                sign.1 = !sign.1;
            } else {
                flip(entries, value);
            }
        }
    }
    // The opposite-sign copy of each value that needs one.
    let mut opposite: Vec<Option<usize>> = vec![None; values];
    for row in entries.chunks_mut(n).filter(|r| all_subtracted(r)) {
        let Some(e) = row.iter_mut().find(|e| matches!(e, Entry::Value { .. })) else {
            continue;
        };
        let Entry::Value { k, .. } = *e else {
            unreachable!("found as a value")
        };
        let copy = *opposite[k].get_or_insert_with(|| {
            stored.push((stored[k].0, !stored[k].1));
            stored.len() - 1
        });
        *e = Entry::Value {
            k: copy,
            negated: false,
        };
    }
    stored
}

impl Program {
    /// y = M v for the n×n matrix M whose entries, row by row, are
    /// `entries`: this program's outputs are the values they name, and v
    /// is inputs `v..v + n`.
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
        assert!(
            entries
                .iter()
                .all(|e| !matches!(e, Entry::Value { k, .. } if *k >= self.outputs)),
            "an entry names one of the program's outputs"
        );
        // The entries become temporaries after this program's own.
        let (instrs, base) = self.outputs_as_temps();
        let mut consts = self.consts.clone();
        let mut b = Rows {
            instrs,
            next: base + self.outputs,
            minus_one: super::constant(&mut consts, -1.0),
            zero: super::constant(&mut consts, 0.0),
        };
        let read = |j: usize| (0..n).any(|i| over_outputs[i] && entries[i * n + j] != Entry::Zero);
        let mut value: Vec<Option<Slot>> = vec![None; n];
        let rows = (0..n)
            .filter(|&i| !over_outputs[i])
            .chain((0..n).filter(|&i| over_outputs[i]));
        for i in rows {
            // Terms added and terms subtracted.
            let (mut plus, mut minus) = (Vec::new(), Vec::new());
            for j in 0..n {
                let e = entries[i * n + j];
                if e == Entry::Zero {
                    continue;
                }
                let x = if over_outputs[i] {
                    value[j].expect("a folded row reads rows computed from v")
                } else {
                    Slot::Input(v + j)
                };
                let term = match e {
                    Entry::Value { k, .. } => b.product(Slot::Temp(base + k), x),
                    _ => x,
                };
                if e.subtracted() {
                    minus.push(term);
                } else {
                    plus.push(term);
                }
            }
            // A row other rows read is kept in a temporary first.
            let out = if read(i) { b.temp() } else { Slot::Out(i) };
            b.row(out, &plus, &minus);
            if out != Slot::Out(i) {
                b.instrs.push(Instr::Assign(Slot::Out(i), out));
            }
            value[i] = Some(out);
        }
        Program {
            inputs: self.inputs,
            consts,
            instrs: b.instrs,
            outputs: n,
        }
    }
}

/// The instructions of a linear map's rows as they are written.
struct Rows {
    instrs: Vec<Instr>,
    /// The next free temporary.
    next: usize,
    minus_one: Slot,
    zero: Slot,
}

impl Rows {
    fn temp(&mut self) -> Slot {
        self.next += 1;
        Slot::Temp(self.next - 1)
    }

    /// A new temporary holding a·x.
    fn product(&mut self, a: Slot, x: Slot) -> Slot {
        self.write(|d| Instr::Mul(d, vec![a, x]))
    }

    /// A new temporary written by `make`.
    fn write(&mut self, make: impl FnOnce(Slot) -> Instr) -> Slot {
        let t = self.temp();
        self.instrs.push(make(t));
        t
    }

    /// `out` = Σ plus − Σ minus: the sum first, then each subtraction;
    /// with nothing to add, the first term subtracted is a negation.
    fn row(&mut self, out: Slot, plus: &[Slot], minus: &[Slot]) {
        let start = self.instrs.len();
        let (first, rest) = match (plus, minus) {
            ([], []) => (self.zero, minus),
            ([], [x, rest @ ..]) => {
                let m = self.minus_one;
                (self.write(|d| Instr::Mul(d, vec![m, *x])), rest)
            }
            ([x], _) => (*x, minus),
            _ => (self.write(|d| Instr::Add(d, plus.to_vec())), minus),
        };
        let value = rest
            .iter()
            .fold(first, |acc, &x| self.write(|d| Instr::Sub(d, [acc, x])));
        // The row's last instruction writes `out`; a lone term is copied.
        match self.instrs[start..].last_mut() {
            Some(last) => *last = last.map_slots(|s| if s == value { out } else { s }),
            None => self.instrs.push(Instr::Assign(out, value)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Output k of the entries' program, and its negation.
    fn value(k: usize) -> Entry {
        Entry::Value { k, negated: false }
    }
    fn negated(k: usize) -> Entry {
        Entry::Value { k, negated: true }
    }

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
        let p = entries.times_vector(&[value(0), Zero, MinusOne, value(1)], 2, 1);
        assert_eq!(p.outputs, 2);
        let y = p.eval(&[1.5, 3.0, -4.0]);
        assert_eq!(y, vec![4.5, -3.0 + 3.0 * -4.0]);
        // Zero and one entries cost nothing: 1 multiplication in row 0,
        // 1 multiplication and 1 subtraction in row 1 (and the entries'
        // own 1 multiplication).
        let ops = p.op_count();
        assert_eq!((ops.add, ops.mul), (1, 3));
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
        let p = entries.times_vector_folded(&[value(0), One, MinusOne, Zero], &[false, true], 2, 1);
        let y = p.eval(&[1.5, 3.0, -4.0]);
        assert_eq!(y, vec![0.5, -0.5]);
        let ops = p.op_count();
        assert_eq!((ops.add, ops.mul), (1, 2));
    }

    /// M = [[b, −b], [−b, −1]] with b = a² (a the first input): one value
    /// stored for b and −b; y₀ = b v₀ − b v₁ subtracts, y₁ = −(b v₀) − v₁
    /// negates its first term, having nothing to add.
    #[test]
    fn a_negated_entry_shares_the_value_and_subtracts() {
        let a = Slot::Input(0);
        let entries = Program {
            inputs: 3,
            consts: vec![],
            instrs: vec![Instr::Mul(Slot::Out(0), vec![a, a])],
            outputs: 1,
        };
        use Entry::*;
        let p = entries.times_vector(&[value(0), negated(0), negated(0), MinusOne], 2, 1);
        let y = p.eval(&[1.5, 3.0, -4.0]);
        assert_eq!(y, vec![2.25 * 3.0 - 2.25 * -4.0, -(2.25 * 3.0) - -4.0]);
        // b once; per call 3 multiplications, 1 negation (counted as a
        // multiplication) and 2 subtractions.
        let ops = p.op_count();
        assert_eq!((ops.add, ops.mul), (2, 5));
        let split = p.split(1, 0);
        assert_eq!(split.stored, 1);
        let (call, once) = split.op_counts(&p);
        assert_eq!((call.add, call.mul, once.mul), (2, 4, 1));
        let subtractions = p
            .instrs
            .iter()
            .filter(|i| matches!(i, Instr::Sub(..)))
            .count();
        assert_eq!(subtractions, 2);
    }

    /// M = [[−b, −c], [c, b]] as first seen (b, c stored as they come):
    /// row 0 has only subtracted terms. Storing −b instead leaves none.
    #[test]
    fn signs_are_chosen_for_fewest_negations() {
        use Entry::*;
        let mut entries = [negated(0), negated(1), value(1), value(0)];
        let stored = stored_signs(&mut entries, 2, 2);
        assert_eq!(stored, vec![(0, true), (1, false)]);
        assert_eq!(entries, [value(0), negated(1), value(1), negated(0)]);
        // A row of −1 alone stays a negation: nothing can flip it.
        let mut entries = [MinusOne, Zero, Zero, value(0)];
        assert_eq!(stored_signs(&mut entries, 2, 1), vec![(0, false)]);
        assert_eq!(entries, [MinusOne, Zero, Zero, value(0)]);
    }

    /// Rows (a, b), (a, −b), (−c, −a), (c, −a), Theorem 3.2's pattern
    /// (`stored_signs` reads only rows): whatever the signs, one row has
    /// only subtracted terms, so its first value gets a copy of the
    /// opposite sign, and no row needs a negation.
    #[test]
    fn a_row_left_all_subtracted_reads_a_copy() {
        let mut entries = [
            value(0),
            value(1),
            value(0),
            negated(1),
            negated(2),
            negated(0),
            value(2),
            negated(0),
        ];
        let stored = stored_signs(&mut entries, 2, 3);
        assert_eq!(stored.len(), 4, "{stored:?}");
        let (source, negated) = stored[3];
        assert_eq!(stored[source], (source, !negated));
        for row in entries.chunks(2) {
            assert!(row.iter().any(|e| !e.subtracted()), "{entries:?}");
        }
    }
}
