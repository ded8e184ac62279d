//! VTU writer: XML `UnstructuredGrid`, ASCII, for ParaView.

use crate::math::{Real, Vec3};
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

/// Write the VTU file (see [`write_vtu`](super::write_vtu)). Inputs are checked before the
/// file is created: every tetrahedron index must be in range and every data array must have
/// one entry per point, else an [`io::ErrorKind::InvalidInput`] error.
pub(crate) fn write_vtu(
    path: &Path,
    positions: &[Vec3],
    tets: &[[u32; 4]],
    point_scalars: &[(&str, &[Real])],
    point_vectors: &[(&str, &[Vec3])],
) -> io::Result<()> {
    let n = positions.len();
    if let Some((t, tet)) = tets
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&i| i as usize >= n))
    {
        return Err(invalid(format!(
            "tetrahedron {t} {tet:?} references a node out of range ({n} points)"
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
        tets.len()
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
    for t in tets {
        writeln!(w, "          {} {} {} {}", t[0], t[1], t[2], t[3])?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(
        w,
        "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    )?;
    for k in 1..=tets.len() {
        writeln!(w, "          {}", 4 * k)?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(
        w,
        "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
    )?;
    for _ in tets {
        writeln!(w, "          10")?;
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
