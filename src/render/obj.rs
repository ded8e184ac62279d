//! Wavefront OBJ for render surfaces: the reader keeps every distinct `v/vt/vn` corner triple
//! as one vertex, on the OBJ parser the tool shapes use too (`crate::mesh::obj`: records,
//! index forms, errors naming the file and the line); the writer writes what it reads back.

use super::mesh::{ObjVertex, RenderMesh};
use crate::kernels::math::{Real, Vec3};
use crate::mesh::obj::{read_records, Attributes, ObjRecords};
use crate::mesh::MeshError;
use std::collections::HashMap;
use std::io::{self, Write};
use std::path::Path;

/// Read an OBJ render surface, positions multiplied by `scale` (mesh units → m; finite,
/// > 0). Normals are normalised; texture coordinates are kept as written (`u`, and `v` or 0).
pub fn read_obj(path: &Path, scale: Real) -> Result<RenderMesh, MeshError> {
    let ObjRecords { v, vt, vn, faces } = read_records(path, scale, Attributes::Read)?;
    let mut mesh = RenderMesh {
        positions: Vec::new(),
        texcoords: Vec::new(),
        normals: Vec::new(),
        sources: Vec::new(),
        triangles: Vec::new(),
        has_texcoords: false,
    };
    let mut index: HashMap<ObjVertex, u32> = HashMap::new();
    for (_, face) in faces {
        let mut ids = Vec::with_capacity(face.len());
        for (pv, pt, pn) in face {
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
