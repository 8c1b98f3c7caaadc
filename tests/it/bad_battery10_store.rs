//! Battery 10, the store, outputs and messages:
//! * F8: an output flag wrote into a study folder without its lock: `drift --report
//!   res/st/runs/a.json` replaced run a's record (the run lost), `adapt --save
//!   res/st/meshes/b_level1.vtu` a snapshot (the folder then refused), `report --out` and
//!   `figures --figures` wrote pages and PNGs into `runs/` and `meshes/`. Every output flag now
//!   refuses a target inside a study folder (one holding `runs/`, `.lock` or `.locks`), before
//!   anything is computed; the defaults, beside the study folders, still work.

use super::common::{scratch, signorini_in};

const STUDY: &str = r#"description = "battery 10: two short runs"
[defaults]
problem = "ex71"
mesh = "structured:4"
levels = 3
save_levels = [1]
[[run]]
id = "a"
[[run]]
id = "b"
theta = 0.3
"#;

/// A scratch folder with `exp/st.toml` ([`STUDY`]) run into `res/`.
fn stored(name: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/st.toml"), STUDY).unwrap();
    let (code, _, err) = signorini_in(&dir, &["run", "exp/st.toml", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    dir
}

#[test]
fn no_output_flag_writes_into_a_study_folder() {
    let dir = stored("battery10-f8");
    let record = std::fs::read(dir.join("res/st/runs/a.json")).unwrap();
    let snapshot = std::fs::read(dir.join("res/st/meshes/b_level1.vtu")).unwrap();
    let tries: [&[&str]; 6] = [
        &["drift", "--experiments", "exp", "--study", "st", "--against", "res", "--results", "res", "--report", "res/st/runs/a.json"],
        &["adapt", "--problem", "ex71", "--levels", "1", "--save", "res/st/meshes/b_level1.vtu"],
        &["report", "--experiments", "exp", "--results", "res", "--out", "res/st/runs"],
        &["figures", "--experiments", "exp", "--results", "res", "--figures", "res/st/meshes"],
        &["export", "--problem", "ex71", "--mesh", "structured:4", "--out", "res/st"],
        // a new file in a subfolder of the study folder, through a symlink to it
        &["adapt", "--problem", "ex71", "--levels", "1", "--save", "link/runs/new.vtu"],
    ];
    std::os::unix::fs::symlink(dir.join("res/st"), dir.join("link")).unwrap();
    for args in tries {
        let (code, out, err) = signorini_in(&dir, args);
        assert_ne!(code, 0, "{args:?}: {out}");
        let folder = if args.contains(&"link/runs/new.vtu") { "link" } else { "res/st" };
        assert!(err.contains(&format!("this is inside the study folder {folder} ")), "{args:?}: {err}");
        assert!(err.contains("Nothing was computed or written"), "{err}");
    }
    assert_eq!(std::fs::read(dir.join("res/st/runs/a.json")).unwrap(), record);
    assert_eq!(std::fs::read(dir.join("res/st/meshes/b_level1.vtu")).unwrap(), snapshot);
    assert!(!dir.join("res/st/runs/new.vtu").exists());
    assert!(!dir.join("res/st/runs/index.html").exists() && !dir.join("res/st/runs/st").exists());
    let (code, _, err) = signorini_in(&dir, &["run", "exp/st.toml", "--results", "res"]);
    assert_eq!(code, 0, "the folder is still sound: {err}");
    // the defaults are beside the study folders: figures, report and drift --against write there
    let (code, _, err) = signorini_in(&dir, &["figures", "--experiments", "exp", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = signorini_in(&dir, &["report", "--experiments", "exp", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("res/figures").is_dir() && dir.join("res/report").is_dir());
    std::fs::remove_dir_all(&dir).ok();
}
