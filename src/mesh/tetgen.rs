//! TetGen `.node` / `.ele` reader (0- or 1-based numbering, detected from the first node).

use super::parse::{prealloc, read_text, Line, Lines};
use super::{MeshError, MeshReport, TetMesh};
use crate::kernels::math::{Real, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The `.node` and `.ele` files of a TetGen mesh named by `path`: the `.node` file, the
/// `.ele` file, or their common base name (with or without a trailing dot).
pub(crate) fn tetgen_paths(path: &Path) -> (PathBuf, PathBuf) {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let base = if ext.eq_ignore_ascii_case("node") || ext.eq_ignore_ascii_case("ele") {
        path.with_extension("")
    } else {
        path.to_path_buf()
    };
    let mut node = base.clone().into_os_string();
    node.push(".node");
    let mut ele = base.into_os_string();
    ele.push(".ele");
    (PathBuf::from(node), PathBuf::from(ele))
}

/// Read the TetGen mesh named by `path` (see [`tetgen_paths`]), positions multiplied by `scale`.
pub(crate) fn read_tetgen(path: &Path, scale: Real) -> Result<(TetMesh, MeshReport), MeshError> {
    let (node_path, ele_path) = tetgen_paths(path);
    let (nodes, ids) = read_node_file(&node_path, scale)?;
    let tets = read_ele_file(&ele_path, &ids)?;
    TetMesh::from_raw(nodes, tets, &ele_path)
}

/// Parse a header count field.
fn count(fields: &mut super::parse::Fields<'_>, what: &str) -> Result<usize, MeshError> {
    fields.next::<usize>(what)
}

/// Error for a line beyond the declared count.
fn extra_line(line: &Line<'_>, declared: usize, what: &str) -> MeshError {
    line.error(format!(
        "more {what} than the {declared} declared in the header"
    ))
}

/// Read a `.node` file: positions (scaled) in file order and the map from point number to
/// file-order index.
fn read_node_file(path: &Path, scale: Real) -> Result<(Vec<Vec3>, HashMap<i64, u32>), MeshError> {
    let text = read_text(path)?;
    let mut lines = Lines::new(path, &text, Some('#'));
    let header = lines.expect_line("the .node header")?;
    let mut f = header.fields();
    let n = count(&mut f, "number of points")?;
    let dim = count(&mut f, "dimension")?;
    if dim != 3 {
        return Err(header.error(format!("dimension must be 3, got {dim}")));
    }
    if n == 0 {
        return Err(header.error("the .node file declares no points"));
    }
    let mut nodes = Vec::with_capacity(prealloc(n));
    let mut ids = HashMap::with_capacity(prealloc(n));
    for k in 0..n {
        let line = lines.expect_line(&format!("point {} of {n}", k + 1))?;
        let mut f = line.fields();
        let id: i64 = f.next("point number")?;
        if k == 0 && id != 0 && id != 1 {
            return Err(line.error(format!("the first point number must be 0 or 1, got {id}")));
        }
        let p = f.next_point(scale)?;
        if ids.insert(id, k as u32).is_some() {
            return Err(line.error(format!("duplicate point number {id}")));
        }
        nodes.push(p);
    }
    if let Some(line) = lines.next() {
        return Err(extra_line(&line, n, "points"));
    }
    Ok((nodes, ids))
}

/// Read a `.ele` file, translating point numbers to file-order node indices.
fn read_ele_file(path: &Path, ids: &HashMap<i64, u32>) -> Result<Vec<[u32; 4]>, MeshError> {
    let text = read_text(path)?;
    let mut lines = Lines::new(path, &text, Some('#'));
    let header = lines.expect_line("the .ele header")?;
    let mut f = header.fields();
    let n = count(&mut f, "number of tetrahedra")?;
    let per = count(&mut f, "nodes per tetrahedron")?;
    if per != 4 && per != 10 {
        return Err(header.error(format!("nodes per tetrahedron must be 4 or 10, got {per}")));
    }
    let mut tets = Vec::with_capacity(prealloc(n));
    for k in 0..n {
        let line = lines.expect_line(&format!("tetrahedron {} of {n}", k + 1))?;
        let mut f = line.fields();
        let _number: i64 = f.next("tetrahedron number")?;
        let mut tet = [0u32; 4];
        for (c, slot) in tet.iter_mut().enumerate() {
            let id: i64 = f.next(&format!("node {} of the tetrahedron", c + 1))?;
            *slot = *ids.get(&id).ok_or_else(|| {
                line.error(format!(
                    "point number {id} is not defined in the .node file"
                ))
            })?;
        }
        for c in 4..per {
            let _: i64 = f.next(&format!("node {} of the tetrahedron", c + 1))?;
        }
        tets.push(tet);
    }
    if let Some(line) = lines.next() {
        return Err(extra_line(&line, n, "tetrahedra"));
    }
    Ok(tets)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_from_any_form() {
        for p in ["a/m.node", "a/m.ele", "a/m"] {
            let (n, e) = tetgen_paths(Path::new(p));
            assert_eq!(n, PathBuf::from("a/m.node"));
            assert_eq!(e, PathBuf::from("a/m.ele"));
        }
    }
}
