//! A scene ready to render: shapes in a BVH, objects (a material, an optional
//! area emission and cut-out mask per object), a constant environment, the
//! camera and the render settings.
//!
//! Conventions follow Mitsuba 3: an area light is one-sided unless said
//! otherwise and emits on the side its geometric normal points to; the camera's
//! field of view is horizontal; pixel `(0, 0)` is the top-left one.

use crate::error::RenderError;
use crate::material::Material;
use crate::math::{mix64, Ray};
use crate::shapes::{Bvh, PrimHit, Shape};
use crate::texture::GreyTexture;
use glam::DVec3;
use paperbsdf_core::Rgb;

/// A pinhole camera.
#[derive(Clone, Debug)]
pub struct Camera {
    /// Eye position.
    pub origin: DVec3,
    /// Unit viewing direction.
    pub forward: DVec3,
    /// Unit vector toward the image's right.
    pub right: DVec3,
    /// Unit vector toward the image's top.
    pub up: DVec3,
    /// `tan(fov_x / 2)`.
    pub tan_half: f64,
}

/// Smallest sine of the angle between a camera's `up` and its view direction
/// (1e-4: 0.0057 degrees; closer, the image's roll is decided by rounding).
pub const UP_MIN_SIN: f64 = 1e-4;

impl Camera {
    /// A camera at `origin` looking at `target` with approximate `up`; `fov_x_deg` is the horizontal field of view.
    /// `up` (any length) must make an angle whose sine is at least [`UP_MIN_SIN`]
    /// with the view direction.
    pub fn look_at(origin: DVec3, target: DVec3, up: DVec3, fov_x_deg: f64) -> Result<Camera, RenderError> {
        let forward = (target - origin).normalize_or_zero();
        if forward == DVec3::ZERO {
            return Err(RenderError::CameraTarget);
        }
        // Parallel within a tolerance: rounding makes the cross product of
        // parallel vectors tiny but not zero, and normalising it would give a
        // meaningless roll.
        let up_n = up.normalize_or_zero();
        let sin = forward.cross(up_n).length();
        if sin.is_nan() || sin < UP_MIN_SIN {
            return Err(RenderError::CameraUp { up });
        }
        let right = forward.cross(up_n).normalize();
        if !(fov_x_deg > 0.0 && fov_x_deg < 180.0) {
            return Err(RenderError::CameraFov { fov: fov_x_deg });
        }
        let up = right.cross(forward);
        Ok(Camera {
            origin,
            forward,
            right,
            up,
            tan_half: (fov_x_deg.to_radians() * 0.5).tan(),
        })
    }

    /// The primary ray through image position `(x, y)` in pixels (`(0, 0)` = top-left corner).
    #[inline]
    pub fn ray(&self, x: f64, y: f64, width: usize, height: usize) -> Ray {
        let sx = (2.0 * x / width as f64 - 1.0) * self.tan_half;
        let sy = (1.0 - 2.0 * y / height as f64) * self.tan_half * height as f64 / width as f64;
        Ray::new(self.origin, (self.forward + self.right * sx + self.up * sy).normalize())
    }
}

/// Render settings of a scene (overridable on the command line).
#[derive(Clone, Debug)]
pub struct Settings {
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// Samples per pixel.
    pub spp: u32,
    /// Longest path (number of scattering events plus one, Mitsuba's `max_depth`).
    pub max_depth: u32,
    /// Depth from which Russian roulette starts (Mitsuba's `rr_depth`).
    pub rr_depth: u32,
    /// Random seed.
    pub seed: u64,
    /// Multiplier applied before tone mapping the PNG.
    pub exposure: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            width: 320,
            height: 240,
            spp: 64,
            max_depth: 64,
            rr_depth: 5,
            seed: 0,
            exposure: 1.0,
        }
    }
}

/// One object: a group of primitives sharing a material, emission and mask.
pub struct Object {
    /// Name for messages.
    pub name: String,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Emitted radiance, if an area light.
    pub emission: Option<Rgb>,
    /// Whether the light emits on both sides.
    pub two_sided: bool,
    /// Cut-out mask: where it is below 1/2 the surface is a hole.
    pub mask: Option<GreyTexture>,
    /// First primitive.
    pub first: usize,
    /// Number of primitives.
    pub count: usize,
    /// Total area.
    pub area: f64,
    /// Cumulative primitive areas (normalised) for area sampling.
    pub cdf: Vec<f64>,
}

/// A light source the integrator can sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// The emitting object with this index.
    Area(usize),
    /// The constant environment.
    Environment,
}

/// A scene ready to render.
pub struct Scene {
    /// All primitives.
    pub shapes: Vec<Shape>,
    /// Object index of each primitive.
    pub prim_object: Vec<u32>,
    /// Objects.
    pub objects: Vec<Object>,
    /// Materials.
    pub materials: Vec<Material>,
    /// Acceleration structure over `shapes`.
    pub bvh: Bvh,
    /// Constant environment radiance (seen by rays that leave the scene).
    pub environment: Option<Rgb>,
    /// The lights, sampled uniformly for next-event estimation.
    pub lights: Vec<Light>,
    /// Light index of each object (`usize::MAX` if it does not emit).
    pub object_light: Vec<usize>,
    /// The camera.
    pub camera: Camera,
    /// Settings.
    pub settings: Settings,
    /// Whether any object has a mask (enables the alpha test in traversal).
    pub has_masks: bool,
}

/// Builds a [`Scene`] object by object.
pub struct SceneBuilder {
    shapes: Vec<Shape>,
    prim_object: Vec<u32>,
    objects: Vec<Object>,
    materials: Vec<Material>,
}

impl Default for SceneBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl SceneBuilder {
    /// An empty scene.
    pub fn new() -> Self {
        SceneBuilder {
            shapes: vec![],
            prim_object: vec![],
            objects: vec![],
            materials: vec![],
        }
    }
    /// Adds a material; returns its index.
    pub fn material(&mut self, m: Material) -> usize {
        self.materials.push(m);
        self.materials.len() - 1
    }
    /// Adds an object made of `shapes`.
    pub fn object(
        &mut self,
        name: &str,
        shapes: Vec<Shape>,
        material: usize,
        emission: Option<Rgb>,
        two_sided: bool,
        mask: Option<GreyTexture>,
    ) {
        let oi = self.objects.len() as u32;
        let first = self.shapes.len();
        let mut cdf = Vec::with_capacity(shapes.len());
        let mut acc = 0.0;
        for s in &shapes {
            acc += s.area();
            cdf.push(acc);
        }
        let area = acc;
        if area > 0.0 {
            for c in &mut cdf {
                *c /= area;
            }
        }
        let count = shapes.len();
        self.shapes.extend(shapes);
        self.prim_object.extend(std::iter::repeat_n(oi, count));
        self.objects.push(Object {
            name: name.to_string(),
            material,
            emission,
            two_sided,
            mask,
            first,
            count,
            area,
            cdf,
        });
    }
    /// The finished scene.
    pub fn build(self, camera: Camera, environment: Option<Rgb>, settings: Settings) -> Scene {
        let bvh = Bvh::build(&self.shapes);
        let mut lights = vec![];
        let mut object_light = vec![usize::MAX; self.objects.len()];
        for (i, o) in self.objects.iter().enumerate() {
            if o.emission.is_some_and(|e| !e.is_black()) && o.area > 0.0 {
                object_light[i] = lights.len();
                lights.push(Light::Area(i));
            }
        }
        if environment.is_some_and(|e| !e.is_black()) {
            lights.push(Light::Environment);
        }
        let has_masks = self.objects.iter().any(|o| o.mask.is_some());
        Scene {
            shapes: self.shapes,
            prim_object: self.prim_object,
            objects: self.objects,
            materials: self.materials,
            bvh,
            environment,
            lights,
            object_light,
            camera,
            settings,
            has_masks,
        }
    }
}

impl Scene {
    /// Whether the hit is on a solid part of its object (not in a hole of its mask).
    #[inline]
    fn solid(&self, pi: usize, ray: &Ray, h: &PrimHit) -> bool {
        let o = &self.objects[self.prim_object[pi] as usize];
        match &o.mask {
            None => true,
            Some(m) => {
                let uv = self.shapes[pi].uv(ray, h);
                m.eval(uv.x, uv.y) >= 0.5
            }
        }
    }

    /// The nearest solid hit along `ray`: primitive index and hit.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<(usize, PrimHit)> {
        if self.has_masks {
            self.bvh.intersect(&self.shapes, ray, |pi, r, h| self.solid(pi, r, h))
        } else {
            self.bvh.intersect(&self.shapes, ray, |_, _, _| true)
        }
    }

    /// Whether a solid surface lies on `ray` within `(0, t_max)`.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.has_masks {
            self.bvh.occluded(&self.shapes, ray, |pi, r, h| self.solid(pi, r, h))
        } else {
            self.bvh.occluded(&self.shapes, ray, |_, _, _| true)
        }
    }

    /// A stable 64-bit hash of the scene's settings seed (for the per-pixel generators).
    pub fn seed_hash(&self) -> u64 {
        mix64(self.settings.seed)
    }
}
