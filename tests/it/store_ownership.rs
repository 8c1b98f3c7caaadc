//! The store removes only what it wrote, and studies and results roots are named and placed
//! where they cannot reach into one another: a user's file in a study folder is never removed
//! (`--fresh` refuses, naming it), a manifest's file name that cannot name a study is refused,
//! and a results root inside a study folder is refused.

use crate::common::{scratch, signorini_in, stored_study, stored_two_short_runs as stored};

const STUDY: &str = "description = \"two runs\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\n\
[[run]]\nid = \"a\"\nlevels = 2\nsave_levels = [1]\n[[run]]\nid = \"b\"\nlevels = 2\n";

#[test]
fn fresh_refuses_a_folder_holding_files_it_did_not_write_and_removes_nothing() {
    let dir = scratch("own-fresh");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    let planted = ["res/s/runs/notes.txt", "res/s/meshes/notes.txt", "res/s/runs/a.json.bak"];
    for f in planted {
        std::fs::write(dir.join(f), "mine").unwrap();
    }
    // a study stored inside the study's runs/ by a --results that pointed there
    std::fs::create_dir_all(dir.join("res/s/runs/inner/t/runs")).unwrap();
    for args in [&["run", "exp/s.toml", "--fresh", "--results", "res"][..], &["run", "exp/s.toml", "--fresh", "--plan", "--results", "res"]]
    {
        let (code, out, err) = signorini_in(&dir, args);
        assert_eq!(code, 1, "{args:?}: {out}{err}");
        for name in ["runs/notes.txt", "meshes/notes.txt", "runs/a.json.bak", "runs/inner"] {
            assert!(err.contains(name), "{args:?} does not name {name}: {err}");
        }
        assert!(err.contains("nothing was removed"), "{err}");
    }
    for f in planted.iter().chain(&["res/s/runs/a.json", "res/s/runs/b.json", "res/s/meshes/a_level1.vtu"]) {
        assert!(dir.join(f).exists(), "{f} was removed");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn fresh_plan_lists_every_file_fresh_removes_and_a_file_beside_them_refuses_it() {
    let dir = scratch("own-plan");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    let (code, out, err) = signorini_in(&dir, &["run", "exp/s.toml", "--fresh", "--plan", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    let listed = out.lines().next().unwrap();
    let stored: Vec<String> =
        ["levels.csv", "meshes/a_level1.json", "meshes/a_level1.vtu", "provenance.json", "runs/a.json", "runs/b.json"]
            .iter()
            .map(|f| format!("res/s/{f}"))
            .collect();
    assert_eq!(listed, format!("s (--fresh first removes {} file(s): {})", stored.len(), stored.join(", ")));
    std::fs::write(dir.join("res/s/levels.csv.keep"), "").unwrap();
    let (code, _, err) = signorini_in(&dir, &["run", "exp/s.toml", "--fresh", "--results", "res"]);
    assert_eq!(code, 1, "a file beside levels.csv is not the store's: {err}");
    assert!(err.contains("levels.csv.keep"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_manifest_whose_file_name_cannot_name_a_study_is_refused_naming_the_rule() {
    let dir = scratch("own-names");
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    for (file, rule) in [
        ("..toml", "names a folder that is no study's own"),
        (".hidden.toml", "starts with `.`"),
        ("figures.toml", "holds for other outputs"),
        ("report.toml", "holds for other outputs"),
        ("my study.toml", "holds ' '"),
    ] {
        std::fs::write(dir.join("exp").join(file), STUDY).unwrap();
        let path = format!("exp/{file}");
        let (code, out, err) = signorini_in(&dir, &["run", &path, "--results", "res"]);
        assert_eq!(code, 1, "{file}: {out}{err}");
        assert!(err.contains("a study is named after its manifest's file") && err.contains(rule), "{file}: {err}");
        std::fs::remove_file(dir.join("exp").join(file)).unwrap();
    }
    assert!(!dir.join("res").exists(), "a refused manifest wrote into the results root");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_results_root_inside_a_study_folder_is_refused_before_anything_is_read() {
    let dir = scratch("own-place");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    std::fs::write(dir.join("exp/t.toml"), STUDY).unwrap();
    let before = std::fs::read(dir.join("res/s/runs/a.json")).unwrap();
    for args in [
        &["run", "exp/t.toml", "--results", "res/s"][..],
        &["run", "exp/t.toml", "--results", "res/s/runs", "--replace"],
        &["run", "exp/t.toml", "--results", "res/s/meshes/deeper"],
        &["figures", "--experiments", "exp", "--results", "res/s"],
        &["report", "--experiments", "exp", "--results", "res/s"],
        &["drift", "--experiments", "exp", "--results", "res", "--against", "res/s"],
    ] {
        let (code, out, err) = signorini_in(&dir, args);
        assert_eq!(code, 1, "{args:?}: {out}{err}");
        assert!(err.contains("is inside the study folder") && err.contains("nothing was read or written"), "{args:?}: {err}");
    }
    assert_eq!(std::fs::read(dir.join("res/s/runs/a.json")).unwrap(), before);
    assert!(!dir.join("res/s/t").exists() && !dir.join("res/s/runs/t").exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_default_output_folder_inside_a_study_folder_is_named_as_the_default_not_as_a_flag_given() {
    let dir = scratch("own-default-out");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    // a study folder under a name the results root keeps for outputs (stored before names were checked)
    std::fs::rename(dir.join("res/s"), dir.join("res/figures")).unwrap();
    std::fs::create_dir_all(dir.join("res/report/runs")).unwrap();
    for (args, default) in [
        (&["figures", "--results", "res", "--experiments", "exp"], "the default output folder (--figures)"),
        (&["report", "--results", "res", "--experiments", "exp"], "the default output folder (--out)"),
    ] {
        let (code, out, err) = signorini_in(&dir, args);
        assert_eq!(code, 1, "{args:?}: {out}{err}");
        assert!(err.contains(default) && err.contains("is inside the study folder"), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn no_output_flag_writes_into_a_study_folder() {
    let dir = stored("store-ownership-no-output-flag");
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
