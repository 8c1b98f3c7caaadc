//! Gmsh MSH 4.1 files of structured grids, written by the tests that need a mesh of their own.

/// A structured grid of `nx` x `ny` cells on [x0, x0 + w] x [y0, y0 + h], two triangles a
/// cell: (vertices, triangles, boundary edges each with its side "bottom", "right", "top" or "left").
pub type Grid = (Vec<[f64; 2]>, Vec<[usize; 3]>, Vec<([usize; 2], &'static str)>);

pub fn grid(nx: usize, ny: usize, at: [f64; 2], size: [f64; 2]) -> Grid {
    let idx = |i: usize, j: usize| j * (nx + 1) + i;
    let mut v = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            v.push([at[0] + size[0] * i as f64 / nx as f64, at[1] + size[1] * j as f64 / ny as f64]);
        }
    }
    let mut t = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            t.push([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)]);
            t.push([idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)]);
        }
    }
    let mut b = Vec::new();
    for i in 0..nx {
        b.push(([idx(i, 0), idx(i + 1, 0)], "bottom"));
        b.push(([idx(i + 1, ny), idx(i, ny)], "top"));
    }
    for j in 0..ny {
        b.push(([idx(nx, j), idx(nx, j + 1)], "right"));
        b.push(([idx(0, j + 1), idx(0, j)], "left"));
    }
    (v, t, b)
}

/// The physical group of each side of a grid.
pub type Groups<'a> = &'a dyn Fn(&str) -> &'static str;

/// An MSH 4.1 file of the grids given, each with a function naming the physical group of each
/// side; one surface group "body". Vertices at the same coordinates are one (grids that meet
/// along matching vertices make one body), and a side edge two triangles hold is no boundary.
pub fn msh(bodies: &[(Grid, Groups)]) -> String {
    let (mut nodes, mut tris, mut lines) = (Vec::new(), Vec::new(), Vec::<([usize; 2], &str)>::new());
    let mut index = std::collections::HashMap::new();
    for ((v, t, b), group) in bodies {
        let at: Vec<usize> = v
            .iter()
            .map(|p| {
                *index.entry(p.map(f64::to_bits)).or_insert_with(|| {
                    nodes.push(*p);
                    nodes.len() - 1
                })
            })
            .collect();
        tris.extend(t.iter().map(|t| t.map(|a| at[a])));
        lines.extend(b.iter().map(|(e, side)| (e.map(|a| at[a]), group(side))));
    }
    let mut held = std::collections::HashMap::new();
    for t in &tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *held.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    lines.retain(|(e, _)| held[&(e[0].min(e[1]), e[0].max(e[1]))] == 1);
    let mut names: Vec<&str> = lines.iter().map(|l| l.1).collect();
    names.sort();
    names.dedup();
    let mut s = format!("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n{}\n", names.len() + 1);
    for (i, n) in names.iter().enumerate() {
        s += &format!("1 {} \"{n}\"\n", i + 1);
    }
    s += &format!("2 {} \"body\"\n$EndPhysicalNames\n$Entities\n0 {} 1 0\n", names.len() + 1, names.len());
    for i in 0..names.len() {
        s += &format!("{} 0 0 0 1 1 0 1 {} 0\n", i + 1, i + 1);
    }
    s += &format!("1 0 0 0 1 1 0 1 {} 0\n$EndEntities\n", names.len() + 1);
    s += &format!("$Nodes\n1 {0} 1 {0}\n2 1 0 {0}\n", nodes.len());
    for i in 0..nodes.len() {
        s += &format!("{}\n", i + 1);
    }
    for p in &nodes {
        s += &format!("{:?} {:?} 0\n", p[0], p[1]);
    }
    let n = lines.len() + tris.len();
    s += &format!("$EndNodes\n$Elements\n{} {n} 1 {n}\n", names.len() + 1);
    let mut tag = 1;
    for (i, name) in names.iter().enumerate() {
        let mine: Vec<_> = lines.iter().filter(|l| l.1 == *name).collect();
        s += &format!("1 {} 1 {}\n", i + 1, mine.len());
        for (e, _) in mine {
            s += &format!("{tag} {} {}\n", e[0] + 1, e[1] + 1);
            tag += 1;
        }
    }
    s += &format!("2 1 2 {}\n", tris.len());
    for t in &tris {
        s += &format!("{tag} {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
        tag += 1;
    }
    s + "$EndElements\n"
}
