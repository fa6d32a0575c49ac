//! The continuous marginal-conditional warp of Dupuy and Jakob 2018 (section 5
//! and its supplement; Mitsuba's `Marginal2D<.., true>` is an implementation of
//! the same construction): a density given on a regular `w x h` grid over the
//! unit square and interpolated bilinearly, conditioned on up to three
//! parameters (incident `phi`, `theta`, colour channel) between whose grid
//! values the tables are interpolated linearly.
//!
//! The mapping from the unit square to itself is marginal in `y`, conditional
//! in `x`, each the exact integral of the piecewise-linear interpolant, so it
//! is continuous and invertible. `invert` is the inverse of that sampling map;
//! the RGL files store reflectance on its output domain, so evaluating a BRDF
//! means inverting the warp of the visible normal distribution.

/// What is wrong with the tables of a warp (the caller names the field).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct WarpError(pub String);

impl From<String> for WarpError {
    fn from(m: String) -> Self {
        WarpError(m)
    }
}

impl From<&str> for WarpError {
    fn from(m: &str) -> Self {
        WarpError(m.to_string())
    }
}

/// A bilinear density on the unit square with its cumulative tables, one slice
/// per combination of parameter grid values.
#[derive(Clone, Debug)]
pub struct Warp2D {
    w: usize,
    h: usize,
    /// Grid values of each parameter, outermost first.
    params: Vec<Vec<f64>>,
    /// Slice stride of each parameter (0 for a parameter with one value).
    strides: Vec<usize>,
    data: Vec<f64>,
    marg: Vec<f64>,
    cond: Vec<f64>,
    normalized: bool,
}

/// Up to 8 (slice, weight) pairs of the multilinear parameter interpolation.
struct Slices {
    n: usize,
    idx: [usize; 8],
    wt: [f64; 8],
}

impl Warp2D {
    /// Builds the warp from `data`, `slices x h x w` values (row-major, `x`
    /// fastest), `params` the grid values of each parameter (the slices are
    /// ordered with the last parameter fastest). With `normalize`, each slice
    /// is scaled to integrate to one over the unit square; with `cdf`, the
    /// tables for [`Warp2D::invert`] are built. Errors on a shape mismatch, a
    /// grid smaller than 2 x 2 or a parameter grid that does not increase.
    pub fn new(
        data: &[f32],
        w: usize,
        h: usize,
        params: Vec<Vec<f64>>,
        normalize: bool,
        cdf: bool,
    ) -> Result<Warp2D, WarpError> {
        if w < 2 || h < 2 {
            return Err(WarpError::from(format!(
                "a {w} x {h} grid is too small (at least 2 x 2)"
            )));
        }
        let mut slices = 1usize;
        let mut strides = vec![0; params.len()];
        for (i, p) in params.iter().enumerate().rev() {
            if p.is_empty() {
                return Err(WarpError::from("a parameter grid is empty"));
            }
            if p.windows(2)
                .any(|v| v[1].partial_cmp(&v[0]) != Some(std::cmp::Ordering::Greater))
                || p.iter().any(|v| !v.is_finite())
            {
                return Err(WarpError::from(
                    "a parameter grid is not strictly increasing and finite",
                ));
            }
            strides[i] = if p.len() > 1 { slices } else { 0 };
            slices *= p.len();
        }
        let n = w * h;
        if data.len() != slices * n {
            return Err(WarpError::from(format!(
                "{} values where the shapes need {}",
                data.len(),
                slices * n
            )));
        }
        if data.iter().any(|v| !v.is_finite()) {
            return Err(WarpError::from("a value is not finite"));
        }
        let (sx, sy) = (0.5 / (w - 1) as f64, 0.5 / (h - 1) as f64);
        let mut out = Vec::with_capacity(slices * n);
        let (mut marg, mut cond) = (Vec::new(), Vec::new());
        for s in 0..slices {
            let d = &data[s * n..(s + 1) * n];
            let mut norm = 1.0;
            if cdf {
                let c0 = cond.len();
                let mut sums = vec![0.0; h];
                for (y, sum) in sums.iter_mut().enumerate() {
                    let mut acc = 0.0;
                    for x in 0..w - 1 {
                        acc += sx * (d[y * w + x] as f64 + d[y * w + x + 1] as f64);
                        cond.push(acc);
                    }
                    *sum = acc;
                }
                let m0 = marg.len();
                let mut acc = 0.0;
                for y in 0..h - 1 {
                    acc += sy * (sums[y] + sums[y + 1]);
                    marg.push(acc);
                }
                if normalize {
                    if acc.is_nan() || acc <= 0.0 {
                        return Err(WarpError::from(format!(
                            "slice {s} has no positive integral and cannot be normalised"
                        )));
                    }
                    norm = 1.0 / acc;
                    cond[c0..].iter_mut().for_each(|v| *v *= norm);
                    marg[m0..].iter_mut().for_each(|v| *v *= norm);
                }
            } else if normalize {
                let mut sum = 0.0;
                for y in 0..h - 1 {
                    for x in 0..w - 1 {
                        let i = y * w + x;
                        sum += d[i] as f64 + d[i + 1] as f64 + d[i + w] as f64 + d[i + w + 1] as f64;
                    }
                }
                if sum.is_nan() || sum <= 0.0 {
                    return Err(WarpError::from(format!(
                        "slice {s} has no positive integral and cannot be normalised"
                    )));
                }
                norm = 1.0 / (sx * sy * sum);
            }
            out.extend(d.iter().map(|&v| v as f64 * norm));
        }
        Ok(Warp2D {
            w,
            h,
            params,
            strides,
            data: out,
            marg,
            cond,
            normalized: normalize,
        })
    }

    fn slices(&self, param: &[f64]) -> Slices {
        let mut s = Slices {
            n: 1,
            idx: [0; 8],
            wt: [1.0; 8],
        };
        for (d, grid) in self.params.iter().enumerate() {
            if grid.len() == 1 {
                continue;
            }
            let x = param[d];
            // the interval [i, i+1] with i the number of interior grid values below x
            let i = grid[1..grid.len() - 1].iter().take_while(|&&g| g < x).count();
            let (p0, p1) = (grid[i], grid[i + 1]);
            let t = ((x - p0) / (p1 - p0)).clamp(0.0, 1.0);
            let t = if t.is_nan() { 0.0 } else { t };
            let n = s.n;
            for k in 0..n {
                s.idx[n + k] = s.idx[k] + (i + 1) * self.strides[d];
                s.wt[n + k] = s.wt[k] * t;
                s.idx[k] += i * self.strides[d];
                s.wt[k] *= 1.0 - t;
            }
            s.n = 2 * n;
        }
        s
    }

    fn look(table: &[f64], per_slice: usize, s: &Slices, i: usize) -> f64 {
        (0..s.n).map(|k| s.wt[k] * table[s.idx[k] * per_slice + i]).sum()
    }

    /// Splits a point of the unit square into its patch and the position in it.
    fn patch(&self, p: [f64; 2]) -> (usize, usize, f64, f64) {
        let fx = p[0].clamp(0.0, 1.0) * (self.w - 1) as f64;
        let fy = p[1].clamp(0.0, 1.0) * (self.h - 1) as f64;
        let fx = if fx.is_nan() { 0.0 } else { fx };
        let fy = if fy.is_nan() { 0.0 } else { fy };
        let ix = (fx as usize).min(self.w - 2);
        let iy = (fy as usize).min(self.h - 2);
        (ix, iy, fx - ix as f64, fy - iy as f64)
    }

    /// The interpolated density at `p` for the parameter values `param`.
    pub fn eval(&self, p: [f64; 2], param: &[f64]) -> f64 {
        let s = self.slices(param);
        let (ix, iy, tx, ty) = self.patch(p);
        let n = self.w * self.h;
        let i = iy * self.w + ix;
        let v00 = Self::look(&self.data, n, &s, i);
        let v10 = Self::look(&self.data, n, &s, i + 1);
        let v01 = Self::look(&self.data, n, &s, i + self.w);
        let v11 = Self::look(&self.data, n, &s, i + self.w + 1);
        let a = v00 + (v10 - v00) * tx;
        let b = v01 + (v11 - v01) * tx;
        a + (b - a) * ty
    }

    /// The inverse of the sampling map: the point of the unit square that the
    /// warp sends to `p`, and the density at `p`. Needs the tables (`cdf`).
    pub fn invert(&self, p: [f64; 2], param: &[f64]) -> ([f64; 2], f64) {
        let s = self.slices(param);
        let (ix, iy, tx, ty) = self.patch(p);
        let (w, n) = (self.w, self.w * self.h);
        let (nc, nm) = (self.h * (w - 1), self.h - 1);
        let i = iy * w + ix;
        let v00 = Self::look(&self.data, n, &s, i);
        let v10 = Self::look(&self.data, n, &s, i + 1);
        let v01 = Self::look(&self.data, n, &s, i + w);
        let v11 = Self::look(&self.data, n, &s, i + w + 1);
        let c0 = v00 + (v01 - v00) * ty;
        let c1 = v10 + (v11 - v10) * ty;
        let pdf = c0 + (c1 - c0) * tx;
        let px = 1.0 / (w - 1) as f64;
        let py = 1.0 / (self.h - 1) as f64;
        // integral of the linear segment over [0, tx] of the patch
        let mut x = tx * (c0 + (c1 - c0) * 0.5 * tx) * px;
        let oc = iy * (w - 1);
        if ix > 0 {
            let a = Self::look(&self.cond, nc, &s, oc + ix - 1);
            let b = Self::look(&self.cond, nc, &s, oc + ix - 1 + (w - 1));
            x += a + (b - a) * ty;
        }
        let r0 = Self::look(&self.cond, nc, &s, oc + (w - 1) - 1);
        let r1 = Self::look(&self.cond, nc, &s, oc + 2 * (w - 1) - 1);
        let row = r0 + (r1 - r0) * ty;
        x = if row > 0.0 { x / row } else { tx * px + ix as f64 * px };
        let mut y = ty * (r0 + (r1 - r0) * 0.5 * ty) * py;
        if iy > 0 {
            y += Self::look(&self.marg, nm, &s, iy - 1);
        }
        if !self.normalized {
            let total = Self::look(&self.marg, nm, &s, nm - 1);
            y = if total > 0.0 { y / total } else { p[1] };
        }
        ([x, y], pdf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A constant density: the warp is the identity.
    #[test]
    fn constant_density_inverts_to_identity() {
        let w = Warp2D::new(&[2.0; 12], 4, 3, vec![], true, true).unwrap();
        for &p in &[[0.0, 0.0], [0.3, 0.7], [1.0, 1.0], [0.99, 0.01]] {
            let (q, pdf) = w.invert(p, &[]);
            assert!(
                (q[0] - p[0]).abs() < 1e-12 && (q[1] - p[1]).abs() < 1e-12,
                "{p:?} -> {q:?}"
            );
            assert!((pdf - 1.0).abs() < 1e-12);
        }
    }

    /// A density linear in x, f = 2x on [0,1] (grid 0, 1): the marginal-conditional
    /// inverse is the CDF x^2 (closed form), whatever the grid of y.
    #[test]
    fn linear_density_inverts_to_its_cdf() {
        let w = Warp2D::new(&[0.0, 1.0, 0.0, 1.0], 2, 2, vec![], true, true).unwrap();
        for &x in &[0.1, 0.5, 0.9] {
            let (q, pdf) = w.invert([x, 0.4], &[]);
            assert!((q[0] - x * x).abs() < 1e-12, "{x}: {q:?}");
            assert!((q[1] - 0.4).abs() < 1e-12);
            assert!((pdf - 2.0 * x).abs() < 1e-12);
        }
    }

    /// Parameter interpolation is linear between slices: halfway between a
    /// constant 1 and a constant 3 (unnormalised) is 2.
    #[test]
    fn parameters_interpolate_linearly() {
        let mut d = vec![1.0f32; 4];
        d.extend([3.0f32; 4]);
        let w = Warp2D::new(&d, 2, 2, vec![vec![0.0, 1.0]], false, false).unwrap();
        assert!((w.eval([0.2, 0.2], &[0.5]) - 2.0).abs() < 1e-12);
        assert!(
            (w.eval([0.2, 0.2], &[-3.0]) - 1.0).abs() < 1e-12,
            "clamped below the grid"
        );
        assert!(
            (w.eval([0.2, 0.2], &[7.0]) - 3.0).abs() < 1e-12,
            "clamped above the grid"
        );
    }
}
