//! The problems CLAIMS rows and figures name by themselves (a row part, a panel or a title per
//! problem), each name written once. These are problem names, not study names: `ex71` here is
//! the built-in problem (`RunSpec::problem`), which study [`super::studies::EX71`] is named
//! after; a problem file is named by its stem (`problems/hertz.toml` is `hertz`). A test holds
//! each to a built-in problem or a problem file under `experiments/problems/`.

/// Example 7.1 (built-in).
pub const EX71: &str = "ex71";
/// Example 7.2 (built-in).
pub const EX72: &str = "ex72";
/// The free-boundary problem (built-in).
pub const FB: &str = "fb";
/// Example 7.2 on rollers (`problems/ex72_rollers.toml`).
pub const EX72_ROLLERS: &str = "ex72_rollers";
/// Hertz's cylinder on a flat (`problems/hertz.toml`).
pub const HERTZ: &str = "hertz";

/// Every problem name above.
pub const ALL: [&str; 5] = [EX71, EX72, FB, EX72_ROLLERS, HERTZ];

/// How the rows name a problem: "Ex. 7.1", "Ex. 7.2", "fb", "Ex. 7.2 on rollers", "Hertz"; any
/// other name as it is.
pub fn label(problem: &str) -> &str {
    match problem {
        EX71 => "Ex. 7.1",
        EX72 => "Ex. 7.2",
        EX72_ROLLERS => "Ex. 7.2 on rollers",
        HERTZ => "Hertz",
        other => other,
    }
}
