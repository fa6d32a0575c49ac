//! The tallies of the walk ([`Tally`]): per walk (or summed over a batch), the
//! next-event estimates of `f(wi, wo_j)` per viewing direction, the reflected
//! and transmitted flux (the totals `R`, `T` of [`crate::walk`]), the
//! collisions, the walks cut at the collision cap, and optionally `f` split by
//! the number of volume scattering events on the path.

/// Per-walk sums: BSDF contributions per target, reflected and transmitted flux.
#[derive(Clone, Debug, Default)]
pub struct Tally {
    /// Sum of next-event contributions to `f(wi, wo_j)` per requested `wo_j`.
    pub f: Vec<f64>,
    /// Flux that left through the lit face.
    pub r: f64,
    /// Flux that left through the other face.
    pub t: f64,
    /// Number of scattering events (collisions with scattering) in the walk(s).
    pub collisions: u64,
    /// Walks cut at the tracer's collision cap ([`super::Tracer::max_collisions`],
    /// [`super::MAX_COLLISIONS_PER_WALK`] by default). A cut walk ends there: its
    /// remaining flux (its weight at the cut, at most 1 each) is added to
    /// neither `r`, `t` nor `f`, so it is missing from every estimate.
    pub truncated: u64,
    /// When `Some`, the contributions to `f` split by the number of volume
    /// scattering events on the path: `[0, 1, 2 or more]` per viewing direction
    /// (0: surface reflection and unscattered light, including internal
    /// reflections; 1: single scattering; the rest: multiple scattering).
    pub by_order: Option<Vec<[f64; 3]>>,
    /// Scattering events so far in the current walk (set by the walk).
    pub(super) order: usize,
}

impl Tally {
    /// A zero tally for `n` viewing directions.
    pub fn new(n: usize) -> Self {
        Tally {
            f: vec![0.0; n],
            r: 0.0,
            t: 0.0,
            collisions: 0,
            truncated: 0,
            by_order: None,
            order: 0,
        }
    }
    /// Adds `o` into `self`.
    pub fn add(&mut self, o: &Tally) {
        for (a, b) in self.f.iter_mut().zip(&o.f) {
            *a += b;
        }
        self.r += o.r;
        self.t += o.t;
        self.collisions += o.collisions;
        self.truncated += o.truncated;
        if let (Some(a), Some(b)) = (self.by_order.as_mut(), o.by_order.as_ref()) {
            for (x, y) in a.iter_mut().zip(b) {
                for k in 0..3 {
                    x[k] += y[k];
                }
            }
        }
    }

    /// A zero tally for `n` viewing directions that also splits `f` by scattering order.
    pub fn with_orders(n: usize) -> Self {
        Tally {
            by_order: Some(vec![[0.0; 3]; n]),
            ..Tally::new(n)
        }
    }

    /// Resets every sum to zero (keeping the sizes).
    pub fn clear(&mut self) {
        self.f.iter_mut().for_each(|v| *v = 0.0);
        if let Some(b) = self.by_order.as_mut() {
            b.iter_mut().for_each(|v| *v = [0.0; 3]);
        }
        self.r = 0.0;
        self.t = 0.0;
        self.collisions = 0;
        self.truncated = 0;
        self.order = 0;
    }

    #[inline]
    pub(super) fn add_f(&mut self, j: usize, c: f64) {
        self.f[j] += c;
        if let Some(b) = self.by_order.as_mut() {
            b[j][self.order.min(2)] += c;
        }
    }
}
