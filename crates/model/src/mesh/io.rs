//! Mesh and field output as VTK XML unstructured grids (`.vtu`), which ParaView and meshio open.
//!
//! Points are the P2 nodes (vertices, then edge midpoints). Cells are the quadratic triangles
//! (VTK type 22, nodes `[v0, v1, v2, m01, m12, m20]`) followed by the boundary edges as quadratic
//! lines (VTK type 21, nodes `[a, b, midpoint]`). Cell data `part` is 0 on triangles and the
//! boundary part's code on lines (1 Dirichlet, 2 Neumann, 3 contact).
//! Written by hand: the format is a few lines of XML and the Rust VTK crates pull in far more
//! than this needs.

use super::{Mesh, P2Nodes};
use std::fmt::Write as _;

/// A named field: per point (P2 node) or per triangle.
pub enum Field<'a> {
    Scalar(&'a [f64]),
    Vector(&'a [[f64; 2]]),
    Int(&'a [i32]),
}

impl Field<'_> {
    fn len(&self) -> usize {
        match self {
            Field::Scalar(v) => v.len(),
            Field::Vector(v) => v.len(),
            Field::Int(v) => v.len(),
        }
    }

    /// Write the XML DataArray; `pad` extra zero entries (boundary lines for cell data).
    fn write(&self, name: &str, pad: usize, out: &mut String) {
        let (ty, comps) = match self {
            Field::Scalar(_) => ("Float64", 1),
            Field::Vector(_) => ("Float64", 3),
            Field::Int(_) => ("Int32", 1),
        };
        let _ = writeln!(out, r#"<DataArray type="{ty}" Name="{name}" NumberOfComponents="{comps}" format="ascii">"#);
        match self {
            Field::Scalar(v) => v.iter().for_each(|x| {
                let _ = writeln!(out, "{x:e}");
            }),
            Field::Vector(v) => v.iter().for_each(|x| {
                let _ = writeln!(out, "{:e} {:e} 0", x[0], x[1]);
            }),
            Field::Int(v) => v.iter().for_each(|x| {
                let _ = writeln!(out, "{x}");
            }),
        }
        for _ in 0..pad {
            out.push_str(if comps == 3 { "0 0 0\n" } else { "0\n" });
        }
        out.push_str("</DataArray>\n");
    }
}

/// The VTU document for a mesh with point fields (one value per P2 node) and cell fields (one
/// value per triangle).
pub fn vtu(mesh: &Mesh, nodes: &P2Nodes, point_data: &[(&str, Field)], cell_data: &[(&str, Field)]) -> String {
    let n_tri = mesh.n_triangles();
    let n_line = mesh.boundary.len();
    let mut s = String::new();
    s.push_str(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n",
    );
    let _ = writeln!(s, r#"<Piece NumberOfPoints="{}" NumberOfCells="{}">"#, nodes.len(), n_tri + n_line);
    s.push_str("<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for p in &nodes.coords {
        let _ = writeln!(s, "{:e} {:e} 0", p[0], p[1]);
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for el in &nodes.elements {
        let _ = writeln!(s, "{} {} {} {} {} {}", el[0], el[1], el[2], el[3], el[4], el[5]);
    }
    for b in &nodes.boundary_nodes {
        let _ = writeln!(s, "{} {} {}", b[0], b[1], b[2]);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for i in 1..=n_tri {
        let _ = writeln!(s, "{}", 6 * i);
    }
    for i in 1..=n_line {
        let _ = writeln!(s, "{}", 6 * n_tri + 3 * i);
    }
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    s.push_str(&"22\n".repeat(n_tri));
    s.push_str(&"21\n".repeat(n_line));
    s.push_str("</DataArray>\n</Cells>\n<PointData>\n");
    for (name, f) in point_data {
        assert_eq!(f.len(), nodes.len(), "point field '{name}' has the wrong length");
        f.write(name, 0, &mut s);
    }
    s.push_str("</PointData>\n<CellData>\n");
    let parts: Vec<i32> = std::iter::repeat_n(0, n_tri).chain(mesh.boundary.iter().map(|b| b.part.code())).collect();
    Field::Int(&parts).write("part", 0, &mut s);
    for (name, f) in cell_data {
        assert_eq!(f.len(), n_tri, "cell field '{name}' has the wrong length");
        f.write(name, n_line, &mut s);
    }
    s.push_str("</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    s
}
