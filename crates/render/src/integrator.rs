//! The path tracer: unidirectional paths from the camera with next-event
//! estimation at every non-delta vertex, both strategies combined by multiple
//! importance sampling with the power heuristic (Veach 1997, chapter 9; pbrt-v4
//! `PathIntegrator`, Mitsuba 3 `path`), and Russian roulette from `rr_depth` on
//! with survival probability `min(max throughput channel, 0.95)` (Mitsuba 3).

use crate::math::{power_heuristic, Frame, Pcg32, Ray};
use crate::scene::{Light, Scene};
use glam::DVec3;
use paperbsdf_core::Rgb;

const INV_4PI: f64 = 1.0 / (4.0 * std::f64::consts::PI);

/// Ray origin offset from a surface point toward the side of `d` (relative to `ng`).
#[inline]
pub fn spawn(p: DVec3, ng: DVec3, d: DVec3) -> Ray {
    let eps = 1e-7 * (1.0 + p.abs().max_element());
    let o = if ng.dot(d) >= 0.0 { p + ng * eps } else { p - ng * eps };
    Ray::new(o, d)
}

/// A point sampled on a light, as seen from a shading point.
struct LightSample {
    /// Unit direction from the shading point to the light.
    wi: DVec3,
    /// Emitted radiance toward the shading point.
    le: Rgb,
    /// Solid-angle density (light choice included).
    pdf: f64,
    /// Distance (infinite for the environment).
    dist: f64,
}

impl Scene {
    /// Probability of choosing any one light.
    #[inline]
    fn light_choice_pdf(&self) -> f64 {
        1.0 / self.lights.len() as f64
    }

    fn sample_light(&self, p: DVec3, rng: &mut Pcg32) -> Option<LightSample> {
        let n = self.lights.len();
        if n == 0 {
            return None;
        }
        let k = ((rng.next_f64() * n as f64) as usize).min(n - 1);
        let sel = self.light_choice_pdf();
        match self.lights[k] {
            Light::Environment => {
                let wi = paperbsdf_core::geometry::sample_uniform_sphere(rng.next_2d());
                Some(LightSample {
                    wi,
                    le: self.environment.unwrap_or(Rgb::ZERO),
                    pdf: sel * INV_4PI,
                    dist: f64::INFINITY,
                })
            }
            Light::Area(oi) => {
                let o = &self.objects[oi];
                let uc = rng.next_f64();
                let j = o.cdf.partition_point(|&c| c <= uc).min(o.count - 1);
                let (q, nq) = self.shapes[o.first + j].sample_area(rng.next_2d());
                let v = q - p;
                let d2 = v.length_squared();
                if d2 == 0.0 {
                    return None;
                }
                let dist = d2.sqrt();
                let wi = v / dist;
                let cos_l = -nq.dot(wi);
                if cos_l == 0.0 || (!o.two_sided && cos_l < 0.0) {
                    return None;
                }
                let pdf = sel * d2 / (cos_l.abs() * o.area);
                Some(LightSample {
                    wi,
                    le: o.emission.unwrap_or(Rgb::ZERO),
                    pdf,
                    dist,
                })
            }
        }
    }

    /// Radiance arriving at the camera along `ray`.
    pub fn li(&self, mut ray: Ray, rng: &mut Pcg32) -> Rgb {
        let s = &self.settings;
        let mut l = Rgb::ZERO;
        let mut beta = Rgb::ONE;
        let mut prev_pdf = 0.0f64;
        let mut prev_specular = true;
        let mut prev_p = ray.o;
        let mut depth = 0u32;
        loop {
            let Some((pi, h)) = self.intersect(&ray) else {
                if let Some(env) = self.environment {
                    let w = if prev_specular {
                        1.0
                    } else {
                        power_heuristic(prev_pdf, self.light_choice_pdf() * INV_4PI)
                    };
                    l += beta * env * w;
                }
                break;
            };
            let shape = &self.shapes[pi];
            let sp = shape.surface(&ray, &h);
            let oi = self.prim_object[pi] as usize;
            let obj = &self.objects[oi];
            let wo_w = -ray.d;
            if let Some(le) = obj.emission {
                let cos_l = sp.ng.dot(wo_w);
                if obj.two_sided || cos_l > 0.0 {
                    let w = if prev_specular {
                        1.0
                    } else {
                        let d2 = (sp.p - prev_p).length_squared();
                        let pdf_l = self.light_choice_pdf() * d2 / (cos_l.abs() * obj.area);
                        power_heuristic(prev_pdf, pdf_l)
                    };
                    l += beta * le * w;
                }
            }
            depth += 1;
            if depth >= s.max_depth {
                break;
            }
            let Some(hb) = self.materials[obj.material].bsdf_at(sp.uv.x, sp.uv.y, rng.next_f64()) else {
                break;
            };
            let bsdf = hb.get();
            let frame = Frame::from_normal(sp.ns);
            let wo = frame.to_local(wo_w);
            if wo.z == 0.0 {
                break;
            }
            // Next-event estimation.
            if bsdf.flags().is_non_specular() {
                if let Some(ls) = self.sample_light(sp.p, rng) {
                    let wi = frame.to_local(ls.wi);
                    let f = bsdf.eval(wi, wo);
                    if !f.is_black() {
                        let mut shadow = spawn(sp.p, sp.ng, ls.wi);
                        if ls.dist.is_finite() {
                            shadow.t_max = (sp.p + ls.wi * ls.dist - shadow.o).length() * (1.0 - 1e-6);
                        }
                        if !self.occluded(&shadow) {
                            let w = power_heuristic(ls.pdf, bsdf.pdf(wi, wo));
                            l += beta * f * ls.le * (wi.z.abs() * w / ls.pdf);
                        }
                    }
                }
            }
            // BSDF sampling.
            let uc = rng.next_f64();
            let u = rng.next_2d();
            let Some(bs) = bsdf.sample(wo, uc, u) else {
                break;
            };
            let wgt = bs.weight();
            if !wgt.is_finite() || wgt.is_black() {
                break;
            }
            beta *= wgt;
            prev_pdf = bs.pdf;
            prev_specular = bs.flags.is_specular();
            prev_p = sp.p;
            let wi_w = frame.to_world(bs.wi);
            ray = spawn(sp.p, sp.ng, wi_w);
            if depth >= s.rr_depth {
                let q = beta.max_channel().min(0.95);
                if rng.next_f64() >= q {
                    break;
                }
                beta = beta / q;
            }
        }
        l
    }
}
