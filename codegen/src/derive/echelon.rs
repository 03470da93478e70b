//! B's and A's rows brought to echelon form over the rational functions
//! of the lowered symbols, with the identities of [`Lowering`] holding:
//! the exact rank test that decides which rows are independent.

use super::Rat;
use super::budget::{self, Over};
use super::lower::Lowering;

/// Rows brought to echelon form one at a time, over the rational
/// functions of a [`Lowering`]'s symbols with sin² + cos² = 1 and
/// cosh² − sinh² = 1 holding: every entry an elimination step makes is
/// reduced by the identities, whose reduced numerators are a normal form
/// (degree at most 1 in each cos and cosh), so a combination of rows that
/// vanishes only by the identities is found to vanish. (An exact rank over
/// the field that treats sin and cos as independent symbols misses such
/// combinations: a rolling disk's rows and its rough wall's contact rows
/// are dependent only through them.)
pub struct Echelon<'l> {
    low: &'l Lowering,
    /// The rows so far, each with the column of its pivot; every row is
    /// zero in the pivot columns of the rows before it.
    rows: Vec<(usize, Vec<Rat>)>,
}

impl<'l> Echelon<'l> {
    pub fn new(low: &'l Lowering) -> Self {
        Self {
            low,
            rows: Vec::new(),
        }
    }

    /// Adds `row` (entries from [`Lowering::to_rat`]) if it is independent
    /// of the rows so far; whether it was.
    pub fn insert(&mut self, row: &[Rat]) -> Result<bool, Over> {
        let mut row = row.to_vec();
        for (p, pivot) in &self.rows {
            if row[*p].numerator.is_zero() {
                continue;
            }
            let factor = row[*p].to_expression() / pivot[*p].to_expression();
            for (x, y) in row.iter_mut().zip(pivot) {
                if y.numerator.is_zero() {
                    continue;
                }
                let e = x.to_expression() - &factor * y.to_expression();
                // Bounded before it is brought to lowest terms, as
                // `to_rat` bounds its input: the combination's common
                // denominator can be far larger than either row's.
                budget::check(budget::rational_terms(&e))?;
                *x = self.low.reduce_rat(self.low.rat(&e))?;
            }
        }
        Ok(match row.iter().position(|x| !x.numerator.is_zero()) {
            Some(p) => {
                self.rows.push((p, row));
                true
            }
            None => false,
        })
    }
}
