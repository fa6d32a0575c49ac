//! Triangle meshes for scenes: Wavefront OBJ files (read with `tobj`, every
//! number checked finite) and the procedural folded sheet, with the transform
//! that places them.

use crate::error::RenderError;
use crate::math::Affine;
use crate::shapes::Shape;
use glam::{DVec2, DVec3};
use std::path::Path;

/// A folded sheet: `panels` strips of a `w x h` sheet, alternately tilted by `angle` out of the `xz` plane
/// (a zig-zag along `x`, `z` up), front facing `-y`, centred at the origin.
pub fn folded_sheet(w: f64, h: f64, panels: u32, angle_deg: f64) -> Vec<Shape> {
    let pw = w / panels as f64;
    let a = angle_deg.to_radians();
    let (dx, dy) = (pw * a.cos(), pw * a.sin());
    let total = dx * panels as f64;
    let mut out = vec![];
    for k in 0..panels {
        let x0 = -0.5 * total + dx * k as f64;
        let y0 = if k % 2 == 0 { 0.0 } else { dy };
        let y1 = if k % 2 == 0 { dy } else { 0.0 };
        let (u0, u1) = (k as f64 / panels as f64, (k + 1) as f64 / panels as f64);
        let p00 = DVec3::new(x0, y0, -0.5 * h);
        let p10 = DVec3::new(x0 + dx, y1, -0.5 * h);
        let p01 = DVec3::new(x0, y0, 0.5 * h);
        let p11 = DVec3::new(x0 + dx, y1, 0.5 * h);
        let tri = |a: DVec3, b: DVec3, c: DVec3, ta: DVec2, tb: DVec2, tc: DVec2| Shape::Tri {
            p0: a,
            e1: b - a,
            e2: c - a,
            ns: None,
            uv: Some(Box::new([ta, tb, tc])),
        };
        out.push(tri(
            p00,
            p10,
            p11,
            DVec2::new(u0, 0.0),
            DVec2::new(u1, 0.0),
            DVec2::new(u1, 1.0),
        ));
        out.push(tri(
            p00,
            p11,
            p01,
            DVec2::new(u0, 0.0),
            DVec2::new(u1, 1.0),
            DVec2::new(u0, 1.0),
        ));
    }
    out
}

/// The triangles of `shapes` through the transform `a` (other shapes unchanged).
pub fn transform_tris(shapes: Vec<Shape>, a: &Affine) -> Vec<Shape> {
    shapes
        .into_iter()
        .map(|s| match s {
            Shape::Tri { p0, e1, e2, ns, uv } => Shape::Tri {
                p0: a.point(p0),
                e1: a.vector(e1),
                e2: a.vector(e2),
                ns: ns.map(|n| Box::new([a.normal(n[0]), a.normal(n[1]), a.normal(n[2])])),
                uv,
            },
            other => other,
        })
        .collect()
}

/// Checks that every number of the OBJ file's `v`, `vn` and `vt` lines is
/// finite (tobj reads `nan` and `inf` as numbers); the error names the line.
fn check_obj_numbers(path: &Path) -> Result<(), RenderError> {
    let bytes = std::fs::read(path).map_err(|e| obj_load_error(path, e))?;
    let text = String::from_utf8_lossy(&bytes);
    for (i, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        let Some(kw @ ("v" | "vn" | "vt")) = it.next() else {
            continue;
        };
        for x in it {
            if let Ok(v) = x.parse::<f64>() {
                if !v.is_finite() {
                    return Err(RenderError::ObjNumber {
                        path: path.to_path_buf(),
                        line: i + 1,
                        keyword: kw.to_string(),
                        number: x.to_string(),
                    });
                }
            }
        }
    }
    Ok(())
}

fn obj_load_error(path: &Path, reason: impl std::fmt::Display) -> RenderError {
    RenderError::ObjLoad {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    }
}

/// The triangles of an OBJ file (all its objects, polygons triangulated, with
/// its normals and texture coordinates where every vertex has them) through the
/// transform `a`; triangles of zero area are left out.
pub fn load_obj(path: &Path, a: &Affine) -> Result<Vec<Shape>, RenderError> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    check_obj_numbers(path)?;
    let (models, _) = tobj::load_obj(path, &opts).map_err(|e| obj_load_error(path, e))?;
    let mut out = vec![];
    for m in &models {
        let mesh = &m.mesh;
        let nv = mesh.positions.len() / 3;
        let pos = |i: usize| {
            a.point(DVec3::new(
                mesh.positions[3 * i] as f64,
                mesh.positions[3 * i + 1] as f64,
                mesh.positions[3 * i + 2] as f64,
            ))
        };
        let has_n = mesh.normals.len() == mesh.positions.len();
        let has_uv = mesh.texcoords.len() / 2 == nv && nv > 0;
        for f in mesh.indices.chunks(3) {
            if f.len() < 3 {
                continue;
            }
            let idx = [f[0] as usize, f[1] as usize, f[2] as usize];
            if idx.iter().any(|&i| i >= nv) {
                return Err(RenderError::ObjFaceIndex {
                    path: path.to_path_buf(),
                    object: m.name.clone(),
                });
            }
            let (p0, p1, p2) = (pos(idx[0]), pos(idx[1]), pos(idx[2]));
            let (e1, e2) = (p1 - p0, p2 - p0);
            if e1.cross(e2).length_squared() == 0.0 {
                continue; // degenerate triangle: no area, never hit
            }
            let ns = has_n.then(|| {
                Box::new(idx.map(|i| {
                    a.normal(DVec3::new(
                        mesh.normals[3 * i] as f64,
                        mesh.normals[3 * i + 1] as f64,
                        mesh.normals[3 * i + 2] as f64,
                    ))
                }))
            });
            let uv = has_uv.then(|| {
                Box::new(idx.map(|i| DVec2::new(mesh.texcoords[2 * i] as f64, mesh.texcoords[2 * i + 1] as f64)))
            });
            out.push(Shape::Tri { p0, e1, e2, ns, uv });
        }
    }
    if out.is_empty() {
        return Err(RenderError::ObjEmpty {
            path: path.to_path_buf(),
        });
    }
    Ok(out)
}
