//! Gauss-Legendre quadrature nodes and weights (Golub-Welsch via Newton on the
//! Legendre recurrence; Abramowitz & Stegun 25.4.29).

/// `n`-point Gauss-Legendre rule on [0, 1]: (nodes, weights), weights summing to 1.
pub fn gauss_legendre_01(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        // Initial guess (Tricomi), then Newton on P_n.
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            if n == 1 {
                p1 = z;
                p0 = 1.0;
            }
            dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-15 {
                break;
            }
        }
        let wt = 2.0 / ((1.0 - z * z) * dp * dp);
        // Map [-1, 1] to [0, 1].
        x[i] = 0.5 * (1.0 - z);
        x[n - 1 - i] = 0.5 * (1.0 + z);
        w[i] = 0.5 * wt;
        w[n - 1 - i] = 0.5 * wt;
    }
    (x, w)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn integrates_polynomials_exactly() {
        for n in [1usize, 2, 5, 16, 33] {
            let (x, w) = gauss_legendre_01(n);
            for p in 0..(2 * n) {
                let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p as i32)).sum();
                assert!((s - 1.0 / (p as f64 + 1.0)).abs() < 1e-12, "n={n} p={p} {s}");
            }
        }
    }
}
