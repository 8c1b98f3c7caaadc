//! What `export` and `adapt --save` write: VTU files ParaView and meshio open, with the
//! estimator's element indicators as a cell field (the marking's eta_T); `export` also its
//! terms per node and the contact forces' round-off bounds (the NGSolve cross-check's input).

use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_signorini"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The values of the cell field `name` and the declared number of cells.
fn cell_field(vtu: &str, name: &str) -> (usize, Vec<f64>) {
    let cells = vtu.split("NumberOfCells=\"").nth(1).and_then(|s| s.split('"').next()).unwrap().parse().unwrap();
    let cell_data = vtu.split("<CellData").nth(1).unwrap_or_else(|| panic!("no CellData"));
    let start = cell_data.find(&format!("Name=\"{name}\"")).unwrap_or_else(|| panic!("no cell field {name}"));
    let body = &cell_data[start..];
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    (cells, body.split_whitespace().map(|v| v.parse().unwrap()).collect())
}

/// Checks the `indicator` cell field of a VTU: one value per cell, finite and non-negative on
/// the triangles (VTK type 22), some positive, zero on the boundary lines (type 21) that carry the
/// parts; returns the number of triangles.
fn check_indicators(vtu: &Path) -> usize {
    let text = std::fs::read_to_string(vtu).unwrap_or_else(|e| panic!("{}: {e}", vtu.display()));
    let (cells, eta) = cell_field(&text, "indicator");
    assert_eq!(eta.len(), cells, "{}: one value per cell", vtu.display());
    let types = text.split("Name=\"types\"").nth(1).unwrap();
    let types: Vec<&str> = types[types.find('>').unwrap() + 1..types.find("</DataArray>").unwrap()].split_whitespace().collect();
    let triangles = types.iter().filter(|t| **t == "22").count();
    assert_eq!(types.len(), cells);
    assert!(types[..triangles].iter().all(|t| *t == "22") && types[triangles..].iter().all(|t| *t == "21"));
    let (on_triangles, on_lines) = eta.split_at(triangles);
    assert!(on_triangles.iter().all(|v| v.is_finite() && *v >= 0.0), "{}", vtu.display());
    assert!(on_triangles.iter().any(|v| *v > 0.0), "{}: all indicators zero", vtu.display());
    assert!(on_lines.iter().all(|v| *v == 0.0), "{}", vtu.display());
    triangles
}

#[test]
fn export_writes_the_element_indicators() {
    let out = scratch("cli-output-export");
    let o = bin().args(["export", "--problem", "ex71", "--mesh", "structured:4", "--out"]).arg(&out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let case: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("case.json")).unwrap()).unwrap();
    assert_eq!(check_indicators(&out.join("mesh.vtu")) as u64, case["n_elements"].as_u64().unwrap());
}

/// The values of the point field `name`.
fn point_field(vtu: &str, name: &str) -> Vec<f64> {
    let point_data = vtu.split("<PointData>").nth(1).and_then(|s| s.split("</PointData>").next()).unwrap();
    let start = point_data.find(&format!("Name=\"{name}\"")).unwrap_or_else(|| panic!("no point field {name}"));
    let body = &point_data[start..];
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    body.split_whitespace().map(|v| v.parse().unwrap()).collect()
}

/// The cross-check's fields: eta_{i,p} per node (eta1 .. eta5), whose maxima are case.json's
/// eta_1 .. eta_5 exactly, and the contact forces' round-off bounds, zero off the contact nodes.
#[test]
fn export_writes_the_nodal_terms_and_the_force_floors() {
    let out = scratch("cli-output-export-nodal");
    let o = bin().args(["export", "--problem", "fb", "--mesh", "structured:8", "--out"]).arg(&out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let case: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("case.json")).unwrap()).unwrap();
    let vtu = std::fs::read_to_string(out.join("mesh.vtu")).unwrap();
    let nodes = case["ndof"].as_u64().unwrap() as usize / 2;
    for i in 1..=5 {
        let eta = point_field(&vtu, &format!("eta{i}"));
        assert_eq!(eta.len(), nodes);
        assert_eq!(eta.iter().fold(0.0f64, |a, v| a.max(*v)), case["estimator"][format!("eta{i}")].as_f64().unwrap(), "eta{i}");
    }
    let (floor, contact) = (point_field(&vtu, "lambda_floor"), point_field(&vtu, "contact"));
    assert!(floor.iter().zip(&contact).all(|(f, c)| if *c == 1.0 { *f > 0.0 } else { *f == 0.0 }));
}

#[test]
fn adapt_saves_its_last_level() {
    let out = scratch("cli-output-adapt");
    let vtu = out.join("last.vtu");
    let o = bin().args(["adapt", "--problem", "fb", "--levels", "4", "--save"]).arg(&vtu).output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // the table's last row is level 3; the file has that level's triangles
    let last = stdout.lines().rfind(|l| l.trim_start().starts_with(char::is_numeric)).unwrap();
    let ndof: usize = last.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(stdout.contains(&format!("wrote {} (level 3, NDF {ndof})", vtu.display())), "{stdout}");
    let cells = check_indicators(&vtu);
    assert!(cells > 32, "level 3 of an adaptive run has more triangles than structured:4's 32 ({cells})");
}

#[test]
fn adapt_refuses_a_save_path_in_a_missing_folder_before_solving() {
    let o = bin().args(["adapt", "--problem", "fb", "--levels", "30", "--save", "/nonexistent/folder/last.vtu"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(stderr.contains("--save /nonexistent/folder/last.vtu") && stderr.contains("/nonexistent/folder does not exist"), "{stderr}");
    assert!(o.stdout.is_empty(), "nothing solved: {}", String::from_utf8_lossy(&o.stdout));
}
