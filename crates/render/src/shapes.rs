//! Geometry: rectangles (parallelograms), spheres and triangles, their ray
//! intersection, uniform area sampling, and a bounding volume hierarchy built
//! with the binned surface area heuristic (Wald 2007, "On fast construction of
//! SAH-based bounding volume hierarchies"; pbrt-v4 section 7.3).
//!
//! Triangles use the Moller-Trumbore test (1997). Rectangles follow Mitsuba 3's
//! convention: the unit shape is `[-1, 1]^2` in the local `xy` plane with normal
//! `+z`, `(u, v) = ((x + 1) / 2, (y + 1) / 2)`.

use crate::math::{Aabb, Ray};
use glam::{DVec2, DVec3};

/// One geometric primitive.
#[derive(Clone, Debug)]
pub enum Shape {
    /// The parallelogram `p0 + a eu + b ev`, `a, b` in [0, 1]; `(u, v) = (a, b)`.
    Rect {
        /// Corner at `(u, v) = (0, 0)`.
        p0: DVec3,
        /// Edge along `u`.
        eu: DVec3,
        /// Edge along `v`.
        ev: DVec3,
        /// Unit normal (the front side).
        n: DVec3,
        /// Dual of `eu` in the plane: `du . eu = 1`, `du . ev = 0`.
        du: DVec3,
        /// Dual of `ev`.
        dv: DVec3,
    },
    /// A sphere; its normal points outward. `(u, v) = (phi / 2 pi, theta / pi)`.
    Sphere {
        /// Centre.
        c: DVec3,
        /// Radius.
        r: f64,
    },
    /// A triangle with optional per-vertex shading normals and texture coordinates.
    Tri {
        /// First vertex.
        p0: DVec3,
        /// `p1 - p0`.
        e1: DVec3,
        /// `p2 - p0`.
        e2: DVec3,
        /// Per-vertex shading normals (unit), if the mesh has them.
        ns: Option<Box<[DVec3; 3]>>,
        /// Per-vertex texture coordinates, if the mesh has them.
        uv: Option<Box<[DVec2; 3]>>,
    },
}

/// Where a ray met a primitive, before the full surface record is built.
#[derive(Clone, Copy, Debug)]
pub struct PrimHit {
    /// Ray parameter.
    pub t: f64,
    /// First surface parameter (rectangle `a`, triangle barycentric `b1`, sphere unused).
    pub a: f64,
    /// Second surface parameter.
    pub b: f64,
}

/// The local geometry at a ray hit.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    /// Position.
    pub p: DVec3,
    /// Geometric normal (unit, front side of the primitive).
    pub ng: DVec3,
    /// Shading normal (unit, on the same side as `ng`).
    pub ns: DVec3,
    /// Texture coordinates.
    pub uv: DVec2,
}

impl Shape {
    /// A rectangle from its corner and two edges.
    pub fn rect(p0: DVec3, eu: DVec3, ev: DVec3, n: DVec3) -> Shape {
        let cu = ev.cross(n);
        let cv = n.cross(eu);
        Shape::Rect {
            p0,
            eu,
            ev,
            n,
            du: cu / cu.dot(eu),
            dv: cv / cv.dot(ev),
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        match self {
            Shape::Rect { p0, eu, ev, .. } => Aabb::EMPTY
                .grow(*p0)
                .grow(*p0 + *eu)
                .grow(*p0 + *ev)
                .grow(*p0 + *eu + *ev),
            Shape::Sphere { c, r } => Aabb {
                min: *c - DVec3::splat(*r),
                max: *c + DVec3::splat(*r),
            },
            Shape::Tri { p0, e1, e2, .. } => Aabb::EMPTY.grow(*p0).grow(*p0 + *e1).grow(*p0 + *e2),
        }
    }

    /// Surface area.
    pub fn area(&self) -> f64 {
        match self {
            Shape::Rect { eu, ev, .. } => eu.cross(*ev).length(),
            Shape::Sphere { r, .. } => 4.0 * std::f64::consts::PI * r * r,
            Shape::Tri { e1, e2, .. } => 0.5 * e1.cross(*e2).length(),
        }
    }

    /// The nearest hit in `(0, ray.t_max)`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<PrimHit> {
        match self {
            Shape::Rect { p0, n, du, dv, .. } => {
                let dn = ray.d.dot(*n);
                if dn == 0.0 {
                    return None;
                }
                let t = (*p0 - ray.o).dot(*n) / dn;
                if !(t > 0.0 && t < ray.t_max) {
                    return None;
                }
                let q = ray.at(t) - *p0;
                let (a, b) = (q.dot(*du), q.dot(*dv));
                if !(0.0..=1.0).contains(&a) || !(0.0..=1.0).contains(&b) {
                    return None;
                }
                Some(PrimHit { t, a, b })
            }
            Shape::Sphere { c, r } => {
                let oc = ray.o - *c;
                let b = oc.dot(ray.d);
                // Numerically stable discriminant (Hearn & Baker form, Ray Tracing Gems ch. 7).
                let f = oc - ray.d * b;
                let disc = r * r - f.length_squared();
                if disc < 0.0 {
                    return None;
                }
                let cc = oc.length_squared() - r * r;
                let q = -b - disc.sqrt().copysign(b);
                let (mut t0, mut t1) = (cc / q, q);
                if q == 0.0 {
                    t0 = 0.0;
                    t1 = 0.0;
                }
                if t0 > t1 {
                    std::mem::swap(&mut t0, &mut t1);
                }
                let t = if t0 > 0.0 && t0 < ray.t_max {
                    t0
                } else if t1 > 0.0 && t1 < ray.t_max {
                    t1
                } else {
                    return None;
                };
                Some(PrimHit { t, a: 0.0, b: 0.0 })
            }
            Shape::Tri { p0, e1, e2, .. } => {
                let pv = ray.d.cross(*e2);
                let det = e1.dot(pv);
                if det == 0.0 {
                    return None;
                }
                let inv = 1.0 / det;
                let tv = ray.o - *p0;
                let a = tv.dot(pv) * inv;
                if !(0.0..=1.0).contains(&a) {
                    return None;
                }
                let qv = tv.cross(*e1);
                let b = ray.d.dot(qv) * inv;
                if b < 0.0 || a + b > 1.0 {
                    return None;
                }
                let t = e2.dot(qv) * inv;
                if !(t > 0.0 && t < ray.t_max) {
                    return None;
                }
                Some(PrimHit { t, a, b })
            }
        }
    }

    /// The surface record of a hit found by [`Shape::intersect`].
    pub fn surface(&self, ray: &Ray, h: &PrimHit) -> SurfacePoint {
        match self {
            Shape::Rect { p0, eu, ev, n, .. } => SurfacePoint {
                p: *p0 + *eu * h.a + *ev * h.b,
                ng: *n,
                ns: *n,
                uv: DVec2::new(h.a, h.b),
            },
            Shape::Sphere { c, r } => {
                let mut p = ray.at(h.t);
                let n = ((p - *c) / *r).normalize();
                // Reproject onto the sphere to reduce the error of the hit point.
                p = *c + n * *r;
                let phi = n.y.atan2(n.x).rem_euclid(2.0 * std::f64::consts::PI);
                let theta = n.z.clamp(-1.0, 1.0).acos();
                SurfacePoint {
                    p,
                    ng: n,
                    ns: n,
                    uv: DVec2::new(phi / (2.0 * std::f64::consts::PI), theta / std::f64::consts::PI),
                }
            }
            Shape::Tri { p0, e1, e2, ns, uv } => {
                let (b1, b2) = (h.a, h.b);
                let b0 = 1.0 - b1 - b2;
                let ng = e1.cross(*e2).normalize();
                let mut nsh = match ns {
                    Some(v) => (v[0] * b0 + v[1] * b1 + v[2] * b2).normalize_or_zero(),
                    None => ng,
                };
                if nsh == DVec3::ZERO {
                    nsh = ng;
                }
                let ng = if ng.dot(nsh) < 0.0 { -ng } else { ng };
                let uvv = match uv {
                    Some(t) => t[0] * b0 + t[1] * b1 + t[2] * b2,
                    None => DVec2::new(b1, b2),
                };
                SurfacePoint {
                    p: *p0 + *e1 * b1 + *e2 * b2,
                    ng,
                    ns: nsh,
                    uv: uvv,
                }
            }
        }
    }

    /// Texture coordinates of a hit only (for cut-out masks during traversal).
    pub fn uv(&self, ray: &Ray, h: &PrimHit) -> DVec2 {
        match self {
            Shape::Rect { .. } => DVec2::new(h.a, h.b),
            Shape::Tri { uv: None, .. } => DVec2::new(h.a, h.b),
            _ => self.surface(ray, h).uv,
        }
    }

    /// A point drawn uniformly by area from `u`: `(position, geometric normal)`.
    pub fn sample_area(&self, u: [f64; 2]) -> (DVec3, DVec3) {
        match self {
            Shape::Rect { p0, eu, ev, n, .. } => (*p0 + *eu * u[0] + *ev * u[1], *n),
            Shape::Sphere { c, r } => {
                let w = paperbsdf_core::geometry::sample_uniform_sphere(u);
                (*c + w * *r, w)
            }
            Shape::Tri { p0, e1, e2, ns, .. } => {
                // Uniform barycentrics (pbrt-v4 SampleUniformTriangle, square-root map).
                let su = u[0].sqrt();
                let (b1, b2) = (1.0 - su, u[1] * su);
                let mut ng = e1.cross(*e2).normalize();
                if let Some(v) = ns {
                    let nsh = v[0] * (1.0 - b1 - b2) + v[1] * b1 + v[2] * b2;
                    if ng.dot(nsh) < 0.0 {
                        ng = -ng;
                    }
                }
                (*p0 + *e1 * b1 + *e2 * b2, ng)
            }
        }
    }
}

/// A node of the flattened BVH.
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    /// Leaf: first primitive index; interior: index of the second child (the first follows the node).
    offset: u32,
    /// Number of primitives (0 for an interior node).
    count: u16,
    /// Split axis of an interior node.
    axis: u8,
}

/// A bounding volume hierarchy over a list of shapes (binned SAH, 16 bins, leaves of up to 4).
#[derive(Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Primitive indices in leaf order.
    order: Vec<u32>,
}

struct BuildItem {
    bounds: Aabb,
    centre: DVec3,
    index: u32,
}

impl Bvh {
    /// Builds the hierarchy over `shapes`.
    pub fn build(shapes: &[Shape]) -> Bvh {
        let mut items: Vec<BuildItem> = shapes
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let b = s.bounds();
                BuildItem {
                    bounds: b,
                    centre: b.centre(),
                    index: i as u32,
                }
            })
            .collect();
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * shapes.len()),
            order: Vec::with_capacity(shapes.len()),
        };
        if !items.is_empty() {
            bvh.build_rec(&mut items[..]);
        }
        bvh
    }

    fn build_rec(&mut self, items: &mut [BuildItem]) -> usize {
        let bounds = items.iter().fold(Aabb::EMPTY, |b, it| b.union(it.bounds));
        let node_index = self.nodes.len();
        let make_leaf = |bvh: &mut Bvh, items: &[BuildItem]| {
            let first = bvh.order.len() as u32;
            bvh.order.extend(items.iter().map(|it| it.index));
            bvh.nodes.push(Node {
                bounds,
                offset: first,
                count: items.len() as u16,
                axis: 0,
            });
        };
        if items.len() <= 2 {
            make_leaf(self, items);
            return node_index;
        }
        let cb = items.iter().fold(Aabb::EMPTY, |b, it| b.grow(it.centre));
        let ext = cb.max - cb.min;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        if ext[axis] <= 0.0 {
            if items.len() <= 8 {
                make_leaf(self, items);
                return node_index;
            }
            // All centres coincide: split in the middle of the list.
            let mid = items.len() / 2;
            return self.push_interior(items, mid, bounds, axis as u8);
        }
        const BINS: usize = 16;
        let mut bin_b = [Aabb::EMPTY; BINS];
        let mut bin_n = [0usize; BINS];
        let bin_of = |c: DVec3| (((c[axis] - cb.min[axis]) / ext[axis] * BINS as f64) as usize).min(BINS - 1);
        for it in items.iter() {
            let k = bin_of(it.centre);
            bin_b[k] = bin_b[k].union(it.bounds);
            bin_n[k] += 1;
        }
        let mut best = (f64::INFINITY, 0usize);
        for split in 1..BINS {
            let (mut lb, mut ln, mut rb, mut rn) = (Aabb::EMPTY, 0, Aabb::EMPTY, 0);
            for k in 0..split {
                lb = lb.union(bin_b[k]);
                ln += bin_n[k];
            }
            for k in split..BINS {
                rb = rb.union(bin_b[k]);
                rn += bin_n[k];
            }
            if ln == 0 || rn == 0 {
                continue;
            }
            let cost = lb.area() * ln as f64 + rb.area() * rn as f64;
            if cost < best.0 {
                best = (cost, split);
            }
        }
        let leaf_cost = bounds.area() * items.len() as f64;
        // Traversal step costs about as much as one primitive test (pbrt-v4 uses 1/2).
        if items.len() <= 4 && best.0 + 0.5 * bounds.area() >= leaf_cost {
            make_leaf(self, items);
            return node_index;
        }
        let split = best.1;
        let mut mid = 0;
        for i in 0..items.len() {
            if bin_of(items[i].centre) < split {
                items.swap(i, mid);
                mid += 1;
            }
        }
        if mid == 0 || mid == items.len() {
            mid = items.len() / 2;
        }
        self.push_interior(items, mid, bounds, axis as u8)
    }

    fn push_interior(&mut self, items: &mut [BuildItem], mid: usize, bounds: Aabb, axis: u8) -> usize {
        let node_index = self.nodes.len();
        self.nodes.push(Node {
            bounds,
            offset: 0,
            count: 0,
            axis,
        });
        let (l, r) = items.split_at_mut(mid);
        self.build_rec(l);
        let second = self.build_rec(r);
        self.nodes[node_index].offset = second as u32;
        node_index
    }

    /// The nearest hit accepted by `accept(primitive, hit)` (cut-out masks reject hits).
    /// Returns the primitive index and the hit.
    #[inline]
    pub fn intersect(
        &self,
        shapes: &[Shape],
        ray: &Ray,
        accept: impl Fn(usize, &Ray, &PrimHit) -> bool,
    ) -> Option<(usize, PrimHit)> {
        self.traverse(shapes, ray, false, accept)
    }

    /// Whether any accepted hit lies within `(0, ray.t_max)`.
    #[inline]
    pub fn occluded(&self, shapes: &[Shape], ray: &Ray, accept: impl Fn(usize, &Ray, &PrimHit) -> bool) -> bool {
        self.traverse(shapes, ray, true, accept).is_some()
    }

    fn traverse(
        &self,
        shapes: &[Shape],
        ray: &Ray,
        any: bool,
        accept: impl Fn(usize, &Ray, &PrimHit) -> bool,
    ) -> Option<(usize, PrimHit)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut ray = *ray;
        let inv_d = DVec3::ONE / ray.d;
        let neg = [inv_d.x < 0.0, inv_d.y < 0.0, inv_d.z < 0.0];
        let mut best: Option<(usize, PrimHit)> = None;
        let mut stack = [0u32; 64];
        let mut sp = 0usize;
        let mut cur = 0usize;
        loop {
            let node = &self.nodes[cur];
            if node.bounds.hit(ray.o, inv_d, ray.t_max) {
                if node.count > 0 {
                    let first = node.offset as usize;
                    for &pi in &self.order[first..first + node.count as usize] {
                        let pi = pi as usize;
                        if let Some(h) = shapes[pi].intersect(&ray) {
                            if accept(pi, &ray, &h) {
                                ray.t_max = h.t;
                                best = Some((pi, h));
                                if any {
                                    return best;
                                }
                            }
                        }
                    }
                } else {
                    // Visit the near child first.
                    let (first, second) = if neg[node.axis as usize] {
                        (node.offset as usize, cur + 1)
                    } else {
                        (cur + 1, node.offset as usize)
                    };
                    stack[sp] = second as u32;
                    sp += 1;
                    cur = first;
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            cur = stack[sp] as usize;
        }
        best
    }
}
