//! The seventh battery of hostile inputs (issue 38): findings fixed in `main` itself (the others
//! are in the modules of the function each went through).
//!
//! * A node of the closure of Gamma_C with one prescribed component (rollers meeting the contact
//!   part, a symmetry hold on it) was not a contact node, so u . n <= chi held nowhere there: the
//!   body sank into the obstacle and the answer was certified. `plausible::check_prescribed`
//!   refuses it, naming the node, wherever the normal has a part along the free component.

use crate::common::signorini_in;

fn tmp(name: &str) -> std::path::PathBuf {
    crate::common::scratch(&format!("battery7-{name}"))
}

const BLOCK: &str = "dirichlet = DIRICHLET\nPOINT\n[material]\nmu = 1\nlambda = 1\n[parts]\ncontact = \"y < 1e-12\"\ndirichlet = DPART\n[contact]\nnormal = \"outward\"\nchi = 0\n";

#[test]
fn bad_a_contact_node_with_one_prescribed_component_is_refused_by_name() {
    let dir = tmp("half");
    // (name, dirichlet, point constraint, Dirichlet part, the node, what prescribes it)
    let cases = [
        (
            "point",
            "[\"0\", \"-0.1\"]",
            "[[point_constraints]]\nat = [0.5, 0]\nu = [0, \"free\"]",
            "\"y > 1 - 1e-12\"",
            "(0.5, 0)",
            "a point constraint",
        ),
        (
            "rollers",
            "[0, \"free\"]",
            "traction = [\"0\", \"-max(0, ny)\"]\n[[point_constraints]]\nat = [0, 1]\nu = [\"free\", -0.05]",
            "\"x < 1e-12\"",
            "(0, 0)",
            "the Dirichlet data",
        ),
    ];
    for (name, dirichlet, point, dpart, node, by) in cases {
        let text = BLOCK.replace("DIRICHLET", dirichlet).replace("POINT", point).replace("DPART", dpart);
        // `traction` must come before the first table
        let text = match text.find("traction") {
            Some(_) => {
                let line = text.lines().find(|l| l.starts_with("traction")).unwrap().to_string();
                format!("{line}\n{}", text.replace(&format!("{line}\n"), ""))
            }
            None => text,
        };
        std::fs::write(dir.join("v.toml"), text).unwrap();
        let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "structured:4"]);
        assert_eq!(code, 1, "{name}: {out}{err}");
        for part in [
            format!("the node at {node} on the closure of the contact part"),
            format!("u_1 prescribed by {by}"),
            "acts on the free u_2".into(),
        ] {
            assert!(err.contains(&part), "{name}: no {part:?} in {err}");
        }
    }
    // the same block with both components prescribed on the contact side's end: solved
    let text = BLOCK.replace("DIRICHLET", "[0, 0]").replace("POINT", "").replace("DPART", "\"x < 1e-12\"");
    std::fs::write(dir.join("v.toml"), format!("body_force = [\"0\", \"-1\"]\n{text}")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 0, "{err}");
}
