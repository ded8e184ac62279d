//! Legacy VTK ASCII `UNSTRUCTURED_GRID`: the reader (both the classic `CELLS n size` layout
//! and the `OFFSETS` / `CONNECTIVITY` layout of file version 5.x; tetrahedra, cell type 10,
//! are kept, other cells skipped and counted) and the writer [`write_vtk`].

use super::parse::{prealloc, read_text, Tokens};
use super::{MeshError, MeshReport, TetMesh};
use crate::kernels::math::{Real, Vec3};
use std::io::Write;
use std::path::Path;

/// VTK cell type of the linear tetrahedron.
const VTK_TETRA: u32 = 10;

/// Keywords that start a section of a legacy VTK file.
const SECTIONS: [&str; 6] = [
    "POINTS",
    "CELLS",
    "CELL_TYPES",
    "POINT_DATA",
    "CELL_DATA",
    "FIELD",
];

/// The cells of a file: for each cell its node indices and the line where they start.
struct Cells {
    offsets: Vec<usize>,
    connectivity: Vec<u32>,
    lines: Vec<usize>,
}

/// Read a legacy VTK ASCII unstructured grid, positions multiplied by `scale`.
pub(crate) fn read_vtk(path: &Path, scale: Real) -> Result<(TetMesh, MeshReport), MeshError> {
    let text = read_text(path)?;
    let mut lines = text.lines();
    let header = lines.next().unwrap_or("");
    if !header.trim_start().starts_with("# vtk DataFile") {
        return Err(MeshError::at(
            path,
            1,
            "not a legacy VTK file: the first line must start with `# vtk DataFile`",
        ));
    }
    if lines.next().is_none() {
        return Err(MeshError::at(
            path,
            1,
            "unexpected end of file: expected the title line",
        ));
    }
    // Tokens start on line 3 (after the header and the free-text title).
    let start = text
        .match_indices('\n')
        .nth(1)
        .map(|(i, _)| i + 1)
        .unwrap_or(text.len());
    let mut tok = Tokens::new(path, &text, start, 3);
    let (format, line) = tok.expect("`ASCII`")?;
    if format.eq_ignore_ascii_case("BINARY") {
        return Err(MeshError::at(
            path,
            line,
            "binary VTK files are not supported",
        ));
    }
    if !format.eq_ignore_ascii_case("ASCII") {
        return Err(MeshError::at(
            path,
            line,
            format!("expected `ASCII`, found `{format}`"),
        ));
    }
    let (kw, line) = tok.expect("`DATASET`")?;
    if kw != "DATASET" {
        return Err(MeshError::at(
            path,
            line,
            format!("expected `DATASET`, found `{kw}`"),
        ));
    }
    let (kind, line) = tok.expect("the dataset type")?;
    if kind != "UNSTRUCTURED_GRID" {
        return Err(MeshError::at(
            path,
            line,
            format!("dataset type must be UNSTRUCTURED_GRID, found `{kind}`"),
        ));
    }

    let mut points: Option<Vec<Vec3>> = None;
    let mut cells: Option<Cells> = None;
    let mut types: Option<(Vec<u32>, Vec<usize>, usize)> = None;
    while let Some((kw, line)) = tok.next_token() {
        match kw {
            "POINTS" => {
                let n: usize = tok.parse("number of points")?;
                let _dtype = tok.expect("the point data type")?;
                let mut p = Vec::with_capacity(prealloc(n));
                for _ in 0..n {
                    let x = tok.parse_real("x coordinate")?;
                    let y = tok.parse_real("y coordinate")?;
                    let z = tok.parse_real("z coordinate")?;
                    p.push(Vec3::new(x, y, z) * scale);
                }
                points = Some(p);
            }
            "CELLS" => {
                let a: usize = tok.parse("number of cells")?;
                let b: usize = tok.parse("cell list size")?;
                let npoints = points.as_ref().map(|p| p.len());
                let mut peek = tok.clone();
                let new_layout = matches!(peek.next_token(), Some(("OFFSETS", _)));
                cells = Some(if new_layout {
                    read_cells_offsets(&mut tok, a, b, npoints)?
                } else {
                    read_cells_classic(&mut tok, line, a, b, npoints)?
                });
            }
            "CELL_TYPES" => {
                let n: usize = tok.parse("number of cell types")?;
                let mut t = Vec::with_capacity(prealloc(n));
                let mut l = Vec::with_capacity(prealloc(n));
                for _ in 0..n {
                    let v: u32 = tok.parse("cell type")?;
                    t.push(v);
                    l.push(tok.line());
                }
                types = Some((t, l, line));
            }
            "METADATA" => {
                // VTK 5.x metadata: skip it up to the next section keyword.
                let mut peek = tok.clone();
                while let Some((t, _)) = peek.next_token() {
                    if SECTIONS.contains(&t) {
                        break;
                    }
                    tok = peek.clone();
                }
            }
            "POINT_DATA" | "CELL_DATA" | "FIELD" => break,
            other => {
                return Err(MeshError::at(
                    path,
                    line,
                    format!("unexpected `{other}`: expected POINTS, CELLS or CELL_TYPES"),
                ))
            }
        }
    }
    let points = points.ok_or_else(|| MeshError::file(path, "missing POINTS section"))?;
    let cells = cells.ok_or_else(|| MeshError::file(path, "missing CELLS section"))?;
    let (types, type_lines, types_line) =
        types.ok_or_else(|| MeshError::file(path, "missing CELL_TYPES section"))?;
    let ncells = cells.offsets.len() - 1;
    if types.len() != ncells {
        return Err(MeshError::at(
            path,
            types_line,
            format!(
                "CELL_TYPES lists {} cells but CELLS has {ncells}",
                types.len()
            ),
        ));
    }
    let mut tets = Vec::new();
    let mut skipped = 0;
    for (c, &t) in types.iter().enumerate() {
        let ids = &cells.connectivity[cells.offsets[c]..cells.offsets[c + 1]];
        if t == VTK_TETRA {
            if ids.len() != 4 {
                return Err(MeshError::at(
                    path,
                    type_lines[c],
                    format!(
                        "cell {c} has type 10 (tetrahedron) but {} nodes (listed at line {})",
                        ids.len(),
                        cells.lines[c]
                    ),
                ));
            }
            tets.push([ids[0], ids[1], ids[2], ids[3]]);
        } else {
            skipped += 1;
        }
    }
    let (mesh, mut report) = TetMesh::from_raw(points, tets, path)?;
    report.skipped_elements = skipped;
    Ok((mesh, report))
}

/// A node index of a cell, checked against the number of points when known.
fn cell_index(tok: &mut Tokens<'_>, npoints: Option<usize>) -> Result<u32, MeshError> {
    let v: u32 = tok.parse("point index")?;
    if let Some(n) = npoints {
        if v as usize >= n {
            return Err(tok.error(format!(
                "point index {v} is out of range: the file has {n} points"
            )));
        }
    }
    Ok(v)
}

/// Classic layout: `CELLS n size`, then per cell `k i1 ... ik`.
fn read_cells_classic(
    tok: &mut Tokens<'_>,
    line: usize,
    n: usize,
    size: usize,
    npoints: Option<usize>,
) -> Result<Cells, MeshError> {
    let mut cells = Cells {
        offsets: vec![0],
        connectivity: Vec::with_capacity(prealloc(size.saturating_sub(n))),
        lines: Vec::with_capacity(prealloc(n)),
    };
    let mut used = 0usize;
    for _ in 0..n {
        let k: usize = tok.parse("number of cell nodes")?;
        cells.lines.push(tok.line());
        for _ in 0..k {
            let v = cell_index(tok, npoints)?;
            cells.connectivity.push(v);
        }
        used += k + 1;
        cells.offsets.push(cells.connectivity.len());
    }
    if used != size {
        return Err(tok.error(format!(
            "CELLS (line {line}) declares a list size of {size} but the cells use {used}"
        )));
    }
    Ok(cells)
}

/// VTK 5.x layout: `CELLS n_offsets n_connectivity`, `OFFSETS type` and `CONNECTIVITY type`.
fn read_cells_offsets(
    tok: &mut Tokens<'_>,
    noffsets: usize,
    nconn: usize,
    npoints: Option<usize>,
) -> Result<Cells, MeshError> {
    let _ = tok.expect("`OFFSETS`")?;
    let _dtype = tok.expect("the offsets data type")?;
    if noffsets == 0 {
        return Err(tok.error("CELLS declares 0 offsets (at least 1 is needed)"));
    }
    let mut offsets = Vec::with_capacity(prealloc(noffsets));
    let mut offset_lines = Vec::with_capacity(prealloc(noffsets));
    for k in 0..noffsets {
        let v: usize = tok.parse("offset")?;
        let prev = offsets.last().copied().unwrap_or(0);
        if (k == 0 && v != 0) || v < prev || v > nconn {
            return Err(tok.error(format!(
                "invalid offset {v}: offsets must start at 0, never decrease and not exceed {nconn}"
            )));
        }
        offsets.push(v);
        offset_lines.push(tok.line());
    }
    if offsets.last().copied() != Some(nconn) {
        return Err(tok.error(format!(
            "the last offset must equal the connectivity size {nconn}"
        )));
    }
    let (kw, line) = tok.expect("`CONNECTIVITY`")?;
    if kw != "CONNECTIVITY" {
        return Err(tok.error(format!(
            "expected `CONNECTIVITY` at line {line}, found `{kw}`"
        )));
    }
    let _dtype = tok.expect("the connectivity data type")?;
    let mut connectivity = Vec::with_capacity(prealloc(nconn));
    let mut conn_lines = Vec::with_capacity(prealloc(nconn));
    for _ in 0..nconn {
        connectivity.push(cell_index(tok, npoints)?);
        conn_lines.push(tok.line());
    }
    let lines = offsets[..noffsets - 1]
        .iter()
        .zip(&offset_lines)
        .map(|(&o, &ol)| conn_lines.get(o).copied().unwrap_or(ol))
        .collect();
    Ok(Cells {
        offsets,
        connectivity,
        lines,
    })
}

/// Write `mesh` as legacy VTK (version 2.0) ASCII `UNSTRUCTURED_GRID`, cell type 10. Positions
/// are written with full precision, so that reading the file back gives the same bits.
pub(crate) fn write_vtk(path: &Path, mesh: &TetMesh) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(w, "# vtk DataFile Version 2.0")?;
    writeln!(w, "tissuesim tetrahedral mesh, positions in m")?;
    writeln!(w, "ASCII")?;
    writeln!(w, "DATASET UNSTRUCTURED_GRID")?;
    writeln!(w, "POINTS {} double", mesh.nodes.len())?;
    for p in &mesh.nodes {
        writeln!(w, "{:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    let m = mesh.tets.len();
    writeln!(w, "CELLS {m} {}", 5 * m)?;
    for t in &mesh.tets {
        writeln!(w, "4 {} {} {} {}", t[0], t[1], t[2], t[3])?;
    }
    writeln!(w, "CELL_TYPES {m}")?;
    for _ in 0..m {
        writeln!(w, "{VTK_TETRA}")?;
    }
    w.flush()
}
