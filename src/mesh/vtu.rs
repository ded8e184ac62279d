//! VTU writer: XML `UnstructuredGrid`, ASCII, for ParaView: tetrahedra (cell type 10) or
//! triangles (cell type 5, surfaces).

use crate::kernels::math::{Real, Vec3};
use std::io::{self, Write};
use std::path::Path;

/// Escape a string for an XML attribute value.
fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// VTK cell type of a tetrahedron.
pub(crate) const VTK_TETRA: u8 = 10;
/// VTK cell type of a triangle.
pub(crate) const VTK_TRIANGLE: u8 = 5;

/// Write the VTU file (see [`write_vtu`](super::write_vtu)): cells of `K` points each, all of
/// VTK type `cell_type`. Inputs are checked before the file is created: every cell index must
/// be in range and every data array must have one entry per point, else an
/// [`io::ErrorKind::InvalidInput`] error.
pub(crate) fn write_vtu<const K: usize>(
    path: &Path,
    positions: &[Vec3],
    cells: &[[u32; K]],
    cell_type: u8,
    point_scalars: &[(&str, &[Real])],
    point_vectors: &[(&str, &[Vec3])],
) -> io::Result<()> {
    let n = positions.len();
    if let Some((c, cell)) = cells
        .iter()
        .enumerate()
        .find(|(_, c)| c.iter().any(|&i| i as usize >= n))
    {
        return Err(invalid(format!(
            "cell {c} {cell:?} references a point out of range ({n} points)"
        )));
    }
    for (name, a) in point_scalars {
        if a.len() != n {
            return Err(invalid(format!(
                "point scalar `{name}` has {} values for {n} points",
                a.len()
            )));
        }
    }
    for (name, a) in point_vectors {
        if a.len() != n {
            return Err(invalid(format!(
                "point vector `{name}` has {} values for {n} points",
                a.len()
            )));
        }
    }

    let mut w = io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\">"
    )?;
    writeln!(w, "  <UnstructuredGrid>")?;
    writeln!(
        w,
        "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{}\">",
        cells.len()
    )?;
    writeln!(w, "      <PointData>")?;
    for (name, a) in point_scalars {
        writeln!(
            w,
            "        <DataArray type=\"Float64\" Name=\"{}\" format=\"ascii\">",
            xml_escape(name)
        )?;
        for v in a.iter() {
            writeln!(w, "          {v:?}")?;
        }
        writeln!(w, "        </DataArray>")?;
    }
    for (name, a) in point_vectors {
        writeln!(
            w,
            "        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"3\" \
             format=\"ascii\">",
            xml_escape(name)
        )?;
        for v in a.iter() {
            writeln!(w, "          {:?} {:?} {:?}", v.x, v.y, v.z)?;
        }
        writeln!(w, "        </DataArray>")?;
    }
    writeln!(w, "      </PointData>")?;
    writeln!(w, "      <Points>")?;
    writeln!(
        w,
        "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" \
         format=\"ascii\">"
    )?;
    for p in positions {
        writeln!(w, "          {:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(w, "      </Points>")?;
    writeln!(w, "      <Cells>")?;
    writeln!(
        w,
        "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    )?;
    for c in cells {
        write!(w, "         ")?;
        for i in c {
            write!(w, " {i}")?;
        }
        writeln!(w)?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(
        w,
        "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    )?;
    for k in 1..=cells.len() {
        writeln!(w, "          {}", K * k)?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(
        w,
        "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
    )?;
    for _ in cells {
        writeln!(w, "          {cell_type}")?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(w, "      </Cells>")?;
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </UnstructuredGrid>")?;
    writeln!(w, "</VTKFile>")?;
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_names() {
        assert_eq!(xml_escape("a<b&\"c\""), "a&lt;b&amp;&quot;c&quot;");
    }
}
