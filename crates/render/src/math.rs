//! Small numeric building blocks of the renderer: rays, orthonormal frames,
//! bounding boxes, affine transforms and a PCG32 random number generator.
//!
//! PCG32 is O'Neill's "XSH RR" generator (pcg-random.org, the variant pbrt-v4
//! and Mitsuba 3 use); the seeding hash is SplitMix64's finaliser (Steele et al. 2014).

use glam::{DMat3, DVec3};
use paperbsdf_core::geometry::coordinate_system;

/// A ray `o + t d` with a valid parameter interval `(0, t_max)`.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin.
    pub o: DVec3,
    /// Direction (unit length).
    pub d: DVec3,
    /// Largest parameter that counts as a hit.
    pub t_max: f64,
}

impl Ray {
    /// A ray of unlimited length.
    pub fn new(o: DVec3, d: DVec3) -> Self {
        Ray {
            o,
            d,
            t_max: f64::INFINITY,
        }
    }
    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f64) -> DVec3 {
        self.o + self.d * t
    }
}

/// An orthonormal frame whose `z` axis is a given normal; converts world
/// directions to the BSDF's local frame (docs/design.md section 2: `+z` = front normal).
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// First tangent.
    pub s: DVec3,
    /// Second tangent.
    pub t: DVec3,
    /// Normal.
    pub n: DVec3,
}

impl Frame {
    /// A frame around the unit normal `n`, the tangents from
    /// [`paperbsdf_core::geometry::coordinate_system`] (Duff et al. 2017).
    pub fn from_normal(n: DVec3) -> Self {
        let (s, t) = coordinate_system(n);
        Frame { s, t, n }
    }
    /// World direction to local coordinates.
    #[inline]
    pub fn to_local(&self, v: DVec3) -> DVec3 {
        DVec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }
    /// Local direction to world coordinates.
    #[inline]
    pub fn to_world(&self, v: DVec3) -> DVec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug)]
pub struct Aabb {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Aabb {
    /// The empty box (union identity).
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };
    /// The union of two boxes.
    #[inline]
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }
    /// The box grown to hold `p`.
    #[inline]
    pub fn grow(self, p: DVec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }
    /// Centre of the box.
    #[inline]
    pub fn centre(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }
    /// Surface area (0 for an empty box).
    pub fn area(&self) -> f64 {
        let e = (self.max - self.min).max(DVec3::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
    /// Slab test: whether the ray meets the box within `(0, t_max)`; `inv_d` = 1 / direction.
    #[inline]
    pub fn hit(&self, o: DVec3, inv_d: DVec3, t_max: f64) -> bool {
        let t0 = (self.min - o) * inv_d;
        let t1 = (self.max - o) * inv_d;
        let tmin = t0.min(t1).max_element().max(0.0);
        let tmax = t0.max(t1).min_element().min(t_max);
        tmin <= tmax
    }
}

/// An affine transform `p -> m p + t` with its normal matrix (inverse transpose).
#[derive(Clone, Copy, Debug)]
pub struct Affine {
    /// Linear part.
    pub m: DMat3,
    /// Translation.
    pub t: DVec3,
}

impl Affine {
    /// The identity.
    pub const IDENTITY: Affine = Affine {
        m: DMat3::IDENTITY,
        t: DVec3::ZERO,
    };
    /// A point through the transform.
    pub fn point(&self, p: DVec3) -> DVec3 {
        self.m * p + self.t
    }
    /// A vector (no translation).
    pub fn vector(&self, v: DVec3) -> DVec3 {
        self.m * v
    }
    /// A normal (inverse transpose), normalised.
    pub fn normal(&self, n: DVec3) -> DVec3 {
        (self.m.inverse().transpose() * n).normalize()
    }
    /// `other` applied after `self`.
    pub fn then(&self, other: &Affine) -> Affine {
        Affine {
            m: other.m * self.m,
            t: other.m * self.t + other.t,
        }
    }
    /// Whether the linear part is invertible (a degenerate scale is an input error).
    pub fn is_invertible(&self) -> bool {
        let det = self.m.determinant();
        det.is_finite() && det.abs() > 1e-300
    }
}

/// SplitMix64's output function: a strong 64-bit mixing hash.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The PCG32 generator (64-bit LCG state, XSH-RR output).
#[derive(Clone, Debug)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

impl Pcg32 {
    const MULT: u64 = 6_364_136_223_846_793_005;
    /// A generator on stream `stream` from `seed` (pcg32_srandom_r).
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut r = Pcg32 {
            state: 0,
            inc: (stream << 1) | 1,
        };
        r.next_u32();
        r.state = r.state.wrapping_add(seed);
        r.next_u32();
        r
    }
    /// The next 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(Self::MULT).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }
    /// A uniform number in [0, 1).
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        self.next_u32() as f64 * (1.0 / 4_294_967_296.0)
    }
    /// Two uniform numbers in [0, 1).
    #[inline]
    pub fn next_2d(&mut self) -> [f64; 2] {
        [self.next_f64(), self.next_f64()]
    }
}

/// Power heuristic with exponent 2 (Veach 1997, section 9.2): weight of the strategy with density `a`.
#[inline]
pub fn power_heuristic(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 == 0.0 || !a2.is_finite() {
        if a.is_infinite() {
            return 1.0;
        }
        return 0.0;
    }
    a2 / (a2 + b2)
}
