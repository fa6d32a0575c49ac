//! The interface every scattering model of the project implements.
//!
//! Modelled on pbrt-v4's `BxDF` (`f`, `Sample_f`, `PDF`, `Flags`) in the
//! conventions of docs/design.md section 2: directions are unit vectors in the local
//! frame whose `+z` is the macro normal of the front face; `wi` points toward the
//! light, `wo` toward the viewer; `eval` is the BSDF *without* the cosine factor,
//! for radiance transport. `sample` is given `wo` and draws `wi`, as a path tracer
//! does; `pdf(wi, wo)` is the solid-angle density of that draw.

use crate::spectrum::Rgb;
use glam::DVec3;

/// Which lobes a BSDF (or one sampled event) has, as bits (pbrt-v4's `BxDFFlags`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct BsdfFlags(pub u8);

impl BsdfFlags {
    /// No lobe (an absorbing or empty BSDF).
    pub const NONE: BsdfFlags = BsdfFlags(0);
    /// Scatters back into the hemisphere of `wo`.
    pub const REFLECTION: BsdfFlags = BsdfFlags(1);
    /// Scatters into the opposite hemisphere.
    pub const TRANSMISSION: BsdfFlags = BsdfFlags(2);
    /// A broad lobe (Lambertian-like).
    pub const DIFFUSE: BsdfFlags = BsdfFlags(4);
    /// A glossy lobe (rough microfacet).
    pub const GLOSSY: BsdfFlags = BsdfFlags(8);
    /// A Dirac delta lobe (smooth interface, unscattered light through a smooth slab).
    pub const SPECULAR: BsdfFlags = BsdfFlags(16);

    /// Whether every bit of `o` is set in `self`.
    pub fn contains(self, o: BsdfFlags) -> bool {
        self.0 & o.0 == o.0
    }
    /// Whether any bit of `o` is set in `self`.
    pub fn intersects(self, o: BsdfFlags) -> bool {
        self.0 & o.0 != 0
    }
    /// Whether the flags include a delta lobe.
    pub fn is_specular(self) -> bool {
        self.intersects(Self::SPECULAR)
    }
    /// Whether the flags include a non-delta lobe that `eval` can see.
    pub fn is_non_specular(self) -> bool {
        self.intersects(BsdfFlags(Self::DIFFUSE.0 | Self::GLOSSY.0))
    }
}

impl std::ops::BitOr for BsdfFlags {
    type Output = BsdfFlags;
    fn bitor(self, o: BsdfFlags) -> BsdfFlags {
        BsdfFlags(self.0 | o.0)
    }
}
impl std::ops::BitOrAssign for BsdfFlags {
    fn bitor_assign(&mut self, o: BsdfFlags) {
        self.0 |= o.0;
    }
}

/// Whether a quantity is transported from the light (importance, particle
/// tracing) or gathered from the camera (radiance). They differ by `eta^2`
/// across a refracting interface (Veach 1997, section 5.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    /// Radiance, as a path tracer from the camera gathers it.
    Radiance,
    /// Importance (flux), as a light tracer or a Monte Carlo photon walk carries it.
    Importance,
}

/// One draw of [`Bsdf::sample`].
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// The sampled direction toward the light (unit, local frame).
    pub wi: DVec3,
    /// The BSDF value `f(wi, wo)` without cosine. For a delta lobe it is the
    /// lobe's weight divided by `|cos wi|` so that `f |cos| / pdf` is the throughput.
    pub f: Rgb,
    /// Solid-angle density of `wi`. For a delta lobe, the discrete probability
    /// of choosing that lobe.
    pub pdf: f64,
    /// The lobe that was sampled (one of REFLECTION/TRANSMISSION with one of DIFFUSE/GLOSSY/SPECULAR).
    pub flags: BsdfFlags,
}

impl BsdfSample {
    /// `f |cos wi| / pdf`: the factor a path's throughput is multiplied by.
    pub fn weight(&self) -> Rgb {
        if self.pdf > 0.0 {
            self.f * (self.wi.z.abs() / self.pdf)
        } else {
            Rgb::ZERO
        }
    }
}

/// A BSDF in the local frame, radiance transport (see the module doc).
pub trait Bsdf: Send + Sync {
    /// `f(wi, wo)`, without cosine; delta lobes are not included (they are zero
    /// for any pair of directions `eval` can be given).
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb;
    /// Draws `wi` for the given `wo` from the random numbers `uc` (lobe choice) and `u`.
    /// `None` when no direction could be drawn (absorbed, below a grazing limit).
    fn sample(&self, wo: DVec3, uc: f64, u: [f64; 2]) -> Option<BsdfSample>;
    /// Solid-angle density with which `sample(wo, ..)` draws `wi`; zero for delta lobes.
    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64;
    /// The lobes this BSDF has.
    fn flags(&self) -> BsdfFlags;
}

/// The lobe of a mixture sampler that `uc` in [0, 1) selects, with the start
/// of its interval: the first `k` whose interval `[sum(probs[..k]),
/// sum(probs[..=k]))` of the cumulative probabilities holds `uc`, if its
/// probability is positive (`(uc - start) / probs[k]` is then a fresh uniform
/// number for the lobe). Where rounding leaves `uc` at or beyond the sum of
/// `probs` (which should be 1), the last lobe with a positive probability;
/// `None` when no lobe has one.
pub fn select_lobe<const N: usize>(uc: f64, probs: &[f64; N]) -> Option<(usize, f64)> {
    let mut acc = 0.0;
    for (k, &p) in probs.iter().enumerate() {
        if uc < acc + p {
            return (p > 0.0).then_some((k, acc));
        }
        acc += p;
    }
    let k = probs.iter().rposition(|&p| p > 0.0)?;
    Some((k, probs[..k].iter().sum()))
}

/// Share of the total albedo estimate that [`defensive_probabilities`] adds
/// to each present lobe's estimate.
pub const LOBE_PROB_FLOOR: f64 = 0.02;

/// Lobe-selection probabilities of a mixture sampler from albedo estimates
/// `est` of its lobes: each `present` lobe gets `est + LOBE_PROB_FLOOR *
/// total` (a defensive mixture: no lobe that carries light is sampled too
/// rarely where the estimates are rough), normalised to sum to 1; all zero
/// when nothing is present or the estimates are not finite. Any positive
/// values are unbiased: they only weigh the strategies.
pub fn defensive_probabilities<const N: usize>(est: [f64; N], present: [bool; N]) -> [f64; N] {
    let total: f64 = est.iter().zip(&present).filter(|(_, p)| **p).map(|(e, _)| *e).sum();
    let mut w = [0.0; N];
    for k in 0..N {
        if present[k] {
            w[k] = est[k] + LOBE_PROB_FLOOR * total;
        }
    }
    let sum: f64 = w.iter().sum();
    if !sum.is_finite() || sum <= 0.0 {
        return [0.0; N];
    }
    w.map(|v| v / sum)
}

/// Directional albedo seen from `wo`, split into reflection and transmission:
/// `int f(wi, wo) |cos wi| dwi` over each hemisphere (pbrt-v4's `rho(wo)`),
/// delta lobes included, by `n x n` stratified samples of [`Bsdf::sample`]
/// (lobe choice from a fixed low-discrepancy offset). For a reciprocal BSDF
/// (any slab with air on both sides) this is also the fraction of the flux
/// arriving from `wo` that is reflected and transmitted.
pub fn sampled_albedo(bsdf: &dyn Bsdf, wo: DVec3, n: usize) -> (Rgb, Rgb) {
    stratified_albedo(bsdf, wo, n, |s| s.weight())
}

/// The `n x n` stratified sampling loop of [`sampled_albedo`] and
/// [`albedo_from`] (and of instruments that leave part of the hemisphere out):
/// draws from [`Bsdf::sample`] started at `w` (lobe choice from a fixed
/// low-discrepancy offset), weighs each sample with `weight` (non-finite
/// weights are skipped), and returns the mean weights on `w`'s side
/// (reflection) and the other (transmission).
pub fn stratified_albedo(bsdf: &dyn Bsdf, w: DVec3, n: usize, weight: impl Fn(&BsdfSample) -> Rgb) -> (Rgb, Rgb) {
    let (mut r, mut t) = (Rgb::ZERO, Rgb::ZERO);
    let inv = 1.0 / n as f64;
    let golden = 0.618_033_988_749_894_9;
    for i in 0..n {
        for j in 0..n {
            let k = (i * n + j) as f64;
            let uc = (0.5 + k * golden).fract();
            let u = [
                (i as f64 + 0.5) * inv,
                (j as f64 + (0.5 + k * 0.754_877_666).fract()) * inv,
            ];
            if let Some(s) = bsdf.sample(w, uc, [u[0], u[1].min(1.0 - 1e-12)]) {
                let v = weight(&s);
                if !v.is_finite() {
                    continue;
                }
                if s.wi.z * w.z > 0.0 {
                    r += v;
                } else {
                    t += v;
                }
            }
        }
    }
    let norm = inv * inv;
    (r * norm, t * norm)
}

/// Directional albedo for light arriving from `wi`, split into reflection and
/// transmission: the fractions of the incident flux that leave on each side,
/// `int f(wi, wo) |cos wo| dwo` over each hemisphere (the integral over the
/// *outgoing* argument), delta lobes included. Estimated with `n x n`
/// stratified directions `w'` drawn by [`Bsdf::sample`] started from `wi`
/// (density `pdf(w', wi)`), weighted by `f(wi, w') |cos w'| / pdf(w', wi)`;
/// a delta lobe's sample carries its own weight (delta lobes of a sheet in
/// air are symmetric). Unlike [`sampled_albedo`] it does not rely on the BSDF
/// being reciprocal.
pub fn albedo_from(bsdf: &dyn Bsdf, wi: DVec3, n: usize) -> (Rgb, Rgb) {
    stratified_albedo(bsdf, wi, n, |s| {
        if s.flags.is_specular() {
            s.weight()
        } else {
            bsdf.eval(wi, s.wi) * (s.wi.z.abs() / s.pdf)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each `uc` selects the lobe whose cumulative interval holds it; a lobe of
    /// probability zero is never selected; `uc` beyond a sum that rounding left
    /// below 1 selects the last lobe that can be sampled instead of running off
    /// the end (the Paper BSDF's sampler indexed a fifth lobe there before).
    #[test]
    fn select_lobe_follows_the_cumulative_probabilities() {
        let p = [0.25, 0.0, 0.5, 0.25];
        assert_eq!(select_lobe(0.0, &p), Some((0, 0.0)));
        assert_eq!(select_lobe(0.2499, &p), Some((0, 0.0)));
        assert_eq!(select_lobe(0.25, &p), Some((2, 0.25)));
        assert_eq!(select_lobe(0.7499, &p), Some((2, 0.25)));
        assert_eq!(select_lobe(0.75, &p), Some((3, 0.75)));
        // A sum of 1 - 2^-53 and uc just below 1.
        let q = [0.5, 0.5 - f64::EPSILON / 2.0, 0.0];
        assert!(q.iter().sum::<f64>() < 1.0);
        assert_eq!(select_lobe(1.0 - f64::EPSILON / 4.0, &q), Some((1, 0.5)));
        assert_eq!(select_lobe(0.3, &[0.0; 3]), None);
    }
}
