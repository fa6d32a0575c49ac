//! The walk's surface events ([`crate::walk`], "The walk"): light meeting a
//! face, from outside or from inside the slab, is reflected, transmitted or
//! lost by an exact draw of the face's BSDF in importance transport (Walter et
//! al. 2007's sampling of a rough dielectric, the microsurface walk of Heitz
//! et al. 2016, or the sub-walk through a front coating: [`crate::faces`]);
//! a smooth or index-matched face is a pair of delta lobes (Fresnel
//! reflection and refraction), chosen in proportion to their weights. Each
//! event is also a next-event vertex ([`super::nee`]). The lit face's own
//! reflection toward viewers on its side is added here too.

use super::nee::Vertex;
use super::{Tally, Tracer};
use crate::faces::FaceOptics;
use crate::slab::Side;
use paperbsdf_core::{DVec3, TransportMode};
use rand::Rng;

impl Tracer<'_> {
    /// Adds the lit face's reflection of light from `wi_l` (local to the lit
    /// face `lit`) toward each viewer on its side: `f = eval_mode(wi, wo,
    /// Radiance)` of the face (an unbiased estimate for a stochastic face;
    /// nothing for a delta face, whose mirror reflection is a Dirac delta in `wo`).
    pub(super) fn lit_face_reflection<R: Rng>(&self, lit: Side, wi_l: DVec3, rng: &mut R, tally: &mut Tally) {
        for (j, t) in self.targets.iter().enumerate() {
            if t.face == lit {
                let f = match self.slab.face(lit) {
                    FaceOptics::Walter(b) => b.eval_mode(wi_l, t.wo_l, TransportMode::Radiance),
                    FaceOptics::Stochastic(s) => {
                        let mut rnd = || rng.gen::<f64>();
                        s.eval(wi_l, t.wo_l, TransportMode::Radiance, &mut rnd)
                    }
                    FaceOptics::Delta(_) => 0.0,
                };
                tally.add_f(j, f);
            }
        }
    }

    /// A surface event at `face` for light arriving from `w_from_l` (face-local)
    /// with weight `weight`: next-event estimation, then the sampled event.
    /// Returns the new propagation direction and weight if the light stays in
    /// the slab; exits are added to the totals (`lit` is the lit face).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn surface_vertex<R: Rng, E: FnMut(DVec3, f64)>(
        &self,
        face: Side,
        w_from_l: DVec3,
        weight: f64,
        lit: Side,
        rng: &mut R,
        tally: &mut Tally,
        on_exit: &mut E,
    ) -> Option<(DVec3, f64)> {
        let v = Vertex::Surface { face, w_from_l };
        let from_outside = w_from_l.z > 0.0;
        let mut exit = |tally: &mut Tally, w: f64, dir_l: DVec3| {
            if face == lit {
                tally.r += w;
            } else {
                tally.t += w;
            }
            on_exit(face.local(dir_l), w);
        };
        match self.slab.face(face) {
            FaceOptics::Walter(b) => {
                self.nee_exit(v, weight, rng, tally);
                let (uc, u0, u1) = (rng.gen::<f64>(), rng.gen::<f64>(), rng.gen::<f64>());
                let s = b.sample_mode(w_from_l, uc, [u0, u1], TransportMode::Importance)?;
                let sw = s.weight().0[0];
                if !(sw.is_finite() && sw > 0.0) {
                    return None;
                }
                if s.wi.z > 0.0 {
                    exit(tally, weight * sw, s.wi);
                    return None;
                }
                let w = face.local(s.wi);
                let nw = weight * sw;
                self.nee_dir(v, nw, w, Some(s.pdf), rng, tally);
                Some((w, nw))
            }
            FaceOptics::Stochastic(sf) => {
                // Exit sampling covers the non-delta part of this face at every
                // target; its delta part (a coating's mirror reflection) is
                // covered along the sampled direction.
                self.nee_exit(v, weight, rng, tally);
                let mut rnd = || rng.gen::<f64>();
                let s = sf.sample(w_from_l, TransportMode::Importance, &mut rnd)?;
                if !(s.weight.is_finite() && s.weight > 0.0) {
                    return None;
                }
                let nw = weight * s.weight;
                if s.dir.z > 0.0 {
                    exit(tally, nw, s.dir);
                    return None;
                }
                let w = face.local(s.dir);
                if s.delta {
                    self.nee_dir(v, nw, w, None, rng, tally);
                }
                Some((w, nw))
            }
            FaceOptics::Delta(df) => {
                let (r, t, t_dir) = df.lobes(w_from_l, TransportMode::Importance);
                // Delta interface: the lobe into the slab and the lobe out of it.
                let mirror = DVec3::new(-w_from_l.x, -w_from_l.y, w_from_l.z);
                let (into, out) = if from_outside {
                    ((t, t_dir.unwrap_or(DVec3::ZERO)), (r, mirror))
                } else {
                    ((r, mirror), (t, t_dir.unwrap_or(DVec3::ZERO)))
                };
                let total = into.0 + out.0;
                if total <= 0.0 {
                    return None;
                }
                let w_into = face.local(into.1);
                if into.0 > 0.0 {
                    self.nee_dir(v, weight * into.0, w_into, None, rng, tally);
                }
                if rng.gen::<f64>() * total < into.0 {
                    Some((w_into, weight * total))
                } else {
                    exit(tally, weight * total, out.1);
                    None
                }
            }
        }
    }
}
