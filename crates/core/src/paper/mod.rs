//! The Paper BSDF of Papas, de Mesa and Jensen (EGSR 2014), docs/design.md section 4.
//!
//! A slab of thickness `d` (front face `z = 0`, back face `z = -d`) of a
//! scattering medium between two rough dielectric faces, each with its own
//! `eta`, `m` and distribution; light may arrive at either face. Four
//! components, each available alone ([`PaperBsdf::eval_component`]) and summed
//! by [`Bsdf::eval`]:
//!
//! - [`Component::Surface`]: the reflection of the face the light arrives at,
//!   docs/design.md 4.3: Walter's lobe, plus the separable lobes of the energy
//!   compensation and of a coating ([`face`]); a delta lobe for a face without
//!   microfacets.
//! - [`Component::Single`]: single scattering (Hanrahan & Krueger 1993) in
//!   reflection and transmission, with the `Att` losses of the faces and the
//!   `1/eta_b^2` of the exit, docs/design.md 4.4; see [`single`].
//! - [`Component::Multiple`]: light scattered more than once, whose split
//!   between reflection and transmission comes from multipole diffusion
//!   `R_d`, `T_d` (Donner & Jensen 2005; supplement eqs. 2 and 4; see
//!   [`multipole`]) and whose amount closes the energy balance (below).
//! - [`Component::Direct`]: light crossing the slab unscattered (our
//!   extension, docs/design.md 4.6; [`PaperOptions::direct`] switches it off); a
//!   delta lobe when neither face deviates light, otherwise the kernel of
//!   [`direct`]. With air on both sides it leaves parallel to the way it came in.
//!
//! The faces ([`face`]) are those of the physical sheet of [`crate::sheet`]:
//! a base of index `eta_b` (every inside direction is the smooth refraction
//! through `eta_b`, and every exit divides radiance by `eta_b^2`), a front
//! face over a coating when `eta_f != eta_b`, and Walter's or energy-conserving
//! faces as `face_scattering` says.
//!
//! **Multiple scattering that closes the energy balance (our form; the
//! paper's `Att(wi) R_d Att(wo) / (pi eta^2 (1 - rho_in))` is kept as the
//! multipole normalisation, [`PaperOptions::energy_bound`] off).** For light
//! from outside face `e` at outside cosine `mu`, per unit incident flux, the
//! face lets in `Att_e(mu)`; the unscattered light leaves by the direct term
//! `D_e(mu)` (computed from the direct term itself); of the rest the medium
//! scatters the fraction `a` (its single-scattering albedo) and absorbs the
//! remainder on first interaction; single scattering sends out
//! `Att_e(mu) E_ss,e(mu)` (computed from the single-scattering term). What is
//! left, `W_e(mu) = a (Att_e - D_e) - Att_e E_ss,e`, reaches the diffusion.
//! The multipole with the source's albedo set to 1 gives the shares of that
//! flux that leave through each face, `P_R(e) = R_d / a'` and
//! `P_T(e) = T_d / a'` (times each face's escape fraction
//! `Tbar_in / (1 - rho_in)`, 1 for energy-conserving faces), so that
//! absorption during diffusion is the multipole's. The term is
//!
//! `f_ms,r = P_R'(e) W_e(mu_i) W_e(mu_o) / (pi Wbar_e)`,
//! `f_ms,t = Q W_e(mu_i) W_x(mu_o) / pi`,
//!
//! with `Wbar = 2 int W mu dmu`, `Q` the mean of `P_T(e) / Wbar_x` over both
//! faces of entry (one constant both ways: reciprocal; capped so that no face
//! of entry transmits more than the multipole's total `P_R + P_T`) and
//! `P_R'(e) = P_R(e) + P_T(e) - Q Wbar_x`, so each face of entry keeps the
//! multipole's total. Both forms are reciprocal, and the albedo of the term
//! for light at `mu` is exactly `(P_R + P_T) W_e(mu)`. Summed over the
//! components, a sheet that absorbs nothing (`a = 1`, `R_d + T_d = a'`,
//! energy-conserving faces) reflects and transmits exactly what arrives,
//! and any sheet at most that: no albedo exceeds 1. The `W` shape also keeps
//! the first-order light out of the diffusion term, which the paper's sum
//! counted twice.
//!
//! **The multipole normalisation** (`energy_bound` off; the reduced
//! multilayer model) is bounded as a whole: every subsurface term is scaled by
//! the largest constant `kappa <= 1` for which no direction on the face nodes
//! reflects and transmits more than arrives.
//!
//! Sampling ([`Bsdf::sample`]) picks a component in proportion to a cheap
//! estimate of its albedo seen from `wo` (the model is reciprocal, so the
//! albedo for light arriving from `wo` is used) and samples it: visible
//! normals for the surface, the phase function refracted through the macro
//! normal for single scattering, cosine lobes for multiple scattering, the
//! kernel for direct transmission. [`Bsdf::pdf`] returns the full mixture density.

mod build;
mod component;
pub mod direct;
mod eval;
pub(crate) mod face;
pub mod multipole;
mod sample;
pub mod single;
mod tables;

use crate::params::{PaperParams, ParamError};
use crate::phase::HgLobes;
use crate::sheet::Sheet;
use crate::spectrum::Rgb;
use build::multipole_shares;
use direct::SheetKernel;
use eval::LobeProbs;
use face::Face;
use glam::DVec3;
use std::f64::consts::PI;
use tables::{lerp_mu, NA, NP, NS};

pub use component::{Component, ComponentSet};

/// Switches of the Paper BSDF's construction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PaperOptions {
    /// Use the faces' attenuation `Att` (false: every `Att` is 1, the reduced multilayer model).
    pub use_att: bool,
    /// The multiple-scattering term closes the energy balance (module doc);
    /// off: the paper's multipole normalisation, bounded as a whole.
    pub energy_bound: bool,
    /// Include the direct (unscattered) transmission.
    pub direct: bool,
}

impl Default for PaperOptions {
    /// The Paper BSDF: `Att` on, energy bound on, direct transmission on.
    fn default() -> Self {
        PaperOptions {
            use_att: true,
            energy_bound: true,
            direct: true,
        }
    }
}

/// Cosine below which a direction counts as lying in the sheet's plane: it
/// carries no light (zero `eval`, `pdf`; `sample` returns `None`). Avoids 0/0
/// in the microfacet terms for cosines that underflow when squared.
pub const GRAZING_COS: f64 = 1e-12;

/// Whether `w` lies within [`GRAZING_COS`] of the sheet's plane.
#[inline]
pub(crate) fn grazing(w: DVec3) -> bool {
    w.z.abs() < GRAZING_COS
}

/// A side of the sheet: the front face (`z = 0`, outside normal `+z`) or the
/// back face (`z = -d`, outside normal `-z`). Light arrives at, and leaves
/// through, one of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// The front face, `z = 0`: directions with `z > 0` are outside it.
    Front,
    /// The back face, `z = -d`: directions with `z < 0` are outside it.
    Back,
}

impl Side {
    /// Both sides, front first.
    pub const BOTH: [Side; 2] = [Side::Front, Side::Back];

    /// The side that outside direction `w` (pointing away from the sheet) is
    /// on: the front for `w.z > 0`, else the back.
    #[inline]
    pub fn of(w: DVec3) -> Side {
        if w.z > 0.0 {
            Side::Front
        } else {
            Side::Back
        }
    }
    /// A sheet-frame vector in the frame of the face on this side (`+z` toward
    /// the air on that side) and back: the identity for the front, `z -> -z`
    /// for the back (the map is its own inverse; the faces are isotropic, so
    /// the mirror image is as good a frame as a rotation).
    #[inline]
    pub fn local(self, v: DVec3) -> DVec3 {
        match self {
            Side::Front => v,
            Side::Back => DVec3::new(v.x, v.y, -v.z),
        }
    }
    /// The depth `z` of the face on this side in a sheet of thickness `d` (mm):
    /// `0` for the front, `-d` for the back.
    #[inline]
    pub fn z(self, d: f64) -> f64 {
        match self {
            Side::Front => 0.0,
            Side::Back => -d,
        }
    }
    /// The opposite side.
    #[inline]
    pub fn other(self) -> Side {
        match self {
            Side::Front => Side::Back,
            Side::Back => Side::Front,
        }
    }
    /// The sign of `z` of the directions outside this side: `+1` front, `-1` back.
    #[inline]
    pub fn sign(self) -> f64 {
        match self {
            Side::Front => 1.0,
            Side::Back => -1.0,
        }
    }
    /// Name in messages and files (`front`, `back`).
    pub fn name(self) -> &'static str {
        match self {
            Side::Front => "front",
            Side::Back => "back",
        }
    }
}

impl std::fmt::Display for Side {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One value per side of the sheet, indexed by [`Side`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PerSide<T>(pub [T; 2]);

impl<T> std::ops::Index<Side> for PerSide<T> {
    type Output = T;
    #[inline(always)]
    fn index(&self, s: Side) -> &T {
        &self.0[s as usize]
    }
}

impl<T> std::ops::IndexMut<Side> for PerSide<T> {
    #[inline(always)]
    fn index_mut(&mut self, s: Side) -> &mut T {
        &mut self.0[s as usize]
    }
}

/// The side of outside direction `w` ([`Side::of`]).
#[inline(always)]
fn side(w: DVec3) -> Side {
    Side::of(w)
}

/// The Paper BSDF (module doc). Build with [`PaperBsdf::new`] or [`PaperBsdf::reduced_multilayer`].
#[derive(Clone, Debug)]
pub struct PaperBsdf {
    faces: PerSide<Face>,
    /// The phase function's HG lobes without their delta parts
    /// ([`delta_fraction`], [`PaperBsdf::new`]), backward lobe first, weights
    /// relative to the scattering that changes directions.
    phase: HgLobes,
    /// Single-scattering albedo `sigma_s / sigma_t` of the scattering that changes directions.
    albedo: Rgb,
    /// Optical thickness of the scattering that changes directions and of absorption.
    tau: Rgb,
    /// Per face of entry: `W_e(mu)`, the flux per unit incident flux that
    /// reaches the diffusion (module doc), on the [`NA`] nodes of the face tables.
    w_tab: PerSide<[Rgb; NA]>,
    /// Per face of entry: `P_R'(e) / (pi Wbar_e)`, the multiple-scattering reflection constant.
    ms_r: PerSide<Rgb>,
    /// `Q / pi`: the multiple-scattering transmission constant (the same both ways).
    ms_t: Rgb,
    /// Per face of entry: the share `P_R'(e)` and `Q Wbar_x` of the flux `W_e` that leaves by reflection and transmission.
    ms_share: PerSide<(Rgb, Rgb)>,
    /// The flat constants of the multipole normalisation (`energy_bound` off).
    c_r: PerSide<Rgb>,
    c_t: PerSide<Rgb>,
    /// The bound of the multipole normalisation: every subsurface term is scaled by it (1 otherwise).
    kappa: f64,
    /// Per face of entry: the single-scattering albedo `E_ss` on [`NS`] nodes in `sqrt(mu)`.
    ess_tab: PerSide<[Rgb; NS]>,
    /// Per face of exit and node of [`NP`]: the lobe probabilities of [`PaperBsdf::lobe_probs`].
    pr_tab: PerSide<[LobeProbs; NP]>,
    kernel: SheetKernel,
    opts: PaperOptions,
    is_rgb: bool,
    /// All channels of `tau` and the albedo equal (compute one channel).
    grey: bool,
    /// Smallest channel of `tau`.
    tau_min: f64,
    /// Per face of entry: the multipole's `(R_d, T_d)`.
    rd_td: PerSide<(Rgb, Rgb)>,
}

/// Optical thickness above which light crossing the sheet unscattered (on
/// either leg of a path) is below `e^{-40} = 4e-18` of the unattenuated
/// value: transmission terms are not worth their exponentials.
const TAU_DROP: f64 = 40.0;

/// Outside cosine of the tables' node at grazing (`t = 0`): just above the
/// sheet's plane, where the face integrals are still defined.
const NODE_MU_MIN: f64 = 1e-6;

/// Fraction of the incident flux below which a lobe counts as absent for
/// sampling (rounding noise, not a strategy worth a share of samples).
const NEGLIGIBLE: f64 = 1e-12;

/// `|g|` above which part of a Henyey-Greenstein lobe is taken as a delta.
pub const G_DELTA_FROM: f64 = 0.9;

/// `|g|` from which a lobe is entirely a delta. A lobe this narrow (width
/// `~ sqrt(2 (1 - |g|))`, 0.14 rad at 0.99) is below what the quadrature of
/// the single-scattering albedo resolves with the model's nodes, and its
/// peak `~ 1 / (1 - |g|)^2` would dominate `eval` with a spike no sampler
/// of the other lobes finds.
pub const G_DELTA_ALL: f64 = 0.99;

/// The fraction of a lobe of mean cosine `g` taken as a delta in direction
/// (module doc): 0 up to `|g| =` [`G_DELTA_FROM`], 1 from
/// [`G_DELTA_ALL`], a smoothstep between. Continuous in `g`, so the model is
/// continuous at `g = +-1`; no lobe of the paper-like range (`|g| <= 0.9`) is touched.
pub fn delta_fraction(g: f64) -> f64 {
    let x = ((g.abs() - G_DELTA_FROM) / (G_DELTA_ALL - G_DELTA_FROM)).clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

impl PaperBsdf {
    /// The Paper BSDF of `p` (validated; an error names the parameter and its
    /// range) with the default [`PaperOptions`].
    ///
    /// A Henyey-Greenstein lobe with `g` near 1 scatters nearly straight on:
    /// its delta part ([`delta_fraction`]) changes nothing, and its share of
    /// `sigma_s` is left out. The delta part of a lobe with `g` near -1
    /// reverses directions: a retro-reflection that `eval` cannot represent, so
    /// it is left out of the single-scattering term and its light joins the
    /// multiple-scattering term.
    pub fn new(p: &PaperParams) -> Result<PaperBsdf, ParamError> {
        Self::with_options(p, PaperOptions::default())
    }

    /// The reduced multilayer model of the supplement (Figure 5, docs/design.md
    /// 4.7): the Paper BSDF with every `Att` set to 1 (multiple scattering is
    /// flat `R_d / pi`, `T_d / pi`), bounded as a whole (module doc).
    pub fn reduced_multilayer(p: &PaperParams) -> Result<PaperBsdf, ParamError> {
        Self::with_options(
            p,
            PaperOptions {
                use_att: false,
                energy_bound: false,
                direct: true,
            },
        )
    }

    /// The model of `p` with explicit options.
    pub fn with_options(p: &PaperParams, opts: PaperOptions) -> Result<PaperBsdf, ParamError> {
        let sheet = Sheet::from_params(p)?;
        // Two identical faces (the usual uncoated paper): build one, and the
        // tables of light entering through the back mirror those of the front.
        let symmetric = p.dist_f == p.dist_b && p.eta_f == p.eta_b && p.m_f == p.m_b;
        let face_f = Face::of_sheet(&sheet, false, opts.use_att);
        let face_b = if symmetric {
            face_f.clone()
        } else {
            Face::of_sheet(&sheet, true, opts.use_att)
        };
        let faces = PerSide([face_f, face_b]);
        // Near-delta lobes (module doc): the delta part of a forward lobe is
        // no scattering at all; that of a backward lobe joins the diffusion.
        let mut w_straight = 0.0;
        let mut lobes = [(0.0, 0.0); 2];
        for (k, (g, w)) in [(p.g_b, p.w_b), (p.g_f, 1.0 - p.w_b)].into_iter().enumerate() {
            let f = delta_fraction(g);
            if g > 0.0 {
                w_straight += w * f;
            }
            if f < 1.0 && w > 0.0 {
                lobes[k] = (g, w * (1.0 - f));
            }
        }
        let sigma_a = sheet.sigma_a;
        let sigma_s = sheet.sigma_s * (1.0 - w_straight);
        let sigma_t = sigma_a + sigma_s;
        let albedo = sigma_s.zip(sigma_t, |s, t| if t > 0.0 { s / t } else { 1.0 });
        let tau = sigma_t * p.d;
        if w_straight < 1.0 {
            for l in lobes.iter_mut() {
                l.1 /= 1.0 - w_straight;
            }
        }
        let phase = HgLobes::new(lobes);
        let sigma_s_p = sheet.sigma_s * (1.0 - sheet.phase.mean_cosine());
        let kernel = SheetKernel::new([
            (
                p.eta_f,
                faces[Side::Front].microfacet().map_or(0.0, |_| p.m_f),
                p.dist_f == crate::Distribution::Beckmann,
            ),
            (
                p.eta_b,
                faces[Side::Back].microfacet().map_or(0.0, |_| p.m_b),
                p.dist_b == crate::Distribution::Beckmann,
            ),
        ]);
        let mut me = PaperBsdf {
            faces,
            phase,
            albedo,
            tau,
            w_tab: PerSide([[Rgb::ZERO; NA]; 2]),
            ms_r: PerSide([Rgb::ZERO; 2]),
            ms_t: Rgb::ZERO,
            ms_share: PerSide([(Rgb::ZERO, Rgb::ZERO); 2]),
            c_r: PerSide([Rgb::ZERO; 2]),
            c_t: PerSide([Rgb::ZERO; 2]),
            kappa: 1.0,
            ess_tab: PerSide([[Rgb::ZERO; NS]; 2]),
            pr_tab: PerSide([[LobeProbs([0.0; 5]); NP]; 2]),
            kernel,
            opts,
            is_rgb: p.is_rgb(),
            grey: tau.0[0] == tau.0[1]
                && tau.0[1] == tau.0[2]
                && albedo.0[0] == albedo.0[1]
                && albedo.0[1] == albedo.0[2],
            rd_td: PerSide([(Rgb::ZERO, Rgb::ZERO); 2]),
            tau_min: tau.0[0].min(tau.0[1]).min(tau.0[2]),
        };
        me.build_single_tables(symmetric);
        // Multiple scattering per face of entry: the multipole's shares, and
        // the escape fraction Tbar_in / (1 - rho_in) of each face (1 for
        // energy-conserving faces).
        let esc = |f: &Face| {
            let open = 1.0 - f.rho_in();
            if open > 1e-12 {
                (f.tbar_in() / open).min(1.0)
            } else {
                0.0
            }
        };
        let mut shares = PerSide([(Rgb::ZERO, Rgb::ZERO); 2]);
        for e in Side::BOTH {
            let x = e.other();
            let (fe, fx) = (&me.faces[e], &me.faces[x]);
            let (mut pr, mut pt, mut rd, mut td) = (Rgb::ZERO, Rgb::ZERO, Rgb::ZERO, Rgb::ZERO);
            for c in 0..3 {
                let (r, t) = multipole_shares(sigma_s_p.0[c], sigma_a.0[c], p.d, fe.rho_in(), fx.rho_in());
                pr.0[c] = r * esc(fe);
                pt.0[c] = t * esc(fx);
                let st = sigma_s_p.0[c] + sigma_a.0[c];
                let ap = if st > 0.0 { sigma_s_p.0[c] / st } else { 0.0 };
                rd.0[c] = r * ap;
                td.0[c] = t * ap;
            }
            shares[e] = (pr, pt);
            me.rd_td[e] = (rd, td);
            let norm = |f: &Face| if opts.use_att { PI * f.abar } else { PI };
            me.c_r[e] = rd * esc(fe) / norm(fe);
            me.c_t[e] = td * esc(fx) / norm(fx);
        }
        // Symmetric multipole-normalisation transmission (reciprocity).
        let ct = (me.c_t[Side::Front] + me.c_t[Side::Back]) * 0.5;
        me.c_t = PerSide([ct; 2]);
        if opts.energy_bound {
            me.build_ms_tables(&shares);
        } else {
            me.kappa = me.multipole_bound();
        }
        for x in Side::BOTH {
            let sign = x.sign();
            for k in 0..NP {
                let t = k as f64 / (NP - 1) as f64;
                // The node at grazing is taken just above the sheet's plane.
                let mu = (t * t).max(NODE_MU_MIN);
                let wo = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, sign * mu);
                me.pr_tab[x][k] = me.lobe_probs_exact(wo);
            }
        }
        Ok(me)
    }

    /// Whether any wavelength-dependent parameter was an RGB triple.
    pub fn is_rgb(&self) -> bool {
        self.is_rgb
    }

    /// The options the model was built with.
    pub fn options(&self) -> PaperOptions {
        self.opts
    }

    /// `(R_d, T_d)` of the multipole for light entering through `face`, before any normalisation.
    pub fn multipole_rd_td(&self, face: Side) -> (Rgb, Rgb) {
        self.rd_td[face]
    }

    /// The constant `kappa <= 1` by which the multipole normalisation's
    /// subsurface terms are scaled to bound the model as a whole (1 for the
    /// energy-closing form; module doc).
    pub fn subsurface_bound(&self) -> f64 {
        self.kappa
    }

    /// `Att` of `face` at outside cosine `mu`.
    pub fn att(&self, face: Side, mu: f64) -> f64 {
        self.faces[face].att(mu)
    }

    /// `(rho_in, Tbar_in)` of `face` for diffuse light from inside.
    pub fn face_inside_hemispherical(&self, face: Side) -> (f64, f64) {
        let f = &self.faces[face];
        (f.rho_in(), f.tbar_in())
    }

    /// `(k_o, k_i)` of the energy compensation of `face`: the transmitted shares of the energy Walter's interface loses
    /// for light from outside and from inside ([`face`]; 0 for Walter's faces).
    pub fn face_compensation(&self, face: Side) -> (f64, f64) {
        self.faces[face].compensation_shares()
    }

    /// Directional reflectance of `face` alone
    /// for light from outside at cosine `mu` (every lobe of the face).
    pub fn face_reflectance(&self, face: Side, mu: f64) -> f64 {
        self.faces[face].r_out(mu)
    }

    /// The surface reflection of the face on `side` (every non-delta lobe of
    /// the face: Walter's and the separable compensation lobes), `f_r(wi, wo)`
    /// without cosine, both directions in the sheet frame on that side
    /// (zero otherwise, and for a face without microfacets).
    pub fn face_reflection(&self, side: Side, wi: DVec3, wo: DVec3) -> f64 {
        if side.local(wi).z <= 0.0 || side.local(wo).z <= 0.0 {
            return 0.0;
        }
        self.faces[side].reflection(side.local(wi), side.local(wo))
    }

    /// [`PaperBsdf::face_reflection`] of the rough interface alone: for a
    /// coated front (`eta_f != eta_b`) without the separable lobe of the
    /// light that the coating/base boundary sends back out (the same as
    /// `face_reflection` otherwise).
    pub fn face_interface_reflection(&self, side: Side, wi: DVec3, wo: DVec3) -> f64 {
        if side.local(wi).z <= 0.0 || side.local(wo).z <= 0.0 {
            return 0.0;
        }
        self.faces[side].interface_reflection(side.local(wi), side.local(wo))
    }

    /// `(f_r, pdf)`: [`PaperBsdf::face_interface_reflection`] and
    /// [`PaperBsdf::face_reflection_pdf`] of the face on `side` at once
    /// (sharing the microfacet terms; for a sampler that needs both), both
    /// zero unless `wi` and `wo` are on `side`.
    pub fn face_interface_reflection_and_pdf(&self, side: Side, wi: DVec3, wo: DVec3) -> (f64, f64) {
        if side.local(wi).z <= 0.0 || side.local(wo).z <= 0.0 {
            return (0.0, 0.0);
        }
        self.faces[side].interface_reflection_and_pdf(side.local(wi), side.local(wo))
    }

    /// Directional reflectance of [`PaperBsdf::face_interface_reflection`]
    /// for light from outside at cosine `mu` (for a coated front without the
    /// coating's returned light; [`PaperBsdf::face_reflectance`] otherwise).
    pub fn face_interface_reflectance(&self, face: Side, mu: f64) -> f64 {
        self.faces[face].interface_r_out(mu)
    }

    /// Draws a reflected `wi` (sheet frame) from the visible normals of the
    /// face on the side of `wo` (Walter's lobe only; `None` for a face
    /// without microfacets or a draw below the face), density [`PaperBsdf::face_reflection_pdf`].
    pub fn sample_face_reflection(&self, wo: DVec3, u: [f64; 2]) -> Option<DVec3> {
        let side = Side::of(wo);
        self.faces[side]
            .sample_reflection(side.local(wo), u)
            .map(|wi| side.local(wi))
    }

    /// Density (solid angle) of [`PaperBsdf::sample_face_reflection`]; zero
    /// when `wi` and `wo` are on different sides.
    pub fn face_reflection_pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z * wo.z <= 0.0 {
            return 0.0;
        }
        let side = Side::of(wo);
        self.faces[side].reflection_pdf(side.local(wi), side.local(wo))
    }

    /// Whether the face on `side` has no microfacets (smooth or index-matched:
    /// its reflection is a delta lobe of reflectance [`PaperBsdf::face_reflectance`]).
    pub fn face_is_smooth(&self, side: Side) -> bool {
        self.face_microfacet(side).is_none()
    }

    /// The microfacet distribution (family and roughness `m`) of the face on
    /// `side`; `None` for a face without microfacets (smooth or index-matched).
    pub fn face_microfacet(&self, side: Side) -> Option<crate::microfacet::Microfacet> {
        self.faces[side].microfacet()
    }

    /// Albedo of the single-scattering term (reflection plus transmission) per
    /// unit flux *entering* through `face` at outside cosine `mu` (tabulated).
    pub fn single_scattering_albedo(&self, face: Side, mu: f64) -> Rgb {
        lerp_mu(&self.ess_tab[face], mu)
    }
}
