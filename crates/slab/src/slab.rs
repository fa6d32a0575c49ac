//! The sheet as a stack: front face, medium, back face, per Fourier order
//! (the physical sheet of `paperbsdf_core::sheet`, air on both sides).
//!
//! **Faces of one index** (`eta_f = eta_b`): two grids, the outside grid
//! (air) and the medium's ([`Grid::inside`]); the sheet is
//! `front + medium + back flipped` (adding, [`crate::layer`]), both faces
//! projected between the outside grid and the medium's.
//!
//! **A coated front** (`eta_f != eta_b`): air | rough front interface
//! (air/coating, index `eta_f`) | a coating of zero thickness that neither
//! scatters nor absorbs | the smooth coating/base boundary (relative index
//! `eta_b / eta_f`) | the medium (the base, index `eta_b`) | the rough back
//! interface (base/air, index `eta_b`), as `paperbsdf_core::sheet` and the
//! simulator (`paperbsdf_sim`'s faces) have it. Three grids
//! ([`crate::quad`]): the outside grid, the coating's and the medium's; the
//! less dense of the two media gets [`Grid::inside`] of the outside grid and
//! the denser [`Grid::denser`] of that, so the boundary is diagonal
//! ([`crate::interface::smooth_boundary`]: Fresnel of the pair, the `n^2`
//! scaling of radiance, total reflection of the denser side's directions
//! beyond its critical angle) and the back face (and a smooth front) can be
//! projected between the outside grid and either inside grid. The front face
//! is projected between the outside grid and the coating's, the back face
//! between the outside grid and the medium's. The coating has no thickness,
//! so the front face and the boundary are simply added: the adding formula's
//! `(I - R_front,bot R_boundary,top)^-1` sums the interreflections inside the
//! coating. That coated front ([`Coating::front`]) depends on neither albedo
//! nor thickness, so [`SlabSpec::prepare`] adds it once; per order the sheet
//! is `coated front + medium + back flipped`. [`Prepared::faces`] keep the
//! bare faces: the front's `r_top` is the rough air/coating interface's
//! reflection from outside alone (what `crate::bsdf` replaces by the
//! analytic face), the boundary's contribution is in [`Prepared::coating`].

use crate::bsdf::MAX_ORDERS;
use crate::error::SlabError;
use crate::interface::{
    column_albedo, face_interface, smooth_boundary, walk_orders_for, Compensation, ProjectedFace, Projection,
    DEFAULT_AZIMUTH_POINTS,
};
use crate::layer::{default_start_thickness, medium_layer, medium_slope, Layer};
use crate::phase::{phase_fourier, validate, PhaseFourier};
use crate::quad::Grid;
use paperbsdf_core::dielectric::{Interface, ETA_RANGE, M_RANGE};
use paperbsdf_core::phase::TwoLobeHg;
use paperbsdf_core::{Distribution, FaceScattering, PaperParams, ParamError, RoughDielectric, Sheet};
use rayon::prelude::*;

/// The scattering medium between the faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    /// Single-scattering albedo `sigma_s / sigma_t`, in `[0, 1]`.
    pub albedo: f64,
    /// Optical thickness `sigma_t d`, in `[0, inf)`.
    pub tau: f64,
    /// The two-lobe Henyey-Greenstein phase function (`|g| < 1` for both lobes).
    pub phase: TwoLobeHg,
}

/// A face of the sheet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Face {
    /// A smooth Fresnel interface to air of relative index `eta` in `[1, 5]`
    /// (1: no interface).
    Smooth {
        /// Relative index (the medium, or a front's coating, over air).
        eta: f64,
    },
    /// A rough interface (core's [`RoughDielectric`]): relative index `eta`
    /// in `[1, 5]`, roughness `m` in `[0, pi/2]` (below
    /// `paperbsdf_core::dielectric::M_SMOOTH` it is smooth), distribution
    /// `dist`, scattering once among its microfacets (Walter et al. 2007) or
    /// with core's energy compensation (`scattering`; [`crate::interface`]).
    Rough {
        /// Relative index (the medium, or a front's coating, over air).
        eta: f64,
        /// Microfacet roughness (alpha).
        m: f64,
        /// Microfacet distribution.
        dist: Distribution,
        /// `face_scattering` of docs/design.md 3.
        scattering: FaceScattering,
    },
}

impl Face {
    /// The face's relative index.
    pub fn eta(&self) -> f64 {
        match *self {
            Face::Smooth { eta } | Face::Rough { eta, .. } => eta,
        }
    }
    /// The face as core's rough dielectric and its scattering mode (a smooth
    /// face is a `RoughDielectric` with `m = 0`); errors name the parameters
    /// with `suffix` (`"_f"`, `"_b"`).
    pub fn dielectric(&self, suffix: &str) -> Result<(RoughDielectric, FaceScattering), SlabError> {
        let (eta, m, dist, fs) = match *self {
            Face::Smooth { eta } => (eta, 0.0, Distribution::Ggx, FaceScattering::Single),
            Face::Rough {
                eta,
                m,
                dist,
                scattering,
            } => (eta, m, dist, scattering),
        };
        ParamError::check_range(&format!("m{suffix}"), m, M_RANGE.0, M_RANGE.1)?;
        let bd = RoughDielectric::new(dist, eta, m).map_err(|e| e.with_suffix(suffix))?;
        Ok((bd, fs))
    }
    /// The face of `sheet` on the back (`back = true`) or front, as [`Face::Rough`].
    pub fn of_sheet(sheet: &Sheet, back: bool) -> Face {
        let bd = sheet.face(back);
        Face::Rough {
            eta: bd.eta,
            m: bd.m,
            dist: bd.dist,
            scattering: sheet.face_scattering,
        }
    }
}

/// The sheet to solve: a medium between a front face (top, `+z`) and a back
/// face; when their indices differ the front face is over a coating of its
/// index (module doc), the medium has the back face's index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabSpec {
    /// The medium.
    pub medium: Medium,
    /// The front face (light from `+z` meets it first).
    pub front: Face,
    /// The back face.
    pub back: Face,
}

/// Most nodes per hemisphere outside, and in a cone of total internal
/// reflection, that a solve takes ([`Discretisation::nodes`],
/// [`Discretisation::tir_nodes`]): every order solves dense systems on
/// all the nodes of a sheet's grids (a face's walk on twice as many): at
/// 1024 outside nodes one outside-by-outside matrix of one order is 8 MB.
/// A larger request is refused with an error rather than exhausting the
/// memory (and `SlabBsdf`'s node guide keeps intervals in 16 bits).
pub const MAX_NODES: usize = 1024;

/// How finely the solver discretises.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Discretisation {
    /// Gauss-Radau nodes per hemisphere outside (air), 2 to [`MAX_NODES`]; the inside
    /// grid has as many in the cone that refracts out ([`crate::quad`]).
    pub nodes: usize,
    /// Gauss-Legendre nodes in each cone of total internal reflection, 1
    /// to [`MAX_NODES`]: the inside grid's cone beyond the air's critical angle (when
    /// the medium's index exceeds 1) and, for a coated sheet, the denser
    /// medium's cone beyond the coating/base boundary's critical angle
    /// ([`Grid::denser`]).
    pub tir_nodes: usize,
    /// Fourier orders `0..orders` in azimuth, at least 1 (totals need only order 0).
    pub orders: usize,
    /// Thickness of the starting layer before doubling; `None` for
    /// [`default_start_thickness`].
    pub start_thickness: Option<f64>,
    /// Gauss-Legendre points per panel of the azimuth rule that projects
    /// rough faces ([`crate::interface`]), 2 to 64; default 8.
    pub azimuth_points: usize,
    /// Whether rough faces are normalised to core's directional albedo
    /// ([`crate::interface`]); default `true`.
    pub normalise_faces: bool,
    /// Fourier orders of the walk's reflection from outside of
    /// `"multiple"` rough faces ([`crate::interface::ProjectedFace::walk_r_top`]);
    /// 0 (the default) for none, as for a totals-only solve.
    pub walk_orders: usize,
}

impl Default for Discretisation {
    fn default() -> Self {
        Discretisation {
            nodes: 32,
            tir_nodes: 16,
            orders: 1,
            start_thickness: None,
            azimuth_points: DEFAULT_AZIMUTH_POINTS,
            normalise_faces: true,
            walk_orders: 0,
        }
    }
}

/// Which face the light arrives at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// From above (`+z`), onto the front face.
    Front,
    /// From below, onto the back face.
    Back,
}

/// The solved stack: per Fourier order, the sheet's matrices between the
/// outside grids above and below (both [`Solution::outside`]).
#[derive(Clone, Debug)]
pub struct Solution {
    /// The grid in air on either side of the sheet.
    pub outside: Grid,
    /// The grid inside the medium (the base: index `eta_b`).
    pub inside: Grid,
    /// The coating's grid (index `eta_f`) of a coated sheet (`eta_f != eta_b`), `None` otherwise.
    pub coating: Option<Grid>,
    /// The sheet's layer per Fourier order.
    pub orders: Vec<Layer>,
    /// The medium layer alone for each order (inside grid).
    pub medium: Vec<Layer>,
    /// Doublings used for the medium.
    pub doublings: u32,
    /// The phase function's normalisation factors ([`crate::phase::PhaseFourier::scale`]).
    pub phase_scale: Vec<f64>,
    /// The compensation of the front and back faces (`"multiple"` rough faces; [`crate::interface`]).
    pub face_compensation: [Option<Compensation>; 2],
}

impl SlabSpec {
    /// The sheet of `p` (docs/design.md 3; `paperbsdf_core::sheet`) in colour
    /// channel `channel` (0 to 2; a scalar parameter is the same in every
    /// channel): albedo `sigma_s / sigma_t` (0 when `sigma_t = 0`),
    /// `tau = sigma_t d`, rough faces as [`Face::of_sheet`] (the front face
    /// has index `eta_f`, the back face `eta_b`; when they differ the sheet
    /// has the front coating of the module doc).
    pub fn from_params(p: &PaperParams, channel: usize) -> Result<SlabSpec, SlabError> {
        if channel > 2 {
            return Err(SlabError::Discretisation {
                name: "channel",
                value: channel as f64,
                range: "0, 1 or 2",
            });
        }
        let sheet = Sheet::from_params(p)?;
        let (sa, ss) = (sheet.sigma_a.0[channel], sheet.sigma_s.0[channel]);
        let st = sa + ss;
        let spec = SlabSpec {
            medium: Medium {
                albedo: if st > 0.0 { ss / st } else { 0.0 },
                tau: st * sheet.d,
                phase: sheet.phase,
            },
            front: Face::of_sheet(&sheet, false),
            back: Face::of_sheet(&sheet, true),
        };
        spec.validate()?;
        Ok(spec)
    }

    /// Checks every parameter (ranges named in the messages).
    pub fn validate(&self) -> Result<(), SlabError> {
        ParamError::check_range("albedo", self.medium.albedo, 0.0, 1.0)?;
        ParamError::check_range("tau", self.medium.tau, 0.0, 1e12)?;
        validate(&self.medium.phase)?;
        ParamError::check_range("eta_f", self.front.eta(), ETA_RANGE.0, ETA_RANGE.1)?;
        ParamError::check_range("eta_b", self.back.eta(), ETA_RANGE.0, ETA_RANGE.1)?;
        self.front.dielectric("_f")?;
        self.back.dielectric("_b")?;
        Ok(())
    }

    /// Solves the sheet with discretisation `disc`: Fourier orders in parallel.
    pub fn solve(&self, disc: &Discretisation) -> Result<Solution, SlabError> {
        self.prepare(disc)?.solve(self.medium.albedo, self.medium.tau)
    }

    /// Everything of a solve that does not depend on the medium's albedo and
    /// optical thickness: the grids, the phase function's Fourier
    /// coefficients and the faces projected on the grids (the costly part of
    /// a solve with rough faces), and for a coated sheet the coating
    /// (module doc). [`Prepared::solve`] then solves the sheet for any albedo
    /// and thickness (one call per colour channel).
    pub fn prepare(&self, disc: &Discretisation) -> Result<Prepared, SlabError> {
        self.validate()?;
        if !(2..=MAX_NODES).contains(&disc.nodes) {
            return Err(SlabError::Discretisation {
                name: "nodes",
                value: disc.nodes as f64,
                range: "[2, 1024]",
            });
        }
        if !(1..=MAX_NODES).contains(&disc.tir_nodes) {
            return Err(SlabError::Discretisation {
                name: "tir_nodes",
                value: disc.tir_nodes as f64,
                range: "[1, 1024]",
            });
        }
        let outside = Grid::outside(disc.nodes);
        let (eta_f, eta_b) = (self.front.eta(), self.back.eta());
        let n_tir = disc.tir_nodes;
        // The coating's grid (if any) and the medium's (module doc): the less
        // dense medium's from the outside grid, the denser one's from that.
        let (coat_grid, inside) = if eta_f == eta_b {
            (None, Grid::inside(&outside, eta_b, n_tir))
        } else if eta_f < eta_b {
            let coat = Grid::inside(&outside, eta_f, n_tir);
            let inside = Grid::denser(&coat, eta_b, n_tir);
            (Some(coat), inside)
        } else {
            let inside = Grid::inside(&outside, eta_b, n_tir);
            (Some(Grid::denser(&inside, eta_f, n_tir)), inside)
        };
        let phase = phase_fourier(&self.medium.phase, &inside, disc.orders)?;
        let start = disc.start_thickness.unwrap_or_else(|| default_start_thickness(&inside));
        let project = |face: &Face, suffix: &str, below: &Grid| -> Result<ProjectedFace, SlabError> {
            let (bd, fs) = face.dielectric(suffix)?;
            // Smoother faces' walks to more orders (`walk_orders_for`).
            let walk_orders = match bd.interface {
                Interface::Rough(mf) => walk_orders_for(disc.walk_orders, mf.alpha, MAX_ORDERS),
                _ => disc.walk_orders,
            };
            let proj = Projection {
                orders: disc.orders,
                azimuth_points: disc.azimuth_points,
                normalise: disc.normalise_faces,
                walk_orders,
            };
            face_interface(&bd, fs, &outside, below, &proj)
        };
        // Two different faces are projected at the same time: each
        // projection's serial steps (the normalisation's scaling, the
        // orders' assembly) leave a core idle that the other fills.
        let (front, back) = if self.back == self.front {
            let front = project(&self.front, "_f", coat_grid.as_ref().unwrap_or(&inside))?;
            (front.clone(), front)
        } else {
            let (front, back) = rayon::join(
                || project(&self.front, "_f", coat_grid.as_ref().unwrap_or(&inside)),
                || project(&self.back, "_b", &inside),
            );
            (front?, back?)
        };
        let coating = match coat_grid {
            None => None,
            Some(grid) => {
                let boundary = smooth_boundary(&grid, &inside)?;
                let coated = front
                    .orders
                    .iter()
                    .map(|l| l.add(&boundary))
                    .collect::<Result<Vec<Layer>, SlabError>>()?;
                Some(Coating {
                    grid,
                    boundary,
                    front: coated,
                })
            }
        };
        Ok(Prepared {
            outside,
            inside,
            phase,
            start,
            orders: disc.orders,
            faces: [front, back],
            coating,
        })
    }
}

/// The front coating of a coated sheet (`eta_f != eta_b`; module doc), on
/// the coating's grid between the front face and the medium.
#[derive(Clone, Debug)]
pub struct Coating {
    /// The coating's grid (index `eta_f`; [`crate::quad`]).
    pub grid: Grid,
    /// The smooth coating/base boundary (coating's grid on top, the
    /// medium's below; the same in every Fourier order):
    /// [`crate::interface::smooth_boundary`].
    pub boundary: Layer,
    /// Per Fourier order, the front face added to the boundary: the coated
    /// front between the outside grid and the medium's grid, the
    /// interreflections inside the coating summed.
    pub front: Vec<Layer>,
}

/// The medium-independent part of a solve ([`SlabSpec::prepare`]).
#[derive(Clone, Debug)]
pub struct Prepared {
    /// The grid in air on either side of the sheet.
    pub outside: Grid,
    /// The grid inside the medium (the base: index `eta_b`).
    pub inside: Grid,
    /// The phase function's Fourier coefficients on the inside grid.
    pub phase: PhaseFourier,
    /// Thickness of the starting layer before doubling.
    pub start: f64,
    /// Fourier orders `0..orders`.
    pub orders: usize,
    /// The front and back faces projected on the grids (air on top, the
    /// coating's grid (coated sheet) or the medium's below for the front,
    /// the medium's below for the back, whose layer is used flipped). A
    /// coated front's layer is the rough air/coating interface alone: its
    /// `r_top` is that interface's reflection from outside, without the
    /// coating/base boundary.
    pub faces: [ProjectedFace; 2],
    /// The coating of a coated sheet (`eta_f != eta_b`), `None` otherwise.
    pub coating: Option<Coating>,
}

impl Prepared {
    /// Solves the sheet for a medium of single-scattering albedo `albedo` in
    /// `[0, 1]` and optical thickness `tau` (the grids, phase function and
    /// faces (and coating) of [`SlabSpec::prepare`]): Fourier orders in parallel.
    pub fn solve(&self, albedo: f64, tau: f64) -> Result<Solution, SlabError> {
        let solved: Vec<(Layer, Layer, u32)> = (0..self.orders)
            .into_par_iter()
            .map(|m| {
                let (med, k) = medium_layer(&self.inside, &self.phase, m, albedo, tau, self.start)?;
                let med = med.into_layer();
                let sheet = self.top(m).add(&med)?.add(&self.faces[1].orders[m].flipped())?;
                Ok((sheet, med, k))
            })
            .collect::<Result<_, SlabError>>()?;
        let doublings = solved.first().map_or(0, |s| s.2);
        let (orders, medium): (Vec<Layer>, Vec<Layer>) = solved.into_iter().map(|(a, b, _)| (a, b)).unzip();
        Ok(self.solution(orders, medium, doublings))
    }

    /// The layer above the medium in order `m`: the front face, or a coated
    /// front's rough interface over its coating.
    fn top(&self, m: usize) -> &Layer {
        match &self.coating {
            Some(c) => &c.front[m],
            None => &self.faces[0].orders[m],
        }
    }

    /// A solution on these grids from its orders and medium layers.
    fn solution(&self, orders: Vec<Layer>, medium: Vec<Layer>, doublings: u32) -> Solution {
        let [front, back] = &self.faces;
        Solution {
            outside: self.outside.clone(),
            inside: self.inside.clone(),
            coating: self.coating.as_ref().map(|c| c.grid.clone()),
            orders,
            medium,
            doublings,
            phase_scale: self.phase.scale.clone(),
            face_compensation: [front.compensation.clone(), back.compensation.clone()],
        }
    }

    /// The sheet without scattering (the same as [`Prepared::solve`] with
    /// albedo 0, to the last bit) and its slope in the albedo at 0, per unit
    /// albedo: `dS/da`, whose product with the albedo is the light
    /// scattered once in the medium, with every face interaction around it
    /// (crate::layer, "First order"). Returned as two solutions on the same
    /// grids; the slope's `medium` is the medium's slope.
    pub fn solve_first_order(&self, tau: f64) -> Result<(Solution, Solution), SlabError> {
        let solved: Vec<[Layer; 4]> = (0..self.orders)
            .into_par_iter()
            .map(|m| {
                let (med, _) = medium_layer(&self.inside, &self.phase, m, 0.0, tau, self.start)?;
                let med = med.into_layer();
                let d_med = medium_slope(&self.inside, &self.phase, m, tau, self.start)?.into_layer();
                let top = self.top(m);
                let flat = |l: &Layer| Layer::zero_slope(l.n_top(), l.n_bot());
                let (upper, d_upper) = top.add_with_slope(&flat(top), &med, &d_med)?;
                let bottom = self.faces[1].orders[m].flipped();
                let (sheet, d_sheet) = upper.add_with_slope(&d_upper, &bottom, &flat(&bottom))?;
                Ok([sheet, med, d_sheet, d_med])
            })
            .collect::<Result<_, SlabError>>()?;
        let mut parts: [Vec<Layer>; 4] = Default::default();
        for layers in solved {
            for (v, l) in parts.iter_mut().zip(layers) {
                v.push(l);
            }
        }
        let [orders, medium, d_orders, d_medium] = parts;
        Ok((self.solution(orders, medium, 0), self.solution(d_orders, d_medium, 0)))
    }
}

impl Solution {
    /// Order 0's reflection and transmission for light arriving at `side`.
    fn rt0(&self, side: Side) -> (&nalgebra::DMatrix<f64>, &nalgebra::DMatrix<f64>) {
        let l = &self.orders[0];
        match side {
            Side::Front => (&l.r_top, &l.t_down),
            Side::Back => (&l.r_bot, &l.t_up),
        }
    }
    /// Total reflectance and transmittance (everything that leaves, mirror
    /// reflection and unscattered light included) for collimated light at
    /// outside node `j` arriving at `side`: `sum_o w_o mu_o K[o][j] / (w_j mu_j)`.
    /// A rough lit face's split between its own reflection and what enters
    /// is the projection's (crate::interface, "Quadrature in `mu` and
    /// normalisation": within 1.1e-3 of core's for paper-like faces,
    /// tests/rough_face.rs; more for a face smoother than the grid at grazing
    /// incidence: thin tissue with GGX 0.001 faces reflects 0.856 at 86.9
    /// degrees here, the smooth sheet 0.841, a probe's numbers), which the
    /// `slab` model's BSDF replaces by the analytic lobe (0.842 for that
    /// sheet; tests/smooth_faces.rs checks such sheets against the smooth
    /// one).
    pub fn totals_collimated(&self, side: Side, j: usize) -> (f64, f64) {
        let g = &self.outside;
        let (r, t) = self.rt0(side);
        (column_albedo(r, g, g, j), column_albedo(t, g, g, j))
    }
    /// Totals for collimated light at normal incidence (the Radau node `mu = 1`).
    pub fn totals_normal(&self, side: Side) -> (f64, f64) {
        self.totals_collimated(side, self.outside.len() - 1)
    }
    /// Totals for diffuse light (uniform radiance over the hemisphere) arriving at `side`.
    pub fn totals_diffuse(&self, side: Side) -> (f64, f64) {
        let g = &self.outside;
        let (r, t) = self.rt0(side);
        let flux = |k: &nalgebra::DMatrix<f64>| -> f64 {
            let mut s = 0.0;
            for o in 0..g.len() {
                for j in 0..g.len() {
                    s += g.w[o] * g.mu[o] * k[(o, j)];
                }
            }
            2.0 * s
        };
        (flux(r), flux(t))
    }
    /// The sheet's BSDF `f` (without cosine, radiance transport) between
    /// outside nodes: light arriving at `side` from node `j`, leaving by
    /// reflection (`transmit = false`) or transmission from node `o`, at
    /// azimuth difference `phi` (radians, between the propagation directions:
    /// `phi = 0` is forward scattering in the plane of incidence), summed over
    /// the solved orders: `f = sum_m (2 - [m = 0]) / (2 pi) K_m[o][j] cos(m phi) / (w_j mu_j)`.
    /// Delta parts (mirror reflection, unscattered light) sit on the diagonal
    /// `o = j` as finite values of the discretisation, not as BSDF values.
    pub fn bsdf_at_nodes(&self, side: Side, transmit: bool, o: usize, j: usize, phi: f64) -> f64 {
        let g = &self.outside;
        let mut f = 0.0;
        for (m, l) in self.orders.iter().enumerate() {
            let k = match (side, transmit) {
                (Side::Front, false) => &l.r_top,
                (Side::Front, true) => &l.t_down,
                (Side::Back, false) => &l.r_bot,
                (Side::Back, true) => &l.t_up,
            };
            let eps = if m == 0 { 1.0 } else { 2.0 };
            f += eps * k[(o, j)] * (m as f64 * phi).cos();
        }
        f / (2.0 * std::f64::consts::PI * g.w[j] * g.mu[j])
    }
}
