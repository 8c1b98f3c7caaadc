//! The contact terms a claim is judged for, and runs that coincide.
//!
//! Every claim of Section 7 is judged once per contact term of eta_5 (as the paper writes it,
//! without full-contact nodes, repaired), each on its own adaptive run of the same problem. Where
//! two terms' runs coincide (the same NDF and errors at every level: the repaired term's tensile
//! part never switches on), their rows are one row that names both terms and says so; where they
//! part, each term has its own row and the row says at which level they part.

use super::{Ctx, Q, source};
use model::settings::estimator::ContactTerm;
use store::records::RunRecord;

/// Two runs coincide when their errors agree to this relative difference at every common level
/// (and their NDF exactly).
pub const COINCIDE_REL: f64 = 1e-12;

/// The contact terms, in the order rows and the headline list them.
pub const ALL: [ContactTerm; 3] = [ContactTerm::AsWritten, ContactTerm::WithoutFullContact, ContactTerm::TensileOnFullContact];

/// A contact term in words: "eta_5 as written", "without full-contact nodes", "repaired".
pub fn name(t: ContactTerm) -> &'static str {
    match t {
        ContactTerm::AsWritten => "eta_5 as written",
        ContactTerm::WithoutFullContact => "without full-contact nodes",
        ContactTerm::TensileOnFullContact => "repaired",
    }
}

/// Where two runs part: the first level whose NDF differ or whose errors differ by more than
/// [`COINCIDE_REL`] (relative), over their common levels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Coincidence {
    /// Levels both runs have.
    pub common: usize,
    /// The first level where they differ; None: they coincide at every common level.
    pub parts_at: Option<usize>,
}

/// Where `a` and `b` part ([`Coincidence`]), comparing `errors` of each (one per level).
pub fn coincidence(a: &RunRecord, ea: &[Option<f64>], b: &RunRecord, eb: &[Option<f64>]) -> Coincidence {
    let common = a.levels.len().min(b.levels.len());
    let parts_at = (0..common).find(|&i| {
        a.levels[i].ndof != b.levels[i].ndof
            || match (ea[i], eb[i]) {
                (Some(x), Some(y)) => (x - y).abs() > COINCIDE_REL * x.abs().max(y.abs()),
                (x, y) => x.is_some() != y.is_some(),
            }
    });
    Coincidence { common, parts_at }
}

/// "deep/ex71_repaired coincides with deep/ex71_without_full_contact at all 28 common levels
/// (same NDF and errors)" or "... parts from ... at level 11 (NDF 3124 against 3080)".
pub fn coincidence_text(a: &RunRecord, b: &RunRecord, c: Coincidence) -> String {
    match c.parts_at {
        None => format!("{} coincides with {} at all {} common levels (same NDF and errors)", source(Some(a)), source(Some(b)), c.common),
        Some(i) => format!(
            "{} parts from {} at level {i} (NDF {} against {})",
            source(Some(a)),
            source(Some(b)),
            a.levels[i].ndof,
            b.levels[i].ndof
        ),
    }
}

/// The run one row judges, and the contact terms it stands for.
#[derive(Clone, Debug)]
pub struct TermRun<'a> {
    /// One term, or two whose runs coincide (without full-contact nodes and repaired).
    pub terms: Vec<ContactTerm>,
    pub run: Option<&'a RunRecord>,
    /// Where the repaired run stands against the one without full-contact nodes (coinciding or
    /// parting), on the rows of either; empty for eta_5 as written.
    pub note: String,
}

impl TermRun<'_> {
    /// What the row's id and topic add for its terms: "" for eta_5 as written (the paper's
    /// rows keep their plain names), " (without full-contact nodes = repaired)" for two.
    pub fn suffix(&self) -> String {
        match self.terms.as_slice() {
            [ContactTerm::AsWritten] => String::new(),
            ts => format!(" ({})", ts.iter().map(|t| name(*t)).collect::<Vec<_>>().join(" = ")),
        }
    }

    /// The terms in words: "eta_5 as written", "without full-contact nodes = repaired".
    pub fn names(&self) -> String {
        self.terms.iter().map(|t| name(*t)).collect::<Vec<_>>().join(" = ")
    }

    /// ": deep/ex71_repaired coincides with ..." to end a row's measured text, or "".
    pub fn note_text(&self) -> String {
        if self.note.is_empty() { String::new() } else { format!(". {}", self.note) }
    }
}

/// The runs of one problem per contact term, the repaired run merged into the one without
/// full-contact nodes where the two coincide ([`coincidence`] on the error in `ctx`'s sampling).
pub(super) fn per_term<'a>(
    ctx: &Ctx,
    as_written: Option<&'a RunRecord>,
    without_full_contact: Option<&'a RunRecord>,
    repaired: Option<&'a RunRecord>,
) -> Vec<TermRun<'a>> {
    let one = |t: ContactTerm, run: Option<&'a RunRecord>, note: String| TermRun { terms: vec![t], run, note };
    let mut out = vec![one(ContactTerm::AsWritten, as_written, String::new())];
    match (without_full_contact, repaired) {
        (Some(w), Some(r)) => {
            let c = coincidence(r, &ctx.values(r, Q::Error), w, &ctx.values(w, Q::Error));
            let note = coincidence_text(r, w, c);
            if c.parts_at.is_none() {
                out.push(TermRun { terms: vec![ContactTerm::WithoutFullContact, ContactTerm::TensileOnFullContact], run: Some(w), note });
            } else {
                out.push(one(ContactTerm::WithoutFullContact, Some(w), note.clone()));
                out.push(one(ContactTerm::TensileOnFullContact, Some(r), note));
            }
        }
        (w, r) => {
            out.push(one(ContactTerm::WithoutFullContact, w, String::new()));
            out.push(one(ContactTerm::TensileOnFullContact, r, String::new()));
        }
    }
    out
}
