//! Gmsh `.msh` reader: legacy v1 (`$NOD` / `$ELM`), 2.2 ASCII and 4.1 ASCII. Linear
//! tetrahedra (element type 4) are kept; other elements are skipped and counted. Node ids may
//! be arbitrary and non-contiguous; nodes keep their file order.

use super::parse::{prealloc, read_text, Line, Lines};
use super::{MeshError, MeshReport, TetMesh};
use crate::kernels::math::{Real, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// Gmsh element type of the 4-node tetrahedron.
const GMSH_TET: u32 = 4;

/// Number of nodes of the Gmsh element types this reader knows (0 when unknown).
fn nodes_per_element(kind: u32) -> usize {
    match kind {
        1 => 2,   // line
        2 => 3,   // triangle
        3 => 4,   // quadrangle
        4 => 4,   // tetrahedron
        5 => 8,   // hexahedron
        6 => 6,   // prism
        7 => 5,   // pyramid
        8 => 3,   // second-order line
        9 => 6,   // second-order triangle
        10 => 9,  // second-order quadrangle
        11 => 10, // second-order tetrahedron
        15 => 1,  // point
        _ => 0,
    }
}

/// The nodes and tetrahedra read so far.
#[derive(Default)]
struct Raw {
    nodes: Vec<Vec3>,
    ids: HashMap<i64, u32>,
    tets: Vec<[u32; 4]>,
    skipped: usize,
    saw_nodes: bool,
    saw_elements: bool,
}

impl Raw {
    fn add_node(&mut self, line: &Line<'_>, id: i64, p: Vec3) -> Result<(), MeshError> {
        if self.ids.insert(id, self.nodes.len() as u32).is_some() {
            return Err(line.error(format!("duplicate node id {id}")));
        }
        self.nodes.push(p);
        Ok(())
    }

    fn node(&self, line: &Line<'_>, id: &str) -> Result<u32, MeshError> {
        let v: i64 = id
            .parse()
            .map_err(|_| line.error(format!("invalid node id `{id}`")))?;
        self.ids
            .get(&v)
            .copied()
            .ok_or_else(|| line.error(format!("node id {v} is not defined in the node section")))
    }

    fn tet(&self, line: &Line<'_>, ids: &[&str]) -> Result<[u32; 4], MeshError> {
        if ids.len() != 4 {
            return Err(line.error(format!(
                "a tetrahedron needs 4 node ids, found {}",
                ids.len()
            )));
        }
        Ok([
            self.node(line, ids[0])?,
            self.node(line, ids[1])?,
            self.node(line, ids[2])?,
            self.node(line, ids[3])?,
        ])
    }
}

/// The Gmsh dialect of a file.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Version {
    V1,
    V2,
    V41,
}

/// Read a Gmsh mesh, positions multiplied by `scale`.
pub(crate) fn read_gmsh(path: &Path, scale: Real) -> Result<(TetMesh, MeshReport), MeshError> {
    let text = read_text(path)?;
    let mut lines = Lines::new(path, &text, None);
    let mut raw = Raw::default();
    let first = lines.expect_line("`$MeshFormat` or `$NOD`")?;
    let version = match first.text {
        "$MeshFormat" => {
            let l = lines.expect_line("the mesh format line")?;
            let mut f = l.fields();
            let v = f.next_str("format version")?;
            let version = if v.starts_with("2.") || v == "2" {
                Version::V2
            } else if v == "4.1" {
                Version::V41
            } else {
                return Err(l.error(format!(
                    "unsupported Gmsh format version {v} (supported: 1, 2.x and 4.1 ASCII)"
                )));
            };
            let file_type: u32 = f.next("file type")?;
            if file_type != 0 {
                return Err(l.error("binary Gmsh files are not supported (file type must be 0)"));
            }
            expect_end(&mut lines, "$EndMeshFormat")?;
            version
        }
        "$NOD" => {
            read_nodes_v1(&mut lines, &mut raw, scale, "$ENDNOD")?;
            Version::V1
        }
        other => {
            return Err(first.error(format!(
                "expected `$MeshFormat` (Gmsh 2.x/4.1) or `$NOD` (Gmsh v1), found `{}`",
                shorten(other)
            )))
        }
    };

    while let Some(line) = lines.next() {
        match (version, line.text) {
            (Version::V1, "$NOD") => read_nodes_v1(&mut lines, &mut raw, scale, "$ENDNOD")?,
            (Version::V1, "$ELM") => read_elements_v1(&mut lines, &mut raw, "$ENDELM")?,
            (Version::V2, "$Nodes") => read_nodes_v1(&mut lines, &mut raw, scale, "$EndNodes")?,
            (Version::V2, "$Elements") => read_elements_v2(&mut lines, &mut raw)?,
            (Version::V41, "$Nodes") => read_nodes_v41(&mut lines, &mut raw, scale)?,
            (Version::V41, "$Elements") => read_elements_v41(&mut lines, &mut raw)?,
            (_, s) if s.starts_with('$') && !s.starts_with("$End") && !s.starts_with("$END") => {
                // An unknown section ($PhysicalNames, $Entities, $NodeData, ...): skip it.
                let end = format!("$End{}", &s[1..]);
                let end_v1 = format!("$END{}", &s[1..]);
                loop {
                    let l = lines.expect_line(&format!("`{end}`"))?;
                    if l.text == end || l.text == end_v1 {
                        break;
                    }
                }
            }
            (_, s) => {
                return Err(line.error(format!(
                    "expected a section start such as `$Nodes`, found `{}`",
                    shorten(s)
                )))
            }
        }
    }
    let (nodes_name, elements_name) = match version {
        Version::V1 => ("$NOD", "$ELM"),
        _ => ("$Nodes", "$Elements"),
    };
    if !raw.saw_nodes {
        return Err(MeshError::file(
            path,
            format!("missing `{nodes_name}` section"),
        ));
    }
    if !raw.saw_elements {
        return Err(MeshError::file(
            path,
            format!("missing `{elements_name}` section"),
        ));
    }
    let (mesh, mut report) = TetMesh::from_raw(raw.nodes, raw.tets, path)?;
    report.skipped_elements = raw.skipped;
    Ok((mesh, report))
}

/// At most 40 characters of `s`, for error messages.
fn shorten(s: &str) -> String {
    if s.chars().count() > 40 {
        format!("{}...", s.chars().take(40).collect::<String>())
    } else {
        s.to_string()
    }
}

/// The next record line of a section, described by `what` (e.g. "node 3 of 10"); a section
/// marker (`$...`) there means the section's count was wrong.
fn record_line<'a>(lines: &mut Lines<'a>, what: &str) -> Result<Line<'a>, MeshError> {
    let l = lines.expect_line(what)?;
    if l.text.starts_with('$') {
        return Err(l.error(format!("expected {what}, found `{}`", l.text)));
    }
    Ok(l)
}

/// Consume the line closing a section, which must be `end`.
fn expect_end(lines: &mut Lines<'_>, end: &str) -> Result<(), MeshError> {
    let l = lines.expect_line(&format!("`{end}`"))?;
    if l.text == end {
        Ok(())
    } else {
        Err(l.error(format!(
            "expected `{end}`, found `{}` (wrong count?)",
            shorten(l.text)
        )))
    }
}

/// A single count on its own line.
fn read_count(lines: &mut Lines<'_>, what: &str) -> Result<usize, MeshError> {
    let l = lines.expect_line(what)?;
    let mut f = l.fields();
    let n = f.next::<usize>(what)?;
    if !f.rest().is_empty() {
        return Err(l.error(format!("unexpected fields after the {what}")));
    }
    Ok(n)
}

/// Nodes of Gmsh v1 (`$NOD`) and 2.2 (`$Nodes`): a count, then `id x y z` lines, then `end`.
fn read_nodes_v1(
    lines: &mut Lines<'_>,
    raw: &mut Raw,
    scale: Real,
    end: &str,
) -> Result<(), MeshError> {
    raw.saw_nodes = true;
    let n = read_count(lines, "number of nodes")?;
    raw.nodes.reserve(prealloc(n));
    for k in 0..n {
        let l = record_line(lines, &format!("node {} of {n}", k + 1))?;
        let mut f = l.fields();
        let id: i64 = f.next("node id")?;
        let p = f.next_point(scale)?;
        raw.add_node(&l, id, p)?;
    }
    expect_end(lines, end)
}

/// Elements of Gmsh v1: `number type reg-phys reg-elem n-nodes node-ids...`.
fn read_elements_v1(lines: &mut Lines<'_>, raw: &mut Raw, end: &str) -> Result<(), MeshError> {
    raw.saw_elements = true;
    let n = read_count(lines, "number of elements")?;
    for k in 0..n {
        let l = record_line(lines, &format!("element {} of {n}", k + 1))?;
        let mut f = l.fields();
        let _number: i64 = f.next("element number")?;
        let kind: u32 = f.next("element type")?;
        let _phys: i64 = f.next("physical region")?;
        let _elem: i64 = f.next("elementary region")?;
        let count: usize = f.next("number of nodes")?;
        let ids = f.rest();
        if ids.len() != count {
            return Err(l.error(format!(
                "element declares {count} nodes but lists {}",
                ids.len()
            )));
        }
        if kind == GMSH_TET {
            let t = raw.tet(&l, &ids)?;
            raw.tets.push(t);
        } else {
            raw.skipped += 1;
        }
    }
    expect_end(lines, end)
}

/// Elements of Gmsh 2.2: `number type n-tags tags... node-ids...`.
fn read_elements_v2(lines: &mut Lines<'_>, raw: &mut Raw) -> Result<(), MeshError> {
    raw.saw_elements = true;
    let n = read_count(lines, "number of elements")?;
    for k in 0..n {
        let l = record_line(lines, &format!("element {} of {n}", k + 1))?;
        let mut f = l.fields();
        let _number: i64 = f.next("element number")?;
        let kind: u32 = f.next("element type")?;
        let ntags: usize = f.next("number of tags")?;
        let rest = f.rest();
        if rest.len() < ntags {
            return Err(l.error(format!(
                "element declares {ntags} tags but has only {} fields after them",
                rest.len()
            )));
        }
        let ids = &rest[ntags..];
        let expected = nodes_per_element(kind);
        if expected != 0 && ids.len() != expected {
            return Err(l.error(format!(
                "element of type {kind} needs {expected} node ids, found {}",
                ids.len()
            )));
        }
        if kind == GMSH_TET {
            let t = raw.tet(&l, ids)?;
            raw.tets.push(t);
        } else {
            raw.skipped += 1;
        }
    }
    expect_end(lines, "$EndElements")
}

/// Nodes of Gmsh 4.1: blocks of tags then coordinates.
fn read_nodes_v41(lines: &mut Lines<'_>, raw: &mut Raw, scale: Real) -> Result<(), MeshError> {
    raw.saw_nodes = true;
    let h = lines.expect_line("the `$Nodes` header")?;
    let mut f = h.fields();
    let blocks: usize = f.next("number of entity blocks")?;
    let total: usize = f.next("number of nodes")?;
    let _min: i64 = f.next("minimum node tag")?;
    let _max: i64 = f.next("maximum node tag")?;
    let mut seen = 0usize;
    for b in 0..blocks {
        let bh = lines.expect_line(&format!("header of node block {} of {blocks}", b + 1))?;
        let mut f = bh.fields();
        let _dim: i64 = f.next("entity dimension")?;
        let _tag: i64 = f.next("entity tag")?;
        let parametric: u32 = f.next("parametric flag")?;
        let count: usize = f.next("number of nodes in block")?;
        let mut tags = Vec::with_capacity(prealloc(count));
        for k in 0..count {
            let l = lines.expect_line(&format!("node tag {} of {count}", k + 1))?;
            let mut f = l.fields();
            let tag: i64 = f.next("node tag")?;
            tags.push(tag);
        }
        for (k, &tag) in tags.iter().enumerate() {
            let l = lines.expect_line(&format!("coordinates of node {} of {count}", k + 1))?;
            let mut f = l.fields();
            let p = f.next_point(scale)?;
            if parametric == 0 && !f.rest().is_empty() {
                return Err(l.error("unexpected fields after the coordinates (wrong count?)"));
            }
            raw.add_node(&l, tag, p)?;
        }
        seen += count;
    }
    if seen != total {
        return Err(h.error(format!(
            "header declares {total} nodes but the blocks hold {seen}"
        )));
    }
    expect_end(lines, "$EndNodes")
}

/// Elements of Gmsh 4.1: blocks of one element type, `tag node-tags...` per line.
fn read_elements_v41(lines: &mut Lines<'_>, raw: &mut Raw) -> Result<(), MeshError> {
    raw.saw_elements = true;
    let h = lines.expect_line("the `$Elements` header")?;
    let mut f = h.fields();
    let blocks: usize = f.next("number of entity blocks")?;
    let total: usize = f.next("number of elements")?;
    let _min: i64 = f.next("minimum element tag")?;
    let _max: i64 = f.next("maximum element tag")?;
    let mut seen = 0usize;
    for b in 0..blocks {
        let bh = lines.expect_line(&format!("header of element block {} of {blocks}", b + 1))?;
        let mut f = bh.fields();
        let _dim: i64 = f.next("entity dimension")?;
        let _tag: i64 = f.next("entity tag")?;
        let kind: u32 = f.next("element type")?;
        let count: usize = f.next("number of elements in block")?;
        let expected = nodes_per_element(kind);
        for k in 0..count {
            let l = record_line(lines, &format!("element {} of {count} of the block", k + 1))?;
            let mut f = l.fields();
            let _number: i64 = f.next("element tag")?;
            let ids = f.rest();
            if expected != 0 && ids.len() != expected {
                return Err(l.error(format!(
                    "element of type {kind} needs {expected} node tags, found {}",
                    ids.len()
                )));
            }
            if kind == GMSH_TET {
                let t = raw.tet(&l, &ids)?;
                raw.tets.push(t);
            } else {
                raw.skipped += 1;
            }
        }
        seen += count;
    }
    if seen != total {
        return Err(h.error(format!(
            "header declares {total} elements but the blocks hold {seen}"
        )));
    }
    expect_end(lines, "$EndElements")
}
