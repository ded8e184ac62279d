//! Wavefront OBJ surface reader (tool shapes): `v` and `f` records, `f a/b/c` index forms,
//! negative (relative) indices, polygons fan-triangulated. Other records are ignored.

use super::parse::{read_text, Lines};
use super::{MeshError, SurfaceMesh};
use crate::kernels::math::Real;
use std::path::Path;

/// Read an OBJ surface, positions multiplied by `scale`.
pub(crate) fn read_obj(path: &Path, scale: Real) -> Result<SurfaceMesh, MeshError> {
    super::parse::check_scale(path, scale)?;
    let text = read_text(path)?;
    let mut vertices = Vec::new();
    // Faces as resolved 0-based indices (validated at the end) with their line number.
    let mut faces: Vec<(usize, Vec<i64>)> = Vec::new();
    for line in Lines::new(path, &text, Some('#')) {
        let mut f = line.fields();
        let tag = f.next_str("record type")?;
        match tag {
            "v" => vertices.push(f.next_point(scale)?),
            "f" => {
                let refs = f.rest();
                if refs.len() < 3 {
                    return Err(line.error(format!(
                        "a face needs at least 3 vertices, found {}",
                        refs.len()
                    )));
                }
                let mut face = Vec::with_capacity(refs.len());
                for r in refs {
                    let first = r.split('/').next().unwrap_or("");
                    let i: i64 = first
                        .parse()
                        .map_err(|_| line.error(format!("invalid vertex reference `{r}`")))?;
                    let resolved = match i {
                        0 => return Err(line.error("vertex index 0 is invalid (OBJ is 1-based)")),
                        i if i > 0 => i - 1,
                        i => {
                            // Relative: -1 is the last vertex defined so far.
                            let v = vertices.len() as i64 + i;
                            if v < 0 {
                                return Err(line.error(format!(
                                    "relative vertex index {i} points before the first vertex \
                                     ({} defined so far)",
                                    vertices.len()
                                )));
                            }
                            v
                        }
                    };
                    face.push(resolved);
                }
                faces.push((line.number, face));
            }
            _ => {}
        }
    }
    if vertices.is_empty() {
        return Err(MeshError::file(path, "no vertices (`v` records)"));
    }
    if faces.is_empty() {
        return Err(MeshError::file(path, "no faces (`f` records)"));
    }
    let n = vertices.len() as i64;
    let mut triangles = Vec::new();
    for (number, face) in faces {
        if let Some(&bad) = face.iter().find(|&&i| i >= n) {
            return Err(MeshError::at(
                path,
                number,
                format!(
                    "vertex index {} is out of range: the file has {n} vertices",
                    bad + 1
                ),
            ));
        }
        for k in 1..face.len() - 1 {
            triangles.push([face[0] as u32, face[k] as u32, face[k + 1] as u32]);
        }
    }
    Ok(SurfaceMesh {
        vertices,
        triangles,
    })
}
