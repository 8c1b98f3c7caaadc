//! A Gmsh mesh is read by its node tags: the same mesh written with its nodes renumbered (a
//! random permutation, tags offset, sparse tags; ASCII and binary; by gmsh itself through
//! `gmsh.model.mesh.renumberNodes`, tests/fixtures/gmsh_renumbered/generate.py) solves to the
//! same u_h as the plain file, to round-off, at every probe.

use std::path::Path;
use std::process::Command;

const PROBES: [&str; 6] = ["0.1,0.05", "0.5,0.01", "0.9,0.1", "0.3,0.6", "0.05,0.9", "0.6,0.4"];

/// u_h at the probes and the number of unknowns, from `solve --json`.
fn solve(msh: &str) -> (Vec<[f64; 2]>, u64) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/gmsh_renumbered");
    let mut args =
        vec!["solve".to_string(), "--problem".into(), "quarter_disc.toml".into(), "--mesh".into(), format!("gmsh:{msh}"), "--json".into()];
    for p in PROBES {
        args.extend(["--probe".to_string(), p.to_string()]);
    }
    let o = Command::new(env!("CARGO_BIN_EXE_signorini")).current_dir(&dir).args(&args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{msh}: {err}");
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let probes = v["probes"].as_array().unwrap();
    assert_eq!(probes.len(), PROBES.len(), "{msh}");
    let u = probes.iter().map(|p| [p["u"][0].as_f64().unwrap(), p["u"][1].as_f64().unwrap()]).collect();
    (u, v["ndof"].as_u64().unwrap())
}

#[test]
fn renumbered_meshes_solve_to_the_plain_meshes_u_h() {
    let (plain, ndof) = solve("plain.msh");
    let scale = plain.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(scale > 1e-4, "the plain solve moves: {plain:?}");
    for msh in ["permuted.msh", "permuted_binary.msh", "offset.msh", "sparse.msh", "sparse_binary.msh"] {
        let (u, n) = solve(msh);
        assert_eq!(n, ndof, "{msh}");
        for (p, (a, b)) in PROBES.iter().zip(plain.iter().zip(&u)) {
            for d in 0..2 {
                assert!((a[d] - b[d]).abs() <= 1e-12 * scale, "{msh} at {p}: u_{} = {} here, {} in plain.msh", d + 1, b[d], a[d]);
            }
        }
    }
}

/// The property: a small valid MSH 4.1 ASCII file, written with its nodes under any tags
/// (permuted, offset, sparse), split into blocks in any order, with its whitespace varied, reads
/// as the same geometry; the same file with a tag listed twice is refused, naming the tag.
mod property {
    use proptest::prelude::*;
    use signorini::mesh::gmsh::{GmshFile, read};
    use std::collections::BTreeMap;

    /// Nodes, triangles and boundary edges (by node index).
    type Square = (Vec<[f64; 2]>, Vec<[usize; 3]>, Vec<[usize; 2]>);

    /// The 2 x 2 squares on [0, 1]^2 (9 nodes, 8 triangles) and its 8 boundary edges, by node index.
    fn square() -> Square {
        let nodes = (0..9).map(|k| [0.5 * (k % 3) as f64, 0.5 * (k / 3) as f64]).collect();
        let mut tris = Vec::new();
        for j in 0..2 {
            for i in 0..2 {
                let a = 3 * j + i;
                tris.push([a, a + 1, a + 4]);
                tris.push([a, a + 4, a + 3]);
            }
        }
        let ring = [0, 1, 2, 5, 8, 7, 6, 3];
        let lines = (0..8).map(|k| [ring[k], ring[(k + 1) % 8]]).collect();
        (nodes, tris, lines)
    }

    /// How one file is written.
    #[derive(Clone, Debug)]
    struct Form {
        /// The tag of node k.
        tags: Vec<u64>,
        /// The nodes in the order the file lists them, cut into blocks at these positions.
        order: Vec<usize>,
        cuts: Vec<usize>,
        /// A triangle's vertices rotated by r and reversed.
        turn: Vec<(usize, bool)>,
        /// Separators between numbers on a line, and the end of line.
        space: &'static str,
        eol: &'static str,
    }

    fn form() -> impl Strategy<Value = Form> {
        let tags = prop_oneof![
            // contiguous from an offset, in a random order
            (1u64..2000).prop_flat_map(|o| Just((o..o + 9).collect::<Vec<_>>()).prop_shuffle()),
            // sparse
            prop::collection::btree_set(1u64..1_000_000, 9).prop_flat_map(|s| Just(s.into_iter().collect::<Vec<_>>()).prop_shuffle()),
        ];
        (
            tags,
            Just((0..9).collect::<Vec<usize>>()).prop_shuffle(),
            prop::collection::btree_set(1usize..9, 0..4),
            prop::collection::vec((0usize..3, any::<bool>()), 8),
            prop::sample::select(vec![" ", "  ", "\t", " \t "]),
            prop::sample::select(vec!["\n", "\r\n"]),
        )
            .prop_map(|(tags, order, cuts, turn, space, eol)| Form {
                tags,
                order,
                cuts: cuts.into_iter().collect(),
                turn,
                space,
                eol,
            })
    }

    /// The file's text; `duplicate` lists node `a`'s tag also for node `b`.
    fn write(f: &Form, duplicate: Option<(usize, usize)>) -> String {
        let (nodes, tris, lines) = square();
        let mut tags = f.tags.clone();
        if let Some((a, b)) = duplicate {
            tags[b] = tags[a];
        }
        let row = |v: Vec<String>| v.join(f.space) + f.eol;
        let mut t = String::new();
        let mut put = |s: String| t.push_str(&s);
        // mshio reads the header line only with single spaces (Gmsh writes it so)
        put(row(vec!["$MeshFormat".into()]) + "4.1 0 8" + f.eol + &row(vec!["$EndMeshFormat".into()]));
        put(row(vec!["$PhysicalNames".into()]) + &row(vec!["1".into()]) + &row(vec!["1".into(), "1".into(), "\"ring\"".into()]));
        put(row(vec!["$EndPhysicalNames".into()]));
        put(["$Entities", "0 1 1 0", "1 0 0 0 1 1 0 1 1 0", "1 0 0 0 1 1 0 1 2 1 1", "$EndEntities"]
            .map(|l| row(l.split(' ').map(String::from).collect()))
            .concat());
        let mut bounds = vec![0];
        bounds.extend(&f.cuts);
        bounds.push(9);
        let (min, max) = (tags.iter().min().unwrap(), tags.iter().max().unwrap());
        put(row(vec!["$Nodes".into()]) + &row([bounds.len() as u64 - 1, 9, *min, *max].map(|v| v.to_string()).to_vec()));
        for w in bounds.windows(2) {
            let block = &f.order[w[0]..w[1]];
            put(row(["2", "1", "0"].map(String::from).into_iter().chain([block.len().to_string()]).collect()));
            for &k in block {
                put(row(vec![tags[k].to_string()]));
            }
            for &k in block {
                put(row(vec![format!("{:?}", nodes[k][0]), format!("{:?}", nodes[k][1]), "0".into()]));
            }
        }
        put(row(vec!["$EndNodes".into()]) + &row(vec!["$Elements".into()]) + &row(["2", "16", "1", "16"].map(String::from).to_vec()));
        put(row(["1", "1", "1", "8"].map(String::from).to_vec()));
        for (e, l) in lines.iter().enumerate() {
            put(row(vec![(e + 1).to_string(), tags[l[0]].to_string(), tags[l[1]].to_string()]));
        }
        put(row(["2", "1", "2", "8"].map(String::from).to_vec()));
        for (e, (tri, &(r, rev))) in tris.iter().zip(&f.turn).enumerate() {
            let mut v: Vec<usize> = (0..3).map(|i| tri[(i + r) % 3]).collect();
            if rev {
                v.reverse();
            }
            put(row(std::iter::once((e + 9).to_string()).chain(v.iter().map(|&k| tags[k].to_string())).collect()));
        }
        put(row(vec!["$EndElements".into()]));
        t
    }

    fn read_text(text: &str, name: &str) -> Result<GmshFile, String> {
        let dir = std::env::temp_dir().join(format!("signorini-gmsh-prop-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("{name}.msh"));
        std::fs::write(&path, text).unwrap();
        read(&path).map_err(|e| e.to_string())
    }

    /// The triangles as sorted triples of coordinates, sorted.
    fn geometry(f: &GmshFile) -> Vec<[[u64; 2]; 3]> {
        let mut out: Vec<[[u64; 2]; 3]> = f
            .triangles
            .iter()
            .map(|t| {
                let mut c = t.map(|v| f.vertices[v].map(f64::to_bits));
                c.sort();
                c
            })
            .collect();
        out.sort();
        out
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(38), ..ProptestConfig::default() })]

        #[test]
        fn any_tags_blocks_and_spacing_read_as_the_same_mesh(f in form(), dup in (0usize..9, 1usize..9)) {
            let plain = Form { tags: (1..10).collect(), order: (0..9).collect(), cuts: vec![], turn: vec![(0, false); 8], space: " ", eol: "\n" };
            let want = read_text(&write(&plain, None), "plain").unwrap();
            let got = read_text(&write(&f, None), "varied").map_err(|e| TestCaseError::fail(format!("{e}\n{f:?}")))?;
            prop_assert_eq!(geometry(&got), geometry(&want));
            prop_assert_eq!(got.groups.len(), 1);
            // vertices in ascending tag order
            let (nodes, _, _) = square();
            let tag_of: BTreeMap<[u64; 2], u64> = nodes.iter().zip(&f.tags).map(|(x, &t)| (x.map(f64::to_bits), t)).collect();
            let tags: Vec<u64> = got.vertices.iter().map(|x| tag_of[&x.map(f64::to_bits)]).collect();
            prop_assert!(tags.windows(2).all(|w| w[0] < w[1]), "{:?}", tags);
            // node a's tag also given to node b: refused, naming the tag
            let (a, b) = (dup.0, (dup.0 + dup.1) % 9);
            let err = read_text(&write(&f, Some((a, b))), "dup").err().unwrap_or_default();
            prop_assert!(err.contains(&format!("node tag {} is listed twice", f.tags[a])), "{}", err);
        }
    }
}
