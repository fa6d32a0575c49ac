//! Measured BSDFs of the RGL material database (Dupuy and Jakob 2018, "An
//! Adaptive Parameterization for Efficient Material Acquisition and
//! Representation", ACM TOG 37(6)), in its `.bsdf` tensor-file format, RGB
//! variant, isotropic or anisotropic, reflection only.
//!
//! The file stores, for each incident direction of a grid (`phi_i`,
//! `theta_i`), the reflectance times the cosine on the paper's adaptive
//! parameterisation: the output unit square of the warp that samples the
//! distribution of visible normals (`vndf`) of the material. Evaluating
//! `f(wi, wo)` therefore means (paper, sections 4 and 5):
//! 1. the half vector `m = (wi + wo)/|wi + wo|` in the spherical coordinates
//!    `u = (sqrt(2 theta / pi), (phi + pi) / (2 pi))` (azimuth relative to the
//!    incident one for isotropic files);
//! 2. inverting the VNDF warp for the incident direction: `u` -> the point of
//!    the unit square where the data live;
//! 3. bilinear interpolation of each colour channel there (and linear between
//!    the incident grid values);
//! 4. when the file's `jacobian` flag is set, the factor `D(m) / (4 sigma(wi))`
//!    of the change of variables from visible normals to outgoing directions,
//!    `D` the tabulated NDF and `sigma` the projected area of the microsurface.
//!
//! The file's value is `f cos(theta_o)`; [`MeasuredBsdf::eval_raw`] divides the
//! cosine out (the project's convention, docs/design.md section 2). Anisotropic files
//! with a reduced azimuth range (`phi_i` covering pi or pi/2) are folded by the
//! material's symmetry as the format description prescribes.
//!
//! Directions: `wi` (toward the light) is the measurement's incident
//! direction, `wo` (toward the viewer) the outgoing one. Spectral files
//! (`wavelengths` and `spectra` fields) are refused with an error that says to
//! use the database's RGB file of the same material: converting 360-1000 nm
//! spectra to RGB would need a choice of observer and illuminant that the file
//! does not record.

pub mod tensor;
pub mod warp;

use crate::DataError;
use paperbsdf_core::models::ComponentModel;
use paperbsdf_core::paper::Component;
use paperbsdf_core::{Bsdf, BsdfFlags, BsdfSample, DVec3, Rgb};
use std::f64::consts::PI;
use tensor::{DType, TensorFile};
use warp::Warp2D;

/// A measured isotropic or anisotropic BRDF read from an RGL `.bsdf` file.
#[derive(Clone, Debug)]
pub struct MeasuredBsdf {
    /// The file's `description` field (the material's name).
    pub description: String,
    /// Where it was read from.
    pub origin: String,
    ndf: Warp2D,
    sigma: Warp2D,
    vndf: Warp2D,
    rgb: Warp2D,
    isotropic: bool,
    jacobian: bool,
    reduction: i32,
    /// Incident elevations of the measurement grid, radians.
    pub theta_i: Vec<f64>,
    /// Incident azimuths of the measurement grid, radians.
    pub phi_i: Vec<f64>,
}

fn elevation(d: DVec3) -> f64 {
    // 2 asin(|d - z|/2): accurate near the pole, where acos(z) loses digits
    let dist = (d.x * d.x + d.y * d.y + (d.z - 1.0) * (d.z - 1.0)).sqrt();
    2.0 * (0.5 * dist).clamp(-1.0, 1.0).asin()
}
/// Azimuth `atan2(y, x)`, with pi (not 0) for a direction on the pole, where the
/// azimuth is undefined. Dr.Jit's `atan2(0, 0)`, which Mitsuba's `measured`
/// plugin uses, gives pi: with this convention the values at normal incidence
/// and at the exact mirror direction agree with Mitsuba's (they differ by a few
/// percent between the two conventions, because the file's tables are not
/// exactly invariant at the pole).
fn azimuth(y: f64, x: f64) -> f64 {
    if x == 0.0 && y == 0.0 {
        PI
    } else {
        y.atan2(x)
    }
}
fn theta2u(t: f64) -> f64 {
    (t * (2.0 / PI)).max(0.0).sqrt()
}
fn phi2u(p: f64) -> f64 {
    (p + PI) / (2.0 * PI)
}
/// `a` with the sign flipped unless `b` is negative (`-a sign(b)`, sign(0) = 1).
fn mulsign_neg(a: f64, b: f64) -> f64 {
    if b >= 0.0 {
        -a
    } else {
        a
    }
}

impl MeasuredBsdf {
    /// Reads an RGL `.bsdf` file.
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<MeasuredBsdf, DataError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| DataError::Io {
            file: file.clone(),
            source,
        })?;
        Self::from_bytes(bytes, &file)
    }

    /// Parses the bytes of an RGL `.bsdf` file; `origin` names it in errors.
    pub fn from_bytes(bytes: Vec<u8>, origin: &str) -> Result<MeasuredBsdf, DataError> {
        let err = |message: String| DataError::Other {
            file: origin.to_string(),
            message,
        };
        let terr = |e: tensor::TensorError| err(e.0);
        let tf = TensorFile::parse(bytes).map_err(terr)?;
        if tf.fields.contains_key("wavelengths") || tf.fields.contains_key("spectra") {
            return Err(err(
                "this is a spectral RGL file (fields `wavelengths`, `spectra`), which is not supported: \
                 download the RGB variant of the material (`..._rgb.bsdf`) from the RGL database"
                    .into(),
            ));
        }
        let shape = |name: &str, rank: usize| -> Result<Vec<usize>, DataError> {
            let f = tf.field(name).map_err(terr)?;
            if f.shape.len() != rank {
                return Err(err(format!(
                    "field `{name}` has shape {:?} (rank {}), expected rank {rank}",
                    f.shape,
                    f.shape.len()
                )));
            }
            Ok(f.shape.clone())
        };
        let floats = |name: &str| -> Result<Vec<f32>, DataError> { tf.f32s(name).map_err(terr) };
        let theta_i = shape("theta_i", 1)?;
        let phi_i = shape("phi_i", 1)?;
        let ndf_s = shape("ndf", 2)?;
        let sigma_s = shape("sigma", 2)?;
        let vndf_s = shape("vndf", 4)?;
        let lum_s = shape("luminance", 4)?;
        let rgb_s = shape("rgb", 5)?;
        let jac = tf.field("jacobian").map_err(terr)?;
        let desc = tf.field("description").map_err(terr)?;
        let (np, nt) = (phi_i[0], theta_i[0]);
        let want = |name: &str, got: &[usize], expected: String| -> Result<(), DataError> {
            Err(err(format!("field `{name}` has shape {got:?}, expected {expected}")))
        };
        if vndf_s[0] != np || vndf_s[1] != nt {
            want("vndf", &vndf_s, format!("[phi_i = {np}, theta_i = {nt}, h, w]"))?;
        }
        if lum_s[0] != np || lum_s[1] != nt || lum_s[2] != lum_s[3] {
            want("luminance", &lum_s, format!("[{np}, {nt}, n, n]"))?;
        }
        if rgb_s[0] != np || rgb_s[1] != nt || rgb_s[2] != 3 || rgb_s[3] != rgb_s[4] || rgb_s[3] != lum_s[2] {
            want(
                "rgb",
                &rgb_s,
                format!("[{np}, {nt}, 3, {n}, {n}] (n from `luminance`)", n = lum_s[2]),
            )?;
        }
        if jac.dtype != DType::U8 && jac.dtype != DType::I8 || jac.len != 1 {
            return Err(err(format!(
                "field `jacobian` must be one uint8, found {} x {:?}",
                jac.dtype.name(),
                jac.shape
            )));
        }
        if desc.dtype.size() != 1 {
            return Err(err(format!(
                "field `description` must be bytes, found {}",
                desc.dtype.name()
            )));
        }
        let description = String::from_utf8_lossy(tf.bytes(desc)).into_owned();
        let jacobian = tf.bytes(jac)[0] != 0;
        let to64 = |v: Vec<f32>| v.into_iter().map(f64::from).collect::<Vec<f64>>();
        let theta = to64(floats("theta_i")?);
        let phi = to64(floats("phi_i")?);
        let isotropic = np <= 2;
        let mut reduction = 0;
        if !isotropic {
            let span = phi[np - 1] - phi[0];
            if span.is_nan() || span <= 0.0 {
                return Err(err(format!("field `phi_i` does not increase: {phi:?}")));
            }
            reduction = (2.0 * PI / span).round() as i32;
        }
        let bad = |name: &'static str| move |m: warp::WarpError| err(format!("field `{name}`: {m}"));
        let params = vec![phi.clone(), theta.clone()];
        let ndf = Warp2D::new(&floats("ndf")?, ndf_s[1], ndf_s[0], vec![], false, false).map_err(bad("ndf"))?;
        let sigma =
            Warp2D::new(&floats("sigma")?, sigma_s[1], sigma_s[0], vec![], false, false).map_err(bad("sigma"))?;
        let vndf =
            Warp2D::new(&floats("vndf")?, vndf_s[3], vndf_s[2], params.clone(), true, true).map_err(bad("vndf"))?;
        let mut p3 = params;
        p3.push(vec![0.0, 1.0, 2.0]);
        let rgb = Warp2D::new(&floats("rgb")?, rgb_s[4], rgb_s[3], p3, false, false).map_err(bad("rgb"))?;
        Ok(MeasuredBsdf {
            description,
            origin: origin.to_string(),
            ndf,
            sigma,
            vndf,
            rgb,
            isotropic,
            jacobian,
            reduction,
            theta_i: theta,
            phi_i: phi,
        })
    }

    /// Whether the material is isotropic (one incident azimuth in the file).
    pub fn is_isotropic(&self) -> bool {
        self.isotropic
    }

    /// The file's value divided by `cos theta_o`: `f(wi, wo)` without cosine, as
    /// stored (it can be slightly negative where the fitted representation
    /// rings). Zero unless both directions are above the surface.
    pub fn eval_raw(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if !(wi.z > 0.0 && wo.z > 0.0) {
            return Rgb::ZERO;
        }
        let (mut wi, mut wo) = (wi, wo);
        if self.reduction >= 2 {
            let sy = wi.y;
            let sx = if self.reduction == 4 { wi.x } else { sy };
            wi.x = mulsign_neg(wi.x, sx);
            wi.y = mulsign_neg(wi.y, sy);
            wo.x = mulsign_neg(wo.x, sx);
            wo.y = mulsign_neg(wo.y, sy);
        }
        let m = (wi + wo).normalize_or_zero();
        if m == DVec3::ZERO {
            return Rgb::ZERO;
        }
        let theta_i = elevation(wi);
        let phi_i = azimuth(wi.y, wi.x);
        let theta_m = elevation(m);
        let phi_m = azimuth(m.y, m.x);
        let u_wi = [theta2u(theta_i), phi2u(phi_i)];
        let mut u_m = [
            theta2u(theta_m),
            phi2u(if self.isotropic { phi_m - phi_i } else { phi_m }),
        ];
        u_m[1] -= u_m[1].floor();
        let params = [phi_i, theta_i];
        let (sample, _) = self.vndf.invert(u_m, &params);
        let mut out = [0.0; 3];
        for (c, o) in out.iter_mut().enumerate() {
            *o = self.rgb.eval(sample, &[phi_i, theta_i, c as f64]);
        }
        let mut scale = 1.0 / wo.z;
        if self.jacobian {
            let s = self.sigma.eval(u_wi, &[]);
            scale *= if s > 0.0 {
                self.ndf.eval(u_m, &[]) / (4.0 * s)
            } else {
                0.0
            };
        }
        Rgb(out.map(|v| v * scale))
    }
}

impl Bsdf for MeasuredBsdf {
    /// [`MeasuredBsdf::eval_raw`] with negative values (ringing of the fitted
    /// representation, never more than a small fraction of the peak) set to zero:
    /// a BSDF is non-negative, and a renderer cannot carry negative throughput.
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.eval_raw(wi, wo).map(|v| v.max(0.0))
    }
    /// Cosine-weighted sampling of `wi` above the surface (exact density, no
    /// importance sampling of the measured lobe).
    fn sample(&self, wo: DVec3, _uc: f64, u: [f64; 2]) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let r = u[0].sqrt();
        let phi = 2.0 * PI * u[1];
        let z = (1.0 - u[0]).max(0.0).sqrt();
        if z <= 0.0 {
            return None;
        }
        let wi = DVec3::new(r * phi.cos(), r * phi.sin(), z);
        Some(BsdfSample {
            wi,
            f: self.eval(wi, wo),
            pdf: z / PI,
            flags: BsdfFlags::REFLECTION | BsdfFlags::GLOSSY,
        })
    }
    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z > 0.0 && wo.z > 0.0 {
            wi.z / PI
        } else {
            0.0
        }
    }
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::REFLECTION | BsdfFlags::GLOSSY
    }
}

impl ComponentModel for MeasuredBsdf {
    /// A measurement has no components: all of it is reported as `surface`.
    fn eval_component(&self, wi: DVec3, wo: DVec3, c: Component) -> Rgb {
        match c {
            Component::Surface => self.eval(wi, wo),
            _ => Rgb::ZERO,
        }
    }
    fn is_rgb(&self) -> bool {
        true
    }
    fn components(&self) -> &'static [Component] {
        &[Component::Surface]
    }
}
