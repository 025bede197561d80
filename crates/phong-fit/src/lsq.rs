//! Box-constrained linear least squares for a handful of unknowns: minimise
//! `|Bx − t|²` with `lo ≤ x ≤ hi`, from the normal equations `G = BᵀB`, `h = Bᵀt`.
//!
//! The problem is a convex quadratic, so its minimum is the best of the candidates that fix
//! each unknown at a bound or leave it free (3ⁿ of them, 81 for the 4 colour terms): each
//! candidate solves its free unknowns' reduced system; infeasible ones are dropped. Exact, and
//! for n ≤ 4 cheaper than an iterative active-set method's bookkeeping.

/// The normal equations of a least-squares problem in `N` unknowns.
#[derive(Clone, Copy, Debug)]
pub struct Normal<const N: usize> {
    /// `BᵀB`.
    pub g: [[f64; N]; N],
    /// `Bᵀt`.
    pub h: [f64; N],
    /// `tᵀt`.
    pub tt: f64,
    /// Rows summed.
    pub rows: usize,
}

impl<const N: usize> Default for Normal<N> {
    fn default() -> Self {
        Normal {
            g: [[0.0; N]; N],
            h: [0.0; N],
            tt: 0.0,
            rows: 0,
        }
    }
}

impl<const N: usize> Normal<N> {
    /// Adds one row: basis values `b` and target `t`.
    #[inline]
    pub fn add(&mut self, b: &[f64; N], t: f64) {
        for i in 0..N {
            for j in 0..N {
                self.g[i][j] += b[i] * b[j];
            }
            self.h[i] += b[i] * t;
        }
        self.tt += t * t;
        self.rows += 1;
    }

    /// The sum of squared residuals at `x`.
    pub fn residual(&self, x: &[f64; N]) -> f64 {
        let mut r = self.tt;
        for i in 0..N {
            r -= 2.0 * self.h[i] * x[i];
            for j in 0..N {
                r += x[i] * self.g[i][j] * x[j];
            }
        }
        r.max(0.0)
    }

    /// The minimiser over `lo ≤ x ≤ hi` (only the unknowns with `free[i]`; the others stay at
    /// `fixed[i]`), and its residual. `hi` may be infinite (no upper bound).
    pub fn solve(&self, free: &[bool; N], fixed: &[f64; N], lo: f64, hi: f64) -> ([f64; N], f64) {
        let mut best = (*fixed, self.residual(fixed));
        let idx: Vec<usize> = (0..N).filter(|&i| free[i]).collect();
        let n = idx.len();
        // Each free unknown: 0 = solved, 1 = at lo, 2 = at hi.
        'candidates: for code in 0..3usize.pow(n as u32) {
            let mut x = *fixed;
            let mut states = vec![0; n];
            let mut c = code;
            for s in states.iter_mut() {
                *s = c % 3;
                c /= 3;
            }
            for (k, &i) in idx.iter().enumerate() {
                match states[k] {
                    1 => x[i] = lo,
                    2 if hi.is_finite() => x[i] = hi,
                    2 => continue 'candidates,
                    _ => {}
                }
            }
            let solved: Vec<usize> = idx
                .iter()
                .zip(&states)
                .filter(|(_, s)| **s == 0)
                .map(|(i, _)| *i)
                .collect();
            if !solved.is_empty() {
                // G_ss x_s = h_s − G_sf x_f.
                let m = solved.len();
                let mut a = vec![vec![0.0; m + 1]; m];
                for (r, &i) in solved.iter().enumerate() {
                    let mut rhs = self.h[i];
                    for j in 0..N {
                        if !solved.contains(&j) {
                            rhs -= self.g[i][j] * x[j];
                        }
                    }
                    for (c2, &j) in solved.iter().enumerate() {
                        a[r][c2] = self.g[i][j];
                    }
                    a[r][m] = rhs;
                }
                let Some(sol) = gauss(a) else { continue };
                if sol.iter().any(|v| !(lo - 1e-12..=hi + 1e-12).contains(v)) {
                    continue;
                }
                for (k, &i) in solved.iter().enumerate() {
                    x[i] = sol[k].clamp(lo, hi);
                }
            }
            let r = self.residual(&x);
            if r < best.1 {
                best = (x, r);
            }
        }
        best
    }
}

/// Solves the augmented system `a` (m rows of m + 1) by Gaussian elimination with partial
/// pivoting; `None` when it is singular.
fn gauss(mut a: Vec<Vec<f64>>) -> Option<Vec<f64>> {
    let m = a.len();
    let scale = a.iter().flat_map(|r| r[..m].iter()).fold(0.0f64, |s, v| s.max(v.abs()));
    if scale == 0.0 {
        return None;
    }
    for col in 0..m {
        let p = (col..m).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[p][col].abs() <= scale * 1e-12 {
            return None;
        }
        a.swap(col, p);
        for r in 0..m {
            if r != col {
                let f = a[r][col] / a[col][col];
                for c in col..=m {
                    a[r][c] -= f * a[col][c];
                }
            }
        }
    }
    Some((0..m).map(|i| a[i][m] / a[i][i]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tiny xorshift for reproducible cases.
    fn rng(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn recovers_an_exact_solution_inside_the_box() {
        let mut seed = 7;
        let x_true = [0.3, 0.7, 0.05, 0.9];
        let mut n = Normal::<4>::default();
        for _ in 0..200 {
            let b = [rng(&mut seed), rng(&mut seed), rng(&mut seed), rng(&mut seed)];
            let t: f64 = (0..4).map(|i| b[i] * x_true[i]).sum();
            n.add(&b, t);
        }
        let (x, r) = n.solve(&[true; 4], &[0.0; 4], 0.0, 1.0);
        for i in 0..4 {
            assert!((x[i] - x_true[i]).abs() < 1e-9, "{x:?}");
        }
        assert!(r < 1e-12);
    }

    #[test]
    fn the_box_optimum_beats_every_point_of_a_grid() {
        // Targets outside the box: the constrained optimum must be no worse than any feasible
        // point tried by brute force.
        let mut seed = 99;
        for _ in 0..20 {
            let mut n = Normal::<3>::default();
            let x_true = [
                rng(&mut seed) * 3.0 - 1.0,
                rng(&mut seed) * 3.0 - 1.0,
                rng(&mut seed) * 3.0 - 1.0,
            ];
            for _ in 0..50 {
                let b = [rng(&mut seed), rng(&mut seed), rng(&mut seed)];
                let t: f64 = (0..3).map(|i| b[i] * x_true[i]).sum::<f64>() + (rng(&mut seed) - 0.5) * 0.1;
                n.add(&b, t);
            }
            let (x, r) = n.solve(&[true; 3], &[0.0; 3], 0.0, 1.0);
            assert!(x.iter().all(|v| (0.0..=1.0).contains(v)));
            for a in 0..=20 {
                for b in 0..=20 {
                    for c in 0..=20 {
                        let y = [a as f64 / 20.0, b as f64 / 20.0, c as f64 / 20.0];
                        assert!(
                            r <= n.residual(&y) + 1e-9,
                            "{x:?} {r} worse than {y:?} {}",
                            n.residual(&y)
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn without_an_upper_bound_values_pass_one() {
        let mut n = Normal::<1>::default();
        for k in 1..10 {
            n.add(&[k as f64], 2.5 * k as f64);
        }
        assert!((n.solve(&[true], &[0.0], 0.0, f64::INFINITY).0[0] - 2.5).abs() < 1e-12);
        assert_eq!(n.solve(&[true], &[0.0], 0.0, 1.0).0[0], 1.0);
    }

    #[test]
    fn fixed_unknowns_stay_put() {
        let mut n = Normal::<2>::default();
        for k in 0..10 {
            let b = [1.0, k as f64];
            n.add(&b, 0.5 + 0.25 * k as f64);
        }
        let (x, _) = n.solve(&[false, true], &[0.1, 0.0], 0.0, 1.0);
        assert_eq!(x[0], 0.1);
        // With x0 fixed at 0.1 the best slope is above 0.25.
        assert!(x[1] > 0.25);
    }
}
