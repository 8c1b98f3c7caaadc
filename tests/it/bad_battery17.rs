//! Battery 17, finding F2 [silent, minor]: `drift --against` compared a study's reference
//! solution (`references/KEY.json`) by its refinement history and NDF only, so a copy whose
//! reference's stored last-level record was edited (eta_h 26.0 -> 1.5) passed as "drift: none".
//! Against another folder the last level's record is now compared as levels are (the fields a
//! one-solve replay cannot give left out) and the final active set exactly.

use super::common::{scratch, signorini_in};

const REF: &str = "description = \"tiny ex72 with a reference\"\n[defaults]\nproblem = \"ex72\"\nmesh = \"structured:4\"\ntheta = 0.5\nlevels = 8\nmax_ndof = 20000\n[defaults.reference]\ntheta = 0.5\nmin_ndof = 30000\ncontact_term = \"without_full_contact\"\n[[run]]\nid = \"adaptive\"\nrole = \"as-written\"\n";

#[test]
fn drift_against_a_copy_whose_reference_record_was_edited_names_the_field() {
    let dir = scratch("b17-ref");
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    std::fs::write(dir.join("experiments/ref.toml"), REF).unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/ref.toml", "--results", "res"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(std::process::Command::new("cp").args(["-r", "res", "alt"]).current_dir(&dir).status().unwrap().success());
    let against = ["drift", "--against", "alt", "--results", "res", "--experiments", "experiments", "--study", "ref"];
    let (code, out, err) = signorini_in(&dir, &against);
    assert_eq!(code, 0, "an unchanged copy: {out}{err}");
    let file = std::fs::read_dir(dir.join("alt/ref/references")).unwrap().next().unwrap().unwrap().path();
    let mut reference: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    reference["last"]["eta_h"] = serde_json::json!(1.5);
    std::fs::write(&file, serde_json::to_string_pretty(&reference).unwrap()).unwrap();
    let (code, out, err) = signorini_in(&dir, &against);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.contains("last.eta_h") && out.contains("reference "), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}
