//! Wavefront OBJ for render surfaces: `v`, `vt`, `vn` and `f` records with the index forms
//! `a`, `a/b`, `a//c` and `a/b/c` (negative indices relative), polygons fan-triangulated.
//! Other records (`g`, `s`, `usemtl`, ...) are ignored. Errors name the file and the line.

use super::mesh::{ObjVertex, RenderMesh};
use crate::kernels::math::{Real, Vec3};
use crate::mesh::parse::{check_scale, read_text, Line, Lines};
use crate::mesh::MeshError;
use std::collections::HashMap;
use std::io::{self, Write};
use std::path::Path;

/// One corner of a face as written: 0-based indices into the `v`, `vt`, `vn` records, with
/// relative indices resolved.
type Corner = (i64, Option<i64>, Option<i64>);

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

/// Parse one face corner `a`, `a/b`, `a//c` or `a/b/c`.
fn corner(line: &Line, r: &str, counts: [usize; 3]) -> Result<Corner, MeshError> {
    let mut parts = r.split('/');
    let v = resolve(line, parts.next().unwrap_or(""), "vertex", counts[0])?;
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

/// Read an OBJ render surface, positions multiplied by `scale` (mesh units → m; finite,
/// > 0). Normals are normalised; texture coordinates are kept as written (`u`, and `v` or 0).
pub fn read_obj(path: &Path, scale: Real) -> Result<RenderMesh, MeshError> {
    check_scale(path, scale)?;
    let text = read_text(path)?;
    let mut v: Vec<Vec3> = Vec::new();
    let mut vt: Vec<[Real; 2]> = Vec::new();
    let mut vn: Vec<Vec3> = Vec::new();
    let mut faces: Vec<(usize, Vec<Corner>)> = Vec::new();
    for line in Lines::new(path, &text, Some('#')) {
        let mut f = line.fields();
        match f.next_str("record type")? {
            "v" => v.push(f.next_point(scale)?),
            "vt" => {
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
            "vn" => {
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
                    .map(|r| corner(&line, r, counts))
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
    let mut mesh = RenderMesh {
        positions: Vec::new(),
        texcoords: Vec::new(),
        normals: Vec::new(),
        sources: Vec::new(),
        triangles: Vec::new(),
        has_texcoords: false,
    };
    let mut index: HashMap<ObjVertex, u32> = HashMap::new();
    for (number, face) in faces {
        let out_of_range = |what: &str, i: i64, n: usize| {
            MeshError::at(
                path,
                number,
                format!("{what} index {} is out of range: the file has {n}", i + 1),
            )
        };
        let mut ids = Vec::with_capacity(face.len());
        for (pv, pt, pn) in face {
            if pv >= v.len() as i64 {
                return Err(out_of_range("vertex", pv, v.len()));
            }
            if let Some(t) = pt.filter(|&t| t >= vt.len() as i64) {
                return Err(out_of_range("texture coordinate", t, vt.len()));
            }
            if let Some(n) = pn.filter(|&n| n >= vn.len() as i64) {
                return Err(out_of_range("normal", n, vn.len()));
            }
            let key = ObjVertex {
                position: pv as u32,
                texcoord: pt.map(|t| t as u32),
                normal: pn.map(|n| n as u32),
            };
            let id = *index.entry(key).or_insert_with(|| {
                mesh.positions.push(v[pv as usize]);
                mesh.texcoords.push(pt.map_or([0.0; 2], |t| vt[t as usize]));
                mesh.normals
                    .push(pn.map_or_else(Vec3::zeros, |n| vn[n as usize]));
                mesh.sources.push(key);
                mesh.has_texcoords |= pt.is_some();
                mesh.positions.len() as u32 - 1
            });
            ids.push(id);
        }
        for k in 1..ids.len() - 1 {
            mesh.triangles.push([ids[0], ids[k], ids[k + 1]]);
        }
    }
    Ok(mesh)
}

/// Write a render surface as OBJ: one `v` (m), `vt` (when `texcoords` is given) and `vn`
/// record per vertex, and `f a/a/a` (or `a//a`) per triangle, 1-based. Numbers are written in
/// Rust's shortest round-trip form: [`read_obj`] with scale 1 reads back the same positions
/// and texture coordinates bit for bit, and the normals to rounding (it renormalises them).
/// Array lengths must agree and indices be in range, else [`io::ErrorKind::InvalidInput`]
/// (checked before the file is created).
pub fn write_obj(
    path: &Path,
    positions: &[Vec3],
    normals: &[Vec3],
    texcoords: Option<&[[Real; 2]]>,
    triangles: &[[u32; 3]],
) -> io::Result<()> {
    let n = positions.len();
    let invalid = |m: String| Err(io::Error::new(io::ErrorKind::InvalidInput, m));
    if normals.len() != n || texcoords.is_some_and(|t| t.len() != n) {
        return invalid(format!(
            "{n} positions but {} normals and {:?} texture coordinates",
            normals.len(),
            texcoords.map(|t| t.len())
        ));
    }
    if let Some(t) = triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        return invalid(format!("triangle {t:?} out of range ({n} vertices)"));
    }
    let mut w = io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(
        w,
        "# tissuesim render surface: {n} vertices, {} triangles, metres",
        triangles.len()
    )?;
    for p in positions {
        writeln!(w, "v {:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    if let Some(t) = texcoords {
        for [u, v] in t {
            writeln!(w, "vt {u:?} {v:?}")?;
        }
    }
    for m in normals {
        writeln!(w, "vn {:?} {:?} {:?}", m.x, m.y, m.z)?;
    }
    for t in triangles {
        let [a, b, c] = t.map(|i| i + 1);
        if texcoords.is_some() {
            writeln!(w, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}")?;
        } else {
            writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
        }
    }
    w.flush()
}
