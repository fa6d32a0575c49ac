//! Dense solves for the adding-doubling: LU with partial pivoting
//! (nalgebra's factorisation), and triangular solves blocked so that most
//! of their work is matrix products (nalgebra's `gemm`, through
//! `matrixmultiply`'s vectorised kernels).
//!
//! nalgebra's `LU::solve` runs its forward and back substitutions one
//! right-hand side column at a time; with as many columns as rows (every
//! adding and doubling step solves for a whole matrix) those two loops took
//! 15% of a build (perf on the glossy preset, more than the LU itself).
//! Splitting each triangle in halves, `L = [L11 0; L21 L22]`, solves
//! `L11 X1 = B1`, updates `B2 -= L21 X1` by a product and solves
//! `L22 X2 = B2`, recursively down to [`BASE`] rows, where nalgebra's
//! substitution finishes (the upper triangle likewise from the bottom).
//! The arithmetic is the same substitution reordered: results agree with
//! nalgebra's `solve` to rounding (tests below).

use nalgebra::{DMatrix, DMatrixView, DMatrixViewMut};

/// Rows up to which a triangle is solved by plain substitution (8: three
/// glossy builds took 4.9 s of CPU, 5.0 s with 24; `perf stat` on a probe
/// while writing this).
const BASE: usize = 8;

/// A square matrix factored as `P A = L U`.
pub(crate) struct Factored {
    perm: nalgebra::linalg::PermutationSequence<nalgebra::Dyn>,
    l: DMatrix<f64>,
    u: DMatrix<f64>,
}

impl Factored {
    /// Factors `a` (square).
    pub(crate) fn new(a: DMatrix<f64>) -> Factored {
        let (perm, l, u) = a.lu().unpack();
        Factored { perm, l, u }
    }

    /// `A^-1 b`, or `None` when `U` has a zero on its diagonal (as
    /// nalgebra's `LU::solve`).
    pub(crate) fn solve(&self, b: &DMatrix<f64>) -> Option<DMatrix<f64>> {
        if (0..self.u.nrows()).any(|i| self.u[(i, i)] == 0.0) {
            return None;
        }
        let mut x = b.clone();
        self.perm.permute_rows(&mut x);
        lower_unit(self.l.as_view(), x.as_view_mut());
        upper(self.u.as_view(), x.as_view_mut());
        Some(x)
    }
}

/// `a^-1 b` by LU with partial pivoting; `None` if singular (as nalgebra's `LU::solve`).
pub(crate) fn solve(a: DMatrix<f64>, b: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    Factored::new(a).solve(b)
}

/// `x <- L^-1 x` for `L` lower triangular with unit diagonal.
fn lower_unit(l: DMatrixView<f64>, mut x: DMatrixViewMut<f64>) {
    let n = l.nrows();
    if n <= BASE {
        l.solve_lower_triangular_with_diag_mut(&mut x, 1.0);
        return;
    }
    let k = n / 2;
    let (mut x1, mut x2) = x.rows_range_pair_mut(0..k, k..n);
    lower_unit(l.view((0, 0), (k, k)), x1.as_view_mut());
    x2.gemm(-1.0, &l.view((k, 0), (n - k, k)), &x1, 1.0);
    lower_unit(l.view((k, k), (n - k, n - k)), x2);
}

/// `x <- U^-1 x` for `U` upper triangular with a non-zero diagonal.
fn upper(u: DMatrixView<f64>, mut x: DMatrixViewMut<f64>) {
    let n = u.nrows();
    if n <= BASE {
        u.solve_upper_triangular_mut(&mut x);
        return;
    }
    let k = n / 2;
    let (mut x1, mut x2) = x.rows_range_pair_mut(0..k, k..n);
    upper(u.view((k, k), (n - k, n - k)), x2.as_view_mut());
    x1.gemm(-1.0, &u.view((0, k), (k, n - k)), &x2, 1.0);
    upper(u.view((0, 0), (k, k)), x1);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random matrix with entries in `[-1, 1)`.
    fn matrix(rows: usize, cols: usize, seed: u64) -> DMatrix<f64> {
        let mut s = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        DMatrix::from_fn(rows, cols, |_, _| {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
    }

    /// Against nalgebra's `LU::solve` and against the residual, for sizes
    /// around the blocking's splits (below, at and above `BASE`, odd
    /// halves) and right-hand sides of one column to more than the rows, on
    /// matrices that need pivoting (random entries, no dominant diagonal)
    /// and on the adding's `I - R R` with `R` scaled to a spectral radius
    /// near 1.
    #[test]
    fn blocked_solve_is_nalgebras() {
        let mut worst: f64 = 0.0;
        for (k, &n) in [1usize, 7, 24, 25, 49, 64, 80, 97].iter().enumerate() {
            for cols in [1, n, n + 3] {
                let r = matrix(n, n, 3 * k as u64) * (0.99 / n as f64);
                for a in [matrix(n, n, 3 * k as u64 + 1), DMatrix::identity(n, n) - &r * &r] {
                    let b = matrix(n, cols, 3 * k as u64 + 2);
                    let ours = solve(a.clone(), &b).expect("regular");
                    let theirs = a.clone().lu().solve(&b).expect("regular");
                    let scale = theirs.abs().max().max(1.0);
                    worst = worst.max((&ours - &theirs).abs().max() / scale);
                    let residual = (&a * &ours - &b).abs().max() / (a.abs().max() * ours.abs().max()).max(1.0);
                    assert!(residual < 1e-10, "n {n}, {cols} columns: residual {residual}");
                }
            }
        }
        println!("largest difference from nalgebra's solve: {worst:.1e}");
        assert!(worst < 1e-9, "{worst}");
    }

    /// A singular matrix is refused as nalgebra refuses it.
    #[test]
    fn singular_is_none() {
        let mut a = matrix(40, 40, 9);
        for i in 0..40 {
            a[(i, 7)] = 0.0;
        }
        assert!(solve(a.clone(), &matrix(40, 3, 1)).is_none());
        assert!(a.lu().solve(&matrix(40, 3, 1)).is_none());
    }
}
