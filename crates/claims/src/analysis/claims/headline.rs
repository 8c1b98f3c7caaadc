//! The headline that opens CLAIMS.md: per contact term of eta_5, how many of the paper's own
//! Section 7 claims reproduce, fail and stay undecided, then the rows beyond the paper and the
//! measurements counted apart. A verdict that is fragile (another window, the other parity of
//! levels or the dense sampling changes it) is counted as undecided, a pass or a failure alike.

use super::{Claim, Kind, RowKind, Verdict, terms};
use model::settings::estimator::ContactTerm;

/// How a row counts in the headline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Count {
    /// Reproduced (or holds) and not fragile.
    Holds,
    /// Not reproduced, different, fails, and not fragile.
    Fails,
    /// Inconclusive, no data, or fragile.
    Undecided,
    /// A measurement without a claim.
    Measured,
}

/// How `c` counts: a fragile verdict is undecided.
pub fn count(c: &Claim) -> Count {
    match c.verdict {
        Verdict::NoClaim => Count::Measured,
        _ if c.fragile.is_some() => Count::Undecided,
        Verdict::Reproduced | Verdict::Holds => Count::Holds,
        Verdict::NotReproduced | Verdict::Different | Verdict::Fails => Count::Fails,
        Verdict::Inconclusive | Verdict::NoData => Count::Undecided,
    }
}

/// The ids of `rows` that count as `which`, without the contact terms their line names
/// ("7.1-error-rate", not "7.1-error-rate (without full-contact nodes = repaired)").
fn ids<'a>(rows: &[&'a Claim], which: Count) -> Vec<&'a str> {
    rows.iter().filter(|c| count(c) == which).map(|c| c.id.split(" (").next().unwrap_or(&c.id)).collect()
}

/// "3 reproduce, 5 fail (7.1-error-rate, ...), 1 undecided (...)"
fn tally(rows: &[&Claim], pass: &str) -> String {
    let part = |which: Count, word: &str| {
        let named = ids(rows, which);
        match named.len() {
            0 => format!("0 {word}"),
            n => format!("{n} {word} ({})", named.join(", ")),
        }
    };
    format!("{}; {}; {}", part(Count::Holds, pass), part(Count::Fails, "fail"), part(Count::Undecided, "undecided"))
}

/// The headline's lines (at most ten), markdown.
pub fn lines(claims: &[Claim]) -> Vec<String> {
    let paper: Vec<&Claim> = claims.iter().filter(|c| c.kind == Kind::Paper).collect();
    let mut out = Vec::new();
    for term in terms::ALL {
        let rows: Vec<&Claim> = paper.iter().copied().filter(|c| c.terms.contains(&term)).collect();
        if rows.is_empty() {
            continue;
        }
        let shared: Vec<&str> = rows.iter().filter(|c| c.terms.len() > 1).map(|c| c.id.as_str()).collect();
        out.push(format!(
            "- **{}**{}: of the paper's {} Section 7 claims, {}{}",
            terms::name(term),
            if term == ContactTerm::AsWritten { " (the paper's estimator)" } else { "" },
            rows.len(),
            tally(&rows, "reproduce"),
            if shared.is_empty() || term == ContactTerm::AsWritten {
                String::new()
            } else {
                format!("; {} of these rows are shared by without full-contact nodes and repaired, whose runs coincide there", shared.len())
            }
        ));
    }
    let beyond: Vec<&Claim> = claims.iter().filter(|c| c.kind == Kind::Beyond && count(c) != Count::Measured).collect();
    let measured = claims.iter().filter(|c| count(c) == Count::Measured).count();
    out.push(format!(
        "- **Beyond the paper** (checks of our own and the paper's claims carried to other problems, counted apart): {} of {} rows hold, {} fail, {} undecided; {measured} rows measure without a claim",
        ids(&beyond, Count::Holds).len(),
        beyond.len(),
        ids(&beyond, Count::Fails).len(),
        ids(&beyond, Count::Undecided).len(),
    ));
    out
}

/// The one-sentence finding under the counts, from the same verdicts: how many of the paper's
/// claims, and of its rate claims, reproduce with eta_5 as written and without full-contact nodes.
pub fn finding(claims: &[Claim]) -> String {
    let of = |t: ContactTerm, rates: bool| {
        let rows: Vec<&Claim> =
            claims.iter().filter(|c| c.kind == Kind::Paper && c.terms.contains(&t) && (!rates || c.row == RowKind::Rate)).collect();
        (ids(&rows, Count::Holds).len(), rows.len())
    };
    let ((aw, n_aw), (aw_r, n_aw_r)) = (of(ContactTerm::AsWritten, false), of(ContactTerm::AsWritten, true));
    let ((wfc, n_wfc), (wfc_r, n_wfc_r)) = (of(ContactTerm::WithoutFullContact, false), of(ContactTerm::WithoutFullContact, true));
    format!(
        "With eta_5 as the paper writes it, {aw} of its {n_aw} Section 7 claims reproduce, {aw_r} of its {n_aw_r} rate claims among them; without the full-contact nodes in eta_5, {wfc} of {n_wfc} do, {wfc_r} of {n_wfc_r} rate claims."
    )
}
