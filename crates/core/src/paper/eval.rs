//! Evaluation of the Paper BSDF and of its sampling density: the components
//! of the module doc of [`super`] for a pair of directions, from the tables
//! of [`super::build`], with the geometry (inside cosines, phase function)
//! that `eval` and `pdf` share.

use super::tables::{node_at, TabPos, NP};
use super::{grazing, side, single, Component, ComponentSet, PaperBsdf, TAU_DROP};
use crate::spectrum::Rgb;
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// Geometry shared by `eval` and `pdf`: inside cosines of `wi` and `wo` and
/// the mixture phase function between the inside directions (0 if not asked).
#[derive(Clone, Copy, Debug)]
pub(super) struct Inside {
    pub(super) mu_i: f64,
    pub(super) mu_o: f64,
    /// The places of `|wi.z|`, `|wo.z|` (outside) on the face tables.
    pub(super) si: TabPos,
    pub(super) so: TabPos,
    /// The phase function as `p_num / p_den` (`p_num = 0`, `p_den = 1` if not asked).
    pub(super) p_num: f64,
    pub(super) p_den: f64,
}

/// The sampling strategies of [`crate::Bsdf::sample`], one per lobe (module
/// doc of [`super`]), in the order of [`LobeProbs`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Lobe {
    /// The face's reflection (visible normals, or the delta of a smooth face).
    Surface,
    /// Single scattering: the phase function refracted through the macro normal.
    Single,
    /// Multiple scattering in reflection: a cosine lobe.
    MultipleR,
    /// Multiple scattering in transmission: a cosine lobe on the other side.
    MultipleT,
    /// Direct transmission: the kernel (or its delta).
    Direct,
}

impl Lobe {
    /// Every lobe, in the order of [`LobeProbs`].
    pub(super) const ALL: [Lobe; 5] = [
        Lobe::Surface,
        Lobe::Single,
        Lobe::MultipleR,
        Lobe::MultipleT,
        Lobe::Direct,
    ];
}

/// A selection probability per [`Lobe`] (summing to 1, or all 0 when nothing
/// can be sampled).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct LobeProbs(pub(super) [f64; 5]);

impl std::ops::Index<Lobe> for LobeProbs {
    type Output = f64;
    #[inline(always)]
    fn index(&self, l: Lobe) -> &f64 {
        &self.0[l as usize]
    }
}

impl std::ops::IndexMut<Lobe> for LobeProbs {
    #[inline(always)]
    fn index_mut(&mut self, l: Lobe) -> &mut f64 {
        &mut self.0[l as usize]
    }
}

impl PaperBsdf {
    /// Inside propagation directions `(t_i, t_o)` and cosines for outside `wi`, `wo`.
    #[inline(always)]
    pub(super) fn inside_dirs(&self, wi: DVec3, wo: DVec3) -> (DVec3, DVec3, f64, f64) {
        let (fe, fx) = (&self.faces[side(wi)], &self.faces[side(wo)]);
        let mu_i = fe.inside_cos(wi.z.abs());
        let mu_o = fx.inside_cos(wo.z.abs());
        let t_i = DVec3::new(-wi.x * fe.inv_n(), -wi.y * fe.inv_n(), -wi.z.signum() * mu_i);
        let t_o = DVec3::new(wo.x * fx.inv_n(), wo.y * fx.inv_n(), wo.z.signum() * mu_o);
        (t_i, t_o, mu_i, mu_o)
    }

    /// Inside cosines of `wi`, `wo` and (if `want_phase`) the phase function
    /// between the inside directions: what `eval` and `pdf` share.
    #[inline(always)]
    pub(super) fn inside(&self, wi: DVec3, wo: DVec3, want_phase: bool, (si, so): (TabPos, TabPos)) -> Inside {
        let (t_i, t_o, mu_i, mu_o) = self.inside_dirs(wi, wo);
        let (p_num, p_den) = if want_phase && self.phase.weight() > 0.0 {
            self.phase.ratio(t_i.dot(t_o).clamp(-1.0, 1.0))
        } else {
            (0.0, 1.0)
        };
        Inside {
            mu_i,
            mu_o,
            si,
            so,
            p_num,
            p_den,
        }
    }

    /// Sum of the components in `set` (no cosine; delta lobes excluded).
    pub fn eval_components(&self, wi: DVec3, wo: DVec3, set: ComponentSet) -> Rgb {
        self.eval_with(wi, wo, set, None, None)
    }

    /// [`PaperBsdf::eval_components`] with the shared geometry `pre` and the
    /// face's reflection `surface` if the caller has them.
    ///
    /// Always inlined: returned through memory, its `Rgb` (written channel by
    /// channel) was read back by the caller with wider loads that could not be
    /// forwarded from those stores, a stall of about 20 ns in `sample`.
    #[inline(always)]
    pub(super) fn eval_with(
        &self,
        wi: DVec3,
        wo: DVec3,
        set: ComponentSet,
        pre: Option<&Inside>,
        surface: Option<f64>,
    ) -> Rgb {
        if grazing(wi) || grazing(wo) || !wi.is_finite() || !wo.is_finite() {
            return Rgb::ZERO;
        }
        let (e, x) = (side(wi), side(wo));
        let reflect = e == x;
        let (si, so) = match pre {
            Some(g) => (g.si, g.so),
            None => (
                TabPos::new(wi.z.abs().min(1.0).sqrt()),
                TabPos::new(wo.z.abs().min(1.0).sqrt()),
            ),
        };
        let mut out = Rgb::ZERO;
        if reflect && set.contains(Component::Surface) {
            let f = match surface {
                Some(f) => f,
                None => self.faces[e].reflection_at(e.local(wi), e.local(wo), si, so),
            };
            out += Rgb::splat(f);
        }
        let (fe, fx) = (&self.faces[e], &self.faces[x]);
        let mut sub = Rgb::ZERO;
        if set.contains(Component::Multiple) {
            if self.opts.energy_bound {
                let (we, wx) = (si.lerp(&self.w_tab[e]), so.lerp(&self.w_tab[x]));
                let c = if reflect { self.ms_r[e] } else { self.ms_t };
                sub += c * we * wx;
            } else {
                let c = if reflect { self.c_r[e] } else { self.c_t[e] };
                sub += c * (fe.att_at(si) * fx.att_at(so));
            }
        }
        let att = fe.att_at(si) * fx.att_at(so);
        if att <= 0.0 {
            return out + sub * self.kappa;
        }
        let g = match pre {
            Some(g) => *g,
            None => self.inside(wi, wo, set.contains(Component::Single), (si, so)),
        };
        let (mu_i, mu_o) = (g.mu_i, g.mu_o);
        if mu_i <= 0.0 || mu_o <= 0.0 {
            return out + sub * self.kappa;
        }
        if set.contains(Component::Single) && self.phase.weight() > 0.0 && g.p_num > 0.0 {
            let ka = att * g.p_num * fx.inv_n2();
            if reflect && self.tau_min * (mu_i + mu_o) > TAU_DROP * mu_i * mu_o {
                // tau (1/mu_i + 1/mu_o) > 40 in every channel: the
                // exponential is below 4e-18 of 1; skip it (thick paper).
                // One division for the phase function and the depth integral.
                sub += self.albedo * (ka / (g.p_den * (mu_i + mu_o)));
            } else if !reflect && self.tau_min > TAU_DROP * mu_i.max(mu_o) {
                // Both paths through the sheet are attenuated by more
                // than e^{-40}: dropped like the direct term below.
            } else {
                let k = ka / g.p_den;
                let depth = |tau: f64| {
                    if reflect {
                        single::depth_reflection(tau, mu_i, mu_o)
                    } else {
                        single::depth_transmission(tau, mu_i, mu_o)
                    }
                };
                if self.grey {
                    sub += Rgb::splat(k * self.albedo.0[0] * depth(self.tau.0[0]));
                } else {
                    for c in 0..3 {
                        sub.0[c] += k * self.albedo.0[c] * depth(self.tau.0[c]);
                    }
                }
            }
        }
        if !reflect && set.contains(Component::Direct) && self.opts.direct && !self.kernel.is_delta() {
            let mu_min = mu_i.min(mu_o);
            // Dropped where e^{-tau/mu} < e^{-40} = 4e-18 of the unattenuated
            // lobe: thick paper never pays for these exponentials.
            let k = if self.tau_min > TAU_DROP * mu_min {
                0.0
            } else {
                self.kernel.eval(DVec2::new(-wi.x, -wi.y), DVec2::new(wo.x, wo.y), 1.0)
            };
            if k > 0.0 {
                let amp = fe.att_dir_at(si) * fx.att_dir_at(so) * k;
                if self.grey {
                    sub += Rgb::splat((-self.tau.0[0] / mu_min).exp() * amp);
                } else {
                    sub += self.tau.map(|t| (-t / mu_min).exp()) * amp;
                }
            }
        }
        out + sub * self.kappa
    }

    /// Weight of the delta direct lobe for incident `wi` and viewer `wo` on
    /// opposite sides, both faces without microfacets: the transmittances,
    /// the attenuation along the path inside, and the series of internal
    /// reflections `1 / (1 - R_e R_x e^{-2 tau / mu})` (exact for smooth faces).
    pub(super) fn direct_delta_weight(&self, wi: DVec3, wo: DVec3) -> Rgb {
        let (e, x) = (side(wi), side(wo));
        let (fe, fx) = (&self.faces[e], &self.faces[x]);
        let (mi_out, mo_out) = (wi.z.abs(), wo.z.abs());
        let mu = fe.inside_cos(mi_out);
        if mu <= 0.0 {
            return Rgb::ZERO;
        }
        let t = fe.att(mi_out) * fx.att(mo_out);
        let r = if self.opts.use_att {
            fe.r_in_delta(mu) * fx.r_in_delta(fx.inside_cos(mo_out))
        } else {
            0.0
        };
        self.tau.map(|tau| {
            let a = (-tau / mu).exp();
            t * a / (1.0 - r * a * a)
        }) * self.kappa
    }

    /// Lobe selection probabilities for viewer `wo`: surface, single, multiple R,
    /// multiple T, direct (normalised; all zero if nothing can be sampled).
    ///
    /// They depend on the face and `|wo.z|` only and are tabulated at
    /// construction ([`PaperBsdf::lobe_probs_exact`] on [`NP`] nodes in
    /// `sqrt(|wo.z|)`) and interpolated: a convex combination of probability
    /// vectors, so they still sum to 1, and `sample` and `pdf` use the same
    /// values, so the mixture density is exactly that of the sampler. (They are
    /// only a choice of strategy weights: any positive values would be unbiased.)
    #[inline(always)]
    pub(super) fn lobe_probs(&self, wo: DVec3) -> LobeProbs {
        let (i, f) = node_at::<NP>(wo.z.abs().min(1.0).sqrt());
        let tab = &self.pr_tab[side(wo)];
        let (a, b) = (&tab[i], &tab[i + 1]);
        LobeProbs(std::array::from_fn(|k| a.0[k] * (1.0 - f) + b.0[k] * f))
    }

    /// Density of the single-scattering strategy: the phase function around
    /// the inside viewer direction, refracted out through the face of `wi`.
    #[inline]
    pub(super) fn pdf_single(&self, wi: DVec3, g: &Inside) -> f64 {
        if g.mu_i <= 0.0 || self.phase.weight() <= 0.0 {
            return 0.0;
        }
        g.p_num * wi.z.abs() * self.faces[side(wi)].inv_n2() / (g.p_den * self.phase.weight() * g.mu_i)
    }

    /// The mixture density; `surface_pdf` is the face's reflection density if the caller has it.
    ///
    /// Always inlined: `sample` and `pdf` then share its side and face
    /// lookups and tests with their own.
    #[inline(always)]
    pub(super) fn pdf_with(
        &self,
        wi: DVec3,
        wo: DVec3,
        pr: &LobeProbs,
        pre: Option<&Inside>,
        surface_pdf: Option<f64>,
    ) -> f64 {
        if grazing(wi) || grazing(wo) {
            return 0.0;
        }
        let (e, x) = (side(wi), side(wo));
        let mut pdf = 0.0;
        if e == x {
            if pr[Lobe::Surface] > 0.0 {
                pdf += pr[Lobe::Surface]
                    * match surface_pdf {
                        Some(p) => p,
                        None => self.faces[x].reflection_pdf(x.local(wi), x.local(wo)),
                    };
            }
            pdf += pr[Lobe::MultipleR] * wi.z.abs() / PI;
        } else {
            pdf += pr[Lobe::MultipleT] * wi.z.abs() / PI;
            if pr[Lobe::Direct] > 0.0 && !self.kernel.is_delta() {
                pdf += pr[Lobe::Direct] * self.kernel.pdf_wi(wi, wo, 1.0);
            }
        }
        if pr[Lobe::Single] > 0.0 {
            let g = match pre {
                Some(g) => *g,
                // The table coordinates are not needed for densities.
                None => self.inside(wi, wo, true, (TabPos::ZERO, TabPos::ZERO)),
            };
            pdf += pr[Lobe::Single] * self.pdf_single(wi, &g);
        }
        pdf
    }
}
