//! Wavefront OBJ reading, one parser for the two kinds of surface the library reads: tool
//! shapes ([`read_obj`]: positions and triangles) and render surfaces
//! ([`crate::render::read_obj`], which keeps the `v/vt/vn` triple of every corner). Records
//! `v`, `vt`, `vn` and `f` with the index forms `a`, `a/b`, `a//c` and `a/b/c` (negative
//! indices relative), polygons fan-triangulated; other records (`g`, `s`, `usemtl`, ...) are
//! ignored. Errors name the file and the line.

use super::parse::{read_text, Line, Lines};
use super::{MeshError, SurfaceMesh};
use crate::kernels::math::{Real, Vec3};
use std::path::Path;

/// One corner of a face as written: 0-based indices into the `v`, `vt`, `vn` records, with
/// relative indices resolved.
pub(crate) type Corner = (i64, Option<i64>, Option<i64>);

/// The records of an OBJ file that the readers use, every face's indices checked in range.
pub(crate) struct ObjRecords {
    /// `v` records, multiplied by the scale.
    pub(crate) v: Vec<Vec3>,
    /// `vt` records (`u`, and `v` or 0).
    pub(crate) vt: Vec<[Real; 2]>,
    /// `vn` records, normalised (zero if of zero length).
    pub(crate) vn: Vec<Vec3>,
    /// The faces (at least three corners each) with their line numbers.
    pub(crate) faces: Vec<(usize, Vec<Corner>)>,
}

/// Which records a reader wants beside `v` and `f`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Attributes {
    /// Positions only: `vt` and `vn` records are ignored, and so are the `/b/c` parts of face
    /// corners (a tool shape).
    Ignore,
    /// Texture coordinates and normals read, and every corner's references checked.
    Read,
}

/// Resolve one 1-based (or negative, relative) OBJ index of a `what` record, `defined` of
/// which are defined so far.
fn resolve(line: &Line, text: &str, what: &str, defined: usize) -> Result<i64, MeshError> {
    let i: i64 = text
        .parse()
        .map_err(|_| line.error(format!("invalid {what} index `{text}`")))?;
    match i {
        0 => Err(line.error(format!("{what} index 0 is invalid (OBJ is 1-based)"))),
        i if i > 0 => Ok(i - 1),
        i => {
            let r = defined as i64 + i;
            if r < 0 {
                Err(line.error(format!(
                    "relative {what} index {i} points before the first one ({defined} defined \
                     so far)"
                )))
            } else {
                Ok(r)
            }
        }
    }
}

/// Parse one face corner `a`, `a/b`, `a//c` or `a/b/c` (with [`Attributes::Ignore`], only `a`).
fn corner(
    line: &Line,
    r: &str,
    counts: [usize; 3],
    attributes: Attributes,
) -> Result<Corner, MeshError> {
    let mut parts = r.split('/');
    let v = resolve(line, parts.next().unwrap_or(""), "vertex", counts[0])?;
    if attributes == Attributes::Ignore {
        return Ok((v, None, None));
    }
    let vt = match parts.next() {
        None | Some("") => None,
        Some(t) => Some(resolve(line, t, "texture coordinate", counts[1])?),
    };
    let vn = match parts.next() {
        None | Some("") => None,
        Some(t) => Some(resolve(line, t, "normal", counts[2])?),
    };
    if parts.next().is_some() {
        return Err(line.error(format!("invalid face corner `{r}` (expected a/b/c)")));
    }
    Ok((v, vt, vn))
}

/// Read the records of the OBJ file at `path`, positions multiplied by `scale` (finite,
/// > 0). At least one vertex and one face; every face index in range.
pub(crate) fn read_records(
    path: &Path,
    scale: Real,
    attributes: Attributes,
) -> Result<ObjRecords, MeshError> {
    super::parse::check_scale(path, scale)?;
    let text = read_text(path)?;
    let mut v: Vec<Vec3> = Vec::new();
    let mut vt: Vec<[Real; 2]> = Vec::new();
    let mut vn: Vec<Vec3> = Vec::new();
    let mut faces: Vec<(usize, Vec<Corner>)> = Vec::new();
    let read = attributes == Attributes::Read;
    for line in Lines::new(path, &text, Some('#')) {
        let mut f = line.fields();
        match f.next_str("record type")? {
            "v" => v.push(f.next_point(scale)?),
            "vt" if read => {
                let u = f.next_real("texture coordinate u")?;
                let w = match f.rest().first() {
                    Some(s) => s
                        .parse::<Real>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| line.error(format!("invalid texture coordinate v `{s}`")))?,
                    None => 0.0,
                };
                vt.push([u, w]);
            }
            "vn" if read => {
                let n = f.next_point(1.0)?;
                vn.push(n.try_normalize(0.0).unwrap_or_else(Vec3::zeros));
            }
            "f" => {
                let refs = f.rest();
                if refs.len() < 3 {
                    return Err(line.error(format!(
                        "a face needs at least 3 vertices, found {}",
                        refs.len()
                    )));
                }
                let counts = [v.len(), vt.len(), vn.len()];
                let face = refs
                    .iter()
                    .map(|r| corner(&line, r, counts, attributes))
                    .collect::<Result<Vec<_>, _>>()?;
                faces.push((line.number, face));
            }
            _ => {}
        }
    }
    if v.is_empty() {
        return Err(MeshError::file(path, "no vertices (`v` records)"));
    }
    if faces.is_empty() {
        return Err(MeshError::file(path, "no faces (`f` records)"));
    }
    for (number, face) in &faces {
        let out_of_range = |what: &str, i: i64, n: usize| {
            MeshError::at(
                path,
                *number,
                format!("{what} index {} is out of range: the file has {n}", i + 1),
            )
        };
        for &(pv, pt, pn) in face {
            if pv >= v.len() as i64 {
                return Err(out_of_range("vertex", pv, v.len()));
            }
            if let Some(t) = pt.filter(|&t| t >= vt.len() as i64) {
                return Err(out_of_range("texture coordinate", t, vt.len()));
            }
            if let Some(n) = pn.filter(|&n| n >= vn.len() as i64) {
                return Err(out_of_range("normal", n, vn.len()));
            }
        }
    }
    Ok(ObjRecords { v, vt, vn, faces })
}

/// Read an OBJ surface (a tool shape), positions multiplied by `scale`: its `v` records and
/// its faces fan-triangulated; texture coordinates and normals are ignored.
pub(crate) fn read_obj(path: &Path, scale: Real) -> Result<SurfaceMesh, MeshError> {
    let records = read_records(path, scale, Attributes::Ignore)?;
    let mut triangles = Vec::new();
    for (_, face) in &records.faces {
        for k in 1..face.len() - 1 {
            triangles.push([face[0].0 as u32, face[k].0 as u32, face[k + 1].0 as u32]);
        }
    }
    Ok(SurfaceMesh {
        vertices: records.v,
        triangles,
    })
}
