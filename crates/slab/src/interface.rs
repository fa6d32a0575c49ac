//! Dielectric interfaces as layers: air (index 1, top side) over a medium of
//! relative index `eta` (bottom side).
//!
//! **Smooth (Fresnel) interface.** Mirror reflection and Snell refraction keep
//! the azimuth of the propagation direction, so the matrices are the same for
//! every Fourier order and diagonal on the grids of [`crate::quad`] (each
//! outside node refracts onto its Snell image inside):
//! - `R_top[k][k] = F(mu_k)`, the unpolarised Fresnel reflectance
//!   (`paperbsdf_core::fresnel`);
//! - `T_down[k'][k] = eta^2 (1 - F)`, `T_up[k][k'] = (1 - F) / eta^2`, where
//!   `k'` is the inside image of outside node `k`: **radiance scales by
//!   `eta^2` on entering the denser medium and by `1 / eta^2` on leaving it**
//!   (the `n^2` law of radiance, the same radiance-transport convention as
//!   `paperbsdf_core::dielectric`); so the flux `sum w mu L` is conserved,
//!   since `w' mu' = w mu / eta^2` on the image nodes;
//! - `R_bot = diag(F)` on the image nodes and `1` on the nodes of total
//!   internal reflection (`mu < mu_c`).
//!
//! With the reciprocity weights `w mu / eta^2` these matrices satisfy the
//! reciprocity relations of [`crate::layer`] exactly.

use crate::layer::Layer;
use crate::quad::Grid;
use nalgebra::DMatrix;
use paperbsdf_core::fresnel::fresnel_dielectric;

/// The smooth interface from the `outside` grid (air) to the `inside` grid
/// made from it by [`Grid::inside`] (module doc). Index-matched (`eta = 1`):
/// the identity.
pub fn smooth_interface(outside: &Grid, inside: &Grid) -> Layer {
    let (no, ni) = (outside.len(), inside.len());
    let eta = inside.eta;
    if eta == 1.0 {
        return Layer::identity(no);
    }
    let e2 = eta * eta;
    let off = ni - no;
    let mut r_top = DMatrix::zeros(no, no);
    let mut t_down = DMatrix::zeros(ni, no);
    let mut t_up = DMatrix::zeros(no, ni);
    let mut r_bot = DMatrix::identity(ni, ni);
    for k in 0..no {
        let f = fresnel_dielectric(outside.mu[k], eta);
        r_top[(k, k)] = f;
        t_down[(off + k, k)] = e2 * (1.0 - f);
        t_up[(k, off + k)] = (1.0 - f) / e2;
        r_bot[(off + k, off + k)] = f;
    }
    Layer {
        r_top,
        t_down,
        r_bot,
        t_up,
    }
}
