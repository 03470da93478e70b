//! Constrained solves with G written out as straight-line code after a
//! program computing G, the rows R and the right-hand sides: the collision
//! map v⁺ = v − 2G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹Bv, and q̈ of G q̈ + h = Aᵀλ, A q̈ + Ȧq̇ = 0.
//!
//! Both are x = G⁻¹(f + Rᵀμ) with R x = g. G = L D Lᵀ (unit lower L, no
//! square roots) is factorised entry by entry; with yᵣ = L⁻¹rᵣ,
//! zᵣ = D⁻¹yᵣ and y_f = L⁻¹f, R G⁻¹Rᵀ = Z Yᵀ, μ solves
//! (Z Yᵀ) μ = g − Z y_f (the same factorisation, k×k), and
//! x = L⁻ᵀ(D⁻¹y_f + Σᵣ μᵣ zᵣ): one forward solve per row and for f, and a
//! single backward solve. Entries known to be zero when the code is
//! generated stay out of every sum, so the fill-in of L (and all work on
//! it) follows G's sparsity. Nothing is normalised or expanded: the size
//! grows as n³/6 + k n², not as an exact closed form does.

use super::{Instr, Program, Slot};

/// Where the entries of G and of the rows are among the outputs of the
/// program that computes them (`None` where an entry is exactly zero).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Number of velocities (G is n×n).
    pub n: usize,
    /// G's lower triangle row by row (G₀₀, G₁₀, G₁₁, G₂₀, …).
    pub g: Vec<Option<usize>>,
    /// The rows (B's for a collision, A's for the motion), n entries each.
    pub rows: Vec<Vec<Option<usize>>>,
}

impl Layout {
    /// Where G's entry (i, j) is among the outputs (either triangle).
    pub fn entry(&self, i: usize, j: usize) -> Option<usize> {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        self.g[i * (i + 1) / 2 + j]
    }
}

/// A value of the code being written: `None` is exactly zero.
type Value = Option<Slot>;

/// Appends instructions, numbering new temporaries past the program's.
struct Writer {
    instrs: Vec<Instr>,
    consts: Vec<f64>,
    next: usize,
}

impl Writer {
    fn constant(&mut self, x: f64) -> Slot {
        super::constant(&mut self.consts, x)
    }

    fn temp(&mut self) -> Slot {
        self.next += 1;
        Slot::Temp(self.next - 1)
    }

    /// The product of `factors` (zero if any is).
    fn product(&mut self, factors: &[Value]) -> Value {
        let slots: Option<Vec<Slot>> = factors.iter().copied().collect();
        let slots = slots?;
        let t = self.temp();
        self.instrs.push(Instr::Mul(t, slots));
        Some(t)
    }

    /// `first` − Σ aₖbₖ over the pairs where neither is zero.
    fn minus_products(&mut self, first: Value, pairs: &[(Value, Value)]) -> Value {
        let minus_one = self.constant(-1.0);
        let mut terms: Vec<Slot> = first.into_iter().collect();
        for &(a, b) in pairs {
            if let Some(t) = self.product(&[Some(minus_one), a, b]) {
                terms.push(t);
            }
        }
        self.sum(terms)
    }

    /// Σ terms (zero when there are none).
    fn sum(&mut self, terms: Vec<Slot>) -> Value {
        match terms.as_slice() {
            [] => None,
            [one] => Some(*one),
            _ => {
                let t = self.temp();
                self.instrs.push(Instr::Add(t, terms));
                Some(t)
            }
        }
    }

    /// 1/x.
    fn reciprocal(&mut self, x: Slot) -> Slot {
        let t = self.temp();
        self.instrs.push(Instr::Pow(t, x, -1));
        t
    }

    /// S = L D Lᵀ of the symmetric m×m matrix whose entry (i, j), i ≥ j, is
    /// `s(i, j)`; `None` when a pivot is zero for every value of the inputs.
    fn factorise(&mut self, m: usize, s: impl Fn(usize, usize) -> Value) -> Option<Ldl> {
        let mut l: Vec<Vec<Value>> = vec![vec![None; m]; m];
        let mut inv = Vec::with_capacity(m);
        let mut d: Vec<Slot> = Vec::with_capacity(m);
        for j in 0..m {
            // wₖ = Lⱼₖ Dₖ, shared by the pivot and the column below it.
            let w: Vec<Value> = (0..j)
                .map(|k| self.product(&[l[j][k], Some(d[k])]))
                .collect();
            let pairs: Vec<(Value, Value)> = (0..j).map(|k| (l[j][k], w[k])).collect();
            let pivot = self.minus_products(s(j, j), &pairs)?;
            let r = self.reciprocal(pivot);
            for (i, li) in l.iter_mut().enumerate().take(m).skip(j + 1) {
                let pairs: Vec<(Value, Value)> = (0..j).map(|k| (li[k], w[k])).collect();
                let x = self.minus_products(s(i, j), &pairs);
                li[j] = self.product(&[x, Some(r)]);
            }
            d.push(pivot);
            inv.push(r);
        }
        Some(Ldl { l, inv })
    }

    /// L⁻¹ b.
    fn forward(&mut self, f: &Ldl, b: &[Value]) -> Vec<Value> {
        let mut y: Vec<Value> = Vec::with_capacity(b.len());
        for (i, bi) in b.iter().enumerate() {
            let pairs: Vec<(Value, Value)> = (0..i).map(|k| (f.l[i][k], y[k])).collect();
            let yi = self.minus_products(*bi, &pairs);
            y.push(yi);
        }
        y
    }

    /// D⁻¹ y.
    fn divide(&mut self, f: &Ldl, y: &[Value]) -> Vec<Value> {
        y.iter()
            .zip(&f.inv)
            .map(|(e, r)| self.product(&[*e, Some(*r)]))
            .collect()
    }

    /// L⁻ᵀ u.
    fn backward(&mut self, f: &Ldl, u: &[Value]) -> Vec<Value> {
        let m = u.len();
        let mut x: Vec<Value> = vec![None; m];
        for i in (0..m).rev() {
            let pairs: Vec<(Value, Value)> = (i + 1..m).map(|k| (f.l[k][i], x[k])).collect();
            x[i] = self.minus_products(u[i], &pairs);
        }
        x
    }

    /// Σ aₖbₖ.
    fn dot(&mut self, pairs: &[(Value, Value)]) -> Value {
        let terms: Vec<Slot> = pairs
            .iter()
            .filter_map(|&(a, b)| self.product(&[a, b]))
            .collect();
        self.sum(terms)
    }
}

/// A factorisation L D Lᵀ: L below the diagonal, and 1/D.
struct Ldl {
    l: Vec<Vec<Value>>,
    inv: Vec<Slot>,
}

impl Writer {
    /// x = G⁻¹(f + Rᵀμ) with R x = g, G factorised as `lg`; `f` may be
    /// all zero. `None` when R G⁻¹Rᵀ has a structurally zero pivot.
    fn constrained(
        &mut self,
        lg: &Ldl,
        rows: &[Vec<Value>],
        f: &[Value],
        g: &[Value],
    ) -> Option<Vec<Value>> {
        let (n, k) = (lg.inv.len(), rows.len());
        let y: Vec<Vec<Value>> = rows.iter().map(|r| self.forward(lg, r)).collect();
        let z: Vec<Vec<Value>> = y.iter().map(|yr| self.divide(lg, yr)).collect();
        let yf = self.forward(lg, f);
        let zf = self.divide(lg, &yf);
        let mut s = vec![vec![None; k]; k];
        for r in 0..k {
            for c in 0..=r {
                let pairs: Vec<(Value, Value)> = (0..n).map(|i| (z[r][i], y[c][i])).collect();
                s[r][c] = self.dot(&pairs);
            }
        }
        let schur = self.factorise(k, |i, j| s[i][j])?;
        let rhs: Vec<Value> = (0..k)
            .map(|r| {
                let pairs: Vec<(Value, Value)> = (0..n).map(|i| (z[r][i], yf[i])).collect();
                self.minus_products(g[r], &pairs)
            })
            .collect();
        let c = self.forward(&schur, &rhs);
        let c = self.divide(&schur, &c);
        let mu = self.backward(&schur, &c);
        let u: Vec<Value> = (0..n)
            .map(|i| {
                let mut terms: Vec<Slot> = zf[i].into_iter().collect();
                terms.extend((0..k).filter_map(|r| self.product(&[mu[r], z[r][i]])));
                self.sum(terms)
            })
            .collect();
        Some(self.backward(lg, &u))
    }
}

impl Program {
    /// The writer continuing this program, its outputs turned into
    /// temporaries, and G's factorisation from `layout`, with the rows as
    /// values.
    fn eliminate(&self, layout: &Layout) -> Option<(Writer, Ldl, Vec<Vec<Value>>, usize)> {
        let n = layout.n;
        assert_eq!(layout.g.len(), n * (n + 1) / 2, "G's lower triangle");
        assert!(layout.rows.iter().all(|r| r.len() == n), "rows of n");
        let (instrs, base) = self.outputs_as_temps();
        let mut w = Writer {
            instrs,
            consts: self.consts.clone(),
            next: base + self.outputs,
        };
        let output = |e: Option<usize>| e.map(|k| Slot::Temp(base + k));
        let lg = w.factorise(n, |i, j| output(layout.entry(i, j)))?;
        let rows = layout
            .rows
            .iter()
            .map(|r| r.iter().map(|e| output(*e)).collect())
            .collect();
        Some((w, lg, rows, base))
    }

    fn finish(&self, w: Writer, outputs: usize) -> Program {
        Program {
            inputs: self.inputs,
            consts: w.consts,
            instrs: w.instrs,
            outputs,
        }
    }

    /// v⁺ = v − 2G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹Bv from this program, whose outputs are the
    /// entries of G and B (the rows) that `layout` places; v is inputs
    /// `v..v + n`. `None` when a pivot of G or of BG⁻¹Bᵀ is structurally
    /// zero (no value of the inputs makes the elimination work without
    /// pivoting; G > 0 and independent rows never do this).
    pub fn reflect_by_elimination(&self, layout: &Layout, v: usize) -> Option<Program> {
        let n = layout.n;
        let (mut w, lg, b, _) = self.eliminate(layout)?;
        let v = |i: usize| Slot::Input(v + i);
        // x = G⁻¹Bᵀμ with B x = −2Bv; v⁺ = v + x.
        let minus_two = w.constant(-2.0);
        let g: Vec<Value> = b
            .iter()
            .map(|r| {
                let pairs: Vec<(Value, Value)> = (0..n).map(|i| (r[i], Some(v(i)))).collect();
                let bv = w.dot(&pairs);
                w.product(&[Some(minus_two), bv])
            })
            .collect();
        let x = w.constrained(&lg, &b, &vec![None; n], &g)?;
        for (i, xi) in x.iter().enumerate() {
            let out = Slot::Out(i);
            w.instrs.push(match xi {
                Some(xi) => Instr::Add(out, vec![v(i), *xi]),
                None => Instr::Assign(out, v(i)),
            });
        }
        Some(self.finish(w, n))
    }

    /// q̈ of G q̈ + h = Aᵀλ, A q̈ + Ȧq̇ = 0 from this program, whose outputs
    /// are the entries of G and A (the rows) that `layout` places and those
    /// of h and Ȧq̇ (one per row) that `forcing` and `drift` place. `None`
    /// as for [`Program::reflect_by_elimination`].
    pub fn motion_by_elimination(
        &self,
        layout: &Layout,
        forcing: &[Option<usize>],
        drift: &[Option<usize>],
    ) -> Option<Program> {
        let n = layout.n;
        assert_eq!(forcing.len(), n, "h has n entries");
        assert_eq!(drift.len(), layout.rows.len(), "one drift per row");
        let (mut w, lg, a, base) = self.eliminate(layout)?;
        let output = |e: &Option<usize>| e.map(|k| Slot::Temp(base + k));
        let h: Vec<Value> = forcing.iter().map(output).collect();
        let c: Vec<Value> = drift.iter().map(output).collect();
        // x = G⁻¹(h + Aᵀμ) with A x = Ȧq̇ is −q̈ (and μ = −λ).
        let x = w.constrained(&lg, &a, &h, &c)?;
        let (minus_one, zero) = (w.constant(-1.0), w.constant(0.0));
        for (i, xi) in x.iter().enumerate() {
            let out = Slot::Out(i);
            w.instrs.push(match xi {
                Some(xi) => Instr::Mul(out, vec![minus_one, *xi]),
                None => Instr::Assign(out, zero),
            });
        }
        Some(self.finish(w, n))
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // matrices by index, as written on paper
mod tests {
    use super::*;

    /// A program whose outputs are its inputs `0..outputs` (the entries of
    /// G, the rows and the right-hand sides given directly); `extra` more
    /// inputs follow (v).
    fn entries(outputs: usize, extra: usize) -> Program {
        Program {
            inputs: outputs + extra,
            consts: vec![],
            instrs: (0..outputs)
                .map(|k| Instr::Assign(Slot::Out(k), Slot::Input(k)))
                .collect(),
            outputs,
        }
    }

    /// The solution of a x = b by Gaussian elimination with partial
    /// pivoting (a may be indefinite).
    fn solve(a: &[Vec<f64>], b: &[f64]) -> Vec<f64> {
        let m = a.len();
        let mut a: Vec<Vec<f64>> = a
            .iter()
            .zip(b)
            .map(|(r, x)| r.iter().copied().chain([*x]).collect())
            .collect();
        for c in 0..m {
            let p = (c..m)
                .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
                .unwrap();
            a.swap(c, p);
            for r in 0..m {
                if r != c {
                    let f = a[r][c] / a[c][c];
                    for j in 0..=m {
                        a[r][j] -= f * a[c][j];
                    }
                }
            }
        }
        (0..m).map(|r| a[r][m] / a[r][r]).collect()
    }

    /// The saddle-point system [G −Rᵀ; R 0] [x; μ] = [f; g], solved
    /// densely: x.
    fn saddle(g: &[Vec<f64>], rows: &[Vec<f64>], f: &[f64], rhs: &[f64]) -> Vec<f64> {
        let (n, k) = (g.len(), rows.len());
        let a: Vec<Vec<f64>> = (0..n + k)
            .map(|i| {
                (0..n + k)
                    .map(|j| match (i < n, j < n) {
                        (true, true) => g[i][j],
                        (true, false) => -rows[j - n][i],
                        (false, true) => rows[i - n][j],
                        (false, false) => 0.0,
                    })
                    .collect()
            })
            .collect();
        let b: Vec<f64> = f.iter().chain(rhs).copied().collect();
        solve(&a, &b)[..n].to_vec()
    }

    /// A small deterministic generator (no dependency for a unit test).
    fn numbers(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }
    }

    /// A random positive definite n×n matrix and k random rows.
    fn system(
        next: &mut impl FnMut() -> f64,
        n: usize,
        k: usize,
    ) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
        let a: Vec<Vec<f64>> = (0..n).map(|_| (0..n).map(|_| next()).collect()).collect();
        let g = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        (0..n).map(|m| a[i][m] * a[j][m]).sum::<f64>()
                            + if i == j { 0.5 } else { 0.0 }
                    })
                    .collect()
            })
            .collect();
        let rows = (0..k).map(|_| (0..n).map(|_| next()).collect()).collect();
        (g, rows)
    }

    /// Inputs holding G's lower triangle and the rows, and their layout.
    fn placed(g: &[Vec<f64>], rows: &[Vec<f64>]) -> (Vec<f64>, Layout) {
        let n = g.len();
        let mut inputs = Vec::new();
        let mut layout = Layout {
            n,
            g: Vec::new(),
            rows: Vec::new(),
        };
        for i in 0..n {
            for j in 0..=i {
                layout.g.push(Some(inputs.len()));
                inputs.push(g[i][j]);
            }
        }
        for r in rows {
            let placed = r
                .iter()
                .map(|x| {
                    inputs.push(*x);
                    Some(inputs.len() - 1)
                })
                .collect();
            layout.rows.push(placed);
        }
        (inputs, layout)
    }

    fn close(got: &[f64], want: &[f64]) {
        for (x, y) in got.iter().zip(want) {
            assert!(
                (x - y).abs() < 1e-9 * (1.0 + y.abs()),
                "{got:?} vs {want:?}"
            );
        }
    }

    /// Dense G (n = 5) and B with k = 1, 2, 3 rows: the written-out code
    /// agrees with v − 2G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹Bv solved densely.
    #[test]
    fn dense_reflection_matches_gaussian_elimination() {
        let n = 5;
        let mut next = numbers(7);
        for k in 1..=3 {
            for _ in 0..20 {
                let (g, b) = system(&mut next, n, k);
                let v: Vec<f64> = (0..n).map(|_| next()).collect();
                let (mut inputs, layout) = placed(&g, &b);
                let p = entries(inputs.len(), n)
                    .reflect_by_elimination(&layout, inputs.len())
                    .expect("dense G");
                inputs.extend(&v);
                // x = G⁻¹Bᵀμ with Bx = −2Bv.
                let bv: Vec<f64> = b
                    .iter()
                    .map(|r| -2.0 * r.iter().zip(&v).map(|(a, b)| a * b).sum::<f64>())
                    .collect();
                let x = saddle(&g, &b, &vec![0.0; n], &bv);
                let want: Vec<f64> = v.iter().zip(&x).map(|(a, b)| a + b).collect();
                close(&p.eval(&inputs), &want);
            }
        }
    }

    /// Dense G (n = 5), h and k = 0…3 rows of A with Ȧq̇: the written-out
    /// q̈ solves G q̈ + h = Aᵀλ, A q̈ + Ȧq̇ = 0.
    #[test]
    fn dense_motion_matches_the_saddle_point_system() {
        let n = 5;
        let mut next = numbers(3);
        for k in 0..=3 {
            for _ in 0..20 {
                let (g, a) = system(&mut next, n, k);
                let (mut inputs, layout) = placed(&g, &a);
                let mut place = |x: f64| {
                    inputs.push(x);
                    Some(inputs.len() - 1)
                };
                let h: Vec<f64> = (0..n).map(|_| next()).collect();
                let c: Vec<f64> = (0..k).map(|_| next()).collect();
                let forcing: Vec<Option<usize>> = h.iter().map(|x| place(*x)).collect();
                let drift: Vec<Option<usize>> = c.iter().map(|x| place(*x)).collect();
                let p = entries(inputs.len(), 0)
                    .motion_by_elimination(&layout, &forcing, &drift)
                    .expect("dense G");
                let minus = |x: &[f64]| x.iter().map(|y| -y).collect::<Vec<_>>();
                close(&p.eval(&inputs), &saddle(&g, &a, &minus(&h), &minus(&c)));
            }
        }
    }

    /// A diagonal G and a single row: no fill-in, so the code is the
    /// textbook formula v − 2 (b·v / Σ bᵢ²/gᵢ) G⁻¹b, n divisions for the
    /// pivots and one for the Schur complement, nothing for the zeros.
    #[test]
    fn zeros_stay_out_of_the_code() {
        let n = 3;
        // G = diag(2, 3, 5), b = (1, 0, 4).
        let layout = Layout {
            n,
            g: vec![Some(0), None, Some(1), None, None, Some(2)],
            rows: vec![vec![Some(3), None, Some(4)]],
        };
        let p = entries(5, n).reflect_by_elimination(&layout, 5).unwrap();
        let v = [1.0, -2.0, 0.5];
        let got = p.eval(&[2.0, 3.0, 5.0, 1.0, 4.0, v[0], v[1], v[2]]);
        let s = 1.0 / 2.0 + 16.0 / 5.0;
        let mu = (v[0] + 4.0 * v[2]) / s;
        let want = [v[0] - 2.0 * mu / 2.0, v[1], v[2] - 2.0 * mu * 4.0 / 5.0];
        for (x, y) in got.iter().zip(&want) {
            assert!((x - y).abs() < 1e-14, "{got:?} vs {want:?}");
        }
        let ops = p.op_count();
        assert_eq!(ops.div, 4, "{ops}");
        // The middle velocity is untouched: its output is a plain copy.
        assert!(
            p.instrs
                .contains(&Instr::Assign(Slot::Out(1), Slot::Input(6)))
        );
    }

    /// A G whose first pivot is structurally zero has no elimination
    /// without pivoting.
    #[test]
    fn a_structurally_zero_pivot_is_refused() {
        let layout = Layout {
            n: 2,
            g: vec![None, Some(0), Some(1)],
            rows: vec![vec![Some(2), Some(3)]],
        };
        assert!(entries(4, 2).reflect_by_elimination(&layout, 4).is_none());
        assert!(
            entries(4, 0)
                .motion_by_elimination(&layout, &[None, None], &[None])
                .is_none()
        );
    }
}
