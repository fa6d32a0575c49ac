//! The Paper BSDF behind the renderer interface ([`Bsdf`]): `eval`, `pdf`,
//! and `sample`, which picks a lobe by the tabulated probabilities and
//! samples it (module doc of [`super`]).

use super::eval::Lobe;
use super::tables::TabPos;
use super::{grazing, side, ComponentSet, PaperBsdf, Side};
use crate::bsdf::{select_lobe, Bsdf, BsdfFlags, BsdfSample};
use crate::geometry::sample_cosine_hemisphere;
use crate::spectrum::Rgb;
use glam::{DVec2, DVec3};

impl Bsdf for PaperBsdf {
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.eval_components(wi, wo, ComponentSet::ALL)
    }

    fn sample(&self, wo: DVec3, uc: f64, u: [f64; 2]) -> Option<BsdfSample> {
        if grazing(wo) || !wo.is_finite() {
            return None;
        }
        let pr = self.lobe_probs(wo);
        let (k, acc) = select_lobe(uc, &pr.0)?;
        let lobe = Lobe::ALL[k];
        let x = side(wo);
        let sx = x.sign();
        let wi = match lobe {
            Lobe::Surface => {
                let fx = &self.faces[x];
                if fx.microfacet().is_none() {
                    let wi = DVec3::new(-wo.x, -wo.y, wo.z);
                    let f = fx.delta_reflectance(wo.z.abs());
                    return Some(BsdfSample {
                        wi,
                        f: Rgb::splat(f / wi.z.abs()),
                        pdf: pr[Lobe::Surface],
                        flags: BsdfFlags::REFLECTION | BsdfFlags::SPECULAR,
                    });
                }
                x.local(fx.sample_reflection(x.local(wo), u)?)
            }
            Lobe::Single => {
                let fx = &self.faces[x];
                let mu_o = fx.inside_cos(wo.z.abs());
                // A unit vector: |t_o|^2 = (1 - wo.z^2) / n^2 + mu_o^2 = 1 (Snell).
                let t_o = DVec3::new(wo.x * fx.inv_n(), wo.y * fx.inv_n(), sx * mu_o);
                // Reuse the lobe-choice number to pick the HG lobe.
                let ucr = ((uc - acc) / pr[lobe]).clamp(0.0, 1.0 - 1e-16);
                let t_i = self.phase.sample(t_o, ucr, u);
                if t_i.z == 0.0 {
                    return None;
                }
                // Light propagating down (t_i.z < 0) came in through the front face.
                let e = if t_i.z < 0.0 { Side::Front } else { Side::Back };
                let n = self.faces[e].n();
                let wt = DVec2::new(-t_i.x * n, -t_i.y * n);
                let r2 = wt.length_squared();
                if r2 >= 1.0 {
                    return None;
                }
                let z = (1.0 - r2).sqrt();
                DVec3::new(wt.x, wt.y, e.sign() * z)
            }
            Lobe::MultipleR | Lobe::MultipleT => {
                let w = sample_cosine_hemisphere(u);
                let s = if lobe == Lobe::MultipleR { sx } else { -sx };
                DVec3::new(w.x, w.y, s * w.z)
            }
            Lobe::Direct => {
                let se = -sx;
                if self.kernel.is_delta() {
                    let wi = DVec3::new(-wo.x, -wo.y, se * wo.z.abs());
                    let wgt = self.direct_delta_weight(wi, wo);
                    return Some(BsdfSample {
                        wi,
                        f: wgt / wi.z.abs(),
                        pdf: pr[Lobe::Direct],
                        flags: BsdfFlags::TRANSMISSION | BsdfFlags::SPECULAR,
                    });
                }
                self.kernel.sample_wi(wo, se, 1.0, u)?
            }
        };
        if grazing(wi) || !wi.is_finite() {
            return None;
        }
        let geo = self.inside(
            wi,
            wo,
            true,
            (
                TabPos::new(wi.z.abs().min(1.0).sqrt()),
                TabPos::new(wo.z.abs().min(1.0).sqrt()),
            ),
        );
        // Reflection on a rough face: its value and density share the half vector.
        let (surf_f, surf_pdf) = if wi.z * wo.z > 0.0 && self.faces[x].microfacet().is_some() {
            let (f, p) = self.faces[x].reflection_and_pdf(x.local(wi), x.local(wo), geo.si, geo.so);
            (Some(f), Some(p))
        } else {
            (None, None)
        };
        let pdf = self.pdf_with(wi, wo, &pr, Some(&geo), surf_pdf);
        if !pdf.is_finite() || pdf <= 0.0 {
            return None;
        }
        let reflect = wi.z * wo.z > 0.0;
        let kind = match lobe {
            Lobe::Surface | Lobe::Direct => BsdfFlags::GLOSSY,
            Lobe::Single | Lobe::MultipleR | Lobe::MultipleT => BsdfFlags::DIFFUSE,
        };
        let dir = if reflect {
            BsdfFlags::REFLECTION
        } else {
            BsdfFlags::TRANSMISSION
        };
        Some(BsdfSample {
            wi,
            f: self.eval_with(wi, wo, ComponentSet::ALL, Some(&geo), surf_f),
            pdf,
            flags: dir | kind,
        })
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if grazing(wo) || !wo.is_finite() || !wi.is_finite() {
            return 0.0;
        }
        let pr = self.lobe_probs(wo);
        self.pdf_with(wi, wo, &pr, None, None)
    }

    fn flags(&self) -> BsdfFlags {
        let mut f = BsdfFlags::REFLECTION | BsdfFlags::TRANSMISSION | BsdfFlags::DIFFUSE;
        if self.faces.0.iter().any(|f| f.microfacet().is_some()) || (self.opts.direct && !self.kernel.is_delta()) {
            f |= BsdfFlags::GLOSSY;
        }
        if self.faces.0.iter().any(|f| f.is_smooth()) || (self.opts.direct && self.kernel.is_delta()) {
            f |= BsdfFlags::SPECULAR;
        }
        f
    }
}
