//! One face of the sheet as the Paper BSDF sees it (docs/design.md 4.1, and the
//! physical sheet of [`crate::sheet`]): its reflection, its directional and
//! hemispherical integrals (`Att`, outside reflectance, `rho_in`, `Tbar_in`),
//! and the smooth refraction into the base through the macro normal that the
//! single- and multiple-scattering terms use (docs/design.md 4.4).
//!
//! A face is built in three steps, each a closed form on the tabulated
//! integrals of Walter's rough interface ([`crate::boundary`]):
//!
//! 1. **Walter's interface** (`face_scattering = "single"`): the tables as they are.
//! 2. **Energy compensation** (`face_scattering = "multiple"`, rough faces only;
//!    our form, after Kulla & Conty 2017). Walter's interface loses
//!    `L_o(mu) = 1 - R(mu) - T(mu)` of the light arriving from outside and
//!    `L_i(mu)` of the light arriving from inside: the light that the exact
//!    walk on the microsurface (Heitz et al. 2016, [`crate::microsurface`])
//!    scatters more than once. The compensated face reflects `(1 - k_o) L_o`
//!    and transmits `k_o L_o` of it (from inside `(1 - k_i) L_i` and `k_i L_i`),
//!    with the outside reflection as the separable, reciprocal lobe
//!    `f = (1 - k_o) L_o(mu_i) L_o(mu_o) / (pi Lbar_o)` (`Lbar = 2 int L mu dmu`),
//!    so each direction's `R + T` is exactly 1 from both sides. `k_o` is the
//!    transmitted share of the lost energy measured by the walk
//!    ([`crate::microsurface_tables`]); `k_i` follows from reciprocity of the
//!    transmission, `k_o Lbar_o = eta^2 k_i Lbar_i` (the flux transmitted by
//!    diffuse light is `eta^2` times larger from outside).
//! 3. **The coating** (front face with `eta_f != eta_b`): the interface of
//!    steps 1-2 over the smooth coating/base boundary of relative index
//!    `nu = eta_b / eta_f`, combined by adding with the internal reflections in
//!    the coating summed (`Att = T_r (1 - F) / (1 - F R_in,r)`; the light the
//!    smooth boundary sends back out is a second separable reflection lobe).
//!    The directional spread inside the coating is neglected (each direction
//!    refracts through the macro normal), an approximation measured against
//!    the simulator, which follows the coating exactly. The combination keeps
//!    `R + T = 1` for energy-conserving interfaces.
//!
//! The back face (`z = -d`) is the same kind of object seen with `z` flipped:
//! [`Side::local`](super::Side::local) maps a direction on the back side to the face's frame.

use super::tables::{hemispherical, hemispherical_of_table, hemispherical_pair, lerp_mu, lerp_nodes, TabPos, NA};
use crate::boundary::{critical_mu, SurfaceIntegrals};
use crate::dielectric::{Interface, RoughDielectric};
use crate::fresnel::fresnel_dielectric;
use crate::microfacet::{Distribution, Microfacet};
use crate::params::{FaceScattering, ParamError};
use crate::sheet::Sheet;
use glam::DVec3;
use std::f64::consts::PI;

/// For `wi`, `wo` both above a face: `(h.z^2, (wo.h)^2)` of their unit half
/// vector `h = (wi + wo) / |wi + wo|`, without forming it: `|wi + wo|^2 =
/// 2 (1 + wi.wo)`, so `h.z^2 = (wi.z + wo.z)^2 / (2 (1 + wi.wo))` and
/// `wo.h = wi.h = sqrt((1 + wi.wo) / 2)` (both see the front of `h`). `None`
/// below the face or for opposite directions.
#[inline]
fn reflection_half(wi: DVec3, wo: DVec3) -> Option<(f64, f64)> {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return None;
    }
    let k = 1.0 + wi.dot(wo);
    if k <= 0.0 || !k.is_finite() {
        return None;
    }
    let zs = wi.z + wo.z;
    Some((zs * zs / (2.0 * k), 0.5 * k))
}

/// The rough (or smooth, or index-matched) interface of a face with the
/// energy compensation of step 2 (module doc): directional reflectances and
/// transmittances from outside (at the outside cosine) and from inside (at
/// the cosine on the interface's inner side).
struct Interface4 {
    si: SurfaceIntegrals,
    kind: Interface,
    eta: f64,
    /// `(k_o, k_i)`: the transmitted shares of the lost energy (0 for Walter's faces).
    k: (f64, f64),
    /// Whether the compensation is on.
    comp: bool,
}

impl Interface4 {
    fn new(bd: &RoughDielectric, fs: FaceScattering) -> Self {
        let si = SurfaceIntegrals::new(bd);
        let mut me = Interface4 {
            si,
            kind: bd.interface,
            eta: bd.eta,
            k: (0.0, 0.0),
            comp: false,
        };
        if fs == FaceScattering::Multiple && matches!(bd.interface, Interface::Rough(_)) {
            let lbar_o = 1.0
                - hemispherical(
                    |mu| {
                        let (att, r_out) = me.si.att_r_out(mu);
                        att + r_out
                    },
                    0.0,
                );
            let lbar_i = (1.0 - me.si.rho_in - me.si.tbar_in).max(0.0);
            let (k_o, k_i) = crate::microsurface_tables::compensation_shares(bd.dist, bd.eta, bd.m, lbar_o, lbar_i);
            me.k = (k_o, k_i);
            me.comp = true;
        }
        me
    }

    /// For light from outside at `mu`: `(T_w, R_w, L_o)`, Walter's
    /// transmittance (the collimated part) and reflectance (the closed-form
    /// lobe's albedo, or Fresnel) and the energy `L_o` his interface loses
    /// (0 without the compensation), from one lookup of the tables.
    #[inline]
    fn outside(&self, mu: f64) -> (f64, f64, f64) {
        match self.kind {
            Interface::IndexMatched => (1.0, 0.0, 0.0),
            Interface::Smooth => {
                let f = fresnel_dielectric(mu, self.eta);
                (1.0 - f, f, 0.0)
            }
            Interface::Rough(_) => {
                let (att, r_out) = self.si.att_r_out(mu);
                let lost = if self.comp { (1.0 - att - r_out).max(0.0) } else { 0.0 };
                (att, r_out, lost)
            }
        }
    }
    /// For light from inside at inner cosine `mu`: `(R_in, T_in)`, the
    /// reflectance (TIR included) and transmittance, all orders.
    #[inline]
    fn inside(&self, mu: f64) -> (f64, f64) {
        match self.kind {
            Interface::IndexMatched => (0.0, 1.0),
            Interface::Smooth => {
                let f = fresnel_dielectric(-mu, self.eta);
                (f, 1.0 - f)
            }
            Interface::Rough(_) => {
                let (r, t) = self.si.r_t_in(mu);
                // The energy lost by Walter's interface from inside.
                let lost = if self.comp { (1.0 - r - t).max(0.0) } else { 0.0 };
                (r + (1.0 - self.k.1) * lost, t + self.k.1 * lost)
            }
        }
    }
    /// `(rho_in, Tbar_in)` for diffuse light from inside, all orders.
    fn hemi_in(&self) -> (f64, f64) {
        let lbar_i = if self.comp {
            (1.0 - self.si.rho_in - self.si.tbar_in).max(0.0)
        } else {
            0.0
        };
        (
            self.si.rho_in + (1.0 - self.k.1) * lbar_i,
            self.si.tbar_in + self.k.1 * lbar_i,
        )
    }
}

/// A separable, reciprocal diffuse reflection lobe `f = c E(mu_i) E(mu_o)` of a face.
#[derive(Clone, Debug)]
struct SeparableLobe {
    /// `E` on the [`NA`] nodes.
    e: [f64; NA],
    /// The constant `c`.
    c: f64,
    /// `c pi Ebar`: the lobe's albedo is `c pi Ebar E(mu)`.
    albedo_scale: f64,
}

impl SeparableLobe {
    /// The lobe whose albedo for light at `mu` is `share * E(mu)`.
    fn new(e: [f64; NA], share: f64) -> Option<Self> {
        let ebar = hemispherical_of_table(&e);
        if ebar <= 1e-12 || share <= 0.0 {
            return None;
        }
        let c = share / (PI * ebar);
        Some(SeparableLobe {
            e,
            c,
            albedo_scale: share,
        })
    }
}

/// A face of the sheet with its precomputed integrals (module doc).
#[derive(Clone, Debug)]
pub(crate) struct Face {
    /// The rough interface with the air, in the face's own frame (outside = `+z`).
    pub bd: RoughDielectric,
    /// Whether `Att` is used; `false` sets every `Att` to 1 (the reduced multilayer model).
    pub use_att: bool,
    /// `Abar = 2 int_0^1 Att(mu) mu dmu` (1 when `use_att` is false).
    pub abar: f64,
    /// Transmittance from outside into the base, all orders (`Att`), on the [`NA`] nodes.
    att_tab: [f64; NA],
    /// The collimated part of `Att` (Walter's first order through the coating):
    /// the light that direct transmission carries.
    att_dir_tab: [f64; NA],
    /// Reflectance from outside, everything (Walter's lobe, the separable lobes, or the delta).
    r_tab: [f64; NA],
    /// Reflectance of the separable lobes alone (for the sampler's estimates).
    r_lobes_tab: [f64; NA],
    /// Separable reflection lobes: the compensation and the coating's (at most two).
    lobes: Vec<SeparableLobe>,
    /// `sqrt(c_j) E_j` of the lobes on the [`NA`] nodes, side by side (zero
    /// for an absent lobe): what `eval` interpolates, one node lookup for both.
    lobe_tab: [[f64; 2]; NA],
    /// The column of [`Face::lobe_tab`] that holds the coating's lobe (a
    /// rough coated front), if any.
    coat_lobe: Option<usize>,
    /// `rho_in` and `Tbar_in` for diffuse light from inside the base.
    rho_in: f64,
    tbar_in: f64,
    /// The compensated interface (for the inside reflectance of a delta face).
    iface_k: (f64, f64),
    /// `nu = eta_b / eta_f` of a coating.
    coating: Option<f64>,
    /// Index of the base (the medium the face refracts into).
    n: f64,
    /// `1 / n`.
    inv_n: f64,
    /// `1 / n^2`.
    inv_n2: f64,
    /// `1 / eta^2` of the rough interface (Fresnel of its reflection lobe).
    inv_eta2: f64,
    /// A smooth face without a coating: `Att` and the reflectance are exact
    /// Fresnel (its curve is too steep at grazing for the node tables).
    exact_smooth: bool,
}

/// Cosine in the medium of relative index `eta` of the smooth refraction of a
/// direction at cosine `mu` outside; `None` at total internal reflection (`eta < 1`).
#[inline]
fn refracted_cos(mu: f64, eta: f64) -> Option<f64> {
    let s2 = (1.0 - mu * mu) / (eta * eta);
    (s2 < 1.0).then(|| (1.0 - s2).sqrt())
}

impl Face {
    /// A face of Walter's interface alone, of base index `eta` (as the glass
    /// of `lambert-glass`); errors name the parameters with `suffix`.
    pub fn walter(dist: Distribution, eta: f64, m: f64, use_att: bool, suffix: &str) -> Result<Face, ParamError> {
        let bd = RoughDielectric::new(dist, eta, m).map_err(|e| e.with_suffix(suffix))?;
        Ok(Face::build(bd, FaceScattering::Single, None, eta, use_att))
    }

    /// The front (`back = false`) or back face of `sheet`.
    pub fn of_sheet(sheet: &Sheet, back: bool, use_att: bool) -> Face {
        let bd = *sheet.face(back);
        let coating = if back { None } else { sheet.coating };
        Face::build(bd, sheet.face_scattering, coating, sheet.eta_medium, use_att)
    }

    fn build(bd: RoughDielectric, fs: FaceScattering, coating: Option<f64>, n: f64, use_att: bool) -> Face {
        let ifc = Interface4::new(&bd, fs);
        let eta = bd.eta;
        let mut f = Face {
            bd,
            use_att,
            abar: 1.0,
            att_tab: [0.0; NA],
            att_dir_tab: [0.0; NA],
            r_tab: [0.0; NA],
            r_lobes_tab: [0.0; NA],
            lobes: Vec::new(),
            lobe_tab: [[0.0; 2]; NA],
            coat_lobe: None,
            rho_in: 0.0,
            tbar_in: 0.0,
            iface_k: ifc.k,
            coating,
            n,
            inv_n: 1.0 / n,
            inv_n2: 1.0 / (n * n),
            inv_eta2: 1.0 / (eta * eta),
            exact_smooth: matches!(bd.interface, Interface::Smooth) && coating.is_none(),
        };
        let rough = matches!(bd.interface, Interface::Rough(_));
        let mut comp_e = [0.0; NA];
        let mut coat_e = [0.0; NA];
        for k in 0..NA {
            let t = k as f64 / (NA - 1) as f64;
            let mu = t * t;
            let (t_w, r_w, lo) = ifc.outside(mu);
            comp_e[k] = lo;
            // Transmittance from outside, all orders.
            let t_r = t_w + ifc.k.0 * lo;
            let r_r = r_w + (1.0 - ifc.k.0) * lo;
            let (att, att_dir, r_coat) = match coating {
                None => (t_r, t_w, 0.0),
                Some(nu) => {
                    // Inside the coating at the smooth refraction of mu through eta.
                    let mu_c = refracted_cos(mu, eta).unwrap_or(0.0);
                    let fs_ = fresnel_dielectric(mu_c, nu);
                    let (r_in, t_in) = ifc.inside(mu_c);
                    let denom = 1.0 - fs_ * r_in;
                    if denom <= 0.0 {
                        (0.0, 0.0, t_r)
                    } else {
                        let g = (1.0 - fs_) / denom;
                        (t_r * g, t_w * g, t_r * fs_ * t_in / denom)
                    }
                }
            };
            f.att_tab[k] = att.clamp(0.0, 1.0);
            f.att_dir_tab[k] = att_dir.clamp(0.0, f.att_tab[k]);
            coat_e[k] = r_coat.max(0.0);
            f.r_tab[k] = (r_r + coat_e[k]).clamp(0.0, 1.0);
        }
        if rough {
            if let Some(l) = SeparableLobe::new(comp_e, 1.0 - ifc.k.0) {
                f.lobes.push(l);
            }
            if let Some(l) = SeparableLobe::new(coat_e, 1.0) {
                f.coat_lobe = Some(f.lobes.len());
                f.lobes.push(l);
            }
        }
        for k in 0..NA {
            f.r_lobes_tab[k] = f.lobes.iter().map(|l| l.albedo_scale * l.e[k]).sum();
            for (j, l) in f.lobes.iter().enumerate() {
                f.lobe_tab[k][j] = l.c.sqrt() * l.e[k];
            }
        }
        // Diffuse light from inside the base.
        let (rho, tbar) = match coating {
            None => ifc.hemi_in(),
            Some(nu) => {
                // Base cosine mu_b -> coating cosine through the smooth boundary (relative index 1/nu from the base).
                let one = |mu_b: f64| -> (f64, f64) {
                    let Some(mu_c) = refracted_cos(mu_b, 1.0 / nu) else {
                        return (1.0, 0.0);
                    };
                    let fs_ = fresnel_dielectric(mu_c, nu);
                    let (r, t_in) = ifc.inside(mu_c);
                    let denom = 1.0 - fs_ * r;
                    if denom <= 0.0 {
                        return (1.0, 0.0);
                    }
                    (fs_ + (1.0 - fs_) * (1.0 - fs_) * r / denom, (1.0 - fs_) * t_in / denom)
                };
                // Kinks: TIR at the smooth boundary and at the rough face's critical angle, seen from the base.
                let mu_k = critical_mu(n / eta.min(n)).max(critical_mu(n));
                hemispherical_pair(one, mu_k)
            }
        };
        f.rho_in = rho.clamp(0.0, 1.0);
        f.tbar_in = tbar.clamp(0.0, 1.0 - f.rho_in);
        if use_att {
            f.abar = if f.exact_smooth {
                hemispherical(|mu| 1.0 - fresnel_dielectric(mu, eta), 0.0)
            } else {
                hemispherical_of_table(&f.att_tab)
            };
        }
        f
    }

    /// Index of the base into which the face refracts.
    #[inline]
    pub fn n(&self) -> f64 {
        self.n
    }

    /// `Att(mu)`: transmittance into the base, all orders, for light from
    /// outside at cosine `mu` (1 when `use_att` is false).
    #[inline]
    pub fn att(&self, mu: f64) -> f64 {
        if !self.use_att {
            return 1.0;
        }
        if self.exact_smooth {
            return 1.0 - fresnel_dielectric(mu.abs().min(1.0), self.bd.eta);
        }
        lerp_mu(&self.att_tab, mu)
    }

    /// [`Face::att`] at `mu` given also `st = sqrt(min(|mu|, 1))`.
    #[inline]
    pub fn att_with_sqrt(&self, st: f64) -> f64 {
        self.att_at(TabPos::new(st))
    }

    /// [`Face::att`] at the place `p` of `mu` on the tables.
    #[inline(always)]
    pub fn att_at(&self, p: TabPos) -> f64 {
        if !self.use_att {
            return 1.0;
        }
        if self.exact_smooth {
            return 1.0 - fresnel_dielectric(p.st * p.st, self.bd.eta);
        }
        p.lerp(&self.att_tab)
    }

    /// The collimated part of [`Face::att`] (what direct transmission carries), given `st`.
    #[inline]
    pub fn att_dir_with_sqrt(&self, st: f64) -> f64 {
        self.att_dir_at(TabPos::new(st))
    }

    /// [`Face::att_dir_with_sqrt`] at the place `p` of `mu` on the tables.
    #[inline(always)]
    pub fn att_dir_at(&self, p: TabPos) -> f64 {
        if !self.use_att {
            return 1.0;
        }
        if self.exact_smooth {
            return 1.0 - fresnel_dielectric(p.st * p.st, self.bd.eta);
        }
        p.lerp(&self.att_dir_tab)
    }

    /// Directional reflectance for light from outside at cosine `mu`, every
    /// lobe (Walter's, the separable ones, or the delta of a smooth face).
    #[inline]
    pub fn r_out(&self, mu: f64) -> f64 {
        if self.exact_smooth {
            return fresnel_dielectric(mu.abs().min(1.0), self.bd.eta);
        }
        lerp_mu(&self.r_tab, mu)
    }

    /// The directional reflectance of [`Face::interface_reflection`] (the
    /// rough interface alone: [`Face::r_out`] without the coating's lobe)
    /// for light from outside at cosine `mu`; for a face without
    /// microfacets, its delta's reflectance.
    pub fn interface_r_out(&self, mu: f64) -> f64 {
        let r = self.r_out(mu);
        match self.coat_lobe {
            Some(j) => {
                let l = &self.lobes[j];
                (r - l.albedo_scale * lerp_mu(&l.e, mu)).max(0.0)
            }
            None => r,
        }
    }

    /// [`Face::r_out`] given `st = sqrt(min(|mu|, 1))`.
    #[inline]
    pub fn r_out_with_sqrt(&self, st: f64) -> f64 {
        if self.exact_smooth {
            return fresnel_dielectric(st * st, self.bd.eta);
        }
        lerp_nodes(&self.r_tab, st)
    }

    /// Albedo of the separable reflection lobes alone, given `st`.
    #[inline]
    pub fn r_lobes_with_sqrt(&self, st: f64) -> f64 {
        lerp_nodes(&self.r_lobes_tab, st)
    }

    /// `rho_in`: hemispherical reflectance for diffuse light from inside the base.
    #[inline]
    pub fn rho_in(&self) -> f64 {
        self.rho_in
    }

    /// `Tbar_in`: hemispherical transmittance for diffuse light from inside the base.
    #[inline]
    pub fn tbar_in(&self) -> f64 {
        self.tbar_in
    }

    /// Reflectance from inside the base at base cosine `mu_b` of a face
    /// without microfacets (smooth or index-matched interface, with its
    /// coating if any): the internal reflections of unscattered light.
    pub fn r_in_delta(&self, mu_b: f64) -> f64 {
        let eta = self.bd.eta;
        let r_face = |mu_c: f64| match self.bd.interface {
            Interface::IndexMatched => 0.0,
            _ => fresnel_dielectric(-mu_c, eta),
        };
        match self.coating {
            None => r_face(mu_b),
            Some(nu) => {
                let Some(mu_c) = refracted_cos(mu_b, 1.0 / nu) else {
                    return 1.0;
                };
                let fs_ = fresnel_dielectric(mu_c, nu);
                let r = r_face(mu_c);
                let denom = 1.0 - fs_ * r;
                if denom <= 0.0 {
                    1.0
                } else {
                    fs_ + (1.0 - fs_) * (1.0 - fs_) * r / denom
                }
            }
        }
    }

    /// Reflectance of a face without microfacets for light from outside at
    /// `mu` (the weight of its delta reflection, coating included).
    #[inline]
    pub fn delta_reflectance(&self, mu: f64) -> f64 {
        self.r_out(mu)
    }

    /// [`fresnel_dielectric`] for light from outside on the rough interface
    /// (`eta >= 1`: no total internal reflection) at the cosine `c = sqrt(c2)`,
    /// given `c2` in `(0, 1]`, with the interface's `1 / eta^2` in place of a
    /// division. From `c2`, the square roots of `c` and of the refracted
    /// cosine are independent and run side by side rather than one after the other.
    #[inline(always)]
    pub fn fresnel_outside_sq(&self, c2: f64) -> f64 {
        if self.bd.eta == 1.0 {
            return 0.0;
        }
        let c2 = c2.min(1.0);
        let cos_t = (1.0 - (1.0 - c2) * self.inv_eta2).max(0.0).sqrt();
        crate::fresnel::fresnel_from_cosines(c2.sqrt(), cos_t, self.bd.eta)
    }

    /// `1 / n` of the base.
    #[inline]
    pub fn inv_n(&self) -> f64 {
        self.inv_n
    }

    /// `1 / n^2`: the change of radiance on leaving the base through this face.
    #[inline]
    pub fn inv_n2(&self) -> f64 {
        self.inv_n2
    }

    /// Cosine (magnitude) in the base of the smooth refraction of an outside direction with cosine `mu`.
    #[inline]
    pub fn inside_cos(&self, mu: f64) -> f64 {
        (1.0 - (1.0 - mu * mu) * self.inv_n2).max(0.0).sqrt()
    }

    /// The microfacet distribution, if rough.
    #[inline]
    pub fn microfacet(&self) -> Option<Microfacet> {
        match self.bd.interface {
            Interface::Rough(mf) => Some(mf),
            _ => None,
        }
    }

    /// Whether the face reflects as a delta (no microfacets, and something reflects).
    #[inline]
    pub fn is_smooth(&self) -> bool {
        self.microfacet().is_none() && !self.is_index_matched()
    }

    /// Whether light passes the face without any reflection (index-matched, no coating).
    #[inline]
    pub fn is_index_matched(&self) -> bool {
        matches!(self.bd.interface, Interface::IndexMatched) && self.coating.is_none()
    }

    /// `(k_o, k_i)` of the energy compensation (0 for Walter's faces).
    pub fn compensation_shares(&self) -> (f64, f64) {
        self.iface_k
    }

    /// The separable lobes' reflection `sum_j c_j E_j(mu_i) E_j(mu_o)`, given
    /// the places of both cosines on the tables.
    #[inline(always)]
    pub fn lobes_reflection(&self, pi: TabPos, po: TabPos) -> f64 {
        let (a, b) = (self.lobe_node(pi), self.lobe_node(po));
        a[0] * b[0] + a[1] * b[1]
    }

    /// Both columns of [`Face::lobe_tab`] interpolated at the place `p`.
    #[inline(always)]
    fn lobe_node(&self, p: TabPos) -> [f64; 2] {
        let (i, f) = (p.i, p.f);
        let (a, b) = (self.lobe_tab[i], self.lobe_tab[i + 1]);
        [a[0] * (1.0 - f) + b[0] * f, a[1] * (1.0 - f) + b[1] * f]
    }

    /// Reflection `f_r(wi, wo)` (no cosine) of the face, both directions in
    /// the face frame on the outside (`z > 0`): Walter's lobe and the
    /// separable lobes; zero for a face without microfacets (its reflection is a delta).
    #[inline]
    pub fn reflection(&self, wi: DVec3, wo: DVec3) -> f64 {
        self.reflection_at(
            wi,
            wo,
            TabPos::new(wi.z.min(1.0).sqrt()),
            TabPos::new(wo.z.min(1.0).sqrt()),
        )
    }

    /// [`Face::reflection`] given also the places `pi`, `po` of `wi.z` and
    /// `wo.z` on the tables (the separable lobes' coordinates), which the
    /// callers already have.
    #[inline(always)]
    pub fn reflection_at(&self, wi: DVec3, wo: DVec3, pi: TabPos, po: TabPos) -> f64 {
        let Interface::Rough(mf) = self.bd.interface else {
            return 0.0;
        };
        let Some((c2, oh2)) = reflection_half(wi, wo) else {
            return 0.0;
        };
        let lobes = if self.lobes.is_empty() {
            0.0
        } else {
            self.lobes_reflection(pi, po)
        };
        self.fresnel_outside_sq(oh2) * mf.reflection_dg_c2(c2, wi.z, wo.z) + lobes
    }

    /// The reflection of the rough interface alone, `f_r(wi, wo)` (no cosine,
    /// face frame, outside): [`Face::reflection`] without the coating's
    /// separable lobe, i.e. Walter's lobe and, for `face_scattering =
    /// "multiple"`, the compensation lobe. For a face without a coating it
    /// is [`Face::reflection`]. (A numerical solution that follows the
    /// light the coating/base boundary sends back out itself needs the
    /// interface's first reflection only.)
    pub fn interface_reflection(&self, wi: DVec3, wo: DVec3) -> f64 {
        if self.coat_lobe.is_none() {
            return self.reflection(wi, wo);
        }
        let Interface::Rough(mf) = self.bd.interface else {
            return 0.0;
        };
        let Some((c2, oh2)) = reflection_half(wi, wo) else {
            return 0.0;
        };
        let walter = self.fresnel_outside_sq(oh2) * mf.reflection_dg_c2(c2, wi.z, wo.z);
        walter
            + self.compensation_beside_coat(
                || TabPos::new(wi.z.min(1.0).sqrt()),
                || TabPos::new(wo.z.min(1.0).sqrt()),
            )
    }

    /// `(f_r, pdf)`: [`Face::interface_reflection`] and [`Face::reflection_pdf`]
    /// at once, sharing `D(h)` and the masking ([`Face::reflection_and_pdf`]).
    #[inline]
    pub fn interface_reflection_and_pdf(&self, wi: DVec3, wo: DVec3) -> (f64, f64) {
        let (pi, po) = (TabPos::new(wi.z.min(1.0).sqrt()), TabPos::new(wo.z.min(1.0).sqrt()));
        if self.coat_lobe.is_none() {
            return self.reflection_and_pdf(wi, wo, pi, po);
        }
        let Interface::Rough(mf) = self.bd.interface else {
            return (0.0, 0.0);
        };
        let Some((c2, oh2)) = reflection_half(wi, wo) else {
            return (0.0, 0.0);
        };
        let (dg, pdf) = mf.reflection_dg_pdf_c2(c2, wi.z, wo.z);
        (
            self.fresnel_outside_sq(oh2) * dg + self.compensation_beside_coat(|| pi, || po),
            pdf,
        )
    }

    /// For a face with a coating's lobe: the compensation lobe's reflection
    /// at the places `pi()`, `po()` of `wi.z`, `wo.z`, or 0 without one.
    /// The lobes of such a face are the compensation's (first) and the
    /// coating's (last), so the interface's reflection is Walter's lobe
    /// plus this, summed directly rather than as the face's reflection less
    /// the coating's lobe (a difference that rounding could take below 0,
    /// and that read the tables for the coating's lobe only to take it
    /// away: about 5% of the model `slab`'s `eval` on glossy at the
    /// grazing pair, perf on its examples/sample_cost.rs, 2026-12-07).
    #[inline(always)]
    fn compensation_beside_coat(&self, pi: impl Fn() -> TabPos, po: impl Fn() -> TabPos) -> f64 {
        if self.lobes.len() < 2 {
            return 0.0;
        }
        debug_assert_eq!(self.coat_lobe, Some(1));
        let (a, b) = (self.lobe_node(pi()), self.lobe_node(po()));
        a[0] * b[0]
    }

    /// Density of [`Face::sample_reflection`]: `pdf_visible(wo, h) / (4 |wo.h|)`.
    #[inline(always)]
    pub fn reflection_pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        let Some(mf) = self.microfacet() else { return 0.0 };
        let Some((c2, _)) = reflection_half(wi, wo) else {
            return 0.0;
        };
        mf.reflection_dg_pdf_c2(c2, wi.z, wo.z).1
    }

    /// `(f_r, pdf)`: [`Face::reflection`] and [`Face::reflection_pdf`] at once,
    /// sharing `D(h)` and the masking of `wo` (for `sample`, which needs both);
    /// `pi`, `po` as in [`Face::reflection_at`].
    #[inline(always)]
    pub fn reflection_and_pdf(&self, wi: DVec3, wo: DVec3, pi: TabPos, po: TabPos) -> (f64, f64) {
        let Interface::Rough(mf) = self.bd.interface else {
            return (0.0, 0.0);
        };
        let Some((c2, oh2)) = reflection_half(wi, wo) else {
            return (0.0, 0.0);
        };
        let (dg, pdf) = mf.reflection_dg_pdf_c2(c2, wi.z, wo.z);
        let lobes = if self.lobes.is_empty() {
            0.0
        } else {
            self.lobes_reflection(pi, po)
        };
        (self.fresnel_outside_sq(oh2) * dg + lobes, pdf)
    }

    /// Walter's reflectance from outside alone (the visible-normal strategy's estimate).
    #[inline]
    pub fn r_walter_with_sqrt(&self, st: f64) -> f64 {
        (self.r_out_with_sqrt(st) - self.r_lobes_with_sqrt(st)).max(0.0)
    }

    /// Draws a reflected `wi` (face frame) from the visible normals seen from `wo`.
    #[inline]
    pub fn sample_reflection(&self, wo: DVec3, u: [f64; 2]) -> Option<DVec3> {
        let mf = self.microfacet()?;
        let h = mf.sample_visible(wo, u);
        let oh = wo.dot(h);
        if oh <= 0.0 {
            return None;
        }
        // The mirror image of the unit `wo` about the unit `h` is a unit vector
        // (to rounding): no normalisation needed.
        let wi = 2.0 * oh * h - wo;
        (wi.z > 0.0).then_some(wi)
    }
}
